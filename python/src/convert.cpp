#include "convert.hpp"

#include <cmath>
#include <span>
#include <string>

#include "kartograf/core/error.hpp"

namespace kartograf::python {

static_assert(sizeof(Rgb8) == 3, "a colour pixel is three bytes, as a NumPy H x W x 3 array");

DepthImage borrow_depth(const DepthArray& depth) {
  return DepthImage::borrow(const_cast<std::uint16_t*>(depth.data()),
                            static_cast<int>(depth.shape(1)), static_cast<int>(depth.shape(0)));
}

RgbImage borrow_color(const ColorArray& color) {
  auto* pixels = reinterpret_cast<Rgb8*>(const_cast<std::uint8_t*>(color.data()));
  return RgbImage::borrow(pixels, static_cast<int>(color.shape(1)),
                          static_cast<int>(color.shape(0)));
}

RgbImage borrow_color(const std::optional<ColorArray>& color) {
  return color ? borrow_color(*color) : RgbImage();
}

Eigen::Isometry3d to_pose(const PoseArray& matrix, const char* what) {
  Eigen::Matrix4d m;
  const auto view = matrix.view();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = view(r, c);
  const Eigen::Matrix3d rotation = m.topLeftCorner<3, 3>();
  require(m.allFinite(), std::string(what) + ": the pose is not finite");
  require((rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
              std::abs(rotation.determinant() - 1) < 1e-6 &&
              m.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)),
          std::string(what) + ": the pose is not a rigid motion (a rotation and a translation)");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.matrix() = m;
  return pose;
}

namespace {

// The poses' 4 x 4 matrices, row-major, one after the other.
std::vector<double> row_major(std::span<const Eigen::Isometry3d> poses) {
  std::vector<double> values(poses.size() * 16);
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) values[i * 16 + std::size_t(r * 4 + c)] = poses[i].matrix()(r, c);
  return values;
}

}  // namespace

NumpyArray<double> pose_array(const Eigen::Isometry3d& pose) {
  return owned_array(row_major({&pose, 1}), {4, 4});
}

NumpyArray<double> pose_stack(const std::vector<Eigen::Isometry3d>& poses) {
  return owned_array(row_major(poses), {poses.size(), 4, 4});
}

nb::list optional_poses(const std::vector<std::optional<Eigen::Isometry3d>>& poses) {
  nb::list out;
  for (const auto& pose : poses) out.append(pose ? nb::cast(pose_array(*pose)) : nb::none());
  return out;
}

NumpyArray<std::uint16_t> depth_array(DepthImage image) {
  const auto w = std::size_t(image.width()), h = std::size_t(image.height());
  return image_array<std::uint16_t>(std::move(image), {h, w});
}

NumpyArray<std::uint8_t> color_array(RgbImage image) {
  const auto w = std::size_t(image.width()), h = std::size_t(image.height());
  return image_array<std::uint8_t>(std::move(image), {h, w, 3});
}

}  // namespace kartograf::python
