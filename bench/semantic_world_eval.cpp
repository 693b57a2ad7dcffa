// Issue 7 experiment (docs/methods.md M2): the semantic grid of the synthetic world against its
// floor plan, and "go to the door" paths checked against the true doors and obstacles.
//   kartograf_semantic_world_eval [seed=5] [frames=300] [step=3] [width=320] [noise 0/1=1] [outdir]
//       [survey 0/1=0]
// TOUR_SURVEY=1 in the environment: the tour itself is a survey (TourParams::survey);
// TOUR_PITCH=degrees: the tour's camera pitch.
// Frames: every step-th frame of the robot tour, plus (survey) 12 headings x 2 pitches at each
// room's most open point and every 25th tour pose. Labels: the synthetic ground truth, or with
// OURS=1 in the environment Kartograf's own (semantic::label_organized_points per frame; frames
// whose gravity cannot be estimated stay unknown). Points go to the world with the true poses.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/semantic/classify.hpp"
#include "kartograf/semantic/planning.hpp"
#include "kartograf/semantic/semantic_grid.hpp"
#include "kartograf/synth/floor_plan.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"

using namespace kartograf;

namespace {

struct Args {
  std::uint64_t seed;
  int frames, step, width;
  bool noise;
  std::string out;
  bool survey;
};

Args parse_args(int argc, char** argv) {
  const std::uint64_t seed = argc > 1 ? std::stoull(argv[1]) : 5;
  const int frames = argc > 2 ? std::stoi(argv[2]) : 300;
  const int step = argc > 3 ? std::stoi(argv[3]) : 3;
  const int width = argc > 4 ? std::stoi(argv[4]) : 320;
  const bool noise = argc > 5 ? std::stoi(argv[5]) != 0 : true;
  const std::string out = argc > 6 ? argv[6] : "";
  const bool survey = argc > 7 ? std::stoi(argv[7]) != 0 : false;
  return {seed, frames, step, width, noise, out, survey};
}

// Every step-th tour pose; with survey, 360-degree sweeps, looking down at the floor and up at the
// lintels, at every room's most open point and every 25th tour pose.
std::vector<Eigen::Isometry3d> camera_poses(const synth::World& world, const Trajectory& tour,
                                            const Args& args) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < args.frames; i += args.step) poses.push_back(tour[i].pose);
  if (!args.survey) return poses;
  std::vector<Eigen::Vector3d> spots;
  for (const auto& room : world.rooms) {
    const Eigen::Vector2d p = synth::most_open_point(world, room.id).first;
    spots.emplace_back(p.x(), p.y(), 1.0);
  }
  for (int i = 0; i < args.frames; i += 25) spots.push_back(tour[i].pose.translation());
  for (const auto& p : spots)
    for (int a = 0; a < 12; ++a)
      for (const double pitch : {0.6, -0.2})
        poses.push_back(synth::camera_pose(p, a * M_PI / 6, pitch));
  return poses;
}

// Kartograf's own labels of a frame; all unknown where the labelling fails (gravity not
// estimated), the first three failures reported.
SemanticImage own_labels(const compute::Context& context, const synth::SyntheticFrame& frame,
                         const PinholeIntrinsics& k, std::size_t i, int& failed) {
  const int width = k.width, height = k.height;
  PointImage image(width, height, invalid_point());
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      const std::uint16_t d = frame.depth(u, v);
      if (!d) continue;
      const double z = d / synth::kTumDepthUnitsPerMetre;
      image(u, v) =
          Point4f(float((u - k.cx) / k.fx * z), float((v - k.cy) / k.fy * z), float(z), 1.0f);
    }
  semantic::LabellingParams lp;
  lp.gravity.prior_up = Eigen::Vector3d(0, -1, 0);
  try {
    return semantic::label_organized_points(context, image, lp).semantic;
  } catch (const std::exception& e) {
    if (++failed <= 3) std::printf("frame %zu unlabelled: %s\n", i, e.what());
    return SemanticImage(width, height, SemanticClass::unknown);
  }
}

struct LabelledPoints {
  std::vector<Eigen::Vector3d> points;
  std::vector<SemanticClass> labels;
};

// The frame's points in the world (through `pose`) with their labels.
void add_frame_points(const synth::SyntheticFrame& frame, const SemanticImage& frame_labels,
                      const PinholeIntrinsics& k, const Eigen::Isometry3d& pose,
                      LabelledPoints& out) {
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::uint16_t d = frame.depth(u, v);
      if (!d) continue;
      const double z = d / synth::kTumDepthUnitsPerMetre;
      out.points.push_back(pose * Eigen::Vector3d((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z));
      out.labels.push_back(frame_labels(u, v));
    }
  }
}

// Renders a frame from each pose; its points with the synthetic labels, or with OURS set
// Kartograf's own.
LabelledPoints render_labelled_points(const synth::World& world, const PinholeIntrinsics& k,
                                      const std::vector<Eigen::Isometry3d>& poses, bool noise) {
  const bool ours = std::getenv("OURS") != nullptr;
  const compute::Context context = compute::Context::cpu();
  int failed = 0;
  LabelledPoints out;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const synth::SyntheticFrame frame = synth::render(
        world, k, poses[i], noise ? synth::NoiseModel::kinect() : synth::NoiseModel::none(), i);
    SemanticImage predicted;
    if (ours) predicted = own_labels(context, frame, k, i, failed);
    add_frame_points(frame, ours ? predicted : frame.semantic, k, poses[i], out);
  }
  return out;
}

// Free-space IoU against the floor plan (with furniture and door leaves).
void print_free_space(const semantic::SemanticGrid& grid, const synth::FloorPlan& plan) {
  long miss_by_ours[6] = {}, extra_by_gt[6] = {};
  long inter = 0, uni = 0, gt_free = 0, ours_free = 0, unobserved_gt_free = 0;
  for (int row = 0; row < plan.grid.height(); ++row) {
    for (int col = 0; col < plan.grid.width(); ++col) {
      const bool gt = plan.grid.cells(col, row) == CellState::free;
      const Eigen::Vector2i c = grid.cell_of(plan.grid.cell_center(col, row));
      const bool in = grid.contains(c);
      const float w = in ? grid.weight(c.x(), c.y()) : semantic::kUnobserved;
      const bool ours = in && w > 0;
      if (gt && !ours && in) ++miss_by_ours[static_cast<int>(grid.classes(c.x(), c.y()))];
      if (!gt && ours) ++extra_by_gt[static_cast<int>(plan.semantic(col, row))];
      inter += gt && ours;
      uni += gt || ours;
      gt_free += gt;
      ours_free += ours;
      unobserved_gt_free += gt && std::isnan(w);
    }
  }
  std::printf("free space IoU %.4f (gt free %ld, ours %ld, both %ld, gt-free unobserved %ld)\n",
              double(inter) / uni, gt_free, ours_free, inter, unobserved_gt_free);

  std::printf("gt free but ours blocked, by our class: ");
  for (int i = 0; i < 6; ++i)
    std::printf("%s %ld  ", std::string(kSemanticClassNames[i]).c_str(), miss_by_ours[i]);
  std::printf("\nours free but gt blocked, by gt class: ");
  for (int i = 0; i < 6; ++i)
    std::printf("%s %ld  ", std::string(kSemanticClassNames[i]).c_str(), extra_by_gt[i]);
  std::printf("\n");
}

// Object counts against the world's; with WALLS set each wall; the true doorways and each found
// doorway's nearest.
void print_objects(const semantic::SemanticGrid& grid, const synth::World& world) {
  int doorways = 0, leaves = 0, walls = 0, furn = 0;
  for (const auto& o : grid.objects) {
    doorways += o.kind == semantic::ObjectKind::doorway;
    leaves += o.kind == semantic::ObjectKind::door_leaf;
    walls += o.kind == semantic::ObjectKind::wall;
    furn += o.kind == semantic::ObjectKind::furniture;
  }
  std::printf(
      "objects: %d doorways (world %zu), %d door leaves (world %zu), %d walls, %d furniture (world "
      "%zu)\n",
      doorways, world.doorways.size(), leaves, world.door_leaves.size(), walls, furn,
      world.furniture.size());
  if (std::getenv("WALLS"))
    for (const auto& o : grid.objects)
      if (o.kind == semantic::ObjectKind::wall)
        std::printf("  %s (%.2f,%.2f)-(%.2f,%.2f) len %.2f cells %zu\n", o.name.c_str(),
                    o.axis_start.x(), o.axis_start.y(), o.axis_end.x(), o.axis_end.y(), o.width,
                    o.cells.size());
  for (const auto& d : world.doorways)
    std::printf("  true doorway %d centre (%.2f, %.2f) width %.2f axis %d\n", d.id,
                d.opening.center().x(), d.opening.center().y(), d.width, d.passage_axis);
  for (const auto& o : grid.objects) {
    if (o.kind != semantic::ObjectKind::doorway) continue;
    double best = 1e9, true_width = 0;
    for (const auto& d : world.doorways) {
      const double dist = (d.opening.center() - o.centre).norm();
      if (dist < best) best = dist, true_width = d.width;
    }
    std::printf(
        "  %s centre (%.2f, %.2f) width %.2f: nearest true doorway %.3f m away, width %.2f\n",
        o.name.c_str(), o.centre.x(), o.centre.y(), o.width, best, true_width);
  }
}

// A planned path against the floor plan.
struct PathCheck {
  double end_dist = 1e9;   // from its end to the nearest true doorway [m]
  int blocked = 0;         // path points outside free floor-plan cells
  double clearance = 1e9;  // to the nearest occupied cell centre (within 12 cells) [m]
};

PathCheck check_path(const semantic::PlannedPath& path, const synth::World& world,
                     const synth::FloorPlan& plan) {
  PathCheck check;
  for (const auto& d : world.doorways)
    check.end_dist = std::min(check.end_dist, (d.opening.center() - path.points.back()).norm());
  // Collision: every path point in free floor-plan space, clearance to occupied cells.
  for (const auto& p : path.points) {
    const Eigen::Vector2i c = plan.grid.cell_of(p);
    if (!plan.grid.contains(c) || plan.grid.cells(c.x(), c.y()) != CellState::free) ++check.blocked;
    for (int dy = -12; dy <= 12; ++dy)
      for (int dx = -12; dx <= 12; ++dx) {
        const Eigen::Vector2i n = c + Eigen::Vector2i(dx, dy);
        if (plan.grid.contains(n) && plan.grid.cells(n.x(), n.y()) == CellState::occupied)
          check.clearance =
              std::min(check.clearance, (plan.grid.cell_center(n.x(), n.y()) - p).norm());
      }
  }
  return check;
}

// "Go to the door" from several tour poses, each path checked and drawn.
void check_goto_door(const semantic::SemanticGrid& grid, const synth::World& world,
                     const synth::FloorPlan& plan, const Trajectory& tour, int frames,
                     semantic::MapPicture& picture) {
  int ok = 0, tried = 0;
  for (int i = 0; i < frames; i += frames / 6) {
    const Eigen::Vector2d start = tour[i].pose.translation().head<2>();
    ++tried;
    try {
      const semantic::PlannedPath path = semantic::plan_to_nearest_door(grid, start);
      const PathCheck check = check_path(path, world, plan);
      const bool good = check.blocked == 0 && check.end_dist <= 0.5;
      ok += good;
      std::printf(
          "goto door from frame %d (%.2f, %.2f): %zu cells, %.2f m, cost %.2f, end %.3f m from a "
          "true doorway, %d cells in gt obstacles, min clearance to gt obstacle centres %.3f m "
          "%s\n",
          i, start.x(), start.y(), path.cells.size(), path.length, path.cost, check.end_dist,
          check.blocked, check.clearance, good ? "OK" : "FAIL");
      semantic::draw_path(picture, path);
    } catch (const Error& e) {
      std::printf("goto door from frame %d: %s\n", i, e.what());
    }
  }
  std::printf("goto door: %d/%d ok\n", ok, tried);
}

// "Along the nearest wall" from the first tour pose: how far the path keeps from the wall line.
void check_along_wall(const semantic::SemanticGrid& grid, const Trajectory& tour,
                      semantic::MapPicture& picture) {
  try {
    const Eigen::Vector2d start = tour[0].pose.translation().head<2>();
    const semantic::PlannedPath wall = semantic::plan_along_nearest_wall(grid, start);
    const auto& o = grid.object(wall.target_object);
    double mean_off = 0;
    for (const auto& p : wall.points) {
      const Eigen::Vector2d ab = (o.axis_end - o.axis_start).normalized();
      mean_off += std::fabs(Eigen::Vector2d(-ab.y(), ab.x()).dot(p - o.axis_start));
    }
    std::printf(
        "along wall %s from frame 0: %zu cells, %.2f m, mean distance to wall line %.3f m\n",
        o.name.c_str(), wall.cells.size(), wall.length, mean_off / wall.points.size());
    semantic::draw_path(picture, wall, {0, 180, 0});
  } catch (const Error& e) {
    std::printf("along wall: %s\n", e.what());
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv);
  const int width = args.width, height = width * 3 / 4;
  const double f = 525.0 * width / 640.0;
  const PinholeIntrinsics k{width, height, f, f, (width - 1) / 2.0, (height - 1) / 2.0};

  const synth::World world = synth::make_building(args.seed);
  synth::TourParams tour_options;
  tour_options.survey = std::getenv("TOUR_SURVEY") != nullptr;  // turns in place (TourParams)
  if (const char* pitch = std::getenv("TOUR_PITCH")) tour_options.pitch_deg = std::stod(pitch);
  const Trajectory tour = synth::robot_tour(world, args.frames, tour_options);
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<Eigen::Isometry3d> poses = camera_poses(world, tour, args);
  const LabelledPoints labelled = render_labelled_points(world, k, poses, args.noise);
  const auto t1 = std::chrono::steady_clock::now();
  const semantic::SemanticGrid grid =
      semantic::build_semantic_grid(labelled.points, labelled.labels);
  const auto t2 = std::chrono::steady_clock::now();
  std::printf(
      "%zu poses (survey %d); seed %llu frames %d/%d %dx%d noise %d: %zu points, render %.2f s, "
      "grid %.3f s, %dx%d cells, floor_z %.3f ceiling %.3f\n",
      poses.size(), args.survey, (unsigned long long)args.seed,
      (args.frames + args.step - 1) / args.step, args.frames, width, height, args.noise,
      labelled.points.size(), std::chrono::duration<double>(t1 - t0).count(),
      std::chrono::duration<double>(t2 - t1).count(), grid.width(), grid.height(), grid.floor_z,
      grid.ceiling_z.value_or(-1));

  const synth::FloorPlan plan = synth::make_floor_plan(world);
  print_free_space(grid, plan);
  print_objects(grid, world);
  semantic::MapPicture picture = semantic::render_map(grid, 3);
  check_goto_door(grid, world, plan, tour, args.frames, picture);
  check_along_wall(grid, tour, picture);
  if (!args.out.empty()) {
    io::write_png(args.out + "/map.png", picture.image);
    io::write_ros_map(args.out + "/costmap.yaml", semantic::to_occupancy_grid(grid));
  }
  return 0;
}
