#include "kartograf/formats/image_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "formats/atomic_file.hpp"
#include "formats/opencv_decode.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::io {

namespace {

using detail::quoted;

template <class Pixel>
void require_writable(const std::filesystem::path& path, const Image<Pixel>& image) {
  require(!image.empty(), "cannot write " + quoted(path) + ": the image is empty (" +
                              std::to_string(image.width()) + "x" + std::to_string(image.height()) +
                              ")");
}

void encode_png_atomically(const std::filesystem::path& path, const cv::Mat& image) {
  std::vector<std::uint8_t> encoded;
  bool ok = false;
  try {
    ok = cv::imencode(".png", image, encoded);
  } catch (const cv::Exception& e) {
    throw Error("cannot write " + quoted(path) + ": PNG encoding failed: " + e.what());
  }
  if (!ok) throw Error("cannot write " + quoted(path) + ": PNG encoding failed");
  detail::write_file_atomically(path, encoded.data(), encoded.size());
}

std::uint8_t to_byte(double value) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(value), 0L, 255L));
}

// Viridis sampled at 256 levels, taken once from OpenCV's table.
const std::array<Rgb8, 256>& viridis() {
  static const std::array<Rgb8, 256> table = [] {
    cv::Mat ramp(1, 256, CV_8UC1);
    for (int i = 0; i < 256; ++i) ramp.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(i);
    cv::Mat bgr;
    cv::applyColorMap(ramp, bgr, cv::COLORMAP_VIRIDIS);
    std::array<Rgb8, 256> rgb{};
    for (int i = 0; i < 256; ++i) {
      const cv::Vec3b& p = bgr.at<cv::Vec3b>(0, i);
      rgb[i] = {p[2], p[1], p[0]};
    }
    return rgb;
  }();
  return table;
}

}  // namespace

DepthImage read_depth_png(const std::filesystem::path& path) {
  const std::string name = "depth image " + quoted(path);
  const cv::Mat image = detail::decode_image(path, name);
  if (image.depth() != CV_16U) {
    throw Error(name + ": is " + detail::bit_depth_name(image.depth()) +
                ", expected 16-bit (raw depth units); an 8-bit file is a visualization, not depth");
  }
  if (image.channels() != 1) {
    throw Error(name + ": has " + std::to_string(image.channels()) + " channels, expected 1");
  }
  return detail::copy_single_channel<std::uint16_t>(image);
}

RgbImage read_color_image(const std::filesystem::path& path) {
  const std::string name = "colour image " + quoted(path);
  const cv::Mat image = detail::decode_image(path, name);
  if (image.depth() != CV_8U)
    throw Error(name + ": is " + detail::pixel_format_name(image) + ", expected 8-bit");
  if (image.channels() != 3 && image.channels() != 4) {
    throw Error(name + ": has " + std::to_string(image.channels()) +
                " channel(s), expected 3 (RGB) or 4 (RGBA)");
  }
  const int channels = image.channels();
  RgbImage rgb(image.cols, image.rows);
  for (int y = 0; y < image.rows; ++y) {
    const std::uint8_t* row = image.ptr<std::uint8_t>(y);
    for (int x = 0; x < image.cols; ++x) {
      const std::uint8_t* bgr = row + static_cast<std::ptrdiff_t>(x) * channels;
      rgb(x, y) = {bgr[2], bgr[1], bgr[0]};
    }
  }
  return rgb;
}

void write_png(const std::filesystem::path& path, const GrayImage& image) {
  require_writable(path, image);
  // cv::Mat only views the pixels; imencode does not modify them.
  const cv::Mat view(image.height(), image.width(), CV_8UC1,
                     const_cast<std::uint8_t*>(image.data()));
  encode_png_atomically(path, view);
}

void write_png(const std::filesystem::path& path, const RgbImage& image) {
  require_writable(path, image);
  static_assert(sizeof(Rgb8) == 3, "Rgb8 must be packed to view it as CV_8UC3");
  const cv::Mat rgb(image.height(), image.width(), CV_8UC3, const_cast<Rgb8*>(image.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  encode_png_atomically(path, bgr);
}

void write_png(const std::filesystem::path& path, const DepthImage& image) {
  require_writable(path, image);
  const cv::Mat view(image.height(), image.width(), CV_16UC1,
                     const_cast<std::uint16_t*>(image.data()));
  encode_png_atomically(path, view);
}

RgbImage colorize_depth(const DepthImage& depth, double units_per_metre, double max_metres) {
  require(
      std::isfinite(units_per_metre) && units_per_metre > 0,
      "colorize_depth: units_per_metre must be positive, got " + std::to_string(units_per_metre));
  require(std::isfinite(max_metres) && max_metres > 0,
          "colorize_depth: max_metres must be positive, got " + std::to_string(max_metres));
  const auto& colormap = viridis();
  const double levels_per_unit = 255.0 / (units_per_metre * max_metres);
  RgbImage colored(depth.width(), depth.height(), Rgb8{0, 0, 0});
  const auto in = depth.pixels();
  const auto out = colored.pixels();
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i] == 0) continue;
    out[i] = colormap[to_byte(in[i] * levels_per_unit)];
  }
  return colored;
}

RgbImage colorize_normals(const NormalImage& normals) {
  RgbImage colored(normals.width(), normals.height(), Rgb8{0, 0, 0});
  const auto in = normals.pixels();
  const auto out = colored.pixels();
  for (std::size_t i = 0; i < in.size(); ++i) {
    const Point4f& n = in[i];
    if (!n.head<3>().allFinite()) continue;
    out[i] = {to_byte((n.x() + 1.0) * 127.5), to_byte((n.y() + 1.0) * 127.5),
              to_byte((n.z() + 1.0) * 127.5)};
  }
  return colored;
}

}  // namespace kartograf::io
