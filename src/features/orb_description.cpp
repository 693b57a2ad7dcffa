// ORB descriptions (features/orb_description.hpp).
#include "features/orb_description.hpp"

#include <utility>

#include "kartograf/core/error.hpp"

namespace kartograf::features {

OrbDescription::OrbDescription(cv::Mat descriptors, std::vector<Eigen::Vector3d> points,
                               std::vector<Eigen::Vector2f> keypoints)
    : descriptors_(std::move(descriptors)),
      points_(std::move(points)),
      keypoints_(std::move(keypoints)) {
  require(static_cast<std::size_t>(descriptors_.rows) == points_.size() &&
              points_.size() == keypoints_.size(),
          "ORB description: descriptors, points and keypoints differ in number");
}

const OrbDescription& as_orb(const registration::FeatureDescription& description,
                             const std::string& what) {
  const auto* orb = dynamic_cast<const OrbDescription*>(&description);
  require(orb != nullptr, what + ": the features were not described by an ORB front end");
  return *orb;
}

}  // namespace kartograf::features
