#pragma once
// Arrays and images that live on a Context's device. On the CPU backend they are host memory that
// operations use in place; on Vulkan/OpenCL they persist on the device across dispatches, and data
// crosses to the host only through upload/download.
#include <cstddef>
#include <memory>
#include <span>
#include <type_traits>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/image.hpp"

namespace kartograf::compute {

namespace detail {
class DeviceBuffer;
}

// Untyped storage: what backends and kernel dispatch see.
class RawBuffer {
 public:
  RawBuffer();
  RawBuffer(const Context& context, std::size_t bytes);
  RawBuffer(RawBuffer&&) noexcept;
  RawBuffer& operator=(RawBuffer&&) noexcept;
  ~RawBuffer();

  std::size_t size_bytes() const { return bytes_; }
  // Ordered after every operation dispatched before it, and before every one dispatched after.
  void write(std::size_t offset, const void* source, std::size_t bytes);
  void read(std::size_t offset, void* destination, std::size_t bytes) const;
  void fill_zero();
  // Copies `bytes` of `source` (a buffer of the same context) to this buffer's offset 0, on the
  // device and in order with the dispatches: no round trip through the host.
  void copy_from(const RawBuffer& source, std::size_t bytes);

  bool on_host() const { return device_ == nullptr; }
  std::byte* host_data();  // CPU backend only
  const std::byte* host_data() const;
  detail::DeviceBuffer* device_buffer() const { return device_buffer_.get(); }
  detail::Device* device() const { return device_.get(); }

 private:
  void check_range(std::size_t offset, std::size_t bytes, const char* what) const;

  std::size_t bytes_ = 0;
  std::shared_ptr<detail::Device> device_;           // null: CPU backend
  std::unique_ptr<detail::DeviceBuffer> device_buffer_;
  std::vector<std::byte, std::allocator<std::byte>> host_;  // CPU backend storage
};

template <class T>
class Buffer {
  // Values cross to devices by memcpy (Eigen's fixed-size vectors qualify).
  static_assert(std::is_standard_layout_v<T> && std::is_trivially_destructible_v<T>,
                "device buffers hold plain values");

 public:
  Buffer() = default;
  Buffer(const Context& context, std::size_t count)
      : count_(count), raw_(context, count * sizeof(T)) {}
  static Buffer from_host(const Context& context, std::span<const T> values) {
    Buffer buffer(context, values.size());
    buffer.upload(values);
    return buffer;
  }

  std::size_t size() const { return count_; }
  bool empty() const { return count_ == 0; }

  void upload(std::span<const T> values, std::size_t first = 0) {
    raw_.write(first * sizeof(T), values.data(), values.size_bytes());
  }
  void download(std::span<T> out, std::size_t first = 0) const {
    raw_.read(first * sizeof(T), out.data(), out.size_bytes());
  }
  std::vector<T> to_vector() const {
    std::vector<T> values(count_);
    download(values);
    return values;
  }
  void fill_zero() { raw_.fill_zero(); }

  // CPU backend only: the storage itself, for the CPU implementation of an operation.
  std::span<T> host_span() { return {reinterpret_cast<T*>(raw_.host_data()), count_}; }
  std::span<const T> host_span() const {
    return {reinterpret_cast<const T*>(raw_.host_data()), count_};
  }

  RawBuffer& raw() { return raw_; }
  const RawBuffer& raw() const { return raw_; }

 private:
  std::size_t count_ = 0;
  RawBuffer raw_;
};

// A Buffer with image dimensions (row-major).
template <class T>
class DeviceImage {
 public:
  DeviceImage() = default;
  DeviceImage(const Context& context, int width, int height)
      : width_(width), height_(height),
        buffer_(context, static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {}
  static DeviceImage from_host(const Context& context, const Image<T>& image) {
    DeviceImage result(context, image.width(), image.height());
    result.buffer_.upload(image.pixels());
    return result;
  }

  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t size() const { return buffer_.size(); }
  Image<T> to_image() const {
    Image<T> image(width_, height_);
    buffer_.download(image.pixels());
    return image;
  }
  void upload(const Image<T>& image) {
    require(image.width() == width_ && image.height() == height_,
            "DeviceImage::upload: image size differs from the device image");
    buffer_.upload(image.pixels());
  }

  Buffer<T>& buffer() { return buffer_; }
  const Buffer<T>& buffer() const { return buffer_; }

 private:
  int width_ = 0;
  int height_ = 0;
  Buffer<T> buffer_;
};

}  // namespace kartograf::compute
