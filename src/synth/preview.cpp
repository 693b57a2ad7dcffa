#include "kartograf/synth/preview.hpp"

#include <algorithm>
#include <cmath>

#include "kartograf/core/error.hpp"
#include "kartograf/core/random.hpp"

namespace kartograf::synth {

namespace {

Rgb8 room_tint(Label room) {
  const std::uint64_t h = mix64(room);
  auto channel = [&](int shift) {
    return static_cast<std::uint8_t>(185 + ((h >> shift) & 0xff) % 60);
  };
  return {channel(0), channel(8), channel(16)};
}

class Canvas {
 public:
  Canvas(const FloorPlan& plan, int scale)
      : plan_(plan), scale_(scale), image_(plan.grid.width() * scale, plan.grid.height() * scale) {}

  RgbImage& image() { return image_; }

  Eigen::Vector2d to_pixel(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d local = (p - plan_.grid.origin.head<2>()) / plan_.grid.resolution;
    return {local.x() * scale_, (plan_.grid.height() - local.y()) * scale_};
  }

  void dot(const Eigen::Vector2d& p, double radius, const Rgb8& color) {
    const Eigen::Vector2d c = to_pixel(p);
    const int r = static_cast<int>(std::ceil(radius));
    for (int y = -r; y <= r; ++y) {
      for (int x = -r; x <= r; ++x) {
        if (x * x + y * y <= radius * radius)
          put(static_cast<int>(c.x()) + x, static_cast<int>(c.y()) + y, color);
      }
    }
  }

  void line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Rgb8& color) {
    const Eigen::Vector2d pa = to_pixel(a), pb = to_pixel(b);
    const int steps = std::max(1, static_cast<int>(std::ceil((pb - pa).lpNorm<Eigen::Infinity>())));
    for (int i = 0; i <= steps; ++i) {
      const Eigen::Vector2d p = pa + (pb - pa) * (static_cast<double>(i) / steps);
      put(static_cast<int>(std::floor(p.x())), static_cast<int>(std::floor(p.y())), color);
    }
  }

 private:
  void put(int x, int y, const Rgb8& color) {
    if (x >= 0 && y >= 0 && x < image_.width() && y < image_.height()) image_(x, y) = color;
  }

  const FloorPlan& plan_;
  int scale_;
  RgbImage image_;
};

}  // namespace

RgbImage floor_plan_preview(const FloorPlan& plan, const Trajectory& trajectory,
                            const std::optional<Eigen::Isometry3d>& scanner, int scale,
                            int tick_every) {
  require(scale >= 1 && scale <= 16, "floor_plan_preview: scale must be in 1..16");
  Canvas canvas(plan, scale);
  RgbImage& image = canvas.image();
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const int col = x / scale, row = y / scale;
      Rgb8 color{70, 70, 70};  // outside
      switch (plan.semantic(col, row)) {
        case SemanticClass::floor:
          color = room_tint(plan.rooms(col, row));
          break;
        case SemanticClass::wall:
          color = {25, 25, 25};
          break;
        case SemanticClass::door:
          color = {176, 120, 64};
          break;
        case SemanticClass::furniture:
          color = {130, 130, 140};
          break;
        default:
          break;
      }
      image(x, y) = color;
    }
  }
  const Rgb8 red{220, 30, 30};
  for (std::size_t i = 1; i < trajectory.size(); ++i) {
    canvas.line(trajectory[i - 1].pose.translation().head<2>(),
                trajectory[i].pose.translation().head<2>(), red);
  }
  for (std::size_t i = 0; tick_every > 0 && i < trajectory.size();
       i += static_cast<std::size_t>(tick_every)) {
    const Eigen::Vector3d p = trajectory[i].pose.translation();
    const Eigen::Vector3d forward = trajectory[i].pose.linear().col(2);
    const Eigen::Vector2d heading = forward.head<2>().normalized();
    canvas.line(p.head<2>(), p.head<2>() + 0.4 * heading, {120, 0, 0});
  }
  if (!trajectory.empty())
    canvas.dot(trajectory.front().pose.translation().head<2>(), 1.5 * scale, {20, 170, 40});
  if (scanner) {
    canvas.dot(scanner->translation().head<2>(), 1.5 * scale, {30, 60, 220});
    const Eigen::Vector2d x = scanner->linear().col(0).head<2>().normalized();
    canvas.line(scanner->translation().head<2>(), scanner->translation().head<2>() + 0.5 * x,
                {30, 60, 220});
  }
  return image;
}

}  // namespace kartograf::synth
