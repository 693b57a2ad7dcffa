// Sequence auto-detection (io/sequence_detect.hpp): TUM, kartograf synth and 7-Scenes folders
// (flat or with frames/), folders that are none of them, the real 7-Scenes copy, and the
// FrameSource adapter (frame limit, images, ground truth collected while reading).
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/outputs/synthetic_dataset.hpp"
#include "kartograf/pipeline/sequence_frame_source.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

namespace fs = std::filesystem;

class SequenceDetect : public testing::TempDirTest {
 protected:
  void touch(const fs::path& path, const std::string& text = "") {
    fs::create_directories(path.parent_path());
    std::ofstream(path) << text;
  }
};

TEST_F(SequenceDetect, NamesEachLayout) {
  touch(dir() / "tum" / "rgb.txt");
  touch(dir() / "tum" / "depth.txt");
  const io::DetectedSequence tum = io::detect_sequence(dir() / "tum");
  EXPECT_EQ(tum.layout, io::SequenceLayout::tum);
  EXPECT_TRUE(tum.has_timestamps);

  touch(dir() / "synth" / "rgb.txt");
  touch(dir() / "synth" / "depth.txt");
  touch(dir() / "synth" / "world.json", "{}");
  EXPECT_EQ(io::detect_sequence(dir() / "synth").layout, io::SequenceLayout::synthetic);

  touch(dir() / "scenes" / "frames" / "frame-000000.depth.png");
  const io::DetectedSequence scenes = io::detect_sequence(dir() / "scenes");
  EXPECT_EQ(scenes.layout, io::SequenceLayout::seven_scenes);
  EXPECT_FALSE(scenes.has_timestamps);
  touch(dir() / "flat" / "frame-000000.depth.png");
  EXPECT_EQ(io::detect_sequence(dir() / "flat").layout, io::SequenceLayout::seven_scenes);
  fs::create_directories(dir() / "depth_alone" / "depth");  // a depth camera's frames
  EXPECT_EQ(io::detect_sequence(dir() / "depth_alone").layout,
            io::SequenceLayout::rgb_depth_folders);

  EXPECT_EQ(io::to_string(io::SequenceLayout::seven_scenes), "7scenes");
  EXPECT_EQ(io::to_string(io::SequenceLayout::synthetic), "synthetic");
}

TEST_F(SequenceDetect, ExplainsWhatItLookedFor) {
  fs::create_directories(dir() / "empty");
  touch(dir() / "only_rgb" / "rgb.txt");
  for (const fs::path& folder : {dir() / "empty", dir() / "only_rgb"}) {
    try {
      io::detect_sequence(folder);
      FAIL() << folder << " was detected";
    } catch (const Error& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find(folder.string()), std::string::npos) << message;
      EXPECT_NE(message.find("rgb.txt and depth.txt"), std::string::npos) << message;
      EXPECT_NE(message.find("frame-000000.depth.png"), std::string::npos) << message;
    }
  }
  EXPECT_THROW(io::detect_sequence(dir() / "missing"), Error);
  touch(dir() / "file.txt");
  EXPECT_THROW(io::detect_sequence(dir() / "file.txt"), Error);
}

TEST_F(SequenceDetect, OpensASyntheticFolderAsAFrameSourceWithGroundTruth) {
  io::SyntheticDatasetParams options;
  options.frames = 3;
  options.intrinsics = {80, 60, 65.625, 66.0, 39.5, 29.75};
  options.laser.lines = 11;
  const io::SyntheticDatasetSummary summary = io::write_synthetic_dataset(dir() / "set", options);
  const io::OpenedSequence opened = io::open_sequence(dir() / "set");
  EXPECT_EQ(opened.detected.layout, io::SequenceLayout::synthetic);
  ASSERT_EQ(opened.sequence->size(), 3u);

  const pipeline::SequenceFrameSource all(*opened.sequence);
  EXPECT_EQ(all.size(), 3u);
  const pipeline::SequenceFrameSource limited(*opened.sequence, 2);
  EXPECT_EQ(limited.size(), 2u);
  EXPECT_EQ(limited.camera().width, 80);
  EXPECT_DOUBLE_EQ(limited.depth_units_per_metre(), 5000.0);
  EXPECT_TRUE(limited.ground_truth().empty());
  const registration::RgbdImages frame = limited.frame(1);
  EXPECT_EQ(frame.depth.width(), 80);
  EXPECT_EQ(frame.color.height(), 60);
  EXPECT_NEAR(frame.timestamp, summary.trajectory[1].timestamp, 1e-6);
  ASSERT_EQ(limited.ground_truth().size(), 2u);
  EXPECT_FALSE(limited.ground_truth()[0].has_value());  // not read yet
  ASSERT_TRUE(limited.ground_truth()[1].has_value());
  EXPECT_LT(
      (limited.ground_truth()[1]->translation() - summary.trajectory[1].pose.translation()).norm(),
      1e-6);
  EXPECT_THROW(limited.frame(2), Error);  // beyond the limit
}

TEST(SequenceDetectRealData, Detects7ScenesRedKitchen) {
  const fs::path folder = testing::data_dir() / "7scenes_redkitchen";
  const io::OpenedSequence opened = io::open_sequence(folder);
  EXPECT_EQ(opened.detected.layout, io::SequenceLayout::seven_scenes);
  EXPECT_FALSE(opened.detected.has_timestamps);
  EXPECT_EQ(opened.sequence->size(), 300u);
  EXPECT_DOUBLE_EQ(opened.sequence->intrinsics().fx, 585.0);
  const pipeline::SequenceFrameSource source(*opened.sequence, 1);
  const registration::RgbdImages frame = source.frame(0);
  EXPECT_EQ(frame.depth.width(), 640);
  ASSERT_TRUE(source.ground_truth().at(0).has_value());
}

}  // namespace
}  // namespace kartograf
