#pragma once
// PCD (PCL's Point Cloud Data, v0.7) files in Kartograf's types, read and written the way PCL
// does, so that clouds move between Kartograf, PCL and Open3D unchanged.
//
// Reading takes every field type PCL writes (F4 F8 I1 I2 I4 I8 U1 U2 U4 U8), fields in any order,
// COUNT > 1, and DATA ascii, binary and binary_compressed (LZF, field by field). Kartograf keeps
// x y z, normal_x normal_y normal_z, rgb or rgba (4 bytes packed 0xAARRGGBB, whatever its TYPE)
// and label; every other field (curvature, intensity, PCL's "_" padding, FPFH histograms...) is
// skipped. A missing VERSION, COUNT, HEIGHT (1) or VIEWPOINT (identity) is tolerated like PCL
// does. Errors throw kartograf::Error naming the file, where (header line, data line, byte offset,
// point index) and what is wrong; sizes are checked against the file before anything is
// allocated, so a corrupt header cannot make the reader allocate what the file cannot hold.
//
// Writing: x y z [normal_x normal_y normal_z] as F4, [rgb] as PCL does (F4 holding 0x00RRGGBB),
// [label] as U4. Ascii floats are written in their shortest exact form, and rgb as the text of
// its float (9 digits): PCL 1.13 itself writes ascii rgb as TYPE U, which its own pcl_pcd2ply
// then corrupts, while TYPE F text is read right by PCL and Open3D (docs/interop.md). Organized
// clouds keep WIDTH x HEIGHT and their NaN points. The write is atomic.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "kartograf/core/color.hpp"
#include "kartograf/core/point_cloud.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::io {

enum class PcdEncoding { ascii, binary, binary_compressed };

// What a PCD file holds. points has width * height entries, row-major when organized.
struct PcdCloud {
  int width = 0;
  int height = 1;                        // > 1: organized
  std::vector<Eigen::Vector3f> points;   // a point with a non-finite coordinate is invalid
  std::vector<Eigen::Vector3f> normals;  // empty or one per point
  std::vector<Rgb8> colors;              // empty or one per point
  std::vector<std::uint32_t> labels;     // empty or one per point
  Eigen::Isometry3d viewpoint = Eigen::Isometry3d::Identity();  // sensor pose (VIEWPOINT)

  bool organized() const { return height > 1; }
  std::size_t size() const { return points.size(); }
  // Organized clouds only: (x, y, z, 1) per pixel, invalid_point() where the point is invalid.
  PointImage to_point_image() const;
  // The valid points with their normals and colours (labels are not part of a PointCloud).
  PointCloud to_point_cloud() const;
};

PcdCloud read_pcd(const std::filesystem::path& path);
// The parser behind read_pcd, on bytes in memory; `name` stands for the file in messages.
PcdCloud parse_pcd(std::span<const std::uint8_t> bytes, const std::string& name);

// Throws Error naming path when points.size() != width * height or normals, colors or labels are
// neither empty nor one per point. The write is atomic.
void write_pcd(const std::filesystem::path& path, const PcdCloud& cloud,
               PcdEncoding encoding = PcdEncoding::binary);
// The bytes write_pcd writes (same checks; `name` stands for the file in messages).
std::vector<std::uint8_t> encode_pcd(const PcdCloud& cloud, PcdEncoding encoding,
                                     const std::string& name = "PCD data");

// An unorganized cloud (width = size, height = 1) with the cloud's normals and colours.
PcdCloud to_pcd(const PointCloud& cloud);
// An organized cloud: invalid pixels become NaN points. normals (x, y, z of each pixel) and colors,
// when given, must have the size of points.
PcdCloud to_pcd(const PointImage& points, const NormalImage* normals = nullptr,
                const RgbImage* colors = nullptr);

}  // namespace kartograf::io
