#include "kartograf/mapping/frame_store.hpp"

#include <algorithm>
#include <span>
#include <string>

#include "kartograf/core/error.hpp"

namespace kartograf::mapping {

namespace {

template <typename Pixel>
std::size_t pixel_count(const Image<Pixel>& image) {
  return static_cast<std::size_t>(image.width()) * image.height();
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
  const std::span<const std::uint8_t> depth =
      bytes_of(small.depth.data(), pixel_count(small.depth));
  const std::span<const std::uint8_t> color =
      bytes_of(small.color.data(), pixel_count(small.color));
  // Memory first, while the file is unused: the in-memory records are the first ones.
  if (file_.size() == 0 && memory_bytes_ + depth.size() + color.size() <= memory_budget_) {
    std::vector<std::uint8_t>& bytes = memory_.emplace_back(depth.begin(), depth.end());
    bytes.insert(bytes.end(), color.begin(), color.end());
    memory_bytes_ += bytes.size();
    record.in_memory = true;
    return;
  }
  const std::span<const std::uint8_t> pieces[] = {depth, color};
  record.offset = file_.append(std::span<const std::span<const std::uint8_t>>(pieces));
}

void FrameStore::read(const Record& record, registration::RgbdImages& out) const {
  const std::span<std::uint8_t> depth = bytes_of(out.depth.data(), pixel_count(out.depth));
  const std::span<std::uint8_t> color = bytes_of(out.color.data(), pixel_count(out.color));
  if (record.in_memory) {
    const std::size_t k = static_cast<std::size_t>(&record - records_.data());
    const std::vector<std::uint8_t>& bytes = memory_[k];  // in-memory records come first
    std::copy(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(depth.size()),
              depth.begin());
    std::copy(bytes.begin() + static_cast<std::ptrdiff_t>(depth.size()), bytes.end(),
              color.begin());
    return;
  }
  file_.read(record.offset, depth);
  file_.read(record.offset + depth.size(), color);
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
