#pragma once
// What OrbFrontEnd::describe makes (private to the features layer): per kept keypoint its
// descriptor (one row of 32 bytes), its 3-D point in the camera frame and its image position,
// strongest corner (detector response) first.
// Immutable once made, so several threads may match against it at once.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "kartograf/registration/feature_front_end.hpp"

namespace kartograf::features {

class OrbDescription final : public registration::FeatureDescription {
 public:
  OrbDescription(cv::Mat descriptors, std::vector<Eigen::Vector3d> points,
                 std::vector<Eigen::Vector2f> keypoints);

  std::size_t size() const override { return points_.size(); }
  std::size_t memory_bytes() const override;
  const cv::Mat& descriptors() const { return descriptors_; }  // CV_8U, size() x 32
  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  const std::vector<Eigen::Vector2f>& keypoints() const { return keypoints_; }

 private:
  cv::Mat descriptors_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<Eigen::Vector2f> keypoints_;
};

// `description` as an OrbDescription; Error naming `what` when another front end made it.
const OrbDescription& as_orb(const registration::FeatureDescription& description,
                             const std::string& what);

// As bytes (a tag, the count, then descriptors, points and keypoints as stored) and back; Error
// when the bytes are not such a record (wrong tag, truncated, trailing bytes, a non-finite point).
std::vector<std::uint8_t> serialize(const OrbDescription& description);
std::shared_ptr<const OrbDescription> deserialize_orb(std::span<const std::uint8_t> bytes);

}  // namespace kartograf::features
