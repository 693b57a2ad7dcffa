// TUM RGB-D lists and trajectories: the genuine fr1/xyz files, round trips and malformed input.
#include <cmath>
#include <fstream>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/formats/tum.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

std::filesystem::path tum_dir() { return testing::data_dir() / "tum_fr1_xyz_lists_only"; }

class TumFiles : public testing::TempDirTest {
 protected:
  std::filesystem::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir() / name) << text;
    return dir() / name;
  }
};

TEST_F(TumFiles, ReadsGenuineFr1XyzGroundTruthAndLists) {
  const Trajectory gt = io::read_tum_trajectory(tum_dir() / "groundtruth.txt");
  ASSERT_EQ(gt.size(), 3000u);  // its third header line has no '#'
  EXPECT_DOUBLE_EQ(gt.front().timestamp, 1305031098.6659);
  EXPECT_NEAR(gt.front().pose.translation().x(), 1.3563, 1e-12);
  const Eigen::Quaterniond q(gt.front().pose.rotation());
  EXPECT_NEAR(std::fabs(q.dot(Eigen::Quaterniond(-0.3986, 0.6132, 0.5962, -0.3311).normalized())), 1.0, 1e-9);
  EXPECT_DOUBLE_EQ(gt.back().timestamp, 1305031128.7555);

  const auto rgb = io::read_tum_file_list(tum_dir() / "rgb.txt");
  const auto depth = io::read_tum_file_list(tum_dir() / "depth.txt");
  ASSERT_EQ(rgb.size(), 798u);
  ASSERT_EQ(depth.size(), 798u);
  EXPECT_EQ(rgb.front().file, "rgb/1305031102.175304.png");
  EXPECT_DOUBLE_EQ(depth.front().timestamp, 1305031102.160407);
}

TEST_F(TumFiles, AssociationReproducesTumsAssociatePy) {
  // rgb-depth-synced.txt is associate.py's output (max difference 0.02 s) for these lists.
  const auto rgb = io::read_tum_file_list(tum_dir() / "rgb.txt");
  const auto depth = io::read_tum_file_list(tum_dir() / "depth.txt");
  std::vector<double> rgb_times, depth_times;
  for (const auto& f : rgb) rgb_times.push_back(f.timestamp);
  for (const auto& f : depth) depth_times.push_back(f.timestamp);
  const auto pairs = io::associate_timestamps(rgb_times, depth_times, 0.02);

  std::ifstream synced(tum_dir() / "rgb-depth-synced.txt");
  std::vector<std::pair<std::string, std::string>> expected;
  for (std::string t1, f1, t2, f2; synced >> t1 >> f1 >> t2 >> f2;) expected.emplace_back(f1, f2);
  ASSERT_EQ(expected.size(), 792u);
  ASSERT_EQ(pairs.size(), expected.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    EXPECT_EQ(rgb[pairs[k].first].file, expected[k].first) << k;
    EXPECT_EQ(depth[pairs[k].second].file, expected[k].second) << k;
  }
}

TEST_F(TumFiles, AssociationTakesClosestPairsFirstAndEachIndexOnce) {
  const auto pairs = io::associate_timestamps({1.0, 1.01, 2.0}, {1.008, 3.0}, 0.02);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0], (std::pair<std::size_t, std::size_t>{1, 0}));  // 1.01 is closer to 1.008
  EXPECT_TRUE(io::associate_timestamps({1.0}, {1.5}, 0.02).empty());
  EXPECT_THROW(io::associate_timestamps({1.0}, {1.0}, -1), Error);
}

TEST_F(TumFiles, TrajectoryRoundTrips) {
  Trajectory trajectory;
  for (int i = 0; i < 5; ++i) {
    StampedPose p;
    p.timestamp = 1305031102.175304 + i * 0.033;
    p.pose = Eigen::Translation3d(0.1 * i, -0.2, 1.5) * Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d(1, 2, 2).normalized());
    trajectory.push_back(p);
  }
  const auto path = dir() / "out.txt";
  io::write_tum_trajectory(path, trajectory);
  const Trajectory back = io::read_tum_trajectory(path);
  ASSERT_EQ(back.size(), trajectory.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_NEAR(back[i].timestamp, trajectory[i].timestamp, 1e-6);
    EXPECT_LT((back[i].pose.matrix() - trajectory[i].pose.matrix()).cwiseAbs().maxCoeff(), 1e-8);
  }
}

TEST_F(TumFiles, MalformedInputNamesFileAndLine) {
  const auto short_line = write("a.txt", "# comment\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0\n");
  EXPECT_ERROR_MENTIONS(io::read_tum_trajectory(short_line), "line 3");
  const auto not_number = write("b.txt", "1.0 0 0 0 0 0 0 1\n2.0 x 0 0 0 0 0 1\n");
  EXPECT_ERROR_MENTIONS(io::read_tum_trajectory(not_number), "'x'");
  const auto bad_quaternion = write("c.txt", "1.0 0 0 0 0 0 0 2\n");
  EXPECT_ERROR_MENTIONS(io::read_tum_trajectory(bad_quaternion), "quaternion");
  const auto nan = write("d.txt", "1.0 nan 0 0 0 0 0 1\n");
  EXPECT_ERROR_MENTIONS(io::read_tum_trajectory(nan), "line 1");
  const auto list = write("e.txt", "timestamp filename\n1.0 rgb/1.png\n2.0\n");
  EXPECT_ERROR_MENTIONS(io::read_tum_file_list(list), "line 3");
  EXPECT_ERROR_MENTIONS(io::read_tum_file_list(dir() / "missing.txt"), "cannot open");
}

}  // namespace
}  // namespace kartograf
