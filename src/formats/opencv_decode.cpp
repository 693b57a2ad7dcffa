#include "formats/opencv_decode.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "formats/input_file.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/core/memory_budget.hpp"

namespace kartograf::io::detail {

namespace {

double big_endian_32(std::span<const std::uint8_t> bytes, std::size_t at) {
  return static_cast<double>((std::uint32_t{bytes[at]} << 24) |
                             (std::uint32_t{bytes[at + 1]} << 16) |
                             (std::uint32_t{bytes[at + 2]} << 8) | bytes[at + 3]);
}

std::optional<DeclaredImageSize> png_size(std::span<const std::uint8_t> bytes) {
  // Signature, then the IHDR chunk: width, height, bit depth, colour type.
  constexpr std::array<std::uint8_t, 8> kSignature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() < 26 || !std::equal(kSignature.begin(), kSignature.end(), bytes.begin())) {
    return std::nullopt;
  }
  const int bit_depth = bytes[24];
  const int channels = bytes[25] == 0 ? 1 : bytes[25] == 4 ? 2 : bytes[25] == 6 ? 4 : 3;
  return DeclaredImageSize{big_endian_32(bytes, 16), big_endian_32(bytes, 20),
                           static_cast<double>(channels * (bit_depth == 16 ? 2 : 1))};
}

// Skips whitespace and '#' comments (to the end of their line) in a PNM header.
std::size_t skip_pnm_space(std::span<const std::uint8_t> bytes, std::size_t at) {
  while (at < bytes.size() && (std::isspace(bytes[at]) || bytes[at] == '#')) {
    if (bytes[at] == '#') {
      while (at < bytes.size() && bytes[at] != '\n') ++at;
    } else {
      ++at;
    }
  }
  return at;
}

// A decimal number at `at` (after skip_pnm_space), as a double: a header can declare sizes beyond
// any integer type. Nothing when no digit is there.
std::optional<double> pnm_number(std::span<const std::uint8_t> bytes, std::size_t& at) {
  if (at >= bytes.size() || !std::isdigit(bytes[at])) return std::nullopt;
  double number = 0;
  while (at < bytes.size() && std::isdigit(bytes[at])) number = number * 10 + (bytes[at++] - '0');
  return number;
}

// PAM (P7): "WIDTH w", "HEIGHT h", "DEPTH d", "MAXVAL m" lines up to "ENDHDR". A field given
// twice, or without its number, is nothing: which one OpenCV would use is not ours to guess.
std::optional<DeclaredImageSize> pam_size(std::span<const std::uint8_t> bytes) {
  std::optional<double> width, height, depth, maxval;
  std::size_t at = 2;
  while ((at = skip_pnm_space(bytes, at)) < bytes.size()) {
    std::string key;
    while (at < bytes.size() && std::isalpha(bytes[at])) key += static_cast<char>(bytes[at++]);
    if (key == "ENDHDR") {
      if (!width || !height) return std::nullopt;
      return DeclaredImageSize{*width, *height,
                               depth.value_or(1.0) * (maxval.value_or(255.0) > 255 ? 2.0 : 1.0)};
    }
    const std::array<std::pair<const char*, std::optional<double>*>, 4> fields = {
        {{"WIDTH", &width}, {"HEIGHT", &height}, {"DEPTH", &depth}, {"MAXVAL", &maxval}}};
    for (const auto& [field_name, field] : fields) {
      if (key != field_name) continue;
      if (field->has_value()) return std::nullopt;
      at = skip_pnm_space(bytes, at);
      *field = pnm_number(bytes, at);
      if (!field->has_value()) return std::nullopt;
    }
    while (at < bytes.size() && bytes[at] != '\n') ++at;  // the rest of the line (TUPLTYPE ...)
  }
  return std::nullopt;
}

// PBM (P1, P4: width, height), PGM (P2, P5) and PPM (P3, P6: width, height, maxval), comments
// allowed, and PAM (P7).
std::optional<DeclaredImageSize> pnm_size(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 3 || bytes[0] != 'P' ||
      std::string_view("1234567").find(bytes[1]) == std::string_view::npos) {
    return std::nullopt;
  }
  if (bytes[1] == '7') return pam_size(bytes);
  const bool bitmap = bytes[1] == '1' || bytes[1] == '4';
  std::array<double, 3> numbers{0, 0, 255};  // a bitmap has no maxval: one byte per pixel
  std::size_t at = 2;
  for (std::size_t i = 0; i < (bitmap ? 2u : 3u); ++i) {
    at = skip_pnm_space(bytes, at);
    const std::optional<double> number = pnm_number(bytes, at);
    if (!number) return std::nullopt;
    numbers[i] = *number;
  }
  const int channels = bytes[1] == '3' || bytes[1] == '6' ? 3 : 1;
  return DeclaredImageSize{numbers[0], numbers[1], channels * (numbers[2] > 255 ? 2.0 : 1.0)};
}

// JPEG: the first start-of-frame marker (SOF0..SOF15 but DHT, JPG and DAC) holds the size.
std::optional<DeclaredImageSize> jpeg_size(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 4 || bytes[0] != 0xff || bytes[1] != 0xd8) return std::nullopt;
  std::size_t at = 2;
  while (at + 9 < bytes.size() && bytes[at] == 0xff) {
    const std::uint8_t marker = bytes[at + 1];
    const std::size_t length = (std::size_t{bytes[at + 2]} << 8) | bytes[at + 3];
    if (marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc) {
      const double height = (bytes[at + 5] << 8) | bytes[at + 6];
      const double width = (bytes[at + 7] << 8) | bytes[at + 8];
      return DeclaredImageSize{width, height, static_cast<double>(bytes[at + 9])};
    }
    at += 2 + length;
  }
  return std::nullopt;
}

}  // namespace

std::optional<DeclaredImageSize> declared_image_size(std::span<const std::uint8_t> bytes) {
  if (auto size = png_size(bytes)) return size;
  if (auto size = pnm_size(bytes)) return size;
  return jpeg_size(bytes);
}

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

namespace {

bool starts_with(const std::vector<std::uint8_t>& bytes,
                 std::initializer_list<std::uint8_t> magic) {
  return bytes.size() >= magic.size() && std::equal(magic.begin(), magic.end(), bytes.begin());
}

// Position of the last `a b` byte pair at or after `from`, or npos.
std::size_t last_pair(const std::vector<std::uint8_t>& bytes, std::uint8_t a, std::uint8_t b,
                      std::size_t from = 0) {
  for (std::size_t i = bytes.size(); i-- > from + 1;) {
    if (bytes[i - 1] == a && bytes[i] == b) return i - 1;
  }
  return std::string::npos;
}

// OpenCV decodes a JPEG or PNG cut short with only a warning on stderr (the missing rows grey or
// black): such a file must not pass as a frame. A JPEG's last scan (SOS, FF DA) ends with EOI
// (FF D9); an entropy-coded scan cannot hold FF D9 itself (FF bytes are stuffed). A PNG ends with
// its IEND chunk.
void require_complete(const std::vector<std::uint8_t>& bytes, const std::string& name) {
  if (starts_with(bytes, {0xFF, 0xD8, 0xFF})) {
    const std::size_t scan = last_pair(bytes, 0xFF, 0xDA);
    const bool ended =
        scan != std::string::npos && last_pair(bytes, 0xFF, 0xD9, scan) != std::string::npos;
    if (!ended)
      throw Error(name + ": truncated JPEG (no end-of-image marker FF D9 after its image data)");
  } else if (starts_with(bytes, {0x89, 'P', 'N', 'G'})) {
    // IEND near the end (some writers append a few bytes after it).
    const std::size_t from = bytes.size() > 1024 ? bytes.size() - 1024 : 0;
    const char* iend = "IEND";
    const auto found =
        std::search(bytes.begin() + static_cast<std::ptrdiff_t>(from), bytes.end(), iend, iend + 4);
    if (found == bytes.end()) throw Error(name + ": truncated PNG (no IEND chunk at its end)");
  }
}

}  // namespace

cv::Mat decode_image(const std::filesystem::path& path, const std::string& name) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path, name);
  if (bytes.empty()) throw Error(name + ": file is empty");
  require_complete(bytes, name);
  // Only formats whose size is known before decoding: OpenCV also decodes BMP, TIFF, WebP, Sun
  // raster, ... whose header Kartograf does not read, and a few bytes of those can declare an
  // image that takes seconds and gigabytes to decode (a 32-byte WebP: 12545x13313 pixels).
  const std::optional<DeclaredImageSize> size = declared_image_size(bytes);
  if (!size) {
    throw Error(name + ": cannot decode: not a PNG, JPEG or PNM (PBM, PGM, PPM, PAM) file with " +
                "a complete header; Kartograf reads images only in these formats, whose size " +
                "it checks before decoding (convert others, such as BMP, TIFF or WebP, to PNG)");
  }
  // The decoded pixels, and the copy the readers make of them.
  // Printed as doubles: a header can declare sizes beyond any integer type.
  char pixels[96];
  std::snprintf(pixels, sizeof(pixels), " (%.0fx%.0f pixels)", size->width, size->height);
  require_fits_in_memory(2.0 * size->width * size->height * size->bytes_per_pixel, name + pixels);
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
