#include "plane_rasterizer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kartograf::synth::detail {

namespace {

constexpr double kNear = 1e-4;  // metres: polygons are clipped to z >= kNear in the camera frame

// Sutherland-Hodgman against the plane z = kNear, keeping z >= kNear.
std::vector<Eigen::Vector3d> clip_near(const std::vector<Eigen::Vector3d>& polygon) {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector3d& a = polygon[i];
    const Eigen::Vector3d& b = polygon[(i + 1) % polygon.size()];
    const bool a_in = a.z() >= kNear, b_in = b.z() >= kNear;
    if (a_in) out.push_back(a);
    if (a_in != b_in) out.push_back(a + (b - a) * ((kNear - a.z()) / (b.z() - a.z())));
  }
  return out;
}

}  // namespace

PlaneRasterizer::PlaneRasterizer(const World& world, const PinholeIntrinsics& k,
                                 const Eigen::Isometry3d& pose)
    : k_(k) {
  const Eigen::Matrix3d to_camera = pose.linear().transpose();
  const Eigen::Vector3d origin = pose.translation();
  for (const Plane& plane : world.planes) {
    const double distance = plane.signed_distance(origin);
    if (distance <= 0) continue;  // seen from behind (or edge-on): never visible
    // n . ray(u, v) with ray = R ((u - cx) / fx, (v - cy) / fy, 1): linear in u and v.
    const Eigen::Vector3d n = to_camera * plane.normal;
    Polygon base;
    base.plane = plane.id;
    base.numerator = -distance;
    base.du = n.x() / k.fx;
    base.dv = n.y() / k.fy;
    base.d0 = n.z() - n.x() * k.cx / k.fx - n.y() * k.cy / k.fy;
    for (const auto& polygon : plane.polygons) {
      std::vector<Eigen::Vector3d> camera;
      for (const Eigen::Vector3d& v : polygon) camera.push_back(to_camera * (v - origin));
      camera = clip_near(camera);
      if (camera.size() < 3) continue;
      Polygon p = base;
      double area = 0;
      for (const Eigen::Vector3d& c : camera) {
        p.vertices.emplace_back(k.fx * c.x() / c.z() + k.cx, k.fy * c.y() / c.z() + k.cy);
      }
      for (std::size_t i = 0; i < p.vertices.size(); ++i) {
        const Eigen::Vector2d& a = p.vertices[i];
        const Eigen::Vector2d& b = p.vertices[(i + 1) % p.vertices.size()];
        area += a.x() * b.y() - a.y() * b.x();
      }
      if (area == 0) continue;
      p.orientation = area > 0 ? 1.0 : -1.0;
      p.min_v = p.max_v = p.vertices[0].y();
      for (const Eigen::Vector2d& v : p.vertices)
        p.min_v = std::min(p.min_v, v.y()), p.max_v = std::max(p.max_v, v.y());
      if (p.max_v < 0 || p.min_v > k.height - 1) continue;
      polygons_.push_back(std::move(p));
    }
  }
}

void PlaneRasterizer::rasterize(int begin, int end, std::vector<double>& depth,
                                std::vector<Label>& ids) const {
  const int w = k_.width;
  for (int v = begin; v < end; ++v) {
    std::fill(depth.begin() + static_cast<std::ptrdiff_t>(v) * w,
              depth.begin() + static_cast<std::ptrdiff_t>(v + 1) * w,
              std::numeric_limits<double>::infinity());
    std::fill(ids.begin() + static_cast<std::ptrdiff_t>(v) * w,
              ids.begin() + static_cast<std::ptrdiff_t>(v + 1) * w, Label{0});
  }
  for (const Polygon& p : polygons_) {
    const int v0 = std::max(begin, static_cast<int>(std::ceil(p.min_v)));
    const int v1 = std::min(end - 1, static_cast<int>(std::floor(p.max_v)));
    for (int v = v0; v <= v1; ++v) {
      // The pixel centres of this row inside every edge's half-plane (edges included).
      double lo = 0, hi = w - 1;
      for (std::size_t i = 0; i < p.vertices.size() && lo <= hi; ++i) {
        const Eigen::Vector2d& a = p.vertices[i];
        const Eigen::Vector2d& b = p.vertices[(i + 1) % p.vertices.size()];
        const double dx = b.x() - a.x(), dy = b.y() - a.y();
        // Inside: orientation * (dx (v - ay) - dy (u - ax)) >= 0, i.e. A u <= B.
        const double A = p.orientation * dy;
        const double B = p.orientation * (dx * (v - a.y()) + dy * a.x());
        if (A > 0) {
          hi = std::min(hi, B / A);
        } else if (A < 0) {
          lo = std::max(lo, B / A);
        } else if (B < 0) {
          hi = -1;  // parallel edge with the row outside it
        }
      }
      if (lo > hi) continue;
      const int u0 = static_cast<int>(std::ceil(lo)), u1 = static_cast<int>(std::floor(hi));
      const std::size_t row = static_cast<std::size_t>(v) * w;
      const double row_term = p.dv * v + p.d0;
      for (int u = u0; u <= u1; ++u) {
        const double denominator = p.du * u + row_term;
        if (!(denominator < 0)) continue;  // the ray runs parallel to or away from the plane
        const double t = p.numerator / denominator;
        double& best = depth[row + u];
        Label& id = ids[row + u];
        if (t < best || (t == best && p.plane < id)) {
          best = t;
          id = p.plane;
        }
      }
    }
  }
}

}  // namespace kartograf::synth::detail
