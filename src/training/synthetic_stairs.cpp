#include "kartograf/training/synthetic_stairs.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "kartograf/core/error.hpp"
#include "kartograf/semantic/normals_image.hpp"
#include "kartograf/synth/ray_caster.hpp"
#include "kartograf/synth/world.hpp"

namespace kartograf::training {

using namespace semantic;
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr Label kStairsLabel = 1;  // face label of the steps, to test their visibility
constexpr Label kClutterLabel = 2;

// The room: interior x in [-kHalfWidth, kHalfWidth], y in [-kDepth, 0]; back wall behind y = 0.
constexpr double kHalfWidth = 5.0, kDepth = 8.0, kWall = 0.2;

void add_box(synth::World& world, const Eigen::Vector3d& min, const Eigen::Vector3d& max,
             Label label) {
  synth::Solid solid;
  solid.box = {min, max};
  solid.kind = synth::SolidKind::object;  // every face labelled: no room bookkeeping needed
  solid.face_planes.fill(label);
  solid.material = 0;
  world.solids.push_back(solid);
}

struct Stairs {
  double center_x = 0, width = 0, tread = 0, rise = 0;
  int steps = 0;
  Eigen::Vector3d min() const { return {center_x - width / 2, -steps * tread, 0}; }
  Eigen::Vector3d max() const { return {center_x + width / 2, 0, steps * rise}; }
};

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

synth::World make_room(std::mt19937_64& rng, const Stairs& stairs, bool with_stairs) {
  synth::World world;
  world.height = uniform(rng, 2.5, 3.0);
  world.bounds = {{-kHalfWidth - kWall, -kDepth - kWall}, {kHalfWidth + kWall, kWall}};
  const double h = world.height;
  add_box(world, {-kHalfWidth - kWall, 0, 0}, {kHalfWidth + kWall, kWall, h}, kClutterLabel);
  add_box(world, {-kHalfWidth - kWall, -kDepth - kWall, 0}, {kHalfWidth + kWall, -kDepth, h},
          kClutterLabel);
  add_box(world, {-kHalfWidth - kWall, -kDepth, 0}, {-kHalfWidth, 0, h}, kClutterLabel);
  add_box(world, {kHalfWidth, -kDepth, 0}, {kHalfWidth + kWall, 0, h}, kClutterLabel);
  if (with_stairs) {
    for (int i = 0; i < stairs.steps; ++i) {
      add_box(world, {stairs.center_x - stairs.width / 2, -(stairs.steps - i) * stairs.tread, 0},
              {stairs.center_x + stairs.width / 2, 0, (i + 1) * stairs.rise}, kStairsLabel);
    }
  }
  // Clutter: cabinets, crates and low boxes (one step alike) away from the stairs' footprint, so
  // that they never hide it and the cascade must tell a flight of steps from a single box.
  const synth::Rect2 keep_clear = synth::Box3{stairs.min(), stairs.max()}.footprint().expanded(0.3);
  const int clutter = std::uniform_int_distribution<int>(2, 6)(rng);
  for (int placed = 0, tries = 0; placed < clutter && tries < 50; ++tries) {
    const double w = uniform(rng, 0.3, 1.5), d = uniform(rng, 0.3, 0.8);
    const double height = uniform(rng, 0.2, 2.0);
    const bool at_back = uniform(rng, 0, 1) < 0.6;
    const double x = uniform(rng, -kHalfWidth + w / 2, kHalfWidth - w / 2);
    const double y = at_back ? -d / 2 : uniform(rng, -kDepth + 1, -1);
    const synth::Rect2 footprint{{x - w / 2, y - d / 2}, {x + w / 2, y + d / 2}};
    if (footprint.overlaps(keep_clear)) continue;
    add_box(world, {footprint.min.x(), footprint.min.y(), 0},
            {footprint.max.x(), footprint.max.y(), height}, kClutterLabel);
    ++placed;
  }
  return world;
}

// Camera rotation (columns: x right, y down, z forward in world coordinates) looking along forward.
Eigen::Matrix3d look_rotation(const Eigen::Vector3d& forward) {
  const Eigen::Vector3d z = forward.normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return r;
}

void check_options(const StairsViewParams& options) {
  require(options.width >= 20 && options.height >= 20 && options.focal > 0 &&
              options.range_noise >= 0 && options.max_range > 0 && options.min_distance > 0.5 &&
              options.max_distance >= options.min_distance && options.max_yaw_deg >= 0 &&
              options.max_yaw_deg < 80,
          "render_stairs_view: options out of range (image >= 20 px, focal > 0, "
          "0.5 < min_distance <= max_distance, 0 <= max_yaw_deg < 80)");
}

Stairs random_stairs(std::mt19937_64& rng) {
  Stairs stairs;
  stairs.steps = std::uniform_int_distribution<int>(3, 5)(rng);
  stairs.width = uniform(rng, 0.8, 1.4);
  stairs.tread = uniform(rng, 0.25, 0.32);
  stairs.rise = uniform(rng, 0.15, 0.2);
  stairs.center_x = uniform(rng, -2.5, 2.5);
  return stairs;
}

struct Camera {
  Eigen::Vector3d eye;
  Eigen::Matrix3d rotation;  // as look_rotation
  double cx, cy;             // principal point [px]
};

// A camera in front of the stairs (yaw and distance within the options), aimed near, not at, them:
// they should appear anywhere in the image. Empty when the eye would be outside the room.
std::optional<Camera> random_camera(std::mt19937_64& rng, const Stairs& stairs,
                                    const StairsViewParams& options) {
  const double yaw = uniform(rng, -options.max_yaw_deg, options.max_yaw_deg) * kPi / 180;
  const double distance = uniform(rng, options.min_distance, options.max_distance);
  const Eigen::Vector3d front(stairs.center_x, stairs.min().y(), 0);
  const Eigen::Vector3d eye(front.x() + distance * std::sin(yaw),
                            front.y() - distance * std::cos(yaw), uniform(rng, 0.5, 1.6));
  if (std::abs(eye.x()) > kHalfWidth - 0.3 || eye.y() < -kDepth + 0.3) return std::nullopt;
  const Eigen::Vector3d center = 0.5 * (stairs.min() + stairs.max());
  const Eigen::Vector3d target =
      center + Eigen::Vector3d(uniform(rng, -0.6, 0.6), 0, uniform(rng, -0.4, 0.4));
  return Camera{eye, look_rotation(target - eye), (options.width - 1) / 2.0,
                (options.height - 1) / 2.0};
}

// The stairs' projected bounding box [px] and the square 1.1 times its larger side around it.
struct ProjectedStairs {
  double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
  bool in_front = true;             // every corner at least 0.3 m in front of the camera
  double side = 0, su = 0, sv = 0;  // the square: side, top-left corner
  // Whether a corner is behind the camera, the square leaves the image (with a margin) or it is
  // too small.
  bool unusable(const StairsViewParams& options) const {
    return !in_front || su < 1 || sv < 1 || su + side > options.width - 2 ||
           sv + side > options.height - 2 || side < 20;
  }
};

ProjectedStairs project_stairs(const Stairs& stairs, const Camera& camera,
                               const StairsViewParams& options) {
  ProjectedStairs b;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p((corner & 1) ? stairs.max().x() : stairs.min().x(),
                            (corner & 2) ? stairs.max().y() : stairs.min().y(),
                            (corner & 4) ? stairs.max().z() : stairs.min().z());
    const Eigen::Vector3d c = camera.rotation.transpose() * (p - camera.eye);
    if (c.z() < 0.3) b.in_front = false;
    const double u = options.focal * c.x() / c.z() + camera.cx,
                 v = options.focal * c.y() / c.z() + camera.cy;
    b.u0 = std::min(b.u0, u), b.u1 = std::max(b.u1, u);
    b.v0 = std::min(b.v0, v), b.v1 = std::max(b.v1, v);
  }
  b.side = 1.1 * std::max(b.u1 - b.u0, b.v1 - b.v0);
  b.su = 0.5 * (b.u0 + b.u1) - b.side / 2, b.sv = 0.5 * (b.v0 + b.v1) - b.side / 2;
  return b;
}

// Every riser and tread centre visible from the eye: no clutter in the way.
bool steps_visible(const synth::RayCaster& caster, const Stairs& stairs,
                   const Eigen::Vector3d& eye) {
  bool visible = true;
  for (int i = 0; i < stairs.steps && visible; ++i) {
    const double y_front = -(stairs.steps - i) * stairs.tread;
    for (const Eigen::Vector3d& p :
         {Eigen::Vector3d(stairs.center_x, y_front, (i + 0.5) * stairs.rise),
          Eigen::Vector3d(stairs.center_x, y_front + stairs.tread / 2, (i + 1) * stairs.rise)}) {
      const auto hit = caster.cast(eye, p - eye);
      visible = visible && hit && hit->plane == kStairsLabel;
    }
  }
  return visible;
}

// The organized points the camera sees (up to max_range), with range noise growing with the
// square of the range.
PointImage render_points(const synth::RayCaster& caster, const Camera& camera,
                         const StairsViewParams& options, std::mt19937_64& rng) {
  PointImage points(options.width, options.height, invalid_point());
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int v = 0; v < options.height; ++v) {
    for (int u = 0; u < options.width; ++u) {
      const Eigen::Vector3d ray((u - camera.cx) / options.focal, (v - camera.cy) / options.focal,
                                1.0);
      const auto hit = caster.cast(camera.eye, camera.rotation * ray);
      if (!hit) continue;
      const Eigen::Vector3d c = camera.rotation.transpose() * (hit->point - camera.eye);
      const double range = c.norm();
      if (range > options.max_range) continue;
      const double noisy = range + options.range_noise * range * range * noise(rng);
      const Eigen::Vector3d p = c * (noisy / range);
      points(u, v) = Point4f(static_cast<float>(p.x()), static_cast<float>(p.y()),
                             static_cast<float>(p.z()), 1.0f);
    }
  }
  return points;
}

// The stairs' boxes in the view: the tight projected box and the square around it.
void set_stairs_boxes(StairsView& view, const Stairs& stairs, const ProjectedStairs& b) {
  view.tight = {static_cast<int>(std::lround(b.u0)),
                static_cast<int>(std::lround(b.v0)),
                static_cast<int>(std::lround(b.u1 - b.u0)),
                static_cast<int>(std::lround(b.v1 - b.v0)),
                0,
                1};
  const int s = static_cast<int>(std::lround(b.side));
  view.object = Detection{
      static_cast<int>(std::lround(b.su)), static_cast<int>(std::lround(b.sv)), s, s, 0, 1};
  view.stairs_width = stairs.width;
  view.stairs_height = stairs.steps * stairs.rise;
}

}  // namespace

StairsView render_stairs_view(const compute::Context& context, std::uint64_t seed, bool with_stairs,
                              const StairsViewParams& options) {
  check_options(options);
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 12345);
  for (int attempt = 0; attempt < 200; ++attempt) {
    const Stairs stairs = random_stairs(rng);
    const synth::World world = make_room(rng, stairs, with_stairs);
    const std::optional<Camera> camera = random_camera(rng, stairs, options);
    if (!camera) continue;
    const ProjectedStairs projected = project_stairs(stairs, *camera, options);
    if (projected.unusable(options)) continue;
    const synth::RayCaster caster(world);
    if (with_stairs && !steps_visible(caster, stairs, camera->eye)) continue;

    StairsView view;
    view.points = render_points(caster, *camera, options, rng);
    NormalsImageParams normals_params;
    normals_params.smoothing_radius = 2;  // small images: keep step edges sharp
    view.gray = normals_rgb_to_gray(
        normals_to_rgb(estimate_organized_normals(context, view.points, normals_params),
                       NormalEncoding::absolute));
    if (with_stairs) set_stairs_boxes(view, stairs, projected);
    return view;
  }
  throw Error("render_stairs_view: no valid camera for seed " + std::to_string(seed) +
              " in 200 attempts (options too tight?)");
}

std::vector<GrayImage> stairs_positives(const StairsView& view, int count, int window,
                                        std::mt19937_64& rng) {
  require(view.object.has_value(), "stairs_positives: the view has no stairs");
  require(count >= 1 && window >= 4, "stairs_positives: need count >= 1 and window >= 4");
  const Detection& box = *view.object;
  const cv::Mat gray(view.gray.height(), view.gray.width(), CV_8UC1,
                     const_cast<std::uint8_t*>(view.gray.data()));
  std::vector<GrayImage> out;
  std::normal_distribution<double> pixel_noise(0.0, 3.0);
  for (int k = 0; k < count; ++k) {
    const bool plain = k == 0;
    const double side = box.width * (plain ? 1.0 : uniform(rng, 0.92, 1.08));
    const double centre_x =
        box.x + box.width / 2.0 + (plain ? 0 : uniform(rng, -0.05, 0.05) * box.width);
    const double centre_y =
        box.y + box.height / 2.0 + (plain ? 0 : uniform(rng, -0.05, 0.05) * box.height);
    const double angle = plain ? 0 : uniform(rng, -8, 8);
    // Area-average down to window scale first (as the detector's pyramid does), then rotate.
    const double f = window / side;
    cv::Mat scaled;
    cv::resize(gray, scaled, cv::Size(), f, f, cv::INTER_AREA);
    const cv::Point2f centre(static_cast<float>(centre_x * f), static_cast<float>(centre_y * f));
    cv::Mat m = cv::getRotationMatrix2D(centre, angle, 1.0);
    m.at<double>(0, 2) += window / 2.0 - centre.x;
    m.at<double>(1, 2) += window / 2.0 - centre.y;
    cv::Mat patch;
    cv::warpAffine(scaled, patch, m, cv::Size(window, window), cv::INTER_LINEAR,
                   cv::BORDER_REPLICATE);
    const double gain = plain ? 1.0 : uniform(rng, 0.8, 1.2);
    const double offset = plain ? 0.0 : uniform(rng, -15, 15);
    GrayImage sample(window, window);
    for (int y = 0; y < window; ++y) {
      for (int x = 0; x < window; ++x) {
        const double g =
            gain * patch.at<std::uint8_t>(y, x) + offset + (plain ? 0 : pixel_noise(rng));
        sample(x, y) = static_cast<std::uint8_t>(std::clamp(std::lround(g), 0L, 255L));
      }
    }
    out.push_back(std::move(sample));
  }
  return out;
}

}  // namespace kartograf::training
