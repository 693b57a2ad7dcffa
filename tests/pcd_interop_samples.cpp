// The Kartograf side of scripts/check-interop.sh, as its own program (kartograf_interop_samples,
// not part of ctest): PcdInterop.WriteSamples writes the PCD and PLY samples that the script hands
// to Open3D and PCL, and PcdInterop.Reads* check that what they wrote from them reads back to the
// values written. Every test needs KARTOGRAF_INTEROP_DIR to name an existing folder and fails
// without it: the program has no use outside the script, so a missing folder is an error.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "kartograf/formats/pcd.hpp"
#include "kartograf/formats/ply.hpp"

namespace kartograf {
namespace {

namespace fs = std::filesystem;
using io::PcdCloud;
using io::PcdEncoding;

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

// Deterministic and exactly representable in PCL's default 8-digit ascii output.
PcdCloud interop_cloud(bool organized) {
  PcdCloud cloud;
  cloud.width = organized ? 16 : 500;
  cloud.height = organized ? 12 : 1;
  for (int i = 0; i < cloud.width * cloud.height; ++i) {
    const bool hole = organized && i % 7 == 3;
    cloud.points.push_back(hole ? Eigen::Vector3f(kNan, kNan, kNan)
                                : Eigen::Vector3f(0.25f * float(i % 16), -0.5f * float(i / 16),
                                                  1.0f + 0.125f * float(i % 5)));
    if (!organized) cloud.normals.push_back(Eigen::Vector3f(0.0f, 0.6f, -0.8f));
    cloud.colors.push_back({static_cast<std::uint8_t>(i % 256), static_cast<std::uint8_t>(200),
                            static_cast<std::uint8_t>(255 - i % 256)});
    if (!organized) cloud.labels.push_back(static_cast<std::uint32_t>(i / 100));
  }
  return cloud;
}

constexpr std::array<std::pair<PcdEncoding, const char*>, 3> kEncodings = {{
    {PcdEncoding::ascii, "ascii"},
    {PcdEncoding::binary, "binary"},
    {PcdEncoding::binary_compressed, "binary_compressed"},
}};

// Every coordinate's bits, with one pattern for all NaNs: PCL and Open3D keep NaN points but not
// necessarily their payload, and everything else must come back bit-exact (-0 included).
std::vector<std::uint32_t> bits_of(const std::vector<Eigen::Vector3f>& vectors) {
  std::vector<std::uint32_t> bits;
  for (const Eigen::Vector3f& v : vectors) {
    for (int axis = 0; axis < 3; ++axis) {
      bits.push_back(std::isnan(v[axis]) ? 0x7fc00000u : std::bit_cast<std::uint32_t>(v[axis]));
    }
  }
  return bits;
}

void expect_same_points(const PointCloud& expected, const PointCloud& actual) {
  EXPECT_EQ(bits_of(actual.points), bits_of(expected.points));
  EXPECT_EQ(bits_of(actual.normals), bits_of(expected.normals));
  EXPECT_EQ(actual.colors, expected.colors);
}

PointCloud points_of(const PcdCloud& cloud) {
  return {cloud.points, cloud.normals, cloud.colors};
}

// A PCD file PCL wrote: the points, the labels and the layout Kartograf wrote.
void expect_same_cloud(const PcdCloud& expected, const PcdCloud& actual) {
  EXPECT_EQ(actual.width, expected.width);
  EXPECT_EQ(actual.height, expected.height);
  expect_same_points(points_of(expected), points_of(actual));
  EXPECT_EQ(actual.labels, expected.labels);
  EXPECT_TRUE(actual.viewpoint.isApprox(expected.viewpoint, 1e-12))
      << actual.viewpoint.matrix() << "\nexpected\n"
      << expected.viewpoint.matrix();
}

class PcdInterop : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* dir = std::getenv("KARTOGRAF_INTEROP_DIR");
    ASSERT_TRUE(dir != nullptr && *dir != '\0')
        << "KARTOGRAF_INTEROP_DIR is not set: this program is run by scripts/check-interop.sh";
    dir_ = dir;
    ASSERT_TRUE(fs::is_directory(dir_)) << dir_ << " (KARTOGRAF_INTEROP_DIR) is not a folder";
  }

  fs::path dir_;
};

TEST_F(PcdInterop, WriteSamples) {
  // expected.txt: file, points in the file, normals, colours, first point, its colour.
  std::ofstream manifest(dir_ / "expected.txt");
  for (bool organized : {false, true}) {
    const PcdCloud cloud = interop_cloud(organized);
    const std::string kind = organized ? "organized" : "unorganized";
    for (const auto& [encoding, name] : kEncodings) {
      const std::string file = "kartograf_" + kind + "_" + name + ".pcd";
      io::write_pcd(dir_ / file, cloud, encoding);
      manifest << file << ' ' << cloud.size() << ' ' << !cloud.normals.empty() << " 1 "
               << cloud.points[0].x() << ' ' << cloud.points[0].y() << ' ' << cloud.points[0].z()
               << ' ' << int{cloud.colors[0][0]} << ' ' << int{cloud.colors[0][1]} << ' '
               << int{cloud.colors[0][2]} << '\n';
    }
  }
  const PointCloud ply = interop_cloud(false).to_point_cloud();
  for (const auto& [encoding, name] :
       {std::pair{io::PlyEncoding::binary_little_endian, "binary_little_endian"},
        std::pair{io::PlyEncoding::ascii, "ascii"}}) {
    const std::string file = std::string("kartograf_unorganized_") + name + ".ply";
    io::write_ply(dir_ / file, ply, encoding);
    manifest << file << ' ' << ply.size() << " 1 1 " << ply.points[0].x() << ' '
             << ply.points[0].y() << ' ' << ply.points[0].z() << ' ' << int{ply.colors[0][0]} << ' '
             << int{ply.colors[0][1]} << ' ' << int{ply.colors[0][2]} << '\n';
  }
  ASSERT_TRUE(manifest.good());
}

// What PCL wrote from the samples (the script puts it in <dir>/pcl): Kartograf reads it back to
// the values it wrote.
TEST_F(PcdInterop, ReadsWhatPclWrote) {
  const fs::path dir = dir_ / "pcl";
  ASSERT_TRUE(fs::is_directory(dir)) << dir << ": run scripts/check-interop.sh";
  int checked = 0;
  for (bool organized : {false, true}) {
    const PcdCloud expected = interop_cloud(organized);
    const std::string kind = organized ? "organized" : "unorganized";
    for (const auto& [encoding, name] : kEncodings) {
      // pcl_convert_pcd_ascii_binary of Kartograf's binary file: PCL's PCD writer.
      const fs::path pcd = dir / ("convert_" + kind + "_" + name + ".pcd");
      SCOPED_TRACE(pcd.string());
      expect_same_cloud(expected, io::read_pcd(pcd));
      // pcl_pcd2ply of each of Kartograf's encodings: PCL keeps the NaN points in its PLY.
      const fs::path ply = dir / ("pcd2ply_" + kind + "_" + name + ".ply");
      SCOPED_TRACE(ply.string());
      expect_same_points(points_of(expected), io::read_ply(ply));
      checked += 2;
    }
  }
  // pcl_ply2pcd of Kartograf's PLY files.
  const PointCloud valid = interop_cloud(false).to_point_cloud();
  for (const char* name : {"binary_little_endian", "ascii"}) {
    const fs::path file = dir / (std::string("ply2pcd_") + name + ".pcd");
    SCOPED_TRACE(file.string());
    expect_same_points(valid, points_of(io::read_pcd(file)));
    ++checked;
  }
  // pcl_fpfh_estimation's output: fpfh (COUNT 33) first, then x y z and the normals.
  const PcdCloud fpfh = io::read_pcd(dir / "fpfh.pcd");
  EXPECT_EQ(bits_of(fpfh.points), bits_of(valid.points));
  EXPECT_EQ(bits_of(fpfh.normals), bits_of(valid.normals));
  ++checked;
  EXPECT_EQ(checked, 15);
}

// What Open3D wrote from the unorganized sample (<dir>/open3d).
TEST_F(PcdInterop, ReadsWhatOpen3dWrote) {
  const fs::path dir = dir_ / "open3d";
  ASSERT_TRUE(fs::is_directory(dir)) << dir << ": run scripts/check-interop.sh";
  const PointCloud valid = interop_cloud(false).to_point_cloud();
  for (const char* name : {"ascii", "binary", "binary_compressed"}) {
    const fs::path file = dir / (std::string("open3d_") + name + ".pcd");
    SCOPED_TRACE(file.string());
    expect_same_points(valid, points_of(io::read_pcd(file)));
  }
  for (const char* name : {"binary", "ascii"}) {
    const fs::path file = dir / (std::string("open3d_") + name + ".ply");
    SCOPED_TRACE(file.string());
    expect_same_points(valid, io::read_ply(file));
  }
}

}  // namespace
}  // namespace kartograf
