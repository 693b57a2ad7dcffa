// Sequence input by content (io/sequence_detect.hpp, io/camera_intrinsics.hpp): numbered frames
// with any first number (the real 7-Scenes 300-599 and SUN3D folders), gaps and missing files,
// camera presets, files and options, depth scale, frame range, skipping bad frames; and the
// input defects of issue 20: colour smaller than depth (1), a missing depth file (5), poses that
// are not rotations (6), unusable depth (8), depth of another size and truncated images (12).
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/camera_intrinsics.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/mapping/slam.hpp"
#include "kartograf/pipeline/sequence_frame_source.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "rgbd_test_sequence.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

namespace fs = std::filesystem;

const fs::path kitchen_frames() {
  return testing::data_dir() / "7scenes_redkitchen" / "frames";
}

std::string frame_name(int n, const char* suffix) {
  char name[64];
  std::snprintf(name, sizeof(name), "frame-%06d%s", n, suffix);
  return name;
}

class SequenceInput : public testing::TempDirTest {
 protected:
  // Frames [first, last] of the real 7-Scenes kitchen linked into dir()/name (no copy), with
  // its camera file.
  fs::path kitchen_copy(const std::string& name, int first, int last) {
    const fs::path folder = dir() / name;
    fs::create_directories(folder);
    fs::copy_file(testing::data_dir() / "7scenes_redkitchen" / "camera-intrinsics.txt",
                  folder / "camera-intrinsics.txt");
    for (int n = first; n <= last; ++n) {
      for (const char* suffix : {".color.jpg", ".depth.png", ".pose.txt"})
        fs::create_symlink(kitchen_frames() / frame_name(n, suffix),
                           folder / frame_name(n, suffix));
    }
    return folder;
  }

  // A TUM folder of `frames` 640x480 frames with constant depth (1.5 m at 5000 per metre).
  fs::path tum_folder(const std::string& name, int frames = 3) {
    const fs::path folder = dir() / name;
    fs::create_directories(folder / "rgb");
    fs::create_directories(folder / "depth");
    std::ofstream rgb(folder / "rgb.txt"), depth(folder / "depth.txt");
    for (int i = 0; i < frames; ++i) {
      const std::string file = std::to_string(i) + ".png";
      io::write_png(folder / "rgb" / file, RgbImage(640, 480, Rgb8{90, 90, 90}));
      io::write_png(folder / "depth" / file, DepthImage(640, 480, std::uint16_t(7500)));
      rgb << 1.0 + i / 30.0 << " rgb/" << file << "\n";
      depth << 1.0 + i / 30.0 << " depth/" << file << "\n";
    }
    return folder;
  }

  void replace(const fs::path& file) { fs::remove(file); }
};

TEST(SequenceInputRealData, SevenScenesFolderStartingAtFrame300) {
  const io::OpenedSequence opened =
      io::open_sequence(testing::data_dir() / "7scenes_redkitchen_300_599");
  EXPECT_EQ(opened.detected.layout, io::SequenceLayout::seven_scenes);
  ASSERT_EQ(opened.sequence->size(), 300u);
  EXPECT_EQ(opened.camera.source, "file");
  EXPECT_DOUBLE_EQ(opened.sequence->intrinsics().fx, 585.0);
  EXPECT_EQ(opened.sequence->intrinsics().width, 640);
  EXPECT_TRUE(opened.warnings.empty());
  const io::RgbdFrame first = opened.sequence->frame(0);
  EXPECT_NEAR(first.timestamp, 300.0 / 30.0, 1e-12);
  EXPECT_EQ(first.depth_file.filename(), "frame-000300.depth.png");
  ASSERT_TRUE(first.pose.has_value());
  EXPECT_EQ(opened.sequence->frame(299).depth_file.filename(), "frame-000599.depth.png");
}

TEST(SequenceInputRealData, Sun3dFolderWithPngColourAndItsOwnCamera) {
  const io::OpenedSequence opened =
      io::open_sequence(testing::data_dir() / "sun3d_studyroom_fragment1");
  EXPECT_EQ(opened.detected.layout, io::SequenceLayout::seven_scenes);
  ASSERT_EQ(opened.sequence->size(), 50u);
  EXPECT_NEAR(opened.sequence->intrinsics().fx, 570.342205, 1e-9);
  EXPECT_DOUBLE_EQ(opened.sequence->intrinsics().cy, 240.0);
  EXPECT_DOUBLE_EQ(opened.sequence->depth_units_per_metre(), 1000.0);
  const io::RgbdFrame frame = opened.sequence->frame(49);
  EXPECT_EQ(frame.color_file.filename(), "frame-000984.color.png");
  EXPECT_EQ(frame.color.width(), 640);
  EXPECT_TRUE(frame.pose.has_value());
}

TEST(SequenceInputRealData, EveryShippedPoseIsWellWithinTheRotationTolerance) {
  for (const char* folder :
       {"7scenes_redkitchen", "7scenes_redkitchen_300_599", "sun3d_studyroom_fragment1"}) {
    const io::OpenedSequence opened = io::open_sequence(testing::data_dir() / folder);
    for (std::size_t i = 0; i < opened.sequence->size(); i += 7)
      EXPECT_NO_THROW(opened.sequence->frame(i)) << folder << " frame " << i;
  }
}

TEST_F(SequenceInput, MissingDepthInTheNumberedRunIsAnErrorNamingItUnlessSkipped) {  // defect 5
  const fs::path folder = kitchen_copy("kitchen", 0, 29);
  fs::remove(folder / frame_name(15, ".depth.png"));
  EXPECT_ERROR_MENTIONS(io::open_sequence(folder), "frame-000015.depth.png", "no such file",
                        "--skip-bad-frames");
  io::SequenceParams skip;
  skip.skip_bad_frames = true;
  const io::OpenedSequence opened = io::open_sequence(folder, skip);
  EXPECT_EQ(opened.sequence->size(), 29u);
  ASSERT_EQ(opened.skipped.size(), 1u);
  EXPECT_EQ(opened.skipped[0].position, 15u);
  EXPECT_NE(opened.skipped[0].reason.find("frame-000015.depth.png"), std::string::npos);
  EXPECT_EQ(opened.sequence->frame(15).depth_file.filename(), "frame-000016.depth.png");
}

TEST_F(SequenceInput, AWholeFrameMissingFromTheRunIsAGapButRegularSubsamplingIsNot) {
  const fs::path gap = kitchen_copy("gap", 0, 9);
  for (const char* suffix : {".color.jpg", ".depth.png", ".pose.txt"})
    fs::remove(gap / frame_name(5, suffix));
  EXPECT_ERROR_MENTIONS(io::open_sequence(gap), "frame-000005.depth.png");

  const fs::path every_tenth = dir() / "every_tenth";
  fs::create_directories(every_tenth);
  for (int n : {20, 30, 40}) {
    for (const char* suffix : {".color.jpg", ".depth.png"})
      fs::create_symlink(kitchen_frames() / frame_name(n, suffix),
                         every_tenth / frame_name(n, suffix));
  }
  const io::OpenedSequence opened = io::open_sequence(every_tenth);
  EXPECT_EQ(opened.sequence->size(), 3u);
  EXPECT_FALSE(opened.warnings.empty());  // no camera file: 7-Scenes' camera assumed, said so
  EXPECT_NE(opened.warnings[0].find("--camera"), std::string::npos);
  EXPECT_EQ(opened.camera.source, "default");
}

TEST_F(SequenceInput, ColourSmallerThanDepthIsAnErrorNamingTheFileAndBothSizes) {  // defect 1
  const fs::path folder = kitchen_copy("small_colour", 0, 4);
  replace(folder / frame_name(2, ".color.jpg"));
  io::write_png(dir() / "small.png", RgbImage(16, 12, Rgb8{1, 2, 3}));
  fs::copy_file(dir() / "small.png", folder / frame_name(2, ".color.jpg"));  // PNG bytes, .jpg name
  const io::OpenedSequence opened = io::open_sequence(folder);
  EXPECT_ERROR_MENTIONS(opened.sequence->frame(2), "frame-000002.color.jpg", "16x12", "640x480");
  io::SequenceParams skip;
  skip.skip_bad_frames = true;
  EXPECT_EQ(io::open_sequence(folder, skip).sequence->size(), 4u);
}

// Serves frame `shrunk` with a 16x12 colour image on its second read (the SLAM map pass): the
// map pass itself must refuse it rather than read past it.
class ColourShrinksOnSecondRead final : public mapping::FrameSource {
 public:
  ColourShrinksOnSecondRead(const testing::RenderedSequence& sequence, std::size_t shrunk)
      : inner_(sequence), shrunk_(shrunk) {}
  std::size_t size() const override { return inner_.size(); }
  PinholeIntrinsics camera() const override { return inner_.camera(); }
  double depth_units_per_metre() const override { return inner_.depth_units_per_metre(); }
  registration::RgbdImages frame(std::size_t i) const override {
    registration::RgbdImages images = inner_.frame(i);
    if (i == shrunk_ && reads_++ > 0) images.color = RgbImage(16, 12, Rgb8{1, 2, 3});
    return images;
  }

 private:
  testing::MemoryFrameSource inner_;
  std::size_t shrunk_;
  mutable int reads_ = 0;
};

TEST(SequenceInputSlam, OdometryAndMapFusionRefuseAColourImageSmallerThanTheDepth) {  // defect 1
  const Trajectory tour = synth::robot_tour(testing::test_world(), 500);
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 400; i < 404; ++i) poses.push_back(tour[static_cast<std::size_t>(i)].pose);
  testing::RenderedSequence sequence = testing::render_sequence(poses, testing::qvga_kinect());
  compute::Context context = testing::make_context(compute::BackendKind::cpu);
  mapping::SlamParams params;
  params.loop_closure = false;
  const ColourShrinksOnSecondRead map_pass(sequence, 2);
  EXPECT_ERROR_MENTIONS(mapping::run_slam(context, map_pass, params), "16x12", "smaller");
  sequence.frames[2].color = RgbImage(16, 12, Rgb8{1, 2, 3});
  const testing::MemoryFrameSource source(sequence);
  EXPECT_ERROR_MENTIONS(mapping::run_slam(context, source, params), "odometry", "frame 2", "16x12",
                        "320x240");
}

TEST_F(SequenceInput, DepthOfAnotherSizeNamesTheFileAndBothSizes) {  // defect 12
  const fs::path folder = kitchen_copy("small_depth", 0, 4);
  replace(folder / frame_name(3, ".depth.png"));
  io::write_png(folder / frame_name(3, ".depth.png"), DepthImage(320, 240, std::uint16_t(1500)));
  const io::OpenedSequence opened = io::open_sequence(folder);
  EXPECT_ERROR_MENTIONS(opened.sequence->frame(3), "frame-000003.depth.png", "320x240", "640x480");
}

TEST_F(SequenceInput, PosesThatAreNotRotationsAreErrorsNamingTheFile) {  // defect 6
  const fs::path folder = kitchen_copy("poses", 0, 2);
  const auto write_pose = [&](int n, const std::string& text) {
    replace(folder / frame_name(n, ".pose.txt"));
    std::ofstream(folder / frame_name(n, ".pose.txt")) << text;
  };
  write_pose(1, "0 0 0 0\n0 0 0 0\n0 0 0 0\n0 0 0 1\n");
  write_pose(2, "2 0 0 0\n0 3 0 0\n0 0 0.001 0\n0 0 0 1\n");
  const io::OpenedSequence opened = io::open_sequence(folder);
  EXPECT_ERROR_MENTIONS(opened.sequence->frame(1), "frame-000001.pose.txt", "not a rotation");
  EXPECT_ERROR_MENTIONS(opened.sequence->frame(2), "frame-000002.pose.txt", "not a rotation");
  // A near-rotation, 1e-3 off (more than the real files' 4e-4), is accepted and re-orthonormalised.
  write_pose(2, "1.001 0 0 0.5\n0 1 0 0\n0 0 0.9995 0\n0 0 0 1\n");
  const Eigen::Matrix3d r = opened.sequence->frame(2).pose->linear();
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-12);

  std::ofstream(dir() / "bad.log") << "0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"
                                   << "1 1 2\n0 0 0 0\n0 0 0 0\n0 0 0 0\n0 0 0 1\n";
  EXPECT_ERROR_MENTIONS(io::read_redwood_log(dir() / "bad.log"), "bad.log", "lines 7-10",
                        "not a rotation");
}

TEST_F(SequenceInput, UnusableDepthIsFoundBeforeARun) {  // defect 8
  geometry::DepthRange range;
  const fs::path zero = tum_folder("zero", 2);
  for (int i = 0; i < 2; ++i)
    io::write_png(zero / "depth" / (std::to_string(i) + ".png"),
                  DepthImage(640, 480, std::uint16_t(0)));
  const io::OpenedSequence zeros = io::open_sequence(zero);
  range.units_per_metre = zeros.sequence->depth_units_per_metre();
  EXPECT_ERROR_MENTIONS(pipeline::check_depth_usable(*zeros.sequence, range), "depth/0.png",
                        "every depth value is 0", "--depth-scale", "5000 units per metre");

  const fs::path far = tum_folder("far", 2);  // 1.5 m stored x1000: 7500 at 5 units per metre
  io::SequenceParams millimetres_as_metres;
  millimetres_as_metres.depth_units_per_metre = 5;
  const io::OpenedSequence wrong = io::open_sequence(far, millimetres_as_metres);
  range.units_per_metre = 5;
  EXPECT_ERROR_MENTIONS(pipeline::check_depth_usable(*wrong.sequence, range), "depth/0.png",
                        "values 7500 to 7500", "--depth-scale");
  range.units_per_metre = 5000;
  EXPECT_NO_THROW(pipeline::check_depth_usable(*io::open_sequence(far).sequence, range));

  // Most of the depth beyond range (a scale 10 times too small) is an error too; a part is not.
  const auto with_far_rows = [&](const std::string& name, int far_rows) {
    const fs::path folder = tum_folder(name, 2);
    DepthImage depth(640, 480, std::uint16_t(7500));  // 1.5 m
    for (int y = 0; y < far_rows; ++y) {
      for (int x = 0; x < 640; ++x) depth(x, y) = 60000;  // 12 m
    }
    for (int i = 0; i < 2; ++i)
      io::write_png(folder / "depth" / (std::to_string(i) + ".png"), depth);
    return io::open_sequence(folder);
  };
  EXPECT_ERROR_MENTIONS(pipeline::check_depth_usable(*with_far_rows("most", 288).sequence, range),
                        "depth/0.png", "only 40 % of the measured pixels", "median 12 m",
                        "--depth-scale");
  EXPECT_NO_THROW(pipeline::check_depth_usable(*with_far_rows("some", 192).sequence, range));
}

TEST_F(SequenceInput, TruncatedJpegAndPngAreErrorsNamingTheFile) {  // defect 12
  for (const char* suffix : {".color.jpg", ".depth.png"}) {
    const std::vector<std::uint8_t> bytes =
        testing::read_bytes(kitchen_frames() / frame_name(0, suffix));
    const fs::path cut = dir() / (std::string("cut") + suffix);
    testing::write_file(
        cut, std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + bytes.size() * 2 / 3));
    if (std::string(suffix) == ".color.jpg") {
      EXPECT_NO_THROW(io::read_color_image(kitchen_frames() / frame_name(0, suffix)));
      EXPECT_ERROR_MENTIONS(io::read_color_image(cut), "cut.color.jpg", "truncated");
    } else {
      EXPECT_NO_THROW(io::read_depth_png(kitchen_frames() / frame_name(0, suffix)));
      EXPECT_ERROR_MENTIONS(io::read_depth_png(cut), "cut.depth.png", "truncated");
    }
  }
}

// Found by fuzzing (fuzz/fuzz_camera_argument, fuzz/fuzz_image): a --camera value too long to be
// a path threw std::filesystem::filesystem_error; a PNM header declaring 6e49 pixels was cast to an
// integer for the message (UBSan). Both are Errors that say what is wrong.
TEST_F(SequenceInput, FuzzFindingsAreErrorsNotCrashes) {
  EXPECT_ERROR_MENTIONS(io::parse_camera_argument(std::string(5000, 'x')), "--camera",
                        "not a preset");
  const fs::path huge = dir() / "huge.png";
  testing::write_file(
      huge, std::string("P6 60444444444444444444444444444444444444444444444444 2\n255\n"));
  EXPECT_ERROR_MENTIONS(io::read_color_image(huge), "huge.png", "60444444");
}

// A BMP file (BITMAPINFOHEADER, 24-bit) declaring width x height, with 8 bytes of pixels: a whole
// image for 2x1 (one row padded to 8 bytes).
std::string bmp(std::uint32_t width, std::uint32_t height) {
  const auto le32 = [](std::uint32_t v) {
    return std::string{char(v & 0xff), char((v >> 8) & 0xff), char((v >> 16) & 0xff),
                       char(v >> 24)};
  };
  std::string file = "BM" + le32(54 + 8) + le32(0) + le32(54);
  file += le32(40) + le32(width) + le32(height) + std::string{1, 0, 24, 0} + le32(0) + le32(8);
  file += le32(2835) + le32(2835) + le32(0) + le32(0);
  return file + std::string(8, char(200));
}

// Fuzz finding (image, 10-minute run): 32 bytes of a WebP lossless bitstream declare 12545 x
// 13313 pixels, which OpenCV decoded for over 10 s under ASan; BMP, TIFF, ... headers can do the
// same. Only PNG, JPEG and PNM images are read: their declared size is checked before decoding.
TEST_F(SequenceInput, ImagesWhoseSizeIsNotCheckedBeforeDecodingAreRefused) {
  const std::string webp_timeout(
      "\x2f\x00\x31\x00\x0d\xc8\x88\x88\x88\x88\x88\x88\x70\x68\x69\x6e"
      "\x69\x00\x88\x2f\x88\x88\x88\x00\x88\x88\x88\x88\x88\x88\x88\x88",
      32);
  const std::vector<std::pair<std::string, std::string>> files = {
      {"webp.png", webp_timeout}, {"small.bmp", bmp(2, 1)}, {"huge.bmp", bmp(30000, 30000)}};
  for (const auto& [name, bytes] : files) {
    testing::write_file(dir() / name, bytes);
    EXPECT_ERROR_MENTIONS(io::read_color_image(dir() / name), "colour image", name,
                          "PNG, JPEG or PNM", "convert");
    EXPECT_ERROR_MENTIONS(io::read_depth_png(dir() / name), "depth image", name,
                          "PNG, JPEG or PNM");
  }
  // PBM and PAM are PNM too: read, with their declared size checked first.
  testing::write_file(dir() / "depth.pam",
                      std::string("P7\nWIDTH 2\nHEIGHT 1\nDEPTH 1\nMAXVAL 65535\n"
                                  "TUPLTYPE GRAYSCALE\nENDHDR\n\x03\xe8\x07\xd0"));  // 1000, 2000
  const DepthImage depth = io::read_depth_png(dir() / "depth.pam");
  ASSERT_EQ(depth.width(), 2);
  EXPECT_EQ(depth(0, 0), 1000);
  EXPECT_EQ(depth(1, 0), 2000);
  testing::write_file(dir() / "huge.pam",
                      "P7\nWIDTH 90000000\nHEIGHT 90000000\nDEPTH 3\nMAXVAL 255\nENDHDR\n");
  EXPECT_ERROR_MENTIONS(io::read_color_image(dir() / "huge.pam"), "huge.pam",
                        "90000000x90000000 pixels");
  testing::write_file(dir() / "twice.pam",  // which WIDTH would OpenCV take?
                      "P7\nWIDTH 1\nWIDTH 90000\nHEIGHT 1\nDEPTH 1\nMAXVAL 255\nENDHDR\n\x01");
  EXPECT_ERROR_MENTIONS(io::read_depth_png(dir() / "twice.pam"), "twice.pam", "PNG, JPEG or PNM");
  testing::write_file(dir() / "huge.pbm", "P4 90000000 90000000\n\xff");
  EXPECT_ERROR_MENTIONS(io::read_depth_png(dir() / "huge.pbm"), "huge.pbm",
                        "90000000x90000000 pixels");
}

TEST_F(SequenceInput, TumCameraFromTheFolderNameAPresetOrADefaultWithAWarning) {
  const io::OpenedSequence plain = io::open_sequence(tum_folder("plain"));
  EXPECT_EQ(plain.camera.source, "default");
  EXPECT_DOUBLE_EQ(plain.sequence->intrinsics().fx, 525.0);
  ASSERT_EQ(plain.warnings.size(), 1u);
  EXPECT_NE(plain.warnings[0].find("--camera"), std::string::npos);

  const io::OpenedSequence fr2 = io::open_sequence(tum_folder("rgbd_dataset_freiburg2_desk"));
  EXPECT_EQ(fr2.camera.source, "preset");
  EXPECT_DOUBLE_EQ(fr2.sequence->intrinsics().fx, 520.9);
  EXPECT_DOUBLE_EQ(fr2.sequence->intrinsics().cy, 249.7);
  EXPECT_TRUE(fr2.warnings.empty());

  io::SequenceParams fr3;
  fr3.camera = "tum-fr3";
  const io::OpenedSequence given = io::open_sequence(dir() / "plain", fr3);
  EXPECT_DOUBLE_EQ(given.sequence->intrinsics().fx, 535.4);
  EXPECT_DOUBLE_EQ(given.sequence->intrinsics().fy, 539.2);
  EXPECT_TRUE(given.warnings.empty());
  EXPECT_NE(io::describe_input(given).find("fx 535.4 fy 539.2"), std::string::npos);
  EXPECT_DOUBLE_EQ(io::camera_preset("tum-fr1")->cx, 318.6);
  EXPECT_DOUBLE_EQ(io::camera_preset("7scenes")->fx, 585.0);
  EXPECT_FALSE(io::camera_preset("tum-fr4").has_value());
  EXPECT_EQ(io::tum_preset_of_folder("/x/rgbd_dataset_freiburg1_xyz"), "tum-fr1");
  EXPECT_FALSE(io::tum_preset_of_folder("/x/kitchen").has_value());
}

TEST_F(SequenceInput, CameraAsNumbersOrFileAndPresetsScaledToTheFrames) {
  const fs::path folder = tum_folder("cam");
  io::SequenceParams numbers;
  numbers.camera = "500,501,320.5,240.5";
  const io::OpenedSequence a = io::open_sequence(folder, numbers);
  EXPECT_DOUBLE_EQ(a.sequence->intrinsics().fy, 501.0);
  EXPECT_EQ(a.sequence->intrinsics().width, 640);  // the frames' size
  EXPECT_EQ(a.camera.source, "option");

  std::ofstream(dir() / "K.txt") << "600 0 310\n0 610 230\n0 0 1\n";
  io::SequenceParams file;
  file.camera = (dir() / "K.txt").string();
  const io::OpenedSequence b = io::open_sequence(folder, file);
  EXPECT_DOUBLE_EQ(b.sequence->intrinsics().fy, 610.0);
  EXPECT_DOUBLE_EQ(b.sequence->intrinsics().cx, 310.0);
  EXPECT_EQ(b.camera.source, "file");

  io::write_camera_intrinsics_json(dir() / "small.json", {320, 240, 300, 300, 160, 120});
  file.camera = (dir() / "small.json").string();
  EXPECT_ERROR_MENTIONS(io::open_sequence(folder, file), "small.json", "320x240", "640x480");
  file.camera = "tum-fr5";
  EXPECT_ERROR_MENTIONS(io::open_sequence(folder, file), "tum-fr5", "tum-fr3", "fx,fy,cx,cy");
  file.camera = "1,2,3";
  EXPECT_THROW(io::open_sequence(folder, file), Error);

  // 320x240 frames: a preset for 640x480 is scaled, and says so.
  const io::Camera half = io::fit_camera_to_frames(io::parse_camera_argument("tum-fr3"), 320, 240);
  EXPECT_DOUBLE_EQ(half.intrinsics.fx, 535.4 / 2);
  EXPECT_NE(half.description.find("scaled"), std::string::npos);
}

TEST_F(SequenceInput, DepthScaleAndFrameRange) {
  const fs::path folder = kitchen_copy("range", 0, 9);
  io::SequenceParams o;
  o.depth_units_per_metre = 500;
  o.first = 2;
  o.count = 3;
  o.step = 2;
  const io::OpenedSequence opened = io::open_sequence(folder, o);
  EXPECT_DOUBLE_EQ(opened.sequence->depth_units_per_metre(), 500.0);
  EXPECT_EQ(opened.depth_scale_source, "--depth-scale");
  ASSERT_EQ(opened.sequence->size(), 3u);
  EXPECT_EQ(opened.sequence->frame(0).index, 2u);
  EXPECT_EQ(opened.sequence->frame(2).depth_file.filename(), "frame-000006.depth.png");
  o.first = 10;
  EXPECT_ERROR_MENTIONS(io::open_sequence(folder, o), "first frame 10", "10 frames");
  o.first = 0;
  o.step = 0;
  EXPECT_ERROR_MENTIONS(io::open_sequence(folder, o), "step");
  o.step = 1;
  o.depth_units_per_metre = -1;
  EXPECT_ERROR_MENTIONS(io::open_sequence(folder, o), "--depth-scale");
}

TEST_F(SequenceInput, RgbAndDepthFoldersPairedByNameWithTheAssumptionsSaid) {
  const fs::path folder = dir() / "plain_folders";
  fs::create_directories(folder / "rgb");
  fs::create_directories(folder / "depth");
  for (const char* name : {"10", "9", "11"}) {
    io::write_png(folder / "rgb" / (std::string(name) + ".png"), RgbImage(64, 48, Rgb8{5, 5, 5}));
    io::write_png(folder / "depth" / (std::string(name) + ".png"),
                  DepthImage(64, 48, std::uint16_t(900)));
  }
  const io::OpenedSequence opened = io::open_sequence(folder);
  EXPECT_EQ(opened.detected.layout, io::SequenceLayout::rgb_depth_folders);
  ASSERT_EQ(opened.sequence->size(), 3u);
  EXPECT_EQ(opened.sequence->frame(0).depth_file.filename(), "9.png");  // numeric order
  EXPECT_EQ(opened.sequence->frame(2).color_file.filename(), "11.png");
  EXPECT_NE(opened.depth_scale_source.find("assumed millimetres"), std::string::npos);
  EXPECT_DOUBLE_EQ(opened.sequence->intrinsics().fx, 525.0 * 64 / 640);  // default, scaled
  EXPECT_FALSE(opened.warnings.empty());
  fs::remove(folder / "rgb" / "11.png");
  EXPECT_ERROR_MENTIONS(io::open_sequence(folder), "rgb/ holds 2 images, depth/ 3");
}

// A depth camera alone: a numbered folder without any colour image, or depth/ without rgb/, opens
// with empty colour in every frame (said so); a folder with some colour images needs them all.
TEST_F(SequenceInput, FoldersWithoutAnyColourImageAreADepthCameraAlone) {
  const fs::path numbered = kitchen_copy("depth_alone", 0, 4);
  for (int n = 0; n <= 4; ++n) fs::remove(numbered / frame_name(n, ".color.jpg"));
  const io::OpenedSequence opened = io::open_sequence(numbered);
  EXPECT_FALSE(opened.has_color);
  ASSERT_EQ(opened.sequence->size(), 5u);
  const io::RgbdFrame frame = opened.sequence->frame(3);
  EXPECT_TRUE(frame.color.empty());
  EXPECT_TRUE(frame.color_file.empty());
  EXPECT_EQ(frame.depth.width(), 640);
  ASSERT_TRUE(frame.pose.has_value());  // the poses still come with the frames
  ASSERT_FALSE(opened.warnings.empty());
  EXPECT_NE(opened.warnings[0].find("has no colour images: depth alone"), std::string::npos);
  io::SequenceParams camera;
  camera.camera = "kinect";  // the user's camera drops the camera warning, not this one
  EXPECT_NE(io::open_sequence(numbered, camera).warnings.at(0).find("depth alone"),
            std::string::npos);
  EXPECT_TRUE(io::open_sequence(kitchen_copy("coloured", 0, 1)).has_color);

  const fs::path some = kitchen_copy("some_colour", 0, 4);
  fs::remove(some / frame_name(2, ".color.jpg"));
  EXPECT_ERROR_MENTIONS(io::open_sequence(some), "frame-000002.color.jpg", "no such file");

  const fs::path plain = dir() / "depth_folder";
  fs::create_directories(plain / "depth");
  for (const char* name : {"1", "2"}) {
    io::write_png(plain / "depth" / (std::string(name) + ".png"),
                  DepthImage(64, 48, std::uint16_t(900)));
  }
  const io::OpenedSequence folders = io::open_sequence(plain);
  EXPECT_EQ(folders.detected.layout, io::SequenceLayout::rgb_depth_folders);
  EXPECT_FALSE(folders.has_color);
  ASSERT_EQ(folders.sequence->size(), 2u);
  EXPECT_TRUE(folders.sequence->frame(1).color.empty());
  EXPECT_EQ(folders.sequence->frame(1).depth_file.filename(), "2.png");

  const fs::path tum = tum_folder("tum_depth");  // depth.txt without rgb.txt: TUM's timestamps
  fs::remove(tum / "rgb.txt");
  const io::OpenedSequence timed = io::open_sequence(tum);
  EXPECT_EQ(timed.detected.layout, io::SequenceLayout::tum);
  EXPECT_FALSE(timed.has_color);
  ASSERT_EQ(timed.sequence->size(), 3u);
  EXPECT_NEAR(timed.sequence->frame(2).timestamp, 1.0 + 2 / 30.0, 1e-4);  // as written: 6 digits
  EXPECT_TRUE(timed.sequence->frame(2).color.empty());
}

}  // namespace
}  // namespace kartograf
