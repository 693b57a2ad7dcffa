#pragma once
// Local image features for what dense ICP cannot do alone: a motion too large for its basin
// (recovery, relocalisation) and places recognised by appearance, not by the pose estimate
// (loop-closure candidates). The interfaces live here, below OpenCV; the implementation that
// uses OpenCV's ORB is the features layer's (features/orb_front_end.hpp), handed in by the
// pipeline, so the odometry and the SLAM stay free of OpenCV.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::registration {

// One frame's features (keypoints with their 3-D points in the camera frame, descriptors):
// opaque here, made by FeatureFrontEnd::describe.
class FeatureDescription {
 public:
  virtual ~FeatureDescription() = default;
  // Keypoints with a valid depth (the ones that can be matched in 3-D).
  virtual std::size_t size() const = 0;
  // What it holds in memory, in bytes (for the keyframes' memory budget).
  virtual std::size_t memory_bytes() const = 0;
};

// A rigid motion from matched features: the RANSAC consensus of 3-D point pairs, refined on its
// inliers.
struct FeatureAlignment {
  Eigen::Isometry3d source_to_target = Eigen::Isometry3d::Identity();
  std::size_t matches = 0;  // descriptor matches that passed the ratio test
  std::size_t inliers = 0;  // pairs within the inlier distance of the consensus
  double inlier_rmse_m = 0;
};

class PlaceIndex;

class FeatureFrontEnd {
 public:
  virtual ~FeatureFrontEnd() = default;
  // An empty place-recognition index over this front end's descriptions (null: the front end
  // has none, and loop closure finds no candidates by appearance).
  virtual std::unique_ptr<PlaceIndex> make_place_index() const { return nullptr; }
  // Features of an RGB-D frame: depth in units_per_metre on the camera's pixel grid, colour on
  // the same grid. Throws Error on mismatched sizes.
  virtual std::shared_ptr<const FeatureDescription> describe(const DepthImage& depth,
                                                             const RgbImage& color,
                                                             const PinholeIntrinsics& camera,
                                                             double units_per_metre) const = 0;
  // The motion that maps source's points onto target's, or nothing when too few matches agree.
  virtual std::optional<FeatureAlignment> align(const FeatureDescription& source,
                                                const FeatureDescription& target) const = 0;
  // A description as bytes and back, for keyframes kept on disk. Throws Error when the description
  // was made by another front end, or the bytes are not one of this front end's descriptions.
  virtual std::vector<std::uint8_t> serialize(const FeatureDescription& description) const = 0;
  virtual std::shared_ptr<const FeatureDescription> deserialize(
      std::span<const std::uint8_t> bytes) const = 0;
};

// A place-recognition index over keyframes' features.
struct PlaceMatch {
  std::size_t place = 0;  // the id it was added with
  double score = 0;       // higher is more similar
};

class PlaceIndex {
 public:
  virtual ~PlaceIndex() = default;
  // Adds a place; ids must increase. The index keeps what it searches, not the description.
  virtual void add(std::size_t place, const FeatureDescription& features) = 0;
  // The places most similar to `features` among those with id < before, best first, at most
  // max_results, only those above the index's own similarity floor.
  virtual std::vector<PlaceMatch> query(const FeatureDescription& features, std::size_t before,
                                        std::size_t max_results) const = 0;
};

}  // namespace kartograf::registration
