#pragma once
// Between NumPy arrays and Kartograf's types, for the bindings. Images come in without a copy when
// the array is C-contiguous with the right dtype (the image borrows its memory; nanobind copies an
// array of another layout or dtype first); results go out as arrays that own their memory.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/color.hpp"
#include "kartograf/core/label_image.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::python {

namespace nb = nanobind;

// Depth images and label images alike: H x W uint16.
using DepthArray = nb::ndarray<const std::uint16_t, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using ColorArray =
    nb::ndarray<const std::uint8_t, nb::shape<-1, -1, 3>, nb::c_contig, nb::device::cpu>;
using PoseArray = nb::ndarray<const double, nb::shape<4, 4>, nb::device::cpu>;
template <class T>
using NumpyArray = nb::ndarray<nb::numpy, T>;

// Images over the arrays' memory (the caller keeps the array alive while the image is used).
DepthImage borrow_depth(const DepthArray& depth);
inline LabelImage borrow_labels(const DepthArray& labels) {
  return borrow_depth(labels);
}
RgbImage borrow_color(const ColorArray& color);
RgbImage borrow_color(const std::optional<ColorArray>& color);  // empty when none

// A 4x4 camera-to-world matrix; Error naming `what` unless it is a finite rigid motion.
Eigen::Isometry3d to_pose(const PoseArray& matrix, const char* what);

// Arrays that own a copy of the values (moved in: no second copy).
template <class T>
NumpyArray<T> owned_array(std::vector<T>&& values, std::initializer_list<std::size_t> shape) {
  auto* owned = new std::vector<T>(std::move(values));
  nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  return NumpyArray<T>(owned->data(), shape.size(), shape.begin(), owner);
}
// The image itself becomes the array's memory (a borrowed one is copied first); T: the pixel's
// element type, shape: the array's.
template <class T, class Pixel>
NumpyArray<T> image_array(Image<Pixel>&& image, std::initializer_list<std::size_t> shape) {
  auto* owned = new Image<Pixel>(image.borrowed() ? Image<Pixel>(image) : std::move(image));
  nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<Image<Pixel>*>(p); });
  return NumpyArray<T>(reinterpret_cast<T*>(owned->data()), shape.size(), shape.begin(), owner);
}
template <class T, class Pixel>
NumpyArray<T> plane_array(Image<Pixel>&& image) {  // H x W
  const auto w = std::size_t(image.width()), h = std::size_t(image.height());
  return image_array<T>(std::move(image), {h, w});
}
NumpyArray<double> pose_array(const Eigen::Isometry3d& pose);                // 4x4
NumpyArray<double> pose_stack(const std::vector<Eigen::Isometry3d>& poses);  // N x 4 x 4
// Per frame: its 4 x 4 pose, or None.
nb::list optional_poses(const std::vector<std::optional<Eigen::Isometry3d>>& poses);
NumpyArray<std::uint16_t> depth_array(DepthImage image);  // H x W
NumpyArray<std::uint8_t> color_array(RgbImage image);     // H x W x 3

}  // namespace kartograf::python
