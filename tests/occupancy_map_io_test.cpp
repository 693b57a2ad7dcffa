// 2-D map files (io/occupancy_map_io.hpp): ROS map_server maps against map_server's rule on
// hand-written PGM/PAM/PNG images, round trips, the atomic YAML+PGM pair, ipa PNG maps and
// ground-truth rooms (hand-made and real), label and semantic PNGs, and every error message.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

namespace fs = std::filesystem;
using testing::TempDirTest;

using testing::read_text;
using testing::write_file;

// An ASCII PGM (P2): one row of 8-bit grey levels.
std::string pgm_row(const std::vector<int>& levels) {
  std::string text = "P2\n" + std::to_string(levels.size()) + " 1\n255\n";
  for (int level : levels) text += std::to_string(level) + " ";
  return text + "\n";
}

std::string ros_yaml(const std::string& image, const std::string& extra = "negate: 0\n") {
  return "image: " + image +
         "\nresolution: 0.05\norigin: [1.5, -2.0, 0.25]\noccupied_thresh: 0.65\n"
         "free_thresh: 0.196\n" +
         extra;
}

std::vector<CellState> row_of(const OccupancyGrid& grid) {
  return {grid.cells.pixels().begin(), grid.cells.pixels().end()};
}

constexpr CellState O = CellState::occupied, F = CellState::free, U = CellState::unknown;

class OccupancyMapIo : public TempDirTest {};

TEST_F(OccupancyMapIo, RosMapFollowsMapServerThresholds) {
  // p = (255 - v) / 255: 0 -> 1, 50 -> .804 (> .65: occupied); 100 -> .608, 150 -> .412,
  // 200 -> .216, 205 -> .19608 (between: unknown; 205 is map_saver's unknown, just above .196);
  // 230 -> .098, 254, 255 (< .196: free).
  write_file(dir() / "m.pgm", pgm_row({0, 50, 100, 150, 200, 205, 230, 254, 255}));
  write_file(dir() / "m.yaml", ros_yaml("m.pgm"));
  const OccupancyGrid grid = io::read_ros_map(dir() / "m.yaml");
  EXPECT_EQ(row_of(grid), (std::vector<CellState>{O, O, U, U, U, U, F, F, F}));
  EXPECT_DOUBLE_EQ(grid.resolution, 0.05);
  EXPECT_EQ(grid.origin, Eigen::Vector3d(1.5, -2.0, 0.25));

  // negate: p = v / 255: 0 free; 50 -> .19608 unknown; ... 200 -> .784 occupied.
  write_file(dir() / "n.yaml", ros_yaml("m.pgm", "negate: 1\n"));
  EXPECT_EQ(row_of(io::read_ros_map(dir() / "n.yaml")),
            (std::vector<CellState>{F, U, U, U, O, O, O, O, O}));
  write_file(dir() / "t.yaml", ros_yaml("m.pgm", "negate: true\nmode: scale\n"));
  EXPECT_EQ(row_of(io::read_ros_map(dir() / "t.yaml")),
            (std::vector<CellState>{F, U, U, U, O, O, O, O, O}));
}

TEST_F(OccupancyMapIo, RosMapThresholdsAreStrict) {
  // (255 - 102) / 255 is exactly 0.6: not above occupied_thresh 0.6, so unknown; 101 is above.
  write_file(dir() / "m.pgm", pgm_row({101, 102}));
  write_file(dir() / "m.yaml",
             "image: m.pgm\nresolution: 0.1\norigin: [0, 0, 0]\noccupied_thresh: 0.6\n"
             "free_thresh: 0.1\nnegate: 0\n");
  EXPECT_EQ(row_of(io::read_ros_map(dir() / "m.yaml")), (std::vector<CellState>{O, U}));
}

TEST_F(OccupancyMapIo, RosMapAveragesChannelsLikeMapServer) {
  // RGB PNG: (255, 0, 0) has mean 85, p = .667: occupied; (255, 255, 235) mean 248.3: free.
  RgbImage rgb(2, 1);
  rgb(0, 0) = {255, 0, 0};
  rgb(1, 0) = {255, 255, 235};
  io::write_png(dir() / "rgb.png", rgb);
  write_file(dir() / "rgb.yaml", ros_yaml("rgb.png"));
  EXPECT_EQ(row_of(io::read_ros_map(dir() / "rgb.yaml")), (std::vector<CellState>{O, F}));

  // RGBA (a PAM file): opaque grey 205. Trinary averages alpha in, as map_server does:
  // (3 * 205 + 255) / 4 = 217.5, p = .147: free. Scale leaves alpha out: 205, unknown.
  std::string pam = "P7\nWIDTH 1\nHEIGHT 1\nDEPTH 4\nMAXVAL 255\nTUPLTYPE RGB_ALPHA\nENDHDR\n";
  pam += std::string{char(205), char(205), char(205), char(255)};
  write_file(dir() / "rgba.pam", pam);
  write_file(dir() / "tri.yaml", ros_yaml("rgba.pam"));
  EXPECT_EQ(row_of(io::read_ros_map(dir() / "tri.yaml")), (std::vector<CellState>{F}));
  write_file(dir() / "scale.yaml", ros_yaml("rgba.pam", "negate: 0\nmode: scale\n"));
  EXPECT_EQ(row_of(io::read_ros_map(dir() / "scale.yaml")), (std::vector<CellState>{U}));
}

TEST_F(OccupancyMapIo, RosMapImagePathsAreRelativeToTheYaml) {
  fs::create_directories(dir() / "maps" / "images");
  write_file(dir() / "maps" / "images" / "m.pgm", pgm_row({0, 255}));
  write_file(dir() / "maps" / "m.yaml", ros_yaml("images/m.pgm"));
  EXPECT_EQ(row_of(io::read_ros_map(dir() / "maps" / "m.yaml")), (std::vector<CellState>{O, F}));
  write_file(dir() / "abs.yaml", ros_yaml((dir() / "maps" / "images" / "m.pgm").string()));
  EXPECT_EQ(row_of(io::read_ros_map(dir() / "abs.yaml")), (std::vector<CellState>{O, F}));
}

OccupancyGrid sample_grid() {
  OccupancyGrid grid;
  grid.cells = Image<CellState>(7, 5, CellState::unknown);
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 7; ++x) {
      grid.cells(x, y) = static_cast<CellState>((x + 2 * y) % 3);
    }
  }
  grid.resolution = 0.025;
  grid.origin = {-3.25, 10.125, -1.5};
  return grid;
}

TEST_F(OccupancyMapIo, RosMapRoundTripsAndWritesWhatMapSaverWrites) {
  const OccupancyGrid grid = sample_grid();
  io::write_ros_map(dir() / "saved.yaml", grid);
  const OccupancyGrid back = io::read_ros_map(dir() / "saved.yaml");
  EXPECT_EQ(row_of(back), row_of(grid));
  EXPECT_EQ(back.resolution, grid.resolution);
  EXPECT_EQ(back.origin, grid.origin);

  // The PGM, byte by byte: binary P5, occupied 0, free 254, unknown 205.
  const std::string pgm = read_text(dir() / "saved.pgm");
  const std::string header = "P5\n# CREATOR: kartograf\n7 5\n255\n";
  ASSERT_EQ(pgm.size(), header.size() + 35);
  EXPECT_EQ(pgm.substr(0, header.size()), header);
  for (std::size_t i = 0; i < 35; ++i) {
    const CellState cell = grid.cells.pixels()[i];
    const int expected = cell == O ? 0 : cell == F ? 254 : 205;
    EXPECT_EQ(static_cast<std::uint8_t>(pgm[header.size() + i]), expected) << "cell " << i;
  }
  const std::string yaml = read_text(dir() / "saved.yaml");
  for (const char* line :
       {"image: saved.pgm\n", "resolution: 0.025\n", "origin: [-3.25, 10.125, -1.5]\n",
        "negate: 0\n", "occupied_thresh: 0.65\n", "free_thresh: 0.196\n", "mode: trinary\n"}) {
    EXPECT_NE(yaml.find(line), std::string::npos) << "missing " << line << " in\n" << yaml;
  }
  // Nothing else was left in the folder.
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir())) names.insert(entry.path().filename());
  EXPECT_EQ(names, (std::set<std::string>{"saved.pgm", "saved.yaml"}));
}

TEST_F(OccupancyMapIo, RosMapWriteFailureLeavesNoHalfPair) {
  // The image name is taken by a folder: staging works, publishing the image fails, and neither
  // a YAML nor a staged file may remain.
  fs::create_directory(dir() / "blocked.pgm");
  EXPECT_ERROR_MENTIONS(io::write_ros_map(dir() / "blocked.yaml", sample_grid()), "blocked.pgm");
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir())) names.insert(entry.path().filename());
  EXPECT_EQ(names, (std::set<std::string>{"blocked.pgm"}));

  EXPECT_ERROR_MENTIONS(io::write_ros_map(dir() / "missing" / "m.yaml", sample_grid()), "missing");
  EXPECT_ERROR_MENTIONS(io::write_ros_map(dir() / "m.pgm", sample_grid()), ".pgm");
  OccupancyGrid bad = sample_grid();
  bad.resolution = 0;
  EXPECT_ERROR_MENTIONS(io::write_ros_map(dir() / "r.yaml", bad), "resolution");
  EXPECT_ERROR_MENTIONS(io::write_ros_map(dir() / "e.yaml", OccupancyGrid{}), "empty");
  EXPECT_FALSE(fs::exists(dir() / "r.yaml"));
}

TEST_F(OccupancyMapIo, RosMapErrorsNameTheKeyAndTheProblem) {
  write_file(dir() / "m.pgm", pgm_row({0, 255}));
  const auto yaml_error = [&](const std::string& text,
                              std::initializer_list<std::string_view> parts) {
    write_file(dir() / "bad.yaml", text);
    testing::expect_mentions(testing::error_message([&] { io::read_ros_map(dir() / "bad.yaml"); }),
                             parts);
  };
  yaml_error(
      "resolution: 0.05\norigin: [0, 0, 0]\noccupied_thresh: 0.65\nfree_thresh: 0.2\n"
      "negate: 0\n",
      {"bad.yaml", "missing key 'image'"});
  yaml_error(ros_yaml("m.pgm", ""), {"missing key 'negate'"});
  yaml_error(
      "image: m.pgm\nresolution: fine\norigin: [0, 0, 0]\noccupied_thresh: 0.65\n"
      "free_thresh: 0.2\nnegate: 0\n",
      {"key 'resolution'", "line 2", "'fine'"});
  yaml_error(
      "image: m.pgm\nresolution: -0.05\norigin: [0, 0, 0]\noccupied_thresh: 0.65\n"
      "free_thresh: 0.2\nnegate: 0\n",
      {"key 'resolution'", "> 0"});
  yaml_error(
      "image: m.pgm\nresolution: 0.05\norigin: [0, 0]\noccupied_thresh: 0.65\n"
      "free_thresh: 0.2\nnegate: 0\n",
      {"key 'origin'", "3 numbers"});
  yaml_error(
      "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\noccupied_thresh: 0.1\n"
      "free_thresh: 0.2\nnegate: 0\n",
      {"free_thresh", "occupied_thresh", "out of range"});
  yaml_error(ros_yaml("m.pgm", "negate: 2\n"), {"key 'negate'", "'2'"});
  yaml_error(ros_yaml("m.pgm", "negate: 0\nmode: raw\n"), {"key 'mode'", "raw", "not supported"});
  yaml_error(ros_yaml("m.pgm", "negate: 0\nmode: fancy\n"), {"unknown mode 'fancy'"});
  yaml_error("image: [m.pgm\n", {"bad.yaml", "line", "not valid YAML"});
  yaml_error("- just\n- a list\n", {"mapping"});
  yaml_error(ros_yaml("absent.pgm"), {"bad.yaml", "absent.pgm", "no such file"});
  LabelImage sixteen(2, 1, 7);
  io::write_label_png(dir() / "deep.png", sixteen);
  yaml_error(ros_yaml("deep.png"), {"deep.png", "16-bit", "expected 8-bit"});
  EXPECT_ERROR_MENTIONS(io::read_ros_map(dir() / "nothing.yaml"), "nothing.yaml", "no such file");
}

TEST_F(OccupancyMapIo, PngMapThresholdsGrey) {
  GrayImage gray(4, 1);
  gray(0, 0) = 0;
  gray(1, 0) = 249;
  gray(2, 0) = 250;
  gray(3, 0) = 255;
  io::write_png(dir() / "map.png", gray);
  const OccupancyGrid grid = io::read_png_map(dir() / "map.png");
  EXPECT_EQ(row_of(grid), (std::vector<CellState>{O, O, F, F}));
  EXPECT_DOUBLE_EQ(grid.resolution, 0.05);
  EXPECT_EQ(grid.origin, Eigen::Vector3d::Zero());
  EXPECT_EQ(row_of(io::read_png_map(dir() / "map.png", 0.1, 200)),
            (std::vector<CellState>{O, F, F, F}));

  // Round trip: free and occupied survive, unknown reads back as occupied (no unknown in ipa maps).
  const OccupancyGrid sample = sample_grid();
  io::write_png_map(dir() / "sample.png", sample);
  const OccupancyGrid back = io::read_png_map(dir() / "sample.png", sample.resolution);
  for (std::size_t i = 0; i < sample.cells.size(); ++i) {
    const CellState expected = sample.cells.pixels()[i] == F ? F : O;
    EXPECT_EQ(back.cells.pixels()[i], expected) << "cell " << i;
  }

  EXPECT_ERROR_MENTIONS(io::read_png_map(dir() / "map.png", 0), "map.png", "resolution");
  EXPECT_ERROR_MENTIONS(io::read_png_map(dir() / "map.png", 0.05, 256), "threshold", "256");
  io::write_label_png(dir() / "deep.png", LabelImage(2, 2, 1));
  EXPECT_ERROR_MENTIONS(io::read_png_map(dir() / "deep.png"), "deep.png", "16-bit");
  write_file(dir() / "junk.png", "not a png");
  EXPECT_ERROR_MENTIONS(io::read_png_map(dir() / "junk.png"), "junk.png", "cannot decode");
}

TEST_F(OccupancyMapIo, ReadsRealIpaMaps) {
  const auto maps = testing::data_dir() / "ipa_room_maps" / "test_maps";
  // office_a is RGBA, lab_ipa RGB: both read as luminance.
  for (const char* name : {"office_a.png", "lab_ipa.png"}) {
    const OccupancyGrid grid = io::read_png_map(maps / name);
    std::size_t free = 0;
    for (CellState cell : grid.cells.pixels()) free += cell == F;
    EXPECT_GT(free, grid.cells.size() / 20) << name;
    EXPECT_LT(free, grid.cells.size()) << name;
  }
}

TEST_F(OccupancyMapIo, GroundTruthRoomsAreWhiteRegionsWithoutSpecks) {
  // Two rooms of 12x10 behind a black wall column, a 3-pixel white speck, grey (250) is not
  // white: labels 1 (left, first in raster order) and 2; the speck and grey get 0.
  GrayImage drawing(30, 12, 0);
  for (int y = 1; y < 11; ++y) {
    for (int x = 1; x < 13; ++x) drawing(x, y) = 255;
    for (int x = 14; x < 26; ++x) drawing(x, y) = 254;
  }
  drawing(28, 0) = drawing(28, 1) = drawing(29, 1) = 255;
  drawing(27, 5) = 250;
  io::write_png(dir() / "gt.png", drawing);
  const LabelImage rooms = io::read_room_ground_truth_png(dir() / "gt.png");
  EXPECT_EQ(rooms(1, 1), 1);
  EXPECT_EQ(rooms(12, 10), 1);
  EXPECT_EQ(rooms(14, 1), 2);
  EXPECT_EQ(rooms(28, 0), 0);
  EXPECT_EQ(rooms(27, 5), 0);
  EXPECT_EQ(rooms(13, 5), 0);
  std::size_t labelled = 0;
  for (Label l : rooms.pixels()) labelled += l != 0;
  EXPECT_EQ(labelled, 240u);
  EXPECT_EQ(io::read_ground_truth_rooms(dir() / "gt.png").pixels()[30 + 1], 1);

  // A 16-bit label image is taken as it is.
  LabelImage labels(3, 1, 0);
  labels(2, 0) = 4242;
  io::write_label_png(dir() / "labels.png", labels);
  EXPECT_EQ(io::read_ground_truth_rooms(dir() / "labels.png")(2, 0), 4242);
}

TEST_F(OccupancyMapIo, RealGroundTruthRoomCounts) {
  // Rooms of >= 100 px as 4-connected regions of grey >= 251, as counted independently with
  // OpenCV's connectedComponentsWithStats while this test was written.
  const auto maps = testing::data_dir() / "ipa_room_maps" / "test_maps";
  const auto count = [](const LabelImage& labels) {
    Label max = 0;
    for (Label l : labels.pixels()) max = std::max(max, l);
    return int{max};
  };
  EXPECT_EQ(count(io::read_room_ground_truth_png(maps / "Freiburg52_scan_gt_segmentation.png")),
            10);
  EXPECT_EQ(count(io::read_room_ground_truth_png(maps / "lab_c_scan_gt_segmentation.png")), 17);
  EXPECT_EQ(count(io::read_room_ground_truth_png(maps / "office_a_gt_segmentation.png")), 27);
}

TEST_F(OccupancyMapIo, LabelImagesRoundTripAndColorize) {
  LabelImage labels(5, 3, 0);
  for (int i = 0; i < 15; ++i) labels.pixels()[i] = static_cast<Label>(i * 4681);  // 0..65534
  labels(4, 2) = 65535;
  io::write_label_png(dir() / "labels.png", labels);
  const LabelImage back = io::read_label_png(dir() / "labels.png");
  ASSERT_EQ(back.width(), 5);
  ASSERT_EQ(back.height(), 3);
  EXPECT_TRUE(std::equal(back.pixels().begin(), back.pixels().end(), labels.pixels().begin()));

  io::write_png(dir() / "gray.png", GrayImage(2, 2, 1));
  EXPECT_ERROR_MENTIONS(io::read_label_png(dir() / "gray.png"), "label image", "gray.png", "8-bit",
                        "expected 16-bit");
  EXPECT_ERROR_MENTIONS(io::read_label_png(dir() / "none.png"), "none.png", "no such file");

  LabelImage ramp(64, 1);
  for (int i = 0; i < 64; ++i) ramp(i, 0) = static_cast<Label>(i);
  const RgbImage colors = io::colorize_labels(ramp);
  EXPECT_EQ(colors(0, 0), (Rgb8{0, 0, 0}));
  std::set<Rgb8> distinct(colors.pixels().begin(), colors.pixels().end());
  EXPECT_EQ(distinct.size(), 64u);
  const RgbImage again = io::colorize_labels(ramp);
  EXPECT_TRUE(std::equal(again.pixels().begin(), again.pixels().end(), colors.pixels().begin()));
}

TEST_F(OccupancyMapIo, SemanticImagesRoundTripAndRejectUnknownValues) {
  SemanticImage classes(kSemanticClassCount, 1);
  for (int c = 0; c < kSemanticClassCount; ++c) classes(c, 0) = static_cast<SemanticClass>(c);
  io::write_semantic_png(dir() / "classes.png", classes);
  const SemanticImage back = io::read_semantic_png(dir() / "classes.png");
  EXPECT_TRUE(std::equal(back.pixels().begin(), back.pixels().end(), classes.pixels().begin()));

  GrayImage bad(3, 2, 1);
  bad(2, 1) = 9;
  io::write_png(dir() / "bad.png", bad);
  EXPECT_ERROR_MENTIONS(io::read_semantic_png(dir() / "bad.png"), "bad.png", "pixel (2, 1)",
                        "value 9");
  io::write_label_png(dir() / "deep.png", LabelImage(2, 2, 1));
  EXPECT_ERROR_MENTIONS(io::read_semantic_png(dir() / "deep.png"), "deep.png", "expected 8-bit");
}

}  // namespace
}  // namespace kartograf
