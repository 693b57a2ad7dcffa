#pragma once
// PLY point clouds. Writes binary little-endian with vertex properties x y z (float), then
// nx ny nz (float) and red green blue (uchar) when given. Reads ascii and binary PLY files whose
// vertex element has x, y, z and optionally nx, ny, nz and red, green, blue (uchar); other
// properties and elements (faces...) are skipped. Errors throw kartograf::Error naming the file,
// where (header line, body line or byte offset) and what is wrong.
#include <filesystem>

#include "kartograf/core/color.hpp"
#include "kartograf/core/point_cloud.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::io {

// An organized (or, with height 1, unorganized) cloud. Pixels whose point is NaN are skipped; a
// point whose normal is NaN is written with normal (0, 0, 0), which viewers treat as "none".
// normals and colors, when given, must have the size of points. The write is atomic.
void write_ply(const std::filesystem::path& path, const PointImage& points,
               const NormalImage* normals = nullptr, const RgbImage* colors = nullptr);

// Same rules; cloud.normals and cloud.colors must be empty or one per point.
void write_ply(const std::filesystem::path& path, const PointCloud& cloud);

PointCloud read_ply(const std::filesystem::path& path);

}  // namespace kartograf::io
