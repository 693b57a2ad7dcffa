#pragma once
// A triangle mesh with vertex colours (the TSDF's surface, mapping/tsdf_mesh.hpp; PLY files,
// formats/ply.hpp).
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace kartograf {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;   // metres
  std::vector<std::uint32_t> colors;       // per vertex, 0xBBGGRR (empty: no colour)
  std::vector<Eigen::Vector3i> triangles;  // vertex indices, counter-clockwise seen from outside
};

}  // namespace kartograf
