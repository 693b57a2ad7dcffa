#pragma once
// Arrays and images that live on a Context's device. On the CPU backend that is host memory; on
// Vulkan/OpenCL they persist on the device across dispatches, and data crosses to the host only
// through upload/download (or a HostView, which is free where the memory is the host's).
#include <cstddef>
#include <exception>
#include <memory>
#include <span>
#include <type_traits>
#include <utility>
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
  // The buffer holds `bytes` at `data`: where the context's buffers are host memory (the CPU
  // backend) it becomes a view of them, no copy (they must stay alive and unchanged while
  // operations use the buffer); elsewhere they are uploaded, reusing the storage when the size
  // is the same. For per-frame inputs that already are in host memory.
  void refer_or_upload(const Context& context, const void* data, std::size_t bytes);

  // Whether the bytes are host memory (the CPU backend, or an empty default buffer): host_data()
  // is then valid.
  bool on_host() const { return host_ != nullptr || !device_; }
  std::byte* host_data();  // on_host() only
  const std::byte* host_data() const;
  detail::DeviceBuffer* device_buffer() const { return device_buffer_.get(); }
  detail::Device* device() const { return device_.get(); }

 private:
  void check_range(std::size_t offset, std::size_t bytes, const char* what) const;

  std::size_t bytes_ = 0;
  std::shared_ptr<detail::Device> device_;  // null: a default-constructed (empty) buffer
  std::unique_ptr<detail::DeviceBuffer> device_buffer_;
  std::byte* host_ = nullptr;  // the device buffer's bytes when they are host memory
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
  // See RawBuffer::refer_or_upload: `values` without a copy on the CPU backend.
  void refer_or_upload(const Context& context, std::span<const T> values) {
    raw_.refer_or_upload(context, values.data(), values.size_bytes());
    count_ = values.size();
  }

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

// Read access on the host to a buffer's values, for host-only steps (a k-d tree search, say) that
// must not branch on the backend: the storage itself where it is host memory (free), else a copy
// downloaded once. Valid while the buffer lives and is not written.
template <class T>
class HostView {
 public:
  explicit HostView(const Buffer<T>& buffer) {
    if (buffer.raw().on_host()) {
      values_ = buffer.host_span();
    } else {
      copy_ = buffer.to_vector();
      values_ = copy_;
    }
  }
  HostView(const HostView&) = delete;
  HostView& operator=(const HostView&) = delete;
  HostView(HostView&&) noexcept = default;  // a moved vector keeps its storage: values_ stays valid
  HostView& operator=(HostView&&) noexcept = default;

  std::span<const T> span() const { return values_; }
  operator std::span<const T>() const { return values_; }  // NOLINT: a view converts freely
  const T* data() const { return values_.data(); }
  std::size_t size() const { return values_.size(); }
  bool empty() const { return values_.empty(); }
  const T& operator[](std::size_t i) const { return values_[i]; }
  auto begin() const { return values_.begin(); }
  auto end() const { return values_.end(); }

 private:
  std::vector<T> copy_;  // empty where the buffer is host memory
  std::span<const T> values_;
};

template <class T>
HostView<T> read_on_host(const Buffer<T>& buffer) {
  return HostView<T>(buffer);
}

// What a HostWriteView starts from: the buffer's values, or anything (the step writes them all,
// so a device buffer needs no download).
enum class HostWriteStart { current_values, overwrite_all };

// Write access on the host to a buffer's values: the storage itself where it is host memory, else a
// host copy that commit() uploads (the destructor commits unless an exception is unwinding).
template <class T>
class HostWriteView {
 public:
  explicit HostWriteView(Buffer<T>& buffer, HostWriteStart start = HostWriteStart::current_values)
      : buffer_(&buffer) {
    if (buffer.raw().on_host()) {
      values_ = buffer.host_span();
      return;
    }
    copy_ = start == HostWriteStart::current_values ? buffer.to_vector()
                                                    : std::vector<T>(buffer.size());
    values_ = copy_;
    uncommitted_ = true;
  }
  HostWriteView(const HostWriteView&) = delete;
  HostWriteView& operator=(const HostWriteView&) = delete;
  HostWriteView(HostWriteView&& other) noexcept
      : buffer_(other.buffer_),
        copy_(std::move(other.copy_)),
        values_(other.values_),
        uncommitted_(std::exchange(other.uncommitted_, false)),
        exceptions_at_start_(other.exceptions_at_start_) {}
  HostWriteView& operator=(HostWriteView&&) = delete;
  ~HostWriteView() noexcept(false) {
    // Uploading half-written values while a failure unwinds would only hide it.
    if (std::uncaught_exceptions() == exceptions_at_start_) commit();
  }

  // Uploads the view's values now (a no-op on host memory). Once only: writes through the view
  // after a commit stay on the host.
  void commit() {
    if (!uncommitted_) return;
    uncommitted_ = false;
    buffer_->upload(copy_);
  }

  std::span<T> span() const { return values_; }
  operator std::span<T>() const { return values_; }  // NOLINT: a view converts freely
  T* data() const { return values_.data(); }
  std::size_t size() const { return values_.size(); }
  T& operator[](std::size_t i) const { return values_[i]; }
  auto begin() const { return values_.begin(); }
  auto end() const { return values_.end(); }

 private:
  Buffer<T>* buffer_;
  std::vector<T> copy_;  // empty where the buffer is host memory
  std::span<T> values_;
  bool uncommitted_ = false;
  int exceptions_at_start_ = std::uncaught_exceptions();
};

template <class T>
HostWriteView<T> write_on_host(Buffer<T>& buffer,
                               HostWriteStart start = HostWriteStart::current_values) {
  return HostWriteView<T>(buffer, start);
}

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
