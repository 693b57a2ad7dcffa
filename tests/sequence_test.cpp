// RGB-D sequences on the real 7-Scenes folder and Open3D's Redwood .log; a TUM folder written here.
#include <cmath>
#include <fstream>

#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/sequence.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

TEST(Sequences, SevenScenesFramesPosesAndIntrinsics) {
  const auto sequence = io::open_seven_scenes(testing::data_dir() / "7scenes_redkitchen");
  ASSERT_EQ(sequence->size(), 300u);
  EXPECT_DOUBLE_EQ(sequence->intrinsics().fx, 585.0);
  EXPECT_DOUBLE_EQ(sequence->intrinsics().cy, 240.0);
  EXPECT_DOUBLE_EQ(sequence->depth_units_per_metre(), 1000.0);
  const io::RgbdFrame frame = sequence->frame(299);
  EXPECT_EQ(frame.depth.width(), 640);
  EXPECT_EQ(frame.color.height(), 480);
  ASSERT_TRUE(frame.pose.has_value());
  const Eigen::Matrix3d r = frame.pose->linear();
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-12);  // re-orthonormalised
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  EXPECT_NEAR(frame.timestamp, 299.0 / 30.0, 1e-12);
  EXPECT_THROW(sequence->frame(300), Error);
  // Frame 0's pose file, as stored, is ~1e-4 from orthonormal; re-orthonormalisation moves it little.
  const io::RgbdFrame first = sequence->frame(0);
  EXPECT_NEAR(first.pose->translation().z(), 0.29656917, 1e-8);
  EXPECT_NEAR(first.pose->linear()(0, 0), 0.9093129, 1e-3);
}

TEST(Sequences, RedwoodLogOfOpen3dTestData) {
  const Trajectory log = io::read_redwood_log(testing::data_dir() / "open3d_testdata/RGBD/trajectory.log");
  ASSERT_EQ(log.size(), 5u);
  EXPECT_NEAR(log[0].pose.translation().x(), -0.31057997014702826, 1e-12);
  EXPECT_NEAR(log[1].pose.translation().y(), 0.5963093994288613, 1e-12);
  EXPECT_DOUBLE_EQ(log[4].timestamp, 4.0);
}

class TempFolder : public testing::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    dir_ = dir();
    std::filesystem::create_directories(dir_ / "rgb");
    std::filesystem::create_directories(dir_ / "depth");
  }
  std::filesystem::path dir_;
};

TEST_F(TempFolder, TumFolderAssociatesFramesAndGroundTruth) {
  for (int i = 0; i < 3; ++i) {
    io::write_png(dir_ / "rgb" / (std::to_string(i) + ".png"), RgbImage(8, 6, Rgb8{10, 20, 30}));
    io::write_png(dir_ / "depth" / (std::to_string(i) + ".png"), DepthImage(8, 6, std::uint16_t(5000 + i)));
  }
  std::ofstream(dir_ / "rgb.txt") << "# color images\ntimestamp filename\n1.00 rgb/0.png\n1.03 rgb/1.png\n1.50 rgb/2.png\n";
  std::ofstream(dir_ / "depth.txt") << "# depth\n1.01 depth/0.png\n1.04 depth/1.png\n2.00 depth/2.png\n";
  std::ofstream(dir_ / "groundtruth.txt") << "# gt\n1.012 1 2 3 0 0 0 1\n";
  const auto sequence = io::open_tum_sequence(dir_);
  ASSERT_EQ(sequence->size(), 2u);  // 1.50 / 2.00 are too far apart
  EXPECT_DOUBLE_EQ(sequence->depth_units_per_metre(), 5000.0);
  const io::RgbdFrame first = sequence->frame(0);
  EXPECT_EQ(first.depth(0, 0), 5000);
  ASSERT_TRUE(first.pose.has_value());
  EXPECT_DOUBLE_EQ(first.pose->translation().y(), 2.0);
  EXPECT_FALSE(sequence->frame(1).pose.has_value());  // 1.04 is 28 ms from the only GT sample
  std::filesystem::remove(dir_ / "depth" / "1.png");
  EXPECT_THROW(sequence->frame(1), Error);
}

TEST_F(TempFolder, MalformedFoldersAndLogs) {
  EXPECT_THROW(io::open_seven_scenes(dir_), Error);
  EXPECT_THROW(io::open_tum_sequence(dir_), Error);  // no rgb.txt
  std::ofstream(dir_ / "bad.log") << "0 0 1\n1 0 0 0\n0 1 0 0\n";
  EXPECT_ERROR_MENTIONS(io::read_redwood_log(dir_ / "bad.log"), "truncated");
}

}  // namespace
}  // namespace kartograf
