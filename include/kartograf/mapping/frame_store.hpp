#pragma once
// Frames kept for a later pass (re-fusing the TSDF at corrected poses, labelling views), every
// factor-th pixel of every factor-th row: the first in memory up to memory_budget bytes, the rest
// in an unnamed temporary file, so that a long run's memory does not grow with its frames (a
// 320x240 frame with colour takes 384 KB). Frames come back through the FrameSource interface,
// with the decimated camera.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "kartograf/core/image.hpp"
#include "kartograf/mapping/frame_source.hpp"
#include "kartograf/mapping/spill_file.hpp"

namespace kartograf::mapping {

// Every factor-th pixel of every factor-th row: a smaller camera with the same rays.
template <typename Pixel>
Image<Pixel> decimate(const Image<Pixel>& image, int factor) {
  if (factor == 1 || image.empty()) return image;
  Image<Pixel> out(image.width() / factor, image.height() / factor);
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) out(x, y) = image(x * factor, y * factor);
  return out;
}

PinholeIntrinsics decimate(const PinholeIntrinsics& camera, int factor);

// The smallest factor that makes the camera at most max_width pixels wide.
int decimation_for_width(const PinholeIntrinsics& camera, int max_width);

class FrameStore final : public FrameSource {
 public:
  // Throws Error when factor < 1.
  FrameStore(const PinholeIntrinsics& camera, double depth_units_per_metre, int factor,
             std::size_t memory_budget = std::size_t{64} << 20);

  // Error unless the frame has the full camera's size (colour: empty or the depth's size).
  void check(const registration::RgbdImages& frame) const;
  // Appends a frame of the full camera's size (Error otherwise; colour may be empty); returns it
  // decimated, as frame() will. Error when the temporary file cannot be made or written.
  registration::RgbdImages add(const registration::RgbdImages& frame);

  std::size_t size() const override { return records_.size(); }
  PinholeIntrinsics camera() const override { return camera_; }  // decimated
  double depth_units_per_metre() const override { return units_; }
  // The decimated frame (its ground truth dropped); Error on a failed read.
  registration::RgbdImages frame(std::size_t i) const override;
  int factor() const { return factor_; }
  std::size_t bytes_in_memory() const { return memory_bytes_; }
  std::size_t bytes_on_disk() const { return file_.size(); }

 private:
  struct Record {
    std::size_t offset = 0;  // in the file; unused when in memory
    double timestamp = 0;
    bool has_color = false;
    bool in_memory = false;
  };
  void write(const registration::RgbdImages& small, Record& record);
  void read(const Record& record, registration::RgbdImages& out) const;
  PinholeIntrinsics full_camera_, camera_;
  double units_;
  int factor_;
  std::size_t memory_budget_;
  SpillFile file_{"frame store"};
  std::vector<Record> records_;
  std::vector<std::vector<std::uint8_t>> memory_;  // per record in memory, in order
  std::size_t memory_bytes_ = 0;
  mutable std::mutex mutex_;  // frame() may run on a prefetch thread
};

}  // namespace kartograf::mapping
