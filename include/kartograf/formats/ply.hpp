#pragma once
// PLY point clouds. Writes binary little-endian (or ascii) with vertex properties x y z (float),
// then nx ny nz (float) and red green blue (uchar) when given. Reads ascii, binary little-endian
// and binary big-endian PLY files whose
// vertex element has x, y, z and optionally nx, ny, nz and red, green, blue (uchar); other
// properties and elements (faces...) are skipped. Errors throw kartograf::Error naming the file,
// where (header line, body line or byte offset) and what is wrong.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "kartograf/core/color.hpp"
#include "kartograf/core/point_cloud.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/core/triangle_mesh.hpp"

namespace kartograf::io {

enum class PlyEncoding { binary_little_endian, ascii };

// An organized (or, with height 1, unorganized) cloud. Pixels whose point is NaN are skipped; a
// point whose normal is NaN is written with normal (0, 0, 0), which viewers treat as "none".
// normals and colors, when given, must have the size of points. The write is atomic.
// Ascii floats are written in their shortest form that reads back to the same value.
void write_ply(const std::filesystem::path& path, const PointImage& points,
               const NormalImage* normals = nullptr, const RgbImage* colors = nullptr,
               PlyEncoding encoding = PlyEncoding::binary_little_endian);

// Same rules; cloud.normals and cloud.colors must be empty or one per point.
void write_ply(const std::filesystem::path& path, const PointCloud& cloud,
               PlyEncoding encoding = PlyEncoding::binary_little_endian);

// A triangle mesh: vertices x y z (float) with red green blue (uchar) when it has colours, faces
// as lists of three vertex indices (uchar count, int indices), binary little-endian. Atomic.
void write_mesh_ply(const std::filesystem::path& path, const TriangleMesh& mesh);

PointCloud read_ply(const std::filesystem::path& path);
// The parser behind read_ply, on bytes in memory; `name` stands for the file in messages.
PointCloud parse_ply(std::span<const std::uint8_t> bytes, const std::string& name);

}  // namespace kartograf::io
