#include "kartograf/compute/buffer.hpp"

#include <algorithm>
#include <cstring>
#include <string>
#include <utility>

#include "compute/device.hpp"
#include "kartograf/compute/kernel.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::compute {

namespace {
// Device buffers are sized in whole 32-bit words (shaders address them as uint arrays), and never
// empty (Vulkan has no zero-sized buffers).
std::size_t padded(std::size_t bytes) { return bytes == 0 ? 4 : (bytes + 3) / 4 * 4; }
}  // namespace

RawBuffer::RawBuffer(const Context& context, std::size_t bytes)
    : bytes_(bytes), device_(context.shared_device()) {
  device_buffer_ = device_->create_buffer(padded(bytes));
  host_ = device_->host_pointer(*device_buffer_);
}

RawBuffer::RawBuffer() = default;
RawBuffer::RawBuffer(RawBuffer&& other) noexcept
    : bytes_(std::exchange(other.bytes_, 0)),
      device_(std::move(other.device_)),
      device_buffer_(std::move(other.device_buffer_)),
      host_(std::exchange(other.host_, nullptr)) {}
RawBuffer& RawBuffer::operator=(RawBuffer&& other) noexcept {
  if (this != &other) {
    device_buffer_.reset();  // before the device it belongs to
    bytes_ = std::exchange(other.bytes_, 0);
    device_ = std::move(other.device_);
    device_buffer_ = std::move(other.device_buffer_);
    host_ = std::exchange(other.host_, nullptr);
  }
  return *this;
}
RawBuffer::~RawBuffer() {
  device_buffer_.reset();  // before the device it belongs to
  device_.reset();
}

void RawBuffer::check_range(std::size_t offset, std::size_t bytes, const char* what) const {
  require(offset <= bytes_ && bytes <= bytes_ - offset,
          std::string("buffer ") + what + ": range [" + std::to_string(offset) + ", " +
              std::to_string(offset + bytes) + ") is outside a buffer of " +
              std::to_string(bytes_) + " bytes");
}

void RawBuffer::write(std::size_t offset, const void* source, std::size_t bytes) {
  check_range(offset, bytes, "write");
  if (bytes == 0) return;
  device_->write(*device_buffer_, offset, source, bytes);
}

void RawBuffer::read(std::size_t offset, void* destination, std::size_t bytes) const {
  check_range(offset, bytes, "read");
  if (bytes == 0) return;
  device_->read(*device_buffer_, offset, destination, bytes);
}

void RawBuffer::fill_zero() {
  if (device_ && bytes_ > 0) device_->fill_zero(*device_buffer_, 0, padded(bytes_));
}

void RawBuffer::copy_from(const RawBuffer& source, std::size_t bytes) {
  check_range(0, bytes, "copy target");
  source.check_range(0, bytes, "copy source");
  require(source.device_ == device_, "buffer copy: the source belongs to another context");
  if (bytes == 0) return;
  device_->copy(*source.device_buffer_, 0, *device_buffer_, 0, bytes);
}

void RawBuffer::refer_or_upload(const Context& context, const void* data, std::size_t bytes) {
  detail::Device* device = context.device();
  // Views never write the data: kernels only read their inputs.
  auto view = device->view_host(static_cast<std::byte*>(const_cast<void*>(data)), bytes);
  if (view) {
    device_buffer_.reset();  // before the device it belongs to
    device_ = context.shared_device();
    device_buffer_ = std::move(view);
    host_ = device_->host_pointer(*device_buffer_);
    bytes_ = bytes;
    return;
  }
  if (device_.get() != device || bytes_ != bytes) *this = RawBuffer(context, bytes);
  write(0, data, bytes);
}

std::byte* RawBuffer::host_data() {
  require(on_host(), "RawBuffer::host_data: the buffer lives on a device, not on the host");
  return host_;
}
const std::byte* RawBuffer::host_data() const {
  require(on_host(), "RawBuffer::host_data: the buffer lives on a device, not on the host");
  return host_;
}

void dispatch_raw(const Context& context, const KernelSpec& kernel, std::span<const BufferArg> buffers,
                  std::span<const std::byte> params, GroupCount groups) {
  detail::Device* device = context.device();
  require(params.size() <= kMaxKernelParamBytes,
          "kernel '" + std::string(kernel.name) + "': parameter block too large");
  constexpr std::size_t kMaxBuffers = 16;
  require(buffers.size() <= kMaxBuffers,
          "kernel '" + std::string(kernel.name) + "': too many buffers");
  detail::DeviceBuffer* bound[kMaxBuffers] = {};
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    const RawBuffer* raw = buffers[i].raw;
    if (!raw) continue;
    require(raw->device() == device, "kernel '" + std::string(kernel.name) + "': buffer " +
                                         std::to_string(i) + " belongs to another context");
    bound[i] = raw->device_buffer();
  }
  if (groups.x == 0 || groups.y == 0) return;
  device->dispatch(kernel, std::span<detail::DeviceBuffer* const>(bound, buffers.size()), params,
                   groups);
}

}  // namespace kartograf::compute
