#pragma once
// A dense, row-major, host-side image of any pixel type.
#include <cstddef>
#include <span>
#include <vector>

#include "kartograf/core/error.hpp"

namespace kartograf {

template <class Pixel>
class Image {
 public:
  Image() = default;
  Image(int width, int height)
      : width_(checked_dim(width)), height_(checked_dim(height)),
        pixels_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {}
  Image(int width, int height, const Pixel& fill)
      : width_(checked_dim(width)), height_(checked_dim(height)),
        pixels_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), fill) {}

  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t size() const { return pixels_.size(); }
  bool empty() const { return pixels_.empty(); }

  Pixel& operator()(int x, int y) { return pixels_[index(x, y)]; }
  const Pixel& operator()(int x, int y) const { return pixels_[index(x, y)]; }

  std::span<Pixel> pixels() { return pixels_; }
  std::span<const Pixel> pixels() const { return pixels_; }
  Pixel* data() { return pixels_.data(); }
  const Pixel* data() const { return pixels_.data(); }

 private:
  static int checked_dim(int d) {
    require(d >= 0, "Image: negative dimension " + std::to_string(d));
    return d;
  }
  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
           static_cast<std::size_t>(x);
  }

  int width_ = 0;
  int height_ = 0;
  std::vector<Pixel> pixels_;
};

}  // namespace kartograf
