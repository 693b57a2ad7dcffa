#include "kartograf/mapping/frame_store.hpp"

#include <algorithm>
#include <string>

#include "kartograf/core/error.hpp"

namespace kartograf::mapping {

namespace {

template <typename Pixel>
std::size_t byte_size(const Image<Pixel>& image) {
  return static_cast<std::size_t>(image.width()) * image.height() * sizeof(Pixel);
}

}  // namespace

PinholeIntrinsics decimate(const PinholeIntrinsics& k, int factor) {
  return {k.width / factor, k.height / factor, k.fx / factor,
          k.fy / factor,    k.cx / factor,     k.cy / factor};
}

int decimation_for_width(const PinholeIntrinsics& camera, int max_width) {
  require(max_width > 0, "decimation: the width must be positive");
  return std::max(1, (camera.width + max_width - 1) / max_width);
}

FrameStore::FrameStore(const PinholeIntrinsics& camera, double depth_units_per_metre, int factor,
                       std::size_t memory_budget)
    : full_camera_(camera),
      camera_(decimate(camera, std::max(factor, 1))),
      units_(depth_units_per_metre),
      factor_(factor),
      memory_budget_(memory_budget) {
  require(factor >= 1, "frame store: the decimation factor must be >= 1");
}

void FrameStore::check(const registration::RgbdImages& frame) const {
  require(frame.depth.width() == full_camera_.width && frame.depth.height() == full_camera_.height,
          "frame store: frame " + std::to_string(records_.size()) + " is " +
              std::to_string(frame.depth.width()) + "x" + std::to_string(frame.depth.height()) +
              ", the camera " + std::to_string(full_camera_.width) + "x" +
              std::to_string(full_camera_.height));
  require(frame.color.empty() || (frame.color.width() == frame.depth.width() &&
                                  frame.color.height() == frame.depth.height()),
          "frame store: frame " + std::to_string(records_.size()) +
              ": the colour image's size differs from the depth's");
}

registration::RgbdImages FrameStore::add(const registration::RgbdImages& frame) {
  check(frame);
  registration::RgbdImages small;
  small.timestamp = frame.timestamp;
  small.depth = decimate(frame.depth, factor_);
  small.color = decimate(frame.color, factor_);
  const std::lock_guard lock(mutex_);
  Record record{0, frame.timestamp, !small.color.empty(), false};
  write(small, record);
  records_.push_back(record);
  return small;
}

void FrameStore::write(const registration::RgbdImages& small, Record& record) {
  const std::size_t depth_bytes = byte_size(small.depth), color_bytes = byte_size(small.color);
  const auto* depth = reinterpret_cast<const std::uint8_t*>(small.depth.data());
  const auto* color = reinterpret_cast<const std::uint8_t*>(small.color.data());
  if (!file_ && memory_bytes_ + depth_bytes + color_bytes <= memory_budget_) {  // memory first
    std::vector<std::uint8_t>& bytes = memory_.emplace_back(depth, depth + depth_bytes);
    bytes.insert(bytes.end(), color, color + color_bytes);
    memory_bytes_ += bytes.size();
    record.in_memory = true;
    return;
  }
  if (!file_) {
    file_.reset(std::tmpfile());
    require(file_ != nullptr, "frame store: cannot create a temporary file for the frames");
  }
  record.offset = end_;
  const bool written = std::fseek(file_.get(), static_cast<long>(end_), SEEK_SET) == 0 &&
                       std::fwrite(depth, 1, depth_bytes, file_.get()) == depth_bytes &&
                       std::fwrite(color, 1, color_bytes, file_.get()) == color_bytes;
  require(written, "frame store: writing frame " + std::to_string(records_.size()) +
                       " to the temporary file failed (disk full?)");
  end_ += depth_bytes + color_bytes;
}

void FrameStore::read(const Record& record, registration::RgbdImages& out) const {
  auto* depth = reinterpret_cast<std::uint8_t*>(out.depth.data());
  auto* color = reinterpret_cast<std::uint8_t*>(out.color.data());
  const std::size_t depth_bytes = byte_size(out.depth), color_bytes = byte_size(out.color);
  if (record.in_memory) {
    const std::size_t k = static_cast<std::size_t>(&record - records_.data());
    const std::vector<std::uint8_t>& bytes = memory_[k];  // in-memory records come first
    std::copy(bytes.begin(), bytes.begin() + depth_bytes, depth);
    std::copy(bytes.begin() + depth_bytes, bytes.end(), color);
    return;
  }
  const bool read = std::fseek(file_.get(), static_cast<long>(record.offset), SEEK_SET) == 0 &&
                    std::fread(depth, 1, depth_bytes, file_.get()) == depth_bytes &&
                    std::fread(color, 1, color_bytes, file_.get()) == color_bytes;
  require(read, "frame store: reading a frame back from the temporary file failed");
}

registration::RgbdImages FrameStore::frame(std::size_t i) const {
  require(i < records_.size(), "frame store: no frame " + std::to_string(i));
  const Record& record = records_[i];
  registration::RgbdImages out;
  out.timestamp = record.timestamp;
  out.depth = DepthImage(camera_.width, camera_.height);
  if (record.has_color) out.color = RgbImage(camera_.width, camera_.height);
  const std::lock_guard lock(mutex_);
  read(record, out);
  return out;
}

}  // namespace kartograf::mapping
