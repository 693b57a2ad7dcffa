#include "kartograf/formats/top_view.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"

namespace kartograf::io {

namespace {

// Floor-plane coordinates: (along, across) in metres, and height.
struct FloorFrame {
  Eigen::Vector3d along, across, up;
  Eigen::Vector2d plane(const Eigen::Vector3d& p) const { return {p.dot(along), p.dot(across)}; }
  double height(const Eigen::Vector3d& p) const { return p.dot(up); }
};

FloorFrame floor_frame(const std::vector<Eigen::Isometry3d>& poses) {
  FloorFrame frame;
  frame.up = estimate_up(poses);
  Eigen::Vector3d view = poses.front().linear().col(2);
  view -= view.dot(frame.up) * frame.up;
  if (view.norm() < 1e-6) view = frame.up.unitOrthogonal();  // looking straight down
  frame.along = view.normalized();
  frame.across = frame.up.cross(frame.along);
  return frame;
}

class Canvas {
 public:
  Canvas(const Eigen::Vector2d& min, const Eigen::Vector2d& max, const TopViewParams& o) {
    const Eigen::Vector2d extent = (max - min).cwiseMax(Eigen::Vector2d::Constant(1e-3));
    scale_ = o.size / std::max(extent.x(), extent.y());  // pixels per metre
    origin_ = min;
    margin_ = o.margin;
    image_ = RgbImage(static_cast<int>(std::ceil(extent.x() * scale_)) + 2 * o.margin + 1,
                      static_cast<int>(std::ceil(extent.y() * scale_)) + 2 * o.margin + 1,
                      Rgb8{40, 40, 40});
    heights_.assign(image_.size(), -std::numeric_limits<double>::infinity());
  }

  // Pixel of a floor point: x along, y across (flipped so that the picture is not mirrored).
  Eigen::Vector2i pixel(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d q = (p - origin_) * scale_;
    return {margin_ + static_cast<int>(std::floor(q.x())),
            image_.height() - 1 - margin_ - static_cast<int>(std::floor(q.y()))};
  }
  bool inside(const Eigen::Vector2i& p) const {
    return p.x() >= 0 && p.y() >= 0 && p.x() < image_.width() && p.y() < image_.height();
  }
  void plot_highest(const Eigen::Vector2i& p, double height, const Rgb8& color) {
    if (!inside(p)) return;
    double& top = heights_[static_cast<std::size_t>(p.y()) * image_.width() + p.x()];
    if (height < top) return;
    top = height;
    image_(p.x(), p.y()) = color;
  }
  void dot(const Eigen::Vector2i& p, int radius, const Rgb8& color) {
    for (int dy = -radius; dy <= radius; ++dy) {
      for (int dx = -radius; dx <= radius; ++dx) {
        const Eigen::Vector2i q = p + Eigen::Vector2i(dx, dy);
        if (dx * dx + dy * dy <= radius * radius && inside(q)) image_(q.x(), q.y()) = color;
      }
    }
  }
  void line(const Eigen::Vector2i& a, const Eigen::Vector2i& b, const Rgb8& color) {
    const int steps = std::max(std::abs(b.x() - a.x()), std::abs(b.y() - a.y()));
    for (int s = 0; s <= steps; ++s) {
      const double t = steps == 0 ? 0.0 : static_cast<double>(s) / steps;
      const Eigen::Vector2i p(static_cast<int>(std::lround(a.x() + t * (b.x() - a.x()))),
                              static_cast<int>(std::lround(a.y() + t * (b.y() - a.y()))));
      dot(p, 1, color);
    }
  }
  RgbImage take() { return std::move(image_); }

 private:
  RgbImage image_;
  std::vector<double> heights_;
  Eigen::Vector2d origin_;
  double scale_ = 1;
  int margin_ = 0;
};

Rgb8 height_shade(double height, double low, double high) {
  const double t = high > low ? std::clamp((height - low) / (high - low), 0.0, 1.0) : 0.5;
  const auto level = static_cast<std::uint8_t>(80 + 175 * t);
  return {level, level, level};
}

}  // namespace

Eigen::Vector3d estimate_up(const std::vector<Eigen::Isometry3d>& camera_poses) {
  require(!camera_poses.empty(), "top view: no camera poses");
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Isometry3d& pose : camera_poses) sum -= pose.linear().col(1);
  require(sum.norm() > 1e-9, "top view: the cameras' up axes cancel out; no floor plane");
  return sum.normalized();
}

RgbImage render_top_view(const PointCloud& map, const std::vector<Eigen::Isometry3d>& camera_poses,
                         const TopViewParams& options,
                         const std::vector<Eigen::Vector3d>& true_path) {
  require(options.size >= 16 && options.size <= 16384 && options.margin >= 0,
          "top view: size must be in [16, 16384] and margin >= 0");
  const FloorFrame frame = floor_frame(camera_poses);
  double camera_top = -std::numeric_limits<double>::infinity();
  Eigen::Vector2d min = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d max = -min;
  for (const Eigen::Isometry3d& pose : camera_poses) {
    camera_top = std::max(camera_top, frame.height(pose.translation()));
    min = min.cwiseMin(frame.plane(pose.translation()));
    max = max.cwiseMax(frame.plane(pose.translation()));
  }
  const double ceiling = camera_top + options.ceiling_clearance;
  double low = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3f& point : map.points) {
    const Eigen::Vector3d p = point.cast<double>();
    if (frame.height(p) > ceiling) continue;
    low = std::min(low, frame.height(p));
    min = min.cwiseMin(frame.plane(p));
    max = max.cwiseMax(frame.plane(p));
  }

  Canvas canvas(min, max, options);
  for (std::size_t i = 0; i < map.points.size(); ++i) {
    const Eigen::Vector3d p = map.points[i].cast<double>();
    const double height = frame.height(p);
    if (height > ceiling) continue;
    const Rgb8 color = map.has_colors() ? map.colors[i] : height_shade(height, low, ceiling);
    canvas.plot_highest(canvas.pixel(frame.plane(p)), height, color);
  }
  for (std::size_t i = 1; i < true_path.size(); ++i) {
    canvas.line(canvas.pixel(frame.plane(true_path[i - 1])),
                canvas.pixel(frame.plane(true_path[i])), Rgb8{255, 200, 0});
  }
  for (std::size_t i = 1; i < camera_poses.size(); ++i) {
    canvas.line(canvas.pixel(frame.plane(camera_poses[i - 1].translation())),
                canvas.pixel(frame.plane(camera_poses[i].translation())), Rgb8{230, 30, 30});
  }
  canvas.dot(canvas.pixel(frame.plane(camera_poses.front().translation())), 5, Rgb8{30, 200, 30});
  canvas.dot(canvas.pixel(frame.plane(camera_poses.back().translation())), 3, Rgb8{40, 90, 255});
  return canvas.take();
}

void write_top_view_png(const std::filesystem::path& path, const PointCloud& map,
                        const std::vector<Eigen::Isometry3d>& camera_poses,
                        const TopViewParams& options) {
  write_png(path, render_top_view(map, camera_poses, options));
}

}  // namespace kartograf::io
