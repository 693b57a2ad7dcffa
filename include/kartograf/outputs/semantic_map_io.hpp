#pragma once
// The files of a semantic grid map (docs/methods.md M2): semantic.json (the grid's geometry, the
// class traversability weights, every object with its contour and metric description, and planned
// paths) and a ROS map_server costmap pair in raw mode (0 free .. 254 lethal, 255 unknown). Each
// file is written whole under a temporary name and renamed: an error leaves no partial file.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include <Eigen/Core>

#include "kartograf/core/image.hpp"
#include "kartograf/semantic/planning.hpp"
#include "kartograf/semantic/semantic_grid.hpp"

namespace kartograf::io {

// A planned path and the query that made it ("goto door", "along wall").
struct NamedPath {
  std::string query;
  semantic::PlannedPath path;
};

void write_semantic_json(const std::filesystem::path& path, const semantic::SemanticGrid& grid,
                         std::span<const NamedPath> paths = {}, const std::string& source = "");

// `yaml_path` and <stem>.pgm beside it. Throws Error for an empty costmap, a resolution <= 0 or a
// YAML path ending in .pgm.
void write_ros_costmap(const std::filesystem::path& yaml_path, const Image<std::uint8_t>& costmap,
                       double resolution, const Eigen::Vector3d& origin);

}  // namespace kartograf::io
