#pragma once
// A dense, row-major, host-side image of any pixel type: its own pixels, or borrowed ones (memory
// the caller owns, such as a NumPy array or a driver's frame buffer, read without a copy).
#include <cstddef>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "kartograf/core/error.hpp"

namespace kartograf {

template <class Pixel>
class Image {
 public:
  Image() = default;
  Image(int width, int height)
      : width_(checked_dim(width)),
        height_(checked_dim(height)),
        pixels_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height)),
        data_(pixels_.data()) {}
  Image(int width, int height, const Pixel& fill)
      : width_(checked_dim(width)),
        height_(checked_dim(height)),
        pixels_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), fill),
        data_(pixels_.data()) {}
  // Borrows width x height pixels, row-major and contiguous, that the caller keeps alive and does
  // not resize while the image (or a move of it) is in use. Copying it makes an owning copy.
  static Image borrow(Pixel* pixels, int width, int height) {
    Image image;
    image.width_ = checked_dim(width);
    image.height_ = checked_dim(height);
    image.data_ = pixels;
    image.borrowed_ = true;
    return image;
  }

  Image(const Image& other)
      : width_(other.width_),
        height_(other.height_),
        pixels_(other.data_, other.data_ + other.size()),
        data_(pixels_.data()) {}
  Image(Image&& other) noexcept { take(std::move(other)); }
  Image& operator=(const Image& other) {
    if (this != &other) *this = Image(other);
    return *this;
  }
  Image& operator=(Image&& other) noexcept {
    if (this != &other) take(std::move(other));
    return *this;
  }
  ~Image() = default;

  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t size() const {
    return static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  }
  bool empty() const { return size() == 0; }
  bool borrowed() const { return borrowed_; }

  Pixel& operator()(int x, int y) { return data_[index(x, y)]; }
  const Pixel& operator()(int x, int y) const { return data_[index(x, y)]; }

  std::span<Pixel> pixels() { return {data_, size()}; }
  std::span<const Pixel> pixels() const { return {data_, size()}; }
  Pixel* data() { return data_; }
  const Pixel* data() const { return data_; }

 private:
  static int checked_dim(int d) {
    require(d >= 0, "Image: negative dimension " + std::to_string(d));
    return d;
  }
  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
           static_cast<std::size_t>(x);
  }
  // A moved vector keeps its buffer, so data_ stays valid for owned pixels too.
  void take(Image&& other) noexcept {
    width_ = std::exchange(other.width_, 0);
    height_ = std::exchange(other.height_, 0);
    pixels_ = std::move(other.pixels_);
    borrowed_ = std::exchange(other.borrowed_, false);
    data_ = borrowed_ ? other.data_ : pixels_.data();
    other.pixels_.clear();
    other.data_ = nullptr;
  }

  int width_ = 0;
  int height_ = 0;
  std::vector<Pixel> pixels_;
  Pixel* data_ = nullptr;  // pixels_.data(), or the borrowed pixels
  bool borrowed_ = false;
};

}  // namespace kartograf
