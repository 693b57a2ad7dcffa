#include "kartograf/pipeline/map_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>

#include "kartograf/core/error.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/mapping/frame_store.hpp"
#include "kartograf/pipeline/labelled_view_pool.hpp"
#include "kartograf/semantic/labelled_views.hpp"

namespace kartograf::pipeline {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A grey image where the source has no colour: region growing then splits by geometry alone.
RgbImage colour_or_grey(const registration::RgbdImages& frame) {
  if (!frame.color.empty()) return frame.color;
  return RgbImage(frame.depth.width(), frame.depth.height(), Rgb8{128, 128, 128});
}

// Stage bookkeeping: announces a stage, and records its time when the next one starts.
class StageClock {
 public:
  StageClock(const MapPipelineObserver& observer, std::vector<StageTiming>& timings)
      : observer_(observer), timings_(timings) {}
  void start(std::string stage) {
    stop();
    timings_.push_back({std::move(stage), 0});
    start_ = Clock::now();
    if (observer_.on_stage) observer_.on_stage(timings_.back().stage);
  }
  void stop() {
    if (!timings_.empty() && timings_.back().seconds == 0)
      timings_.back().seconds = seconds_since(start_);
  }

 private:
  const MapPipelineObserver& observer_;
  std::vector<StageTiming>& timings_;
  Clock::time_point start_;
};

// Rooms separated by a doorway of the grid are neighbours through it: the first room cell on
// either side of the doorway's middle (within reach) names the two, the doorway's opening is their
// doorway. Neighbours already touching keep their own record.
void connect_rooms_through_doorways(const semantic::SemanticGrid& grid,
                                    rooms::RoomSegmentation& segmentation) {
  constexpr double kReach = 0.6;  // metres from the doorway's line
  const LabelImage& labels = segmentation.rooms;
  const auto room_towards = [&](const Eigen::Vector2d& from, const Eigen::Vector2d& direction) {
    for (double t = 0; t <= kReach; t += 0.5 * grid.resolution) {
      const Eigen::Vector2i c = grid.cell_of(from + t * direction);
      if (!grid.contains(c)) break;
      if (const Label room = labels(c.x(), c.y())) return room;
    }
    return Label{0};
  };
  for (const semantic::SemanticObject& door : grid.objects) {
    if (door.kind != semantic::ObjectKind::doorway || door.width <= 0) continue;
    const Eigen::Vector2d u = (door.axis_end - door.axis_start).normalized();
    const Eigen::Vector2d n(-u.y(), u.x());
    const Label a = room_towards(door.centre, n), b = room_towards(door.centre, -n);
    if (!a || !b || a == b) continue;
    for (const auto& [room, other] : {std::pair{a, b}, std::pair{b, a}}) {
      rooms::RoomRecord& record = segmentation.records[room - 1];
      const auto at = std::lower_bound(record.neighbours.begin(), record.neighbours.end(), other);
      if (at != record.neighbours.end() && *at == other) continue;
      const auto index = at - record.neighbours.begin();
      record.neighbours.insert(at, other);
      rooms::Doorway doorway;
      doorway.other = other;
      doorway.from = door.axis_start, doorway.to = door.axis_end, doorway.width_m = door.width;
      doorway.cells = static_cast<int>(door.cells.size());
      record.doorways.insert(record.doorways.begin() + index, doorway);
    }
  }
}

// Stage 5: rooms on the occupancy grid (doorways closed if asked), then over what they enclose.
void segment_rooms(const compute::Context& context, const MapPipelineParams& params,
                   MapPipelineResult& result) {
  const semantic::SemanticGrid& grid = result.semantic;
  OccupancyGrid room_map = result.occupancy;
  // Furniture stands inside rooms: it must not split one (a cabinet narrowing a corridor).
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      if (grid.classes(col, row) == SemanticClass::furniture)
        room_map.cells(col, row) = CellState::free;
    }
  }
  // Before the doorways are closed: a doorway's cells are no unseen island.
  if (params.room_unseen_island_m2 > 0)
    rooms::free_unseen_islands(room_map, params.room_unseen_island_m2);
  if (params.rooms_end_at_doorways) {
    for (const semantic::SemanticObject& object : grid.objects) {
      if (object.kind != semantic::ObjectKind::doorway) continue;
      for (const Eigen::Vector2i& c : object.cells)
        room_map.cells(c.x(), c.y()) = CellState::occupied;
    }
  }
  result.rooms = rooms::segment_rooms(context, room_map, params.room_method, params.rooms);
  if (params.rooms_take_enclosed) {
    // Walls and doors bound rooms; everything else (furniture, unclassified obstacles, floor no
    // room reached, cells never observed) may belong to the room around it.
    Image<std::uint8_t> fillable(grid.width(), grid.height(), 0);
    for (int row = 0; row < grid.height(); ++row) {
      for (int col = 0; col < grid.width(); ++col) {
        const SemanticClass c = grid.classes(col, row);
        fillable(col, row) = c != SemanticClass::wall && c != SemanticClass::door;
      }
    }
    result.enclosed_cells_taken = rooms::extend_rooms_over_enclosed(result.rooms.rooms, fillable);
    if (params.room_fragment_area_m2 > 0) {
      const double cell_area = grid.resolution * grid.resolution;
      rooms::merge_room_fragments(result.rooms.rooms, cell_area, params.room_fragment_area_m2);
    }
    result.rooms.records = rooms::describe_rooms(result.rooms.rooms, result.occupancy);
  }
  connect_rooms_through_doorways(grid, result.rooms);
}

// The views stage's inputs for one view.
struct ViewLabeller {
  const compute::Context& context;
  const mapping::FrameSource& source;
  int factor;
  PinholeIntrinsics camera;  // of the decimated view
  geometry::DepthRange range;
  segmentation::PlaneExtractor extractor;

  // Labels frame i at `pose`, pools it and its planes; on failure the reason goes to `failure`
  // (when given; else the view is counted as skipped).
  bool label(std::size_t i, const Eigen::Isometry3d& pose, const semantic::LabellingParams& params,
             semantic::LabelledViews& views, mapping::PlaneMap& plane_map, std::string* failure) {
    const registration::RgbdImages frame = source.frame(i);
    const PointImage points =
        geometry::backproject(context, mapping::decimate(frame.depth, factor), camera, range);
    const std::string frame_name = "frame " + std::to_string(i) + ": ";
    const std::optional<semantic::SemanticLabelling> labelling =
        label_and_pool_view(context, points, pose, params, views, frame_name, failure);
    if (!labelling) return false;
    try {
      plane_map.add_view(
          extractor.extract(points, mapping::decimate(colour_or_grey(frame), factor)), points,
          labelling->semantic, pose);
    } catch (const Error& e) {
      views.skip(frame_name + e.what());  // a pooled view whose planes failed: skipped as well
    }
    return true;
  }
};

// Every label_step-th frame, or fewer so that at most max_views are labelled.
std::size_t view_step(const MapPipelineParams& params, std::size_t frames) {
  return std::max(params.label_step, (frames + params.max_views - 1) / params.max_views);
}

// Every view_step-th frame labelled with its own gravity estimate and pooled. Frames that cannot
// find up alone (no floor or ceiling in sight: close to a wall, a kitchen counter) are labelled
// again with the map's up and floor from the other views, through their SLAM pose.
void label_views(const compute::Context& context, const mapping::FrameSource& source,
                 const MapPipelineParams& params, const std::vector<Eigen::Isometry3d>& poses,
                 semantic::LabelledViews& views, mapping::PlaneMap& plane_map,
                 const MapPipelineObserver& observer) {
  const PinholeIntrinsics camera = source.camera();
  const int factor = mapping::decimation_for_width(camera, params.label_width);
  geometry::DepthRange range;
  range.units_per_metre = source.depth_units_per_metre();
  const PinholeIntrinsics view_camera = mapping::decimate(camera, factor);
  ViewLabeller labeller{context, source,
                        factor,  view_camera,
                        range,   segmentation::PlaneExtractor(context, view_camera, params.planes)};
  semantic::LabellingParams own = params.labelling;
  if (!own.gravity.prior_up) own.gravity.prior_up = Eigen::Vector3d(0, -1, 0);  // image up
  std::vector<std::pair<std::size_t, std::string>> retry;
  const std::size_t step = view_step(params, poses.size());
  for (std::size_t i = 0; i < poses.size(); i += step) {
    std::string failure;
    if (!labeller.label(i, poses[i], own, views, plane_map, &failure))
      retry.push_back({i, failure});
    if (observer.slam.on_progress) observer.slam.on_progress("views", i + 1, poses.size());
  }
  const Eigen::Vector3d up = views.up();
  const std::optional<double> floor = semantic::floor_height(views, up);
  for (const auto& [i, failure] : retry) {
    if (views.views() == 0 || !floor) {
      views.skip(failure);
      continue;
    }
    semantic::LabellingParams known = params.labelling;
    known.gravity.known_up = poses[i].linear().transpose() * up;
    known.gravity.known_floor_height = *floor - up.dot(poses[i].translation());
    labeller.label(i, poses[i], known, views, plane_map, nullptr);
  }
}

}  // namespace

features::OrbParams map_orb_params() {
  features::OrbParams params;
  params.fast_threshold = 5;
  params.features_per_frame = 3000;
  return params;
}

segmentation::PlaneExtractionParams view_plane_params() {
  segmentation::PlaneExtractionParams params;
  params.min_plane_pixels = 150;
  return params;
}

void MapPipelineParams::validate() const {
  require(label_step >= 1, "MapPipelineParams: label_step must be >= 1");
  require(max_views >= 1, "MapPipelineParams: max_views must be >= 1");
  require(label_width >= 64, "MapPipelineParams: label_width must be >= 64 pixels");
  require(room_fragment_area_m2 >= 0 && std::isfinite(room_fragment_area_m2),
          "MapPipelineParams: room_fragment_area_m2 must be finite and >= 0");
  require(room_unseen_island_m2 >= 0 && std::isfinite(room_unseen_island_m2),
          "MapPipelineParams: room_unseen_island_m2 must be finite and >= 0");
  planes.validate();
  plane_map.validate();
  grid.validate();
}

double MapPipelineResult::total_seconds() const {
  return std::accumulate(timings.begin(), timings.end(), 0.0,
                         [](double sum, const StageTiming& t) { return sum + t.seconds; });
}

void complete_map(const compute::Context& context, const mapping::FrameSource& views_source,
                  const MapPipelineParams& params, const MapPipelineObserver& observer,
                  MapPipelineResult& result) {
  StageClock clock(observer, result.timings);
  clock.start("views");
  semantic::LabelledViews views;
  mapping::PlaneMap plane_map(params.plane_map);
  label_views(context, views_source, params, result.slam.poses, views, plane_map, observer);
  result.labelled_views = views.views();
  result.unlabelled_views = views.skipped();
  result.first_unlabelled_reason = views.first_skip_reason();
  require(views.views() > 0,
          "map: views: no frame could be labelled (" + views.first_skip_reason() + ")");

  clock.start("gravity");
  const Eigen::Matrix3d up_to_z = views.make_up_z();
  const std::optional<double> floor = semantic::floor_height(views);
  require(floor.has_value(), "map: gravity: no view saw the floor");
  Eigen::Isometry3d& map_from_slam = result.map_from_slam;
  map_from_slam = Eigen::Isometry3d::Identity();
  map_from_slam.linear() = up_to_z;
  map_from_slam.translation() = Eigen::Vector3d(0, 0, -*floor);
  views.transform(Eigen::Isometry3d(Eigen::Translation3d(0, 0, -*floor)));
  for (const Eigen::Isometry3d& pose : result.slam.poses)
    result.poses.push_back(map_from_slam * pose);
  result.planes = plane_map.planes(map_from_slam);

  clock.start("grid");
  result.semantic = semantic::build_semantic_grid(views.points(), views.labels(), params.grid, {},
                                                  views.view_ids(), views.view_origins());
  result.occupancy = semantic::to_occupancy_grid(result.semantic);

  clock.start("rooms");
  segment_rooms(context, params, result);
  clock.stop();
}

}  // namespace kartograf::pipeline
