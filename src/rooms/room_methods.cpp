#include "kartograf/rooms/room_methods.hpp"

#include "kartograf/core/error.hpp"
#include "kartograf/core/memory_budget.hpp"
#include "kartograf/rooms/feature_segmentation.hpp"
#include "kartograf/rooms/threshold_methods.hpp"
#include "kartograf/rooms/voronoi_random_field.hpp"
#include "kartograf/rooms/voronoi_segmentation.hpp"

namespace kartograf::rooms {

namespace {

template <class Params>
Params with_options(Params params, const RoomMethodParams& options) {
  if (options.room_area) params.room_area = *options.room_area;
  params.furniture = options.furniture;
  return params;
}

// Peak memory per map cell: the max RSS of `kartograf rooms` on ipa_room_maps/lab_ipa.png scaled
// 1 and 3 times (864 x 768 and 2592 x 2304 cells) grew by 28, 33, 20, 11 and 34 bytes per added
// cell (morphological, distance, voronoi, feature, vrf); half as much again for other maps.
double bytes_per_cell(RoomMethod method) {
  switch (method) {
    case RoomMethod::morphological:
      return 42;
    case RoomMethod::distance:
      return 50;
    case RoomMethod::voronoi:
      return 30;
    case RoomMethod::feature:
      return 17;
    case RoomMethod::vrf:
      return 51;
  }
  return 51;
}

}  // namespace

const std::vector<RoomMethod>& all_room_methods() {
  static const std::vector<RoomMethod> methods{RoomMethod::morphological, RoomMethod::distance,
                                               RoomMethod::voronoi, RoomMethod::feature,
                                               RoomMethod::vrf};
  return methods;
}

std::string to_string(RoomMethod method) {
  switch (method) {
    case RoomMethod::morphological:
      return "morphological";
    case RoomMethod::distance:
      return "distance";
    case RoomMethod::voronoi:
      return "voronoi";
    case RoomMethod::feature:
      return "feature";
    case RoomMethod::vrf:
      return "vrf";
  }
  return "unknown";
}

RoomMethod parse_room_method(const std::string& name) {
  std::string known;
  for (const RoomMethod method : all_room_methods()) {
    if (to_string(method) == name) return method;
    if (!known.empty()) known += '|';
    known += to_string(method);
  }
  throw Error("unknown room segmentation method '" + name + "' (known: " + known + ")");
}

RoomSegmentation segment_rooms(const compute::Context& context, const OccupancyGrid& map,
                               RoomMethod method, const RoomMethodParams& options) {
  require_fits_in_memory(bytes_per_cell(method) * static_cast<double>(map.cells.size()),
                         "room segmentation (" + to_string(method) + ") of a " +
                             std::to_string(map.width()) + " x " + std::to_string(map.height()) +
                             " map");
  switch (method) {
    case RoomMethod::morphological:
      return segment_morphological(map, with_options(MorphologicalParams{}, options));
    case RoomMethod::distance:
      return segment_distance_transform(map, with_options(DistanceTransformParams{}, options));
    case RoomMethod::voronoi:
      return segment_voronoi(map, with_options(VoronoiParams{}, options));
    case RoomMethod::feature: {
      FeatureSegmentationParams params;
      if (options.room_area) params.region_area = *options.room_area;
      const RoomClassifier classifier = RoomClassifier::load(
          options.model.empty() ? default_room_classifier_path() : options.model);
      return segment_feature_based(context, map, classifier, params);
    }
    case RoomMethod::vrf: {
      const VrfModel model =
          VrfModel::load(options.model.empty() ? default_vrf_model_path() : options.model);
      return segment_voronoi_random_field(map, model, with_options(VrfParams{}, options));
    }
  }
  throw Error("segment_rooms: unknown method");
}

}  // namespace kartograf::rooms
