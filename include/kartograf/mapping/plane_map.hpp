#pragma once
// The planes of a whole map, pooled from the planes extracted in many views (docs/methods.md M1 on
// each view, segmentation/plane_extraction.hpp): a view's plane joins a map plane with the same
// orientation and offset whose points it touches, else it starts one. Map planes keep their
// points' moments (for a total-least-squares fit of everything they gathered), a thinned copy of
// the points (for their extent) and the votes of the points' semantic classes.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/point_image.hpp"
#include "kartograf/core/semantic_class.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"

namespace kartograf::mapping {

struct PlaneMapParams {
  double max_normal_angle_deg = 10.0;  // a view plane joins a map plane within this angle ...
  double max_offset = 0.05;            // ... whose plane its centroid lies within [m] ...
  double max_gap = 0.10;               // ... and whose points' box is this close to its own [m]
  int point_stride = 4;                // every stride-th pixel of a row and column is kept
  std::uint64_t min_points = 500;      // map planes with fewer pixels (all views) are dropped

  void validate() const;  // throws Error naming the first bad field
};

// A plane n . p + offset = 0 in the map frame; n points towards the side it was seen from.
struct MapPlane {
  int id = 0;                                    // 1..n by decreasing point count
  SemanticClass label = SemanticClass::unknown;  // the most frequent class of its points
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  // In-plane axes (major: the points' largest spread) and the box of the kept points along them.
  Eigen::Vector3d major_axis = Eigen::Vector3d::UnitX(), minor_axis = Eigen::Vector3d::UnitY();
  Eigen::Vector2d extent_min = Eigen::Vector2d::Zero(), extent_max = Eigen::Vector2d::Zero();
  double area = 0;                // of that box [m^2]
  std::uint64_t point_count = 0;  // pixels over all views
  double rms_error = 0;           // RMS distance of all its pixels to the plane [m]
  int views = 0;                  // view planes merged into it
};

class PlaneMap {
 public:
  explicit PlaneMap(const PlaneMapParams& params = {});  // throws Error on bad params

  // planes: extracted from `points` (sensor frame); labels: the view's classes, or empty.
  // Throws Error on a size mismatch.
  void add_view(const segmentation::PlaneSet& planes, const PointImage& points,
                const SemanticImage& labels, const Eigen::Isometry3d& sensor_to_world);

  // The map planes, moved by `transform` (e.g. into a gravity-aligned frame), after merging map
  // planes that have grown together.
  std::vector<MapPlane> planes(const Eigen::Isometry3d& transform = Eigen::Isometry3d::Identity());

 private:
  struct Accumulator {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();  // sum of (p - anchor)(p - anchor)^T
    std::uint64_t count = 0;
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    double offset = 0;
    Eigen::AlignedBox3d box;
    std::vector<Eigen::Vector3f> kept;
    std::array<std::uint64_t, kSemanticClassCount> votes{};
    int views = 0;
  };
  static void refit(Accumulator& a, const Eigen::Vector3d& anchor);
  bool joins(const Accumulator& a, const Accumulator& b) const;
  void absorb(Accumulator& into, Accumulator& from) const;

  PlaneMapParams params_;
  Eigen::Vector3d anchor_ = Eigen::Vector3d::Zero();  // moments about it (float-safe sums)
  bool anchored_ = false;
  std::vector<Accumulator> planes_;
};

}  // namespace kartograf::mapping
