// Ratio-tested Hamming matching (features/orb_matching.hpp).
#include "features/orb_matching.hpp"

#include <opencv2/features2d.hpp>

namespace kartograf::features {
namespace {

// Each target row's nearest source row.
std::vector<int> nearest_source_of_each_target(const cv::Mat& source, const cv::Mat& target) {
  std::vector<cv::DMatch> backward;
  cv::BFMatcher(cv::NORM_HAMMING).match(target, source, backward);
  std::vector<int> nearest(static_cast<std::size_t>(target.rows), -1);
  for (const cv::DMatch& m : backward) nearest[static_cast<std::size_t>(m.queryIdx)] = m.trainIdx;
  return nearest;
}

}  // namespace

std::vector<DescriptorMatch> ratio_matches(const cv::Mat& source, const cv::Mat& target,
                                           double ratio, bool cross_check) {
  std::vector<DescriptorMatch> result;
  if (source.rows == 0 || target.rows == 0) return result;
  std::vector<std::vector<cv::DMatch>> knn;
  cv::BFMatcher(cv::NORM_HAMMING).knnMatch(source, target, knn, 2);
  const std::vector<int> backward =
      cross_check ? nearest_source_of_each_target(source, target) : std::vector<int>{};
  for (const auto& neighbours : knn) {
    if (neighbours.empty()) continue;
    const cv::DMatch& best = neighbours[0];
    if (neighbours.size() > 1 && best.distance >= ratio * neighbours[1].distance) continue;
    if (cross_check && backward[static_cast<std::size_t>(best.trainIdx)] != best.queryIdx) continue;
    result.push_back({best.queryIdx, best.trainIdx});
  }
  return result;
}

}  // namespace kartograf::features
