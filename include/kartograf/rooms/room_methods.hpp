#pragma once
// The room segmentation methods by name, for the CLI, the benchmark and the pipeline: one call
// that runs any of them with its reference parameters (or other room-area limits).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/rooms/furniture.hpp"
#include "kartograf/rooms/room_segmentation.hpp"

namespace kartograf::compute {
class Context;
}

namespace kartograf::rooms {

enum class RoomMethod { morphological, distance, voronoi, feature, vrf };

std::string to_string(RoomMethod method);
// Throws Error listing the known names.
RoomMethod parse_room_method(const std::string& name);
const std::vector<RoomMethod>& all_room_methods();

struct RoomMethodParams {
  std::optional<AreaLimits> room_area;  // else the method's own default
  // Segment the map without its furniture (furniture.hpp), then give the furniture's cells no
  // room: the rooms stay whole where tables and chairs stand. Empty: segment the map as it is
  // (the survey's reference behaviour).
  std::optional<FurnitureParams> furniture = FurnitureParams{};
  // feature, vrf: the trained model (default_room_classifier_path() or default_vrf_model_path()
  // when empty).
  std::filesystem::path model;
};

// `context`: the backend the feature method's laser scans run on (the other methods run on the
// host).
RoomSegmentation segment_rooms(const compute::Context& context, const OccupancyGrid& map,
                               RoomMethod method, const RoomMethodParams& options = {});

}  // namespace kartograf::rooms
