#include "io/opencv_decode.hpp"

#include <cstdint>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "io/input_file.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::io::detail {

std::string bit_depth_name(int depth) {
  switch (depth) {
    case CV_8U:
      return "8-bit";
    case CV_8S:
      return "8-bit signed";
    case CV_16U:
      return "16-bit";
    case CV_16S:
      return "16-bit signed";
    case CV_32S:
      return "32-bit integer";
    case CV_32F:
      return "32-bit float";
    case CV_64F:
      return "64-bit float";
    default:
      return "unknown bit depth";
  }
}

std::string pixel_format_name(const cv::Mat& image) {
  return bit_depth_name(image.depth()) + " " + std::to_string(image.channels()) + "-channel";
}

cv::Mat decode_image(const std::filesystem::path& path, const std::string& name) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path, name);
  if (bytes.empty()) throw Error(name + ": file is empty");
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw Error(name + ": cannot decode: " + e.what());
  }
  if (image.empty()) {
    throw Error(name + ": cannot decode: not an image file in a format OpenCV reads, or corrupt");
  }
  return image;
}

}  // namespace kartograf::io::detail
