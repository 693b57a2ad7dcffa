#pragma once
// The feature front end on OpenCV's ORB (registration/feature_front_end.hpp): oriented FAST
// corners with rotated BRIEF descriptors on the grey image, kept where the depth image measures
// them and back-projected to 3-D; two frames aligned by Hamming matching with Lowe's ratio test
// and rigid RANSAC in 3-D (registration/rigid_ransac.hpp). OpenCV stays inside the .cpp files.
#include "kartograf/features/orb_place_index.hpp"
#include "kartograf/registration/feature_front_end.hpp"
#include "kartograf/registration/rigid_ransac.hpp"

namespace kartograf::features {

struct OrbParams {
  int features_per_frame = 1000;
  double scale_factor = 1.2;  // between pyramid levels
  int levels = 8;
  int fast_threshold = 20;  // OpenCV's default: a lower one finds corners in weaker texture
  // A match is kept when its Hamming distance is below ratio x that of the second best.
  double ratio = 0.8;
  // Keep only pairs that are also each other's best match from the target's side.
  bool cross_check = false;
  // Keypoints farther than this, or with no depth, are dropped (Kinect depth is poor beyond).
  double max_depth_m = 4.0;
  // Keypoints on a depth edge get the depth of either side: dropped when the depths of their 3x3
  // neighbourhood spread over more than this fraction of their own depth (or one is missing).
  double max_local_depth_spread = 0.03;
  // The colour camera's focal length over the depth camera's, for data whose colour images are
  // not registered to depth (same centre and axis assumed): 1 for registered data (TUM, Redwood,
  // the synthetic world). 7-Scenes' Kinect v1 colour camera has f ~ 525 against depth's 585:
  // 525 / 585 there cut the mean error at 30 frames apart from 5.4 to 3.1 cm (measured here).
  double color_to_depth_focal = 1.0;
  // ransac.min_inliers is the least consensus that align() answers with.
  registration::RigidRansacParams ransac;
  OrbPlaceParams places;  // make_place_index()'s
};

// Stateless apart from its parameters: describe() and align() may run on several threads at once,
// and the descriptions it makes are read-only.
class OrbFrontEnd final : public registration::FeatureFrontEnd {
 public:
  // Throws Error on parameters out of range.
  explicit OrbFrontEnd(const OrbParams& params = {});

  // Throws Error naming the sizes when depth, colour and camera disagree, or when the colour
  // image is empty or units_per_metre is not positive.
  std::shared_ptr<const registration::FeatureDescription> describe(
      const DepthImage& depth, const RgbImage& color, const PinholeIntrinsics& camera,
      double units_per_metre) const override;

  // Throws Error when a description was not made by an OrbFrontEnd.
  std::optional<registration::FeatureAlignment> align(
      const registration::FeatureDescription& source,
      const registration::FeatureDescription& target) const override;

  // Throws Error when a description was not made by an OrbFrontEnd, or the bytes are not one.
  std::vector<std::uint8_t> serialize(
      const registration::FeatureDescription& description) const override;
  std::shared_ptr<const registration::FeatureDescription> deserialize(
      std::span<const std::uint8_t> bytes) const override;

  // An OrbPlaceIndex with params().places.
  std::unique_ptr<registration::PlaceIndex> make_place_index() const override;

  const OrbParams& params() const { return params_; }

 private:
  OrbParams params_;
};

}  // namespace kartograf::features
