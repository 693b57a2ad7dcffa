// The synthetic data set on disk: it opens as a TUM sequence with the right intrinsics and poses,
// two runs give identical bytes, its ground-truth images agree with world.json; and the
// camera_intrinsics.json reader behind open_tum_sequence.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/formats/pcd.hpp"
#include "kartograf/formats/sequence.hpp"
#include "kartograf/outputs/synthetic_dataset.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

namespace fs = std::filesystem;

io::SyntheticDatasetParams small_options() {
  io::SyntheticDatasetParams o;
  o.frames = 4;
  o.intrinsics = {80, 60, 65.625, 66.0, 39.5, 29.75};
  o.laser.lines = 41;
  o.laser.min_elevation_deg = -40;
  o.laser.max_elevation_deg = 60;
  return o;
}

std::map<std::string, std::string> folder_bytes(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file())
      files[fs::relative(entry.path(), dir).string()] = testing::read_text(entry.path());
  }
  return files;
}

void expect_intrinsics(const PinholeIntrinsics& actual, const PinholeIntrinsics& expected) {
  EXPECT_EQ(actual.width, expected.width);
  EXPECT_EQ(actual.height, expected.height);
  EXPECT_DOUBLE_EQ(actual.fx, expected.fx);
  EXPECT_DOUBLE_EQ(actual.fy, expected.fy);
  EXPECT_DOUBLE_EQ(actual.cx, expected.cx);
  EXPECT_DOUBLE_EQ(actual.cy, expected.cy);
}

class SynthDataset : public testing::TempDirTest {};

TEST_F(SynthDataset, OpensAsTumSequenceWithIntrinsicsAndPoses) {
  const io::SyntheticDatasetParams options = small_options();
  const io::SyntheticDatasetSummary summary = io::write_synthetic_dataset(dir() / "set", options);
  const auto sequence = io::open_tum_sequence(dir() / "set");
  ASSERT_EQ(sequence->size(), 4u);
  expect_intrinsics(sequence->intrinsics(), {80, 60, 65.625, 66.0, 39.5, 29.75});
  EXPECT_DOUBLE_EQ(sequence->depth_units_per_metre(), 5000.0);
  for (std::size_t i = 0; i < sequence->size(); ++i) {
    const io::RgbdFrame frame = sequence->frame(i);
    ASSERT_TRUE(frame.pose.has_value());
    const Eigen::Isometry3d& truth = summary.trajectory[i].pose;
    EXPECT_LT((frame.pose->translation() - truth.translation()).norm(), 1e-6);
    EXPECT_LT(Eigen::AngleAxisd(frame.pose->linear().transpose() * truth.linear()).angle(), 1e-6);
    EXPECT_NEAR(frame.timestamp, summary.trajectory[i].timestamp, 1e-6);
    EXPECT_EQ(frame.depth.width(), 80);
    EXPECT_EQ(frame.color.height(), 60);
  }
  EXPECT_EQ(summary.world.seed, 1u);
}

TEST_F(SynthDataset, ByteIdenticalAcrossRunsAndThreadCounts) {
  io::SyntheticDatasetParams a = small_options();
  a.threads = 1;
  io::SyntheticDatasetParams b = small_options();
  b.threads = 3;
  io::write_synthetic_dataset(dir() / "a", a);
  io::write_synthetic_dataset(dir() / "b", b);
  const auto files_a = folder_bytes(dir() / "a");
  const auto files_b = folder_bytes(dir() / "b");
  EXPECT_EQ(files_a.size(), 4u * 4u + 16u);
  ASSERT_EQ(files_a.size(), files_b.size());
  for (const auto& [name, content] : files_a) {
    ASSERT_TRUE(files_b.count(name)) << name;
    EXPECT_TRUE(files_b.at(name) == content) << name << " differs";
  }
  io::SyntheticDatasetParams c = small_options();
  c.seed = 2;
  io::write_synthetic_dataset(dir() / "c", c);
  EXPECT_NE(testing::read_text(dir() / "a" / "world.json"),
            testing::read_text(dir() / "c" / "world.json"));
}

TEST_F(SynthDataset, RefusesANonEmptyFolderUnlessForced) {
  io::SyntheticDatasetParams options = small_options();
  options.frames = 1;
  io::write_synthetic_dataset(dir() / "set", options);
  EXPECT_ERROR_MENTIONS(io::write_synthetic_dataset(dir() / "set", options), "--force");
  options.force = true;
  EXPECT_NO_THROW(io::write_synthetic_dataset(dir() / "set", options));
  std::ofstream(dir() / "file") << "x";
  EXPECT_THROW(io::write_synthetic_dataset(dir() / "file", options), Error);
}

// frames 0: a robot tour takes the frames it needs to keep its per-frame limits; a hand-held
// sequence has no such count.
TEST_F(SynthDataset, ZeroFramesMeansTheTourOwnCount) {
  io::SyntheticDatasetParams options = small_options();
  options.intrinsics = {16, 12, 13.125, 13.125, 7.5, 5.5};
  options.frames = 0;
  const io::SyntheticDatasetSummary summary = io::write_synthetic_dataset(dir() / "tour", options);
  EXPECT_GT(summary.tour_frames_needed, 100);
  EXPECT_EQ(summary.trajectory.size(), static_cast<std::size_t>(summary.tour_frames_needed));
  const std::string poses = testing::read_text(dir() / "tour" / "groundtruth.txt");
  EXPECT_EQ(static_cast<std::size_t>(std::count(poses.begin(), poses.end(), '\n')),
            summary.trajectory.size() + 1);  // one comment line
  options.trajectory = io::SyntheticTrajectory::handheld;
  EXPECT_ERROR_MENTIONS(io::write_synthetic_dataset(dir() / "handheld", options), "frames",
                        "got 0");
}

TEST_F(SynthDataset, GroundTruthFilesAgreeWithWorldJson) {
  io::SyntheticDatasetParams options = small_options();
  options.frames = 2;
  options.trajectory = io::SyntheticTrajectory::handheld;
  const io::SyntheticDatasetSummary summary = io::write_synthetic_dataset(dir() / "set", options);
  std::ifstream in(dir() / "set" / "world.json");
  const nlohmann::json world = nlohmann::json::parse(in);
  std::map<int, int> plane_class;
  for (const auto& plane : world["planes"])
    plane_class[plane["id"].get<int>()] = plane["class"].get<int>();
  ASSERT_EQ(plane_class.size(), summary.world.planes.size());

  int checked = 0;
  for (const auto& entry : fs::directory_iterator(dir() / "set" / "gt" / "planes")) {
    const LabelImage planes = io::read_label_png(entry.path());
    const SemanticImage semantic =
        io::read_semantic_png(dir() / "set" / "gt" / "semantic" / entry.path().filename());
    for (int y = 0; y < planes.height(); ++y) {
      for (int x = 0; x < planes.width(); ++x) {
        ASSERT_TRUE(plane_class.count(planes(x, y))) << "plane " << planes(x, y);
        EXPECT_EQ(static_cast<int>(semantic(x, y)), plane_class[planes(x, y)]);
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 2 * 80 * 60);

  // Room labels of the floor plan: the ids of world.json's rooms, at their rectangles.
  const LabelImage rooms = io::read_label_png(dir() / "set" / "rooms.png");
  const OccupancyGrid grid = io::read_ros_map(dir() / "set" / "floor_plan.yaml");
  EXPECT_EQ(grid.width(), rooms.width());
  const auto& plan = world["dataset"]["floor_plan"];
  EXPECT_DOUBLE_EQ(grid.resolution, plan["resolution"].get<double>());
  std::set<int> seen;
  for (int y = 0; y < rooms.height(); ++y) {
    for (int x = 0; x < rooms.width(); ++x) {
      if (!rooms(x, y)) continue;
      seen.insert(rooms(x, y));
      const auto& room = world["rooms"][rooms(x, y) - 1];
      const Eigen::Vector2d c = grid.cell_center(x, y);
      EXPECT_GE(c.x(), room["min"][0].get<double>());
      EXPECT_LE(c.y(), room["max"][1].get<double>());
      EXPECT_EQ(grid.cells(x, y) == CellState::free || grid.cells(x, y) == CellState::occupied,
                true);
    }
  }
  EXPECT_EQ(seen.size(), world["rooms"].size());

  // The laser scan: organized, its labels are plane ids, VIEWPOINT is the scanner's pose.
  const io::PcdCloud scan = io::read_pcd(dir() / "set" / "laser_scan.pcd");
  EXPECT_EQ(scan.width, 361);
  EXPECT_EQ(scan.height, 41);
  ASSERT_EQ(scan.labels.size(), scan.points.size());
  for (std::uint32_t label : scan.labels) EXPECT_TRUE(plane_class.count(static_cast<int>(label)));
  const auto& t = world["dataset"]["laser_scan"]["pose"]["translation"];
  EXPECT_NEAR(scan.viewpoint.translation().z(), t[2].get<double>(), 1e-6);
  EXPECT_TRUE(fs::exists(dir() / "set" / "preview.png"));
}

TEST_F(SynthDataset, CameraIntrinsicsJsonRoundTripAndErrors) {
  const PinholeIntrinsics k{320, 240, 262.5, 263.0, 159.5, 119.25};
  io::write_camera_intrinsics_json(dir() / "k.json", k);
  expect_intrinsics(io::read_camera_intrinsics_json(dir() / "k.json"), k);
  // Open3D's own file (column-major matrix), as in open3d_testdata's camera_primesense.json.
  std::ofstream(dir() / "open3d.json")
      << R"({"width": 640, "height": 480, "intrinsic_matrix": [525.0, 0.0, 0.0, 0.0, 525.0, 0.0, 319.5, 239.5, 1.0]})";
  EXPECT_DOUBLE_EQ(io::read_camera_intrinsics_json(dir() / "open3d.json").cx, 319.5);

  auto expect_error = [&](const std::string& text, const std::string& words) {
    std::ofstream(dir() / "bad.json") << text;
    SCOPED_TRACE(text);
    EXPECT_ERROR_MENTIONS(io::read_camera_intrinsics_json(dir() / "bad.json"), words, "bad.json");
  };
  expect_error("{", "not valid JSON");
  expect_error(R"({"height": 4, "intrinsic_matrix": [1,0,0,0,1,0,0,0,1]})", "'width'");
  expect_error(R"({"width": 4, "height": 4, "intrinsic_matrix": [1,0,0,0,1,0,0,0]})", "9 numbers");
  expect_error(R"({"width": 4, "height": 4, "intrinsic_matrix": [1,0.1,0,0,1,0,0,0,1]})",
               "pinhole");
  expect_error(R"({"width": 4, "height": 4, "intrinsic_matrix": [-1,0,0,0,1,0,0,0,1]})", "focal");

  // open_tum_sequence prefers an explicit argument over the file.
  const io::SyntheticDatasetSummary summary = io::write_synthetic_dataset(dir() / "set", [] {
    io::SyntheticDatasetParams o = small_options();
    o.frames = 1;
    return o;
  }());
  const PinholeIntrinsics given{80, 60, 262.5, 263.0, 39.5, 29.75};
  EXPECT_DOUBLE_EQ(io::open_tum_sequence(dir() / "set", 0.02, given)->intrinsics().fx, 262.5);
  // A camera for other frames than the folder's is refused, naming both sizes.
  EXPECT_ERROR_MENTIONS(io::open_tum_sequence(dir() / "set", 0.02, k), "320x240", "80x60");
  EXPECT_DOUBLE_EQ(io::open_tum_sequence(dir() / "set")->intrinsics().fx, 65.625);
}

}  // namespace
}  // namespace kartograf
