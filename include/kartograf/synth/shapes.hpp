#pragma once
// Axis-aligned shapes of the synthetic world: floor-plan rectangles and 3-D boxes, and the six
// faces of a box. The whole world is axis-aligned, which makes ray casting exact and cheap.
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace kartograf::synth {

// A rectangle of the floor plan (x, y in metres), min <= max componentwise.
struct Rect2 {
  Eigen::Vector2d min = Eigen::Vector2d::Zero();
  Eigen::Vector2d max = Eigen::Vector2d::Zero();

  Eigen::Vector2d size() const { return max - min; }
  Eigen::Vector2d center() const { return 0.5 * (min + max); }
  double area() const { return size().x() * size().y(); }
  bool contains(const Eigen::Vector2d& p) const {
    return p.x() >= min.x() && p.x() <= max.x() && p.y() >= min.y() && p.y() <= max.y();
  }
  // Strict overlap: rectangles that only touch along an edge do not overlap.
  bool overlaps(const Rect2& other) const {
    return min.x() < other.max.x() && other.min.x() < max.x() && min.y() < other.max.y() &&
           other.min.y() < max.y();
  }
  Rect2 expanded(double margin) const {
    return {min - Eigen::Vector2d::Constant(margin), max + Eigen::Vector2d::Constant(margin)};
  }
  // Euclidean distance from p to the rectangle (0 inside).
  double distance(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = (min - p).cwiseMax(p - max).cwiseMax(0.0);
    return d.norm();
  }
};

// A solid box; the six faces are indexed by Face.
struct Box3 {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();

  Rect2 footprint() const { return {min.head<2>(), max.head<2>()}; }
  bool empty() const { return (max - min).minCoeff() <= 0; }
};

// A box face, by its outward normal: 2 * axis + (1 if the normal points along +axis).
enum class Face : std::uint8_t { neg_x = 0, pos_x = 1, neg_y = 2, pos_y = 3, neg_z = 4, pos_z = 5 };
inline constexpr int kFaceCount = 6;

constexpr int face_axis(Face f) {
  return static_cast<int>(f) / 2;
}
constexpr double face_sign(Face f) {
  return (static_cast<int>(f) % 2) ? 1.0 : -1.0;
}
constexpr Face make_face(int axis, bool positive) {
  return static_cast<Face>(2 * axis + (positive ? 1 : 0));
}
inline Eigen::Vector3d face_normal(Face f) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  n[face_axis(f)] = face_sign(f);
  return n;
}

// The parts of `a` outside `b` (up to six boxes; `a` itself when they do not overlap).
inline std::vector<Box3> subtract(const Box3& a, const Box3& b) {
  for (int axis = 0; axis < 3; ++axis) {
    if (b.max[axis] <= a.min[axis] || b.min[axis] >= a.max[axis]) return {a};
  }
  std::vector<Box3> parts;
  Box3 rest = a;
  for (int axis = 0; axis < 3; ++axis) {
    if (b.min[axis] > rest.min[axis]) {
      Box3 below = rest;
      below.max[axis] = b.min[axis];
      parts.push_back(below);
      rest.min[axis] = b.min[axis];
    }
    if (b.max[axis] < rest.max[axis]) {
      Box3 above = rest;
      above.min[axis] = b.max[axis];
      parts.push_back(above);
      rest.max[axis] = b.max[axis];
    }
  }
  return parts;  // `rest` is now inside b
}

}  // namespace kartograf::synth
