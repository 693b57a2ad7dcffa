// ORB descriptions (features/orb_description.hpp).
#include "features/orb_description.hpp"

#include <cstring>
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

std::size_t OrbDescription::memory_bytes() const {
  return descriptors_.total() * descriptors_.elemSize() + points_.size() * sizeof(Eigen::Vector3d) +
         keypoints_.size() * sizeof(Eigen::Vector2f) + sizeof(*this);
}

namespace {

constexpr std::uint32_t kOrbTag = 0x42524f4b;  // "KORB"
constexpr int kDescriptorBytes = 32;

template <typename T>
void put(std::vector<std::uint8_t>& out, const T* values, std::size_t count) {
  const std::size_t at = out.size(), length = count * sizeof(T);
  out.resize(at + length);
  if (length > 0) std::memcpy(out.data() + at, static_cast<const void*>(values), length);
}

// Reads `count` values of T from `in` at `at`, advancing it; Error when too few bytes are left.
template <typename T>
void take(std::span<const std::uint8_t> in, std::size_t& at, T* values, std::size_t count) {
  const std::size_t length = count * sizeof(T);
  require(length <= in.size() - at, "ORB description: the record is truncated");
  if (length > 0) std::memcpy(static_cast<void*>(values), in.data() + at, length);
  at += length;
}

}  // namespace

std::vector<std::uint8_t> serialize(const OrbDescription& description) {
  const std::uint64_t count = description.size();
  require(count == 0 || (description.descriptors().cols == kDescriptorBytes &&
                         description.descriptors().type() == CV_8U),
          "ORB description: descriptors are not 32-byte rows");
  std::vector<std::uint8_t> out;
  out.reserve(12 + count * (kDescriptorBytes + sizeof(Eigen::Vector3d) + sizeof(Eigen::Vector2f)));
  put(out, &kOrbTag, 1);
  put(out, &count, 1);
  for (int row = 0; row < static_cast<int>(count); ++row)
    put(out, description.descriptors().ptr<std::uint8_t>(row), kDescriptorBytes);
  put(out, description.points().data(), count);
  put(out, description.keypoints().data(), count);
  return out;
}

std::shared_ptr<const OrbDescription> deserialize_orb(std::span<const std::uint8_t> bytes) {
  std::size_t at = 0;
  std::uint32_t tag = 0;
  std::uint64_t count = 0;
  take(bytes, at, &tag, 1);
  require(tag == kOrbTag, "ORB description: the record is not an ORB description");
  take(bytes, at, &count, 1);
  const std::size_t per_point =
      kDescriptorBytes + sizeof(Eigen::Vector3d) + sizeof(Eigen::Vector2f);
  require(count == (bytes.size() - at) / per_point && (bytes.size() - at) % per_point == 0,
          "ORB description: the record's length does not match its count");
  const auto n = static_cast<std::size_t>(count);
  cv::Mat descriptors;
  if (n > 0) descriptors.create(static_cast<int>(n), kDescriptorBytes, CV_8U);
  for (int row = 0; row < static_cast<int>(n); ++row)
    take(bytes, at, descriptors.ptr<std::uint8_t>(row), kDescriptorBytes);
  std::vector<Eigen::Vector3d> points(n);
  std::vector<Eigen::Vector2f> keypoints(n);
  take(bytes, at, points.data(), n);
  take(bytes, at, keypoints.data(), n);
  for (const Eigen::Vector3d& p : points)
    require(p.allFinite(), "ORB description: the record holds a non-finite point");
  return std::make_shared<const OrbDescription>(std::move(descriptors), std::move(points),
                                                std::move(keypoints));
}

}  // namespace kartograf::features
