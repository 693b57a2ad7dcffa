// Measures M2 labelling (kartograf::semantic) on synthetic RGB-D frames and laser scans against
// the world's exact labels: per-class IoU (furniture and pixels without a point not scored) for
// robot-tour frames, the same poses looking 20 degrees up, one frame facing each door leaf, and one
// laser scan per room (also in a random frame). Usage:
//   kartograf_semantic_label_eval [seed=5] [frames=8] [kinect|none]
// KG_DUMP=DIR writes truth | labels | normals | regions pictures, KG_REGIONS=1 prints regions,
// KG_CONF=1 confusion matrices; KG_SMOOTH, KG_SJUMP, KG_NSIG, KG_LRAD, KG_NANG, KG_RANG, KG_JUMP,
// KG_TRIM, KG_FILLQ, KG_DOORW override parameters (see tune() below).
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>

#include "kartograf/compute/context.hpp"
#include "kartograf/eval/semantic_metrics.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/pcd.hpp"
#include "kartograf/semantic/classify.hpp"
#include "kartograf/synth/laser_scan.hpp"
#include "kartograf/synth/ray_caster.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"

using namespace kartograf;

namespace {

struct Totals {
  eval::ConfusionMatrix ignored = eval::ConfusionMatrix::Zero();  // furniture ignored
  eval::ConfusionMatrix counted = eval::ConfusionMatrix::Zero();  // furniture = unknown, counted
};

void add(Totals& t, const PointImage& points, const SemanticImage& gt, const SemanticImage& pred,
         const std::string& name) {
  SemanticImage g1 = gt, g2 = gt, p2 = pred;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    const bool valid = is_valid(points.pixels()[i]);
    const bool furniture = gt.pixels()[i] == SemanticClass::furniture;
    if (!valid || furniture) g1.pixels()[i] = SemanticClass::unknown;
    if (furniture) g2.pixels()[i] = SemanticClass::unknown;
    if (!valid) g2.pixels()[i] = p2.pixels()[i] = SemanticClass::unknown;
  }
  const auto a = eval::evaluate_semantic_segmentation(g1, pred);
  eval::SemanticEvaluationParams counted;
  counted.include_unknown_ground_truth = true;
  const auto b = eval::evaluate_semantic_segmentation(g2, p2, counted);
  t.ignored += a.confusion;
  if (std::getenv("KG_CONF")) {
    std::printf("confusion (rows GT unknown..furniture, cols pred):\n");
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) std::printf(" %7lld", static_cast<long long>(b.confusion(r, c)));
      std::printf("\n");
    }
  }
  t.counted += b.confusion;
  std::printf("%-22s", name.c_str());
  for (int c = 1; c <= 4; ++c) {
    if (a.iou[c])
      std::printf(" %7.4f", *a.iou[c]);
    else
      std::printf("       -");
  }
  std::printf("   (furniture counted:");
  for (int c = 1; c <= 4; ++c) {
    if (b.iou[c])
      std::printf(" %6.4f", *b.iou[c]);
    else
      std::printf("      -");
  }
  std::printf(")\n");
}

Rgb8 class_colour(SemanticClass c) {
  switch (c) {
    case SemanticClass::floor:
      return {60, 160, 60};
    case SemanticClass::wall:
      return {200, 200, 200};
    case SemanticClass::ceiling:
      return {80, 80, 220};
    case SemanticClass::door:
      return {220, 120, 20};
    case SemanticClass::furniture:
      return {160, 60, 160};
    default:
      return {0, 0, 0};
  }
}

// GT | prediction | normals (absolute) | regions, side by side.
RgbImage dump_picture(const SemanticImage& gt, const semantic::SemanticLabelling& r) {
  const int w = gt.width(), h = gt.height();
  RgbImage out(4 * w, h);
  const RgbImage normals = semantic::normals_to_rgb(r.normals, semantic::NormalEncoding::absolute);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      out(x, y) = class_colour(gt(x, y));
      out(w + x, y) = class_colour(r.semantic(x, y));
      out(2 * w + x, y) = normals(x, y);
      const unsigned l = r.regions.labels(x, y);
      out(3 * w + x, y) = l == 0 ? Rgb8{0, 0, 0}
                                 : Rgb8{static_cast<std::uint8_t>(l * 97 % 200 + 55),
                                        static_cast<std::uint8_t>(l * 57 % 200 + 55),
                                        static_cast<std::uint8_t>(l * 31 % 200 + 55)};
    }
  }
  return out;
}

// The GT door pixels: how many lie in no region, have a point, have a normal, and how far their
// normals turn from their mean.
void print_door_pixels(const PointImage& points, const SemanticImage& gt,
                       const semantic::SemanticLabelling& r) {
  int door_total = 0, door_unlabelled = 0;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    if (gt.pixels()[i] != SemanticClass::door) continue;
    ++door_total;
    if (!r.regions.labels.pixels()[i]) ++door_unlabelled;
  }
  int door_point = 0, door_normal = 0;
  Eigen::Vector3d door_mean = Eigen::Vector3d::Zero();
  std::vector<double> dots;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    if (gt.pixels()[i] != SemanticClass::door) continue;
    if (is_valid(r.normals.pixels()[i]))
      door_mean += r.normals.pixels()[i].head<3>().cast<double>();
  }
  door_mean.normalize();
  for (std::size_t i = 0; i < gt.size(); ++i) {
    if (gt.pixels()[i] != SemanticClass::door) continue;
    door_point += is_valid(points.pixels()[i]);
    if (is_valid(r.normals.pixels()[i])) {
      ++door_normal;
      dots.push_back(
          std::acos(std::min(1.0, door_mean.dot(r.normals.pixels()[i].head<3>().cast<double>()))) *
          57.3);
    }
  }
  std::sort(dots.begin(), dots.end());
  std::printf(
      "   GT door px %d, in no region %d, with point %d, with normal %d, angle to mean median "
      "%.1f p90 %.1f\n",
      door_total, door_unlabelled, door_point, door_normal,
      dots.empty() ? 0.0 : dots[dots.size() / 2], dots.empty() ? 0.0 : dots[dots.size() * 9 / 10]);
}

// A region with many GT door pixels: the parallel regions near its plane, and its neighbours.
void print_door_region_context(const semantic::SemanticLabelling& r,
                               const semantic::RegionMeasurements& m) {
  for (const auto& o : r.measurements) {
    if (o.id == m.id || o.mean_normal.dot(m.mean_normal) < 0.96) continue;
    const double off = o.plane_normal.dot(m.centroid - o.centroid);
    if (std::fabs(off) < 0.3)
      std::printf("     vs region %d (%s): in_front %.3f range %.2f\n", o.id,
                  std::string(to_string(r.region_classes[o.id - 1u])).c_str(), off,
                  m.centroid.norm());
  }
  std::printf("     neighbours:");
  for (auto nb : m.neighbours) std::printf(" %d", nb);
  std::printf("\n");
}

// The large regions (and those with GT door pixels): their GT classes and measurements.
void print_regions(const SemanticImage& gt, const semantic::SemanticLabelling& r) {
  std::vector<std::array<int, 6>> hist(r.measurements.size(), std::array<int, 6>{});
  for (std::size_t i = 0; i < gt.size(); ++i) {
    const unsigned l = r.regions.labels.pixels()[i];
    if (l) hist[l - 1][static_cast<int>(gt.pixels()[i])]++;
  }
  for (const auto& m : r.measurements) {
    if (m.pixel_count < 300 && hist[m.id - 1][4] < 50) continue;
    const auto& hh = hist[m.id - 1];
    if (hh[4] > 1000) print_door_region_context(r, m);
    std::printf("   gt[u%d f%d w%d c%d d%d F%d]", hh[0], hh[1], hh[2], hh[3], hh[4], hh[5]);
    std::printf(
        "   region %3d px %6d class %-8s orient %d h [%.2f %.2f] w %.2f area %.2f cut a%d b%d "
        "s%d n=(%.2f %.2f %.2f) nb %zu\n",
        m.id, m.pixel_count, std::string(to_string(r.region_classes[m.id - 1u])).c_str(),
        int(m.orientation), m.min_height, m.max_height, m.width, m.area, m.cut_above, m.cut_below,
        m.cut_sideways, m.mean_normal.x(), m.mean_normal.y(), m.mean_normal.z(),
        m.neighbours.size());
  }
}

// When KG_DUMP is set: the picture (dump_picture) and the gravity; with KG_REGIONS the door
// pixels and regions too.
void dump(const std::string& name, const PointImage& points, const SemanticImage& gt,
          const semantic::SemanticLabelling& r) {
  const char* dir = std::getenv("KG_DUMP");
  if (!dir) return;
  io::write_png(std::string(dir) + "/" + name + ".png", dump_picture(gt, r));
  std::printf("  gravity up (%.3f %.3f %.3f) floor %s ceiling %s\n", r.gravity.up.x(),
              r.gravity.up.y(), r.gravity.up.z(),
              r.gravity.floor_height ? std::to_string(*r.gravity.floor_height).c_str() : "-",
              r.gravity.ceiling_height ? std::to_string(*r.gravity.ceiling_height).c_str() : "-");
  if (std::getenv("KG_REGIONS")) {
    print_door_pixels(points, gt, r);
    print_regions(gt, r);
  }
}

void report(const char* title, const eval::ConfusionMatrix& m) {
  std::printf("%-22s", title);
  for (int c = 1; c <= 4; ++c) {
    const double tp = static_cast<double>(m(c, c));
    const double denom = static_cast<double>(m.row(c).sum() + m.col(c).sum()) - tp;
    if (denom > 0)
      std::printf(" %7.4f", tp / denom);
    else
      std::printf("       -");
  }
  std::printf("\n");
}

void header(const char* what) {
  std::printf("\n== %s ==\n%-22s %7s %7s %7s %7s\n", what, "item", "floor", "wall", "ceiling",
              "door");
}

// A real organized scan (no ground truth): the labelling's regions and pictures.
int label_real_scan(const std::string& path) {
  const PointImage points = io::read_pcd(path).to_point_image();
  const auto result = semantic::label_organized_points(compute::Context::cpu(), points, {});
  dump(std::filesystem::path(path).stem().string(), points,
       SemanticImage(points.width(), points.height(), SemanticClass::unknown), result);
  std::array<int, 6> counts{};
  for (const SemanticClass c : result.semantic.pixels()) counts[static_cast<int>(c)]++;
  std::printf("%s: unknown %d floor %d wall %d ceiling %d door %d\n", path.c_str(), counts[0],
              counts[1], counts[2], counts[3], counts[4]);
  return 0;
}

// KG_* in the environment override labelling parameters.
void tune(semantic::LabellingParams& p) {
  if (const char* s = std::getenv("KG_SMOOTH")) p.normals.smoothing_radius = std::atoi(s);
  if (const char* s = std::getenv("KG_SJUMP")) p.normals.max_relative_range_jump = std::atof(s);
  if (const char* s = std::getenv("KG_NSIG")) p.normals.noise_sigmas = std::atof(s);
  if (const char* s = std::getenv("KG_LRAD")) p.layers.smoothing_radius = std::atoi(s);
  if (const char* s = std::getenv("KG_LAYER")) p.layers.min_offset = std::atof(s);
  if (const char* s = std::getenv("KG_NANG")) p.regions.max_neighbour_angle_deg = std::atof(s);
  if (const char* s = std::getenv("KG_RANG")) p.regions.max_region_angle_deg = std::atof(s);
  if (const char* s = std::getenv("KG_JUMP")) p.regions.max_relative_range_jump = std::atof(s);
  if (const char* s = std::getenv("KG_TRIM")) p.measure.trim_fraction = std::atof(s);
  if (const char* s = std::getenv("KG_FILLQ")) p.regions.fill_quadratic_distance = std::atof(s);
  if (const char* s = std::getenv("KG_DOORW")) p.classes.door_max_width = std::atof(s);
}

// Renders RGB-D frames of the world, labels them and scores them against its labels.
struct FrameScorer {
  const compute::Context& context;
  const synth::World& world;
  PinholeIntrinsics k;
  bool kinect;
  semantic::LabellingParams params;

  // Renders a frame from `pose`, labels it and adds it to `totals` (dump name: prefix + index).
  void operator()(const Eigen::Isometry3d& pose, std::uint64_t noise_seed, Totals& totals,
                  const std::string& prefix, int index) const {
    const auto frame =
        synth::render(world, k, pose,
                      kinect ? synth::NoiseModel::kinect() : synth::NoiseModel::none(), noise_seed);
    const PointImage points = geometry::backproject(context, frame.depth, k, {5000.0, 0.1, 10.0});
    const std::string name = prefix + " " + std::to_string(index);
    try {
      const auto result = semantic::label_organized_points(context, points, params);
      add(totals, points, frame.semantic, result.semantic, name);
      dump(prefix + std::to_string(index), points, frame.semantic, result);
    } catch (const Error& e) {
      std::printf("%s: %s\n", name.c_str(), e.what());
    }
  }
};

// The tour pose of the f-th of `frames` frames spread over the tour (15 poses in from its ends).
int tour_index(const Trajectory& tour, int f, int frames) {
  return 15 + f * (tour.size() - 30) / std::max(1, frames - 1);
}

Totals score_tour_frames(const FrameScorer& score_frame, const Trajectory& tour, int frames) {
  Totals totals;
  header(score_frame.kinect ? "RGB-D frames (Kinect noise), furniture ignored"
                            : "RGB-D frames (no noise)");
  for (int f = 0; f < frames; ++f) {
    const int index = tour_index(tour, f, frames);
    score_frame(tour[index].pose, 100 + f, totals, "frame", index);
  }
  report("ALL frames (ignored)", totals.ignored);
  report("ALL frames (counted)", totals.counted);
  return totals;
}

// The tour's poses looking 20 degrees up instead of 12 down: the ceiling in view.
Totals score_up_frames(const FrameScorer& score_frame, const Trajectory& tour, int frames) {
  Totals totals;
  header("RGB-D frames of the tour looking 20 deg up");
  for (int f = 0; f < frames; ++f) {
    const int index = tour_index(tour, f, frames);
    const Eigen::Vector3d view = tour[index].pose.linear() * Eigen::Vector3d::UnitZ();
    const Eigen::Isometry3d pose =
        synth::camera_pose(tour[index].pose.translation(), std::atan2(view.y(), view.x()),
                           -20 * std::numbers::pi / 180);
    score_frame(pose, 300 + f, totals, "up", index);
  }
  report("ALL up frames (ign.)", totals.ignored);
  report("ALL up frames (cnt.)", totals.counted);
  return totals;
}

// Facing the door leaf from 2.5 m inside its room, camera 1.3 m high, level.
Eigen::Isometry3d door_facing_pose(const synth::World& world, const synth::DoorLeaf& leaf) {
  const synth::Box3& box = world.solids[leaf.solid].box;
  const synth::Doorway& door = world.doorways[leaf.doorway - 1];
  const synth::Room& room = world.room(leaf.room);
  const int axis = door.passage_axis;
  const Eigen::Vector2d centre = 0.5 * (box.min.head<2>() + box.max.head<2>());
  const double into =
      (0.5 * (room.rect.min[axis] + room.rect.max[axis]) > centre[axis]) ? 1.0 : -1.0;
  Eigen::Vector2d eye = centre;
  eye[axis] += into * std::min(2.5, 0.9 * std::fabs(room.rect.max[axis] - room.rect.min[axis]));
  Eigen::Vector2d look = centre - eye;
  const double yaw = std::atan2(look.y(), look.x());
  return synth::camera_pose(Eigen::Vector3d(eye.x(), eye.y(), 1.3), yaw, 0.0);
}

// Frames facing each door leaf: doors (and more ceiling) in view, which the robot tour rarely
// gives.
Totals score_door_frames(const FrameScorer& score_frame) {
  Totals totals;
  header("RGB-D frames facing door leaves");
  for (const synth::DoorLeaf& leaf : score_frame.world.door_leaves)
    score_frame(door_facing_pose(score_frame.world, leaf), 500 + leaf.doorway, totals, "door",
                leaf.doorway);
  report("ALL door frames (ign.)", totals.ignored);
  report("ALL door frames (cnt.)", totals.counted);
  return totals;
}

// At the room's most open point, 0.8 m high, facing its longer extent.
Eigen::Isometry3d room_scan_pose(const synth::World& world, const synth::Room& room) {
  const auto [centre, clearance] = synth::most_open_point(world, room.id);
  const Eigen::Vector2d size = room.rect.max - room.rect.min;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(centre.x(), centre.y(), 0.8);
  pose.linear() =
      Eigen::AngleAxisd(size.x() >= size.y() ? 0.0 : std::numbers::pi / 2, Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  return pose;
}

// The points in an arbitrary frame: a rotation that differs per room.
void rotate_points(PointImage& points, Label room_id) {
  const Eigen::Matrix3f r =
      (Eigen::AngleAxisf(0.7f + room_id, Eigen::Vector3f(1, 2, 3).normalized()) *
       Eigen::AngleAxisf(1.3f * room_id, Eigen::Vector3f::UnitX()))
          .toRotationMatrix();
  for (Point4f& p : points.pixels()) {
    if (is_valid(p)) p.head<3>() = r * p.head<3>();
  }
}

// Laser scans: one per room at its most open point; the same scans again with the points in an
// arbitrary (random rotation) frame.
void score_laser_scans(const compute::Context& context, const synth::World& world) {
  const synth::RayCaster caster(world);
  Totals scan_totals, rotated_totals;
  header("laser scans (1 cm range noise), furniture ignored");
  semantic::LabellingParams scan_params;  // no prior: the frame is arbitrary
  tune(scan_params);
  for (const synth::Room& room : world.rooms) {
    const auto scan = synth::scan_laser(caster, room_scan_pose(world, room), {}, 7 + room.id);
    for (const bool rotate : {false, true}) {
      PointImage points = scan.points;
      if (rotate) rotate_points(points, room.id);
      try {
        const auto result = semantic::label_organized_points(context, points, scan_params);
        add(rotate ? rotated_totals : scan_totals, points, scan.semantic, result.semantic,
            (rotate ? "rotated scan room " : "scan room ") + std::to_string(room.id));
        if (!rotate) dump("scan" + std::to_string(room.id), points, scan.semantic, result);
      } catch (const Error& e) {
        std::printf("scan %d: %s\n", room.id, e.what());
      }
    }
  }
  report("ALL scans (ignored)", scan_totals.ignored);
  report("ALL scans (counted)", scan_totals.counted);
  report("ALL rotated (ignored)", rotated_totals.ignored);
  report("ALL rotated (counted)", rotated_totals.counted);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]).ends_with(".pcd")) return label_real_scan(argv[1]);
  const std::uint64_t seed = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 5;
  const int frames = argc > 2 ? std::atoi(argv[2]) : 8;
  const bool kinect = argc > 3 ? std::string(argv[3]) != "none" : true;
  const compute::Context context = compute::Context::cpu();
  const synth::World world = synth::make_building(seed);
  const Trajectory tour = synth::robot_tour(world, 300);
  semantic::LabellingParams frame_params;
  frame_params.gravity.prior_up = Eigen::Vector3d(0, -1, 0);
  tune(frame_params);
  const FrameScorer score_frame{context, world, PinholeIntrinsics::kinect_7scenes(), kinect,
                                frame_params};

  const Totals frame_totals = score_tour_frames(score_frame, tour, frames);
  const Totals up_totals = score_up_frames(score_frame, tour, frames);
  const Totals door_totals = score_door_frames(score_frame);
  report("POOLED frames (ign.)", frame_totals.ignored + up_totals.ignored + door_totals.ignored);
  score_laser_scans(context, world);
  return 0;
}
