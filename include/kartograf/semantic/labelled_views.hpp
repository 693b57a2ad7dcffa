#pragma once
// Labelled views pooled in one world frame for the semantic grid: each view's valid points move to
// the world with the view's pose, keeping their classes, and the views vote for the world's up
// direction (each view's estimated up, weighted by the horizontal area that supported it: a view
// that saw much floor and ceiling knows up better than one that saw a strip of floor).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/point_image.hpp"
#include "kartograf/core/semantic_class.hpp"
#include "kartograf/semantic/gravity.hpp"

namespace kartograf::semantic {

class LabelledViews {
 public:
  // points: the view's organized points in its sensor frame (NaN: none); labels: their classes
  // (same size); gravity: the view's up estimate in its sensor frame. Throws Error on a size
  // mismatch.
  void add(const PointImage& points, const SemanticImage& labels, const GravityEstimate& gravity,
           const Eigen::Isometry3d& sensor_to_world);
  // A view that could not be labelled (e.g. no floor or ceiling to find up from): counted, and the
  // first reason kept for the message.
  void skip(const std::string& reason);

  // Turns every point so that the voted up direction becomes +z and returns that rotation (the
  // identity when no view voted). Call once, after the last add().
  Eigen::Matrix3d make_up_z();
  // Moves every point by `transform` (e.g. into a map frame).
  void transform(const Eigen::Isometry3d& transform);

  std::span<const Eigen::Vector3d> points() const { return points_; }
  std::span<const SemanticClass> labels() const { return labels_; }
  // The view (0-based, in the order added) each point came from.
  std::span<const std::uint32_t> view_ids() const { return view_ids_; }
  // Where each view saw from (its sensor's origin), in the points' frame.
  std::span<const Eigen::Vector3d> view_origins() const { return origins_; }
  Eigen::Vector3d up() const;  // the voted up, unit (+z when no view voted)
  int views() const { return views_; }
  int skipped() const { return skipped_; }
  const std::string& first_skip_reason() const { return first_skip_reason_; }

 private:
  std::vector<Eigen::Vector3d> points_;
  std::vector<SemanticClass> labels_;
  std::vector<std::uint32_t> view_ids_;
  std::vector<Eigen::Vector3d> origins_;
  Eigen::Vector3d up_sum_ = Eigen::Vector3d::Zero();
  int views_ = 0, skipped_ = 0;
  std::string first_skip_reason_;
};

// The floor's height: the lowest level that holds at least 15 % of the floor points' heights
// (within 5 cm either side of its 5 cm bin), the median of the heights within 7.5 cm of it; their
// median where that level holds it (one level, as a robot's survey has). A view that sees a table
// and not the floor takes the table's top for its floor (its lowest large horizontal surface):
// over 7-Scenes' kitchen such tops outnumbered the floor, and the median of all floor points put
// the map's floor on the table, 0.75 m up. None without heights.
std::optional<double> floor_level(std::vector<double> heights);
// The same over the views' points labelled floor, heights along `up`.
std::optional<double> floor_height(const LabelledViews& views,
                                   const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

}  // namespace kartograf::semantic
