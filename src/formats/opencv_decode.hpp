#pragma once
// Image files decoded with OpenCV for the image and map readers, with one set of messages, and
// OpenCV's pixels copied into Kartograf's images. OpenCV stays private to kartograf_io: only its
// sources include this header.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>

#include <opencv2/core.hpp>

#include "kartograf/core/image.hpp"

namespace kartograf::io::detail {

// The size an image file declares in its header (PNG, PBM/PGM/PPM/PAM, JPEG; others: nothing),
// read before decoding so that a small file announcing a huge image is refused before it
// allocates.
struct DeclaredImageSize {
  double width = 0, height = 0;
  double bytes_per_pixel = 1;  // decoded: channels x bytes per sample
};
std::optional<DeclaredImageSize> declared_image_size(std::span<const std::uint8_t> bytes);

// Exactly what the file stores: IMREAD_UNCHANGED keeps the bit depth, every channel and the
// stored pixel order (no EXIF rotation). Throws Error starting with `name` (what the file is and
// its quoted path, e.g. "label image 'a.png'") when the file cannot be read, is empty, is not in
// a format whose size declared_image_size reads (BMP, TIFF, WebP, ... are refused: OpenCV would
// decode them before their size is known), cannot be decoded, or when the size its header
// declares would not fit in memory (core/memory_budget.hpp).
cv::Mat decode_image(const std::filesystem::path& path, const std::string& name);

// How messages name a bit depth (CV_16U: "16-bit") and an image's pixels ("8-bit 3-channel").
std::string bit_depth_name(int depth);
std::string pixel_format_name(const cv::Mat& image);

// A copy of a single-channel image whose elements are Pixels (CV_16U for std::uint16_t, ...).
template <class Pixel>
Image<Pixel> copy_single_channel(const cv::Mat& image) {
  Image<Pixel> copy(image.cols, image.rows);
  for (int y = 0; y < image.rows; ++y) {
    const Pixel* row = image.ptr<Pixel>(y);
    std::copy(row, row + image.cols, &copy(0, y));
  }
  return copy;
}

}  // namespace kartograf::io::detail
