// The io layer: PNG and PLY files written and read back, checked against an independent PNG
// codec (zlib only, no OpenCV) so that a mistake shared by writer and reader cannot hide;
// hand-written PLY variants (ascii with CRLF, extra properties, faces before and after the
// vertices, big-endian); every error path with what its message must say; atomic writes; and a
// real 7-Scenes depth frame.
#include <dlfcn.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/core/point_cloud.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/ply.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Files, directories and error messages

using testing::error_message;
using testing::expect_mentions;
using testing::read_bytes;
using testing::read_text;
using testing::write_file;

std::string quoted(const fs::path& path) {
  return "'" + path.string() + "'";
}

// Every test gets its own empty directory, removed afterwards.
class IoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("kartograf-io-test-" + std::to_string(::getpid()) + "-" +
                                        info->test_suite_name() + "-" + info->name());
    fs::remove_all(dir_);
    ASSERT_TRUE(fs::create_directories(dir_)) << dir_;
  }

  void TearDown() override {
    std::error_code error;
    fs::remove_all(dir_, error);
    EXPECT_FALSE(error) << "cannot remove " << dir_ << ": " << error.message();
  }

  fs::path path(const std::string& name) const { return dir_ / name; }

  // Names of everything directly in the test directory.
  std::set<std::string> entries() const {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      names.insert(entry.path().filename().string());
    }
    return names;
  }

  fs::path dir_;
};

class IoPng : public IoTest {};
class IoColorize : public IoTest {};
class IoPly : public IoTest {};
class IoAtomic : public IoTest {};
class IoRealData : public IoTest {};

// ---------------------------------------------------------------------------------------------
// An independent PNG codec: zlib (already loaded for libpng) plus the PNG specification.

struct Zlib {
  using Codec = int (*)(unsigned char*, unsigned long*, const unsigned char*, unsigned long);
  using Bound = unsigned long (*)(unsigned long);
  using Crc = unsigned long (*)(unsigned long, const unsigned char*, unsigned int);
  Codec compress = nullptr;
  Codec uncompress = nullptr;
  Bound compress_bound = nullptr;
  Crc crc32 = nullptr;
  bool loaded() const { return compress && uncompress && compress_bound && crc32; }
};

const Zlib& zlib() {
  static const Zlib library = [] {
    Zlib z;
    void* handle = ::dlopen("libz.so.1", RTLD_NOW);
    if (!handle) return z;
    z.compress = reinterpret_cast<Zlib::Codec>(::dlsym(handle, "compress"));
    z.uncompress = reinterpret_cast<Zlib::Codec>(::dlsym(handle, "uncompress"));
    z.compress_bound = reinterpret_cast<Zlib::Bound>(::dlsym(handle, "compressBound"));
    z.crc32 = reinterpret_cast<Zlib::Crc>(::dlsym(handle, "crc32"));
    return z;
  }();
  return library;
}

#define ASSERT_ZLIB() ASSERT_TRUE(zlib().loaded()) << "libz.so.1 is needed to check PNG files"

std::uint32_t load_be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

void append_be32(std::vector<std::uint8_t>& out, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8)
    out.push_back(static_cast<std::uint8_t>(value >> shift));
}

int channels_of(int color_type) {
  switch (color_type) {
    case 0:
      return 1;
    case 2:
      return 3;
    case 4:
      return 2;
    case 6:
      return 4;
    default:
      return 0;
  }
}

constexpr std::array<std::uint8_t, 8> kPngSignature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

struct DecodedPng {
  int width = 0;
  int height = 0;
  int bit_depth = 0;
  int color_type = -1;
  int channels = 0;
  std::vector<std::uint8_t> rows;  // unfiltered samples, big-endian as stored

  unsigned sample(int x, int y, int channel) const {
    const std::size_t bytes = static_cast<std::size_t>(bit_depth / 8);
    const std::size_t stride = static_cast<std::size_t>(width) * channels * bytes;
    const std::uint8_t* p = rows.data() + static_cast<std::size_t>(y) * stride +
                            (static_cast<std::size_t>(x) * channels + channel) * bytes;
    return bytes == 2 ? (unsigned{p[0]} << 8) | p[1] : p[0];
  }
};

int paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a);
  const int pb = std::abs(p - b);
  const int pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return a;
  return pb <= pc ? b : c;
}

// Reads the chunks after the signature, checking each one's CRC: the header into png, the image
// data appended to compressed.
::testing::AssertionResult read_png_chunks(const std::vector<std::uint8_t>& file, DecodedPng& png,
                                           std::vector<std::uint8_t>& compressed) {
  bool saw_header = false;
  bool saw_end = false;
  std::size_t at = 8;
  while (!saw_end) {
    if (file.size() - at < 12) return ::testing::AssertionFailure() << "truncated chunk at " << at;
    const std::uint32_t length = load_be32(&file[at]);
    if (file.size() - at - 12 < length) return ::testing::AssertionFailure() << "chunk too long";
    const std::string type(reinterpret_cast<const char*>(&file[at + 4]), 4);
    const std::uint8_t* data = &file[at + 8];
    const auto crc = static_cast<std::uint32_t>(zlib().crc32(0, &file[at + 4], length + 4));
    if (crc != load_be32(data + length)) {
      return ::testing::AssertionFailure() << "bad CRC in chunk " << type;
    }
    if (type == "IHDR") {
      if (length != 13) return ::testing::AssertionFailure() << "IHDR has length " << length;
      png.width = static_cast<int>(load_be32(data));
      png.height = static_cast<int>(load_be32(data + 4));
      png.bit_depth = data[8];
      png.color_type = data[9];
      png.channels = channels_of(png.color_type);
      if (data[12] != 0) return ::testing::AssertionFailure() << "interlaced";
      if (png.channels == 0 || (png.bit_depth != 8 && png.bit_depth != 16)) {
        return ::testing::AssertionFailure()
               << "unsupported colour type " << png.color_type << " / bit depth " << png.bit_depth;
      }
      saw_header = true;
    } else if (type == "IDAT") {
      compressed.insert(compressed.end(), data, data + length);
    } else if (type == "IEND") {
      saw_end = true;
    }
    at += 12 + length;
  }
  if (!saw_header) return ::testing::AssertionFailure() << "no IHDR";
  return ::testing::AssertionSuccess();
}

// Undoes the rows' filters: raw holds each row's filter byte and filtered bytes.
::testing::AssertionResult unfilter_rows(const std::vector<std::uint8_t>& raw, std::size_t bpp,
                                         DecodedPng& png) {
  const std::size_t stride = static_cast<std::size_t>(png.width) * bpp;
  png.rows.assign(static_cast<std::size_t>(png.height) * stride, 0);
  for (std::size_t y = 0; y < static_cast<std::size_t>(png.height); ++y) {
    const std::uint8_t filter = raw[y * (stride + 1)];
    const std::uint8_t* in = &raw[y * (stride + 1) + 1];
    std::uint8_t* out = &png.rows[y * stride];
    const std::uint8_t* previous = y > 0 ? out - stride : nullptr;
    for (std::size_t i = 0; i < stride; ++i) {
      const int a = i >= bpp ? out[i - bpp] : 0;
      const int b = previous ? previous[i] : 0;
      const int c = previous && i >= bpp ? previous[i - bpp] : 0;
      int predictor = 0;
      switch (filter) {
        case 0:
          break;
        case 1:
          predictor = a;
          break;
        case 2:
          predictor = b;
          break;
        case 3:
          predictor = (a + b) / 2;
          break;
        case 4:
          predictor = paeth(a, b, c);
          break;
        default:
          return ::testing::AssertionFailure() << "row " << y << " has filter " << int{filter};
      }
      out[i] = static_cast<std::uint8_t>(in[i] + predictor);
    }
  }
  return ::testing::AssertionSuccess();
}

// Decodes a non-interlaced 8- or 16-bit PNG, checking every chunk's CRC.
::testing::AssertionResult decode_png(const std::vector<std::uint8_t>& file, DecodedPng& png) {
  if (!zlib().loaded()) return ::testing::AssertionFailure() << "libz.so.1 not found";
  if (file.size() < 8 || !std::equal(kPngSignature.begin(), kPngSignature.end(), file.begin())) {
    return ::testing::AssertionFailure() << "no PNG signature";
  }
  std::vector<std::uint8_t> compressed;
  if (::testing::AssertionResult read = read_png_chunks(file, png, compressed); !read) return read;
  const std::size_t bpp = static_cast<std::size_t>(png.channels * png.bit_depth / 8);
  const std::size_t stride = static_cast<std::size_t>(png.width) * bpp;
  std::vector<std::uint8_t> raw(static_cast<std::size_t>(png.height) * (stride + 1));
  unsigned long raw_size = raw.size();
  if (zlib().uncompress(raw.data(), &raw_size, compressed.data(), compressed.size()) != 0 ||
      raw_size != raw.size()) {
    return ::testing::AssertionFailure() << "IDAT does not inflate to " << raw.size() << " bytes";
  }
  return unfilter_rows(raw, bpp, png);
}

void append_chunk(std::vector<std::uint8_t>& png, const char* type,
                  const std::vector<std::uint8_t>& data) {
  append_be32(png, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  append_be32(png, static_cast<std::uint32_t>(
                       zlib().crc32(0, &png[start], static_cast<unsigned>(png.size() - start))));
}

// A PNG of the given samples (big-endian for 16 bits), every row with filter 0.
std::vector<std::uint8_t> encode_png(int width, int height, int bit_depth, int color_type,
                                     const std::vector<std::uint8_t>& samples) {
  const std::size_t stride =
      static_cast<std::size_t>(width) * channels_of(color_type) * (bit_depth / 8);
  EXPECT_EQ(samples.size(), stride * height);
  std::vector<std::uint8_t> raw;
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    raw.insert(raw.end(), samples.begin() + y * stride, samples.begin() + (y + 1) * stride);
  }
  std::vector<std::uint8_t> compressed(zlib().compress_bound(raw.size()));
  unsigned long compressed_size = compressed.size();
  EXPECT_EQ(zlib().compress(compressed.data(), &compressed_size, raw.data(), raw.size()), 0);
  compressed.resize(compressed_size);

  std::vector<std::uint8_t> png(kPngSignature.begin(), kPngSignature.end());
  std::vector<std::uint8_t> header;
  append_be32(header, static_cast<std::uint32_t>(width));
  append_be32(header, static_cast<std::uint32_t>(height));
  header.insert(header.end(), {static_cast<std::uint8_t>(bit_depth),
                               static_cast<std::uint8_t>(color_type), 0, 0, 0});
  append_chunk(png, "IHDR", header);
  append_chunk(png, "IDAT", compressed);
  append_chunk(png, "IEND", {});
  return png;
}

// ---------------------------------------------------------------------------------------------
// Test images

DepthImage random_depth(int width, int height, std::mt19937_64& rng) {
  std::uniform_int_distribution<int> value(0, 65535);
  DepthImage depth(width, height);
  for (auto& d : depth.pixels()) d = static_cast<std::uint16_t>(value(rng));
  // The extremes, where a sign or byte-order mistake shows.
  depth(0, 0) = 0;
  depth(width - 1, 0) = 1;
  depth(0, height - 1) = 65535;
  depth(width - 1, height - 1) = 0x0102;
  return depth;
}

RgbImage random_rgb(int width, int height, std::mt19937_64& rng) {
  std::uniform_int_distribution<int> value(0, 255);
  RgbImage rgb(width, height);
  for (auto& p : rgb.pixels()) {
    p = {static_cast<std::uint8_t>(value(rng)), static_cast<std::uint8_t>(value(rng)),
         static_cast<std::uint8_t>(value(rng))};
  }
  rgb(0, 0) = {255, 0, 0};  // pure red: swapped channels would read as blue
  rgb(1, 0) = {0, 0, 255};
  return rgb;
}

GrayImage random_gray(int width, int height, std::mt19937_64& rng) {
  std::uniform_int_distribution<int> value(0, 255);
  GrayImage gray(width, height);
  for (auto& p : gray.pixels()) p = static_cast<std::uint8_t>(value(rng));
  gray(0, 0) = 0;
  gray(1, 0) = 255;
  return gray;
}

template <class Pixel>
std::size_t count_differences(const Image<Pixel>& a, const Image<Pixel>& b) {
  if (a.width() != b.width() || a.height() != b.height()) return std::max(a.size(), b.size()) + 1;
  std::size_t differences = 0;
  for (std::size_t i = 0; i < a.size(); ++i) differences += a.pixels()[i] == b.pixels()[i] ? 0 : 1;
  return differences;
}

// ---------------------------------------------------------------------------------------------
// PNG

TEST_F(IoPng, DepthRoundTripKeepsEveryValueAsBigEndian16BitGray) {
  std::mt19937_64 rng(1);
  const DepthImage depth = random_depth(61, 37, rng);
  io::write_png(path("depth.png"), depth);

  const DepthImage back = io::read_depth_png(path("depth.png"));
  ASSERT_EQ(back.width(), 61);
  ASSERT_EQ(back.height(), 37);
  EXPECT_EQ(count_differences(depth, back), 0u);

  DecodedPng png;
  ASSERT_TRUE(decode_png(read_bytes(path("depth.png")), png));
  EXPECT_EQ(png.width, 61);
  EXPECT_EQ(png.height, 37);
  EXPECT_EQ(png.bit_depth, 16);
  EXPECT_EQ(png.color_type, 0);
  std::size_t mismatches = 0;
  for (int y = 0; y < 37; ++y) {
    for (int x = 0; x < 61; ++x) mismatches += png.sample(x, y, 0) == depth(x, y) ? 0 : 1;
  }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(entries(), std::set<std::string>{"depth.png"});
}

TEST_F(IoPng, DepthReaderReadsAnIndependentlyEncodedPng) {
  ASSERT_ZLIB();
  std::mt19937_64 rng(2);
  const DepthImage depth = random_depth(9, 5, rng);
  std::vector<std::uint8_t> samples;
  for (std::uint16_t d : depth.pixels()) {
    samples.push_back(static_cast<std::uint8_t>(d >> 8));
    samples.push_back(static_cast<std::uint8_t>(d & 0xff));
  }
  write_file(path("depth.png"), encode_png(9, 5, 16, 0, samples));
  const DepthImage back = io::read_depth_png(path("depth.png"));
  EXPECT_EQ(back(8, 4), 0x0102);
  EXPECT_EQ(count_differences(depth, back), 0u);
}

TEST_F(IoPng, RgbRoundTripKeepsChannelOrder) {
  std::mt19937_64 rng(3);
  const RgbImage rgb = random_rgb(23, 17, rng);
  io::write_png(path("rgb.png"), rgb);

  const RgbImage back = io::read_color_image(path("rgb.png"));
  ASSERT_EQ(back.width(), 23);
  ASSERT_EQ(back.height(), 17);
  EXPECT_EQ(back(0, 0), (Rgb8{255, 0, 0}));
  EXPECT_EQ(back(1, 0), (Rgb8{0, 0, 255}));
  EXPECT_EQ(count_differences(rgb, back), 0u);

  // In the file, PNG's order is R, G, B whatever OpenCV's in-memory order is.
  DecodedPng png;
  ASSERT_TRUE(decode_png(read_bytes(path("rgb.png")), png));
  EXPECT_EQ(png.bit_depth, 8);
  EXPECT_EQ(png.color_type, 2);
  ASSERT_EQ(png.width, 23);
  ASSERT_EQ(png.height, 17);
  std::size_t mismatches = 0;
  for (int y = 0; y < 17; ++y) {
    for (int x = 0; x < 23; ++x) {
      for (int c = 0; c < 3; ++c) mismatches += png.sample(x, y, c) == rgb(x, y)[c] ? 0 : 1;
    }
  }
  EXPECT_EQ(mismatches, 0u);
}

TEST_F(IoPng, GrayIsWrittenAs8BitGrayscale) {
  std::mt19937_64 rng(4);
  const GrayImage gray = random_gray(31, 11, rng);
  io::write_png(path("gray.png"), gray);

  DecodedPng png;
  ASSERT_TRUE(decode_png(read_bytes(path("gray.png")), png));
  EXPECT_EQ(png.bit_depth, 8);
  EXPECT_EQ(png.color_type, 0);
  ASSERT_EQ(png.width, 31);
  ASSERT_EQ(png.height, 11);
  std::size_t mismatches = 0;
  for (int y = 0; y < 11; ++y) {
    for (int x = 0; x < 31; ++x) mismatches += png.sample(x, y, 0) == gray(x, y) ? 0 : 1;
  }
  EXPECT_EQ(mismatches, 0u);

  // Neither reader takes it: not depth (8-bit), not colour (one channel).
  EXPECT_ERROR_MENTIONS(io::read_depth_png(path("gray.png")), quoted(path("gray.png")), "is 8-bit",
                        "expected 16-bit");
  EXPECT_ERROR_MENTIONS(io::read_color_image(path("gray.png")), quoted(path("gray.png")),
                        "has 1 channel(s), expected 3 (RGB) or 4 (RGBA)");
}

TEST_F(IoPng, ColorReaderDropsAlpha) {
  ASSERT_ZLIB();
  const std::vector<std::uint8_t> rgba = {10, 20, 30, 255, 40, 50, 60, 0,
                                          70, 80, 90, 128, 1,  2,  3,  4};
  write_file(path("rgba.png"), encode_png(2, 2, 8, 6, rgba));
  const RgbImage rgb = io::read_color_image(path("rgba.png"));
  ASSERT_EQ(rgb.width(), 2);
  ASSERT_EQ(rgb.height(), 2);
  EXPECT_EQ(rgb(0, 0), (Rgb8{10, 20, 30}));
  EXPECT_EQ(rgb(1, 0), (Rgb8{40, 50, 60}));  // transparent, but the colour is what is stored
  EXPECT_EQ(rgb(0, 1), (Rgb8{70, 80, 90}));
  EXPECT_EQ(rgb(1, 1), (Rgb8{1, 2, 3}));
}

TEST_F(IoPng, DepthReaderRejectsEverythingButOneChannel16Bit) {
  ASSERT_ZLIB();
  std::mt19937_64 rng(5);
  io::write_png(path("rgb.png"), random_rgb(4, 4, rng));
  EXPECT_ERROR_MENTIONS(io::read_depth_png(path("rgb.png")), "depth image", quoted(path("rgb.png")),
                        "is 8-bit", "not depth");

  // 16-bit, but three channels.
  write_file(path("rgb16.png"), encode_png(2, 1, 16, 2, std::vector<std::uint8_t>(12, 7)));
  EXPECT_ERROR_MENTIONS(io::read_depth_png(path("rgb16.png")), quoted(path("rgb16.png")),
                        "has 3 channels, expected 1");
}

TEST_F(IoPng, ColorReaderRejects16Bit) {
  std::mt19937_64 rng(6);
  io::write_png(path("depth.png"), random_depth(4, 3, rng));
  EXPECT_ERROR_MENTIONS(io::read_color_image(path("depth.png")), "colour image",
                        quoted(path("depth.png")), "is 16-bit 1-channel, expected 8-bit");
}

TEST_F(IoPng, ReadersNameTheFileAndTheProblem) {
  for (const auto& read : std::vector<std::function<void(const fs::path&)>>{
           [](const fs::path& p) { io::read_depth_png(p); },
           [](const fs::path& p) { io::read_color_image(p); }}) {
    EXPECT_ERROR_MENTIONS(read(path("missing.png")), quoted(path("missing.png")), "no such file");
    EXPECT_ERROR_MENTIONS(read(dir_), quoted(dir_), "is a directory, not a file");

    write_file(path("empty.png"), "");
    EXPECT_ERROR_MENTIONS(read(path("empty.png")), quoted(path("empty.png")), "file is empty");

    write_file(path("text.png"), "this is not a PNG file, only text with a .png name\n");
    EXPECT_ERROR_MENTIONS(read(path("text.png")), quoted(path("text.png")), "cannot decode");
  }
}

// Cut short: refused before decoding (OpenCV would decode part of it with a warning only).
TEST_F(IoPng, TruncatedFileIsUndecodable) {
  std::mt19937_64 rng(7);
  io::write_png(path("depth.png"), random_depth(64, 64, rng));
  const std::vector<std::uint8_t> full = read_bytes(path("depth.png"));
  ASSERT_GT(full.size(), 1000u);
  write_file(path("half.png"), std::vector<std::uint8_t>(full.begin(), full.begin() + 100));
  EXPECT_ERROR_MENTIONS(io::read_depth_png(path("half.png")), quoted(path("half.png")),
                        "truncated PNG");
  write_file(path("header-only.png"), std::vector<std::uint8_t>(full.begin(), full.begin() + 8));
  EXPECT_ERROR_MENTIONS(io::read_depth_png(path("header-only.png")),
                        quoted(path("header-only.png")), "truncated PNG");
}

TEST_F(IoPng, EmptyImagesAreNotWritten) {
  EXPECT_ERROR_MENTIONS(io::write_png(path("d.png"), DepthImage()), quoted(path("d.png")),
                        "the image is empty (0x0)");
  EXPECT_ERROR_MENTIONS(io::write_png(path("g.png"), GrayImage(0, 5)), "the image is empty (0x5)");
  EXPECT_ERROR_MENTIONS(io::write_png(path("c.png"), RgbImage(7, 0)), "the image is empty (7x0)");
  EXPECT_TRUE(entries().empty());
}

TEST_F(IoPng, SinglePixelImagesRoundTrip) {
  io::write_png(path("d.png"), DepthImage(1, 1, 4321));
  io::write_png(path("c.png"), RgbImage(1, 1, Rgb8{9, 8, 7}));
  EXPECT_EQ(io::read_depth_png(path("d.png"))(0, 0), 4321);
  EXPECT_EQ(io::read_color_image(path("c.png"))(0, 0), (Rgb8{9, 8, 7}));
}

// ---------------------------------------------------------------------------------------------
// Colorize helpers

constexpr Rgb8 kViridisLow{68, 1, 84};      // dark purple
constexpr Rgb8 kViridisHigh{253, 231, 37};  // yellow

::testing::AssertionResult near_color(const Rgb8& actual, const Rgb8& expected, int tolerance) {
  for (int c = 0; c < 3; ++c) {
    if (std::abs(int{actual[c]} - int{expected[c]}) > tolerance) {
      return ::testing::AssertionFailure()
             << "(" << int{actual[0]} << ", " << int{actual[1]} << ", " << int{actual[2]}
             << ") is not within " << tolerance << " of (" << int{expected[0]} << ", "
             << int{expected[1]} << ", " << int{expected[2]} << ")";
    }
  }
  return ::testing::AssertionSuccess();
}

TEST_F(IoColorize, DepthRunsFromPurpleToYellowAndIsBlackWithoutDepth) {
  // Millimetres, 0 to 4 m: x = 0 has no depth, x = 1 is 1 mm, x = 2 is 4 m, x = 3 beyond.
  DepthImage depth(5, 2, 0);
  depth(1, 0) = 1;
  depth(2, 0) = 4000;
  depth(3, 0) = 65000;
  depth(4, 0) = 2000;
  const RgbImage colored = io::colorize_depth(depth, 1000.0, 4.0);
  ASSERT_EQ(colored.width(), 5);
  ASSERT_EQ(colored.height(), 2);
  EXPECT_EQ(colored(0, 0), (Rgb8{0, 0, 0}));
  EXPECT_EQ(colored(0, 1), (Rgb8{0, 0, 0}));
  EXPECT_TRUE(near_color(colored(1, 0), kViridisLow, 3));
  EXPECT_TRUE(near_color(colored(2, 0), kViridisHigh, 3));
  EXPECT_EQ(colored(3, 0), colored(2, 0)) << "beyond max_metres stays at the top of the map";
  // Half way is viridis' teal: green well above red, blue between.
  const Rgb8 middle = colored(4, 0);
  EXPECT_TRUE(near_color(middle, Rgb8{33, 145, 140}, 12));
}

TEST_F(IoColorize, DepthScaleFollowsUnitsAndRange) {
  DepthImage depth(256, 1);
  for (int x = 0; x < 256; ++x) depth(x, 0) = static_cast<std::uint16_t>(1 + x * 40);
  const RgbImage colored = io::colorize_depth(depth, 1000.0, 10.2);
  // Viridis' green rises monotonically from purple to yellow; the ramp must follow it.
  for (int x = 1; x < 256; ++x) {
    EXPECT_GE(colored(x, 0)[1], colored(x - 1, 0)[1]) << "at x = " << x;
  }
  EXPECT_GT(colored(255, 0)[1], colored(0, 0)[1] + 200);

  // 2 m in millimetres and 2 m in half-millimetres look the same; 2000 half-millimetres do not.
  const RgbImage mm = io::colorize_depth(DepthImage(1, 1, 2000), 1000.0, 5.0);
  const RgbImage half_mm = io::colorize_depth(DepthImage(1, 1, 4000), 2000.0, 5.0);
  const RgbImage one_metre = io::colorize_depth(DepthImage(1, 1, 2000), 2000.0, 5.0);
  EXPECT_EQ(mm(0, 0), half_mm(0, 0));
  EXPECT_NE(mm(0, 0), one_metre(0, 0));
  // A shorter range moves the same depth up the map.
  const RgbImage short_range = io::colorize_depth(DepthImage(1, 1, 2000), 1000.0, 2.0);
  EXPECT_TRUE(near_color(short_range(0, 0), kViridisHigh, 3));
}

TEST_F(IoColorize, DepthRejectsBadParameters) {
  const DepthImage depth(2, 2, 1000);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (double units : {0.0, -1000.0, nan, inf}) {
    EXPECT_ERROR_MENTIONS(io::colorize_depth(depth, units, 4.0),
                          "units_per_metre must be positive");
  }
  for (double max_metres : {0.0, -4.0, nan, inf}) {
    EXPECT_ERROR_MENTIONS(io::colorize_depth(depth, 1000.0, max_metres),
                          "max_metres must be positive");
  }
}

TEST_F(IoColorize, NormalsMapAxesToChannels) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  NormalImage normals(3, 2, invalid_point());
  normals(0, 0) = Point4f(0, 0, -1, 0);
  normals(1, 0) = Point4f(1, 0, 0, 0);
  normals(2, 0) = Point4f(0, -1, 1, 0);
  normals(0, 1) = Point4f(0.6f, 0.8f, nan, 0);  // one NaN component: no normal
  normals(1, 1) = Point4f(2, -3, 0, 0);         // out of range: clamped
  const RgbImage colored = io::colorize_normals(normals);
  ASSERT_EQ(colored.width(), 3);
  ASSERT_EQ(colored.height(), 2);
  EXPECT_EQ(colored(0, 0), (Rgb8{128, 128, 0}));
  EXPECT_EQ(colored(1, 0), (Rgb8{255, 128, 128}));
  EXPECT_EQ(colored(2, 0), (Rgb8{128, 0, 255}));
  EXPECT_EQ(colored(0, 1), (Rgb8{0, 0, 0}));
  EXPECT_EQ(colored(1, 1), (Rgb8{255, 0, 128}));
  EXPECT_EQ(colored(2, 1), (Rgb8{0, 0, 0}));  // all NaN
}

TEST_F(IoColorize, PicturesCanBeWrittenAndReadBack) {
  std::mt19937_64 rng(8);
  const RgbImage colored = io::colorize_depth(random_depth(40, 30, rng), 1000.0, 8.0);
  io::write_png(path("depth_color.png"), colored);
  EXPECT_EQ(count_differences(io::read_color_image(path("depth_color.png")), colored), 0u);
}

// ---------------------------------------------------------------------------------------------
// PLY: writing and reading back

std::string expected_header(std::size_t count, bool normals, bool colors) {
  std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment written by kartograf\nelement vertex " +
      std::to_string(count) + "\nproperty float x\nproperty float y\nproperty float z\n";
  if (normals) header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (colors) header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  return header + "end_header\n";
}

float load_le_float(const std::vector<std::uint8_t>& bytes, std::size_t offset) {
  std::uint32_t bits = 0;
  for (int i = 0; i < 4; ++i) bits |= std::uint32_t{bytes.at(offset + i)} << (8 * i);
  return std::bit_cast<float>(bits);
}

struct OrganizedCloud {
  PointImage points;
  NormalImage normals;
  RgbImage colors;
  std::vector<int> valid;  // row-major pixel indices with a point
};

OrganizedCloud organized_cloud() {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  OrganizedCloud cloud{PointImage(5, 4, invalid_point()),
                       NormalImage(5, 4, invalid_point()),
                       RgbImage(5, 4, Rgb8{0, 0, 0}),
                       {}};
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 5; ++x) {
      const int i = y * 5 + x;
      cloud.colors(x, y) = {static_cast<std::uint8_t>(10 * i), static_cast<std::uint8_t>(255 - i),
                            static_cast<std::uint8_t>(i * 7)};
      if ((x + y) % 3 == 1) continue;  // no point here
      cloud.points(x, y) = Point4f(0.25f * x - 0.5f, -1.5f + y, 1.0f + 0.001f * i, 1);
      cloud.normals(x, y) = Point4f(0, 0.6f, -0.8f, 0);
      cloud.valid.push_back(i);
    }
  }
  // A point whose normal could not be estimated.
  cloud.normals(0, 0) = invalid_point();
  // A point with only x NaN counts as no point.
  cloud.points(3, 3) = Point4f(nan, 1, 2, 1);
  const auto nan_x = std::find(cloud.valid.begin(), cloud.valid.end(), 3 * 5 + 3);
  EXPECT_NE(nan_x, cloud.valid.end());
  if (nan_x != cloud.valid.end()) cloud.valid.erase(nan_x);
  return cloud;
}

TEST_F(IoPly, ImageCloudRoundTripsAsBinaryLittleEndian) {
  const OrganizedCloud cloud = organized_cloud();
  ASSERT_EQ(cloud.valid.size(), 12u);
  io::write_ply(path("cloud.ply"), cloud.points, &cloud.normals, &cloud.colors);

  // The exact layout: header, then per vertex 3 + 3 little-endian floats and 3 bytes.
  const std::vector<std::uint8_t> bytes = read_bytes(path("cloud.ply"));
  const std::string header = expected_header(12, true, true);
  ASSERT_GE(bytes.size(), header.size());
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + header.size()), header);
  EXPECT_EQ(bytes.size(), header.size() + 12 * 27);
  const Point4f& first = cloud.points.pixels()[cloud.valid[0]];
  EXPECT_EQ(load_le_float(bytes, header.size()), first.x());
  EXPECT_EQ(load_le_float(bytes, header.size() + 4), first.y());
  EXPECT_EQ(load_le_float(bytes, header.size() + 8), first.z());
  EXPECT_EQ(load_le_float(bytes, header.size() + 27 + 16),
            cloud.normals.pixels()[cloud.valid[1]].y());

  const PointCloud back = io::read_ply(path("cloud.ply"));
  ASSERT_EQ(back.size(), 12u);
  ASSERT_TRUE(back.has_normals());
  ASSERT_TRUE(back.has_colors());
  for (std::size_t k = 0; k < back.size(); ++k) {
    SCOPED_TRACE("vertex " + std::to_string(k));
    const int i = cloud.valid[k];
    EXPECT_EQ(back.points[k], Eigen::Vector3f(cloud.points.pixels()[i].head<3>()));
    const Eigen::Vector3f normal = cloud.normals.pixels()[i].head<3>();
    EXPECT_EQ(back.normals[k], normal.allFinite() ? normal : Eigen::Vector3f::Zero());
    EXPECT_EQ(back.colors[k], cloud.colors.pixels()[i]);
  }
  EXPECT_EQ(back.normals[0], Eigen::Vector3f::Zero());  // the NaN normal at (0, 0)
  EXPECT_EQ(entries(), std::set<std::string>{"cloud.ply"});
}

TEST_F(IoPly, ImageCloudWithoutNormalsOrColors) {
  const OrganizedCloud cloud = organized_cloud();
  io::write_ply(path("points.ply"), cloud.points);
  const std::vector<std::uint8_t> bytes = read_bytes(path("points.ply"));
  const std::string header = expected_header(12, false, false);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + std::min(bytes.size(), header.size())),
            header);
  EXPECT_EQ(bytes.size(), header.size() + 12 * 12);
  const PointCloud back = io::read_ply(path("points.ply"));
  ASSERT_EQ(back.size(), 12u);
  EXPECT_FALSE(back.has_normals());
  EXPECT_FALSE(back.has_colors());
  EXPECT_EQ(back.points[11], Eigen::Vector3f(cloud.points.pixels()[cloud.valid[11]].head<3>()));

  // Colours only.
  io::write_ply(path("colored.ply"), cloud.points, nullptr, &cloud.colors);
  const PointCloud colored = io::read_ply(path("colored.ply"));
  EXPECT_FALSE(colored.has_normals());
  ASSERT_TRUE(colored.has_colors());
  EXPECT_EQ(colored.colors[3], cloud.colors.pixels()[cloud.valid[3]]);
}

TEST_F(IoPly, PointCloudRoundTripSkipsNonFinitePoints) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  PointCloud cloud;
  cloud.points = {{1, 2, 3}, {nan, 0, 0}, {-0.0f, 1e-30f, 3.4e38f}, {0, inf, 0}, {-7, -8, -9}};
  cloud.normals = {{0, 0, 1}, {0, 0, 1}, {nan, 0, 0}, {1, 0, 0}, {0, -1, 0}};
  cloud.colors = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}, {10, 11, 12}, {255, 254, 253}};
  io::write_ply(path("cloud.ply"), cloud);

  const PointCloud back = io::read_ply(path("cloud.ply"));
  ASSERT_EQ(back.size(), 3u);
  ASSERT_TRUE(back.has_normals());
  ASSERT_TRUE(back.has_colors());
  EXPECT_EQ(back.points[0], Eigen::Vector3f(1, 2, 3));
  EXPECT_EQ(back.points[1], Eigen::Vector3f(-0.0f, 1e-30f, 3.4e38f));
  EXPECT_TRUE(std::signbit(back.points[1].x()));
  EXPECT_EQ(back.points[2], Eigen::Vector3f(-7, -8, -9));
  EXPECT_EQ(back.normals[0], Eigen::Vector3f(0, 0, 1));
  EXPECT_EQ(back.normals[1], Eigen::Vector3f::Zero());
  EXPECT_EQ(back.normals[2], Eigen::Vector3f(0, -1, 0));
  EXPECT_EQ(back.colors[0], (Rgb8{1, 2, 3}));
  EXPECT_EQ(back.colors[1], (Rgb8{7, 8, 9}));
  EXPECT_EQ(back.colors[2], (Rgb8{255, 254, 253}));

  // Written again from what was read, the file is byte for byte the same.
  io::write_ply(path("again.ply"), back);
  EXPECT_EQ(read_bytes(path("again.ply")), read_bytes(path("cloud.ply")));
}

TEST_F(IoPly, LargeCloudRoundTripsExactly) {
  // Larger than the writer's 1 MiB block, so that it streams in several writes.
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<float> coordinate(-100, 100);
  PointCloud cloud;
  for (int i = 0; i < 150000; ++i) {
    cloud.points.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
    cloud.colors.push_back({static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i >> 8),
                            static_cast<std::uint8_t>(i >> 16)});
  }
  io::write_ply(path("large.ply"), cloud);
  EXPECT_EQ(fs::file_size(path("large.ply")),
            expected_header(150000, false, true).size() + 150000u * 15);
  const PointCloud back = io::read_ply(path("large.ply"));
  ASSERT_EQ(back.size(), cloud.size());
  EXPECT_FALSE(back.has_normals());
  EXPECT_TRUE(back.points == cloud.points);
  EXPECT_TRUE(back.colors == cloud.colors);
}

TEST_F(IoPly, EmptyCloudRoundTrips) {
  io::write_ply(path("empty.ply"), PointCloud{});
  EXPECT_EQ(read_text(path("empty.ply")), expected_header(0, false, false));
  EXPECT_TRUE(io::read_ply(path("empty.ply")).empty());

  // An image with no valid pixel gives the same.
  io::write_ply(path("none.ply"), PointImage(3, 3, invalid_point()));
  EXPECT_EQ(read_text(path("none.ply")), expected_header(0, false, false));
}

TEST_F(IoPly, AsciiWriterWritesShortestExactFloats) {
  PointCloud cloud;
  cloud.points = {{1, 2, 3}, {-0.0f, 1e-30f, 3.4e38f}};
  cloud.normals = {{0, 0, 1}, {0.1f, -1, 0}};
  cloud.colors = {{1, 2, 3}, {255, 254, 253}};
  io::write_ply(path("cloud.ply"), cloud, io::PlyEncoding::ascii);
  std::string expected = expected_header(2, true, true);
  expected.replace(expected.find("binary_little_endian"), 20, "ascii");
  EXPECT_EQ(read_text(path("cloud.ply")), expected +
                                              "1 2 3 0 0 1 1 2 3\n"
                                              "-0 1e-30 3.4e+38 0.1 -1 0 255 254 253\n");
  const PointCloud back = io::read_ply(path("cloud.ply"));
  EXPECT_TRUE(back.points == cloud.points);
  EXPECT_TRUE(std::signbit(back.points[1].x()));
  EXPECT_TRUE(back.normals == cloud.normals);
  EXPECT_TRUE(back.colors == cloud.colors);
}

TEST_F(IoPly, AsciiAndBinaryWritersAgreeOnRandomClouds) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> coordinate(-1e4f, 1e4f);
  std::uniform_real_distribution<float> small(-1e-6f, 1e-6f);
  PointCloud cloud;
  for (int i = 0; i < 5000; ++i) {
    cloud.points.emplace_back(coordinate(rng), small(rng), coordinate(rng) * small(rng));
    cloud.normals.emplace_back(small(rng), 1.0f / float(i + 1), -coordinate(rng));
    cloud.colors.push_back({static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i >> 4),
                            static_cast<std::uint8_t>(i >> 8)});
  }
  io::write_ply(path("ascii.ply"), cloud, io::PlyEncoding::ascii);
  const PointCloud back = io::read_ply(path("ascii.ply"));
  EXPECT_TRUE(back.points == cloud.points);
  EXPECT_TRUE(back.normals == cloud.normals);
  EXPECT_TRUE(back.colors == cloud.colors);

  // The organized writer too: the same vertices as its binary form.
  const OrganizedCloud organized = organized_cloud();
  io::write_ply(path("image_ascii.ply"), organized.points, &organized.normals, &organized.colors,
                io::PlyEncoding::ascii);
  io::write_ply(path("image_binary.ply"), organized.points, &organized.normals, &organized.colors);
  const PointCloud from_ascii = io::read_ply(path("image_ascii.ply"));
  const PointCloud from_binary = io::read_ply(path("image_binary.ply"));
  ASSERT_EQ(from_ascii.size(), organized.valid.size());
  EXPECT_TRUE(from_ascii.points == from_binary.points);
  EXPECT_TRUE(from_ascii.normals == from_binary.normals);
  EXPECT_TRUE(from_ascii.colors == from_binary.colors);
}

TEST_F(IoPly, ParsesBytesInMemoryNamingThemInMessages) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1 2 3\n4 5 6\n";
  const std::vector<std::uint8_t> bytes(text.begin(), text.end());
  const PointCloud cloud = io::parse_ply(bytes, "memory.ply");
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.points[1], Eigen::Vector3f(4, 5, 6));
  const std::vector<std::uint8_t> cut(bytes.begin(), bytes.end() - 6);
  EXPECT_ERROR_MENTIONS(io::parse_ply(cut, "memory.ply"), "PLY file 'memory.ply'", "truncated");
  EXPECT_ERROR_MENTIONS(io::parse_ply({}, "nothing"), "PLY file 'nothing'", "not a PLY file");
}

TEST_F(IoPly, WriterRejectsMismatchedSizes) {
  const OrganizedCloud cloud = organized_cloud();
  const NormalImage small_normals(5, 3, invalid_point());
  const RgbImage wide_colors(6, 4, Rgb8{0, 0, 0});
  EXPECT_ERROR_MENTIONS(io::write_ply(path("a.ply"), cloud.points, &small_normals),
                        quoted(path("a.ply")), "the normals are 5x3 but the points are 5x4");
  EXPECT_ERROR_MENTIONS(io::write_ply(path("b.ply"), cloud.points, nullptr, &wide_colors),
                        quoted(path("b.ply")), "the colours are 6x4 but the points are 5x4");

  PointCloud bad;
  bad.points = {{1, 2, 3}, {4, 5, 6}};
  bad.normals = {{0, 0, 1}};
  EXPECT_ERROR_MENTIONS(io::write_ply(path("c.ply"), bad), quoted(path("c.ply")),
                        "1 normals for 2 points");
  bad.normals.clear();
  bad.colors = {{1, 1, 1}, {2, 2, 2}, {3, 3, 3}};
  EXPECT_ERROR_MENTIONS(io::write_ply(path("d.ply"), bad), "3 colours for 2 points");
  EXPECT_TRUE(entries().empty());
}

// ---------------------------------------------------------------------------------------------
// PLY: files written by other programs

// Bytes of a binary PLY body in either byte order.
class Body {
 public:
  explicit Body(bool big_endian) : big_endian_(big_endian) {}
  template <class T>
  Body& put(T value) {
    std::array<char, sizeof(T)> raw;
    std::memcpy(raw.data(), &value, sizeof(T));
    if (big_endian_ != (std::endian::native == std::endian::big)) {
      std::reverse(raw.begin(), raw.end());
    }
    bytes_.append(raw.data(), raw.size());
    return *this;
  }
  const std::string& bytes() const { return bytes_; }

 private:
  bool big_endian_;
  std::string bytes_;
};

TEST_F(IoPly, AsciiWithCrlfCommentsExtraPropertiesAndFacesAfterVertices) {
  write_file(path("hand.ply"),
             "ply\r\n"
             "format ascii 1.0\r\n"
             "comment made by hand\r\n"
             "obj_info scanner none\r\n"
             "element vertex 3\r\n"
             "property double x\r\n"
             "property float intensity\r\n"
             "property double y\r\n"
             "property double z\r\n"
             "property float nx\r\n"
             "property float ny\r\n"
             "property float nz\r\n"
             "property uchar red\r\n"
             "property uchar green\r\n"
             "property uchar blue\r\n"
             "property uchar alpha\r\n"
             "property list uchar int neighbours\r\n"
             "element face 2\r\n"
             "property list uchar int vertex_indices\r\n"
             "end_header\r\n"
             "1.5 0.25 -2 3e2 0 0 1 255 128 0 255 2 1 2\r\n"
             "\r\n"
             "-1e-3 9 .5 7 0 1 0 1 2 3 4 0\r\n"
             "  4\t5 6 7 1 0 0 10 20 30 40 3 0 1 2  \r\n"
             "3 0 1 2\r\n"
             "3 0 2 1\r\n");
  const PointCloud cloud = io::read_ply(path("hand.ply"));
  ASSERT_EQ(cloud.size(), 3u);
  ASSERT_TRUE(cloud.has_normals());
  ASSERT_TRUE(cloud.has_colors());
  EXPECT_EQ(cloud.points[0], Eigen::Vector3f(1.5f, -2.0f, 300.0f));
  EXPECT_EQ(cloud.points[1], Eigen::Vector3f(-0.001f, 0.5f, 7.0f));
  EXPECT_EQ(cloud.points[2], Eigen::Vector3f(4.0f, 6.0f, 7.0f));
  EXPECT_EQ(cloud.normals[0], Eigen::Vector3f(0, 0, 1));
  EXPECT_EQ(cloud.normals[1], Eigen::Vector3f(0, 1, 0));
  EXPECT_EQ(cloud.normals[2], Eigen::Vector3f(1, 0, 0));
  EXPECT_EQ(cloud.colors[0], (Rgb8{255, 128, 0}));
  EXPECT_EQ(cloud.colors[1], (Rgb8{1, 2, 3}));
  EXPECT_EQ(cloud.colors[2], (Rgb8{10, 20, 30}));
}

TEST_F(IoPly, AsciiWithFacesBeforeVertices) {
  write_file(path("faces-first.ply"),
             "ply\n"
             "format ascii 1.0\n"
             "element face 2\n"
             "property list uchar int vertex_indices\n"
             "property uchar flags\n"
             "element edge 1\n"
             "property int vertex1\n"
             "property int vertex2\n"
             "element vertex 2\n"
             "property float x\n"
             "property float y\n"
             "property float z\n"
             "end_header\n"
             "3 0 1 2 7\n"
             "4 0 1 2 3 8\n"
             "0 1\n"
             "-1 -2 -3\n"
             "0.5 0.25 0.125\n");
  const PointCloud cloud = io::read_ply(path("faces-first.ply"));
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_FALSE(cloud.has_normals());
  EXPECT_FALSE(cloud.has_colors());
  EXPECT_EQ(cloud.points[0], Eigen::Vector3f(-1, -2, -3));
  EXPECT_EQ(cloud.points[1], Eigen::Vector3f(0.5f, 0.25f, 0.125f));
}

TEST_F(IoPly, BinaryLittleEndianWithFacesBeforeVerticesAndOtherTypeNames) {
  std::string file =
      "ply\n"
      "format binary_little_endian 1.0\n"
      "element face 2\n"
      "property list uchar int vertex_indices\n"
      "property uchar flags\n"
      "element vertex 2\n"
      "property float32 x\n"
      "property ushort confidence\n"
      "property float32 y\n"
      "property float64 z\n"
      "property uint8 red\n"
      "property uint8 green\n"
      "property uint8 blue\n"
      "end_header\n";
  Body body(false);
  body.put<std::uint8_t>(3).put<std::int32_t>(0).put<std::int32_t>(1).put<std::int32_t>(2);
  body.put<std::uint8_t>(0xaa);
  body.put<std::uint8_t>(0).put<std::uint8_t>(0xbb);  // a face with no indices
  body.put(7.0f)
      .put<std::uint16_t>(999)
      .put(8.0f)
      .put(9.0)
      .put<std::uint8_t>(1)
      .put<std::uint8_t>(2)
      .put<std::uint8_t>(3);
  body.put(-0.5f)
      .put<std::uint16_t>(0)
      .put(1e6f)
      .put(-2.25)
      .put<std::uint8_t>(250)
      .put<std::uint8_t>(251)
      .put<std::uint8_t>(252);
  write_file(path("binary.ply"), file + body.bytes());

  const PointCloud cloud = io::read_ply(path("binary.ply"));
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_FALSE(cloud.has_normals());
  ASSERT_TRUE(cloud.has_colors());
  EXPECT_EQ(cloud.points[0], Eigen::Vector3f(7, 8, 9));
  EXPECT_EQ(cloud.points[1], Eigen::Vector3f(-0.5f, 1e6f, -2.25f));
  EXPECT_EQ(cloud.colors[0], (Rgb8{1, 2, 3}));
  EXPECT_EQ(cloud.colors[1], (Rgb8{250, 251, 252}));
}

TEST_F(IoPly, BinaryBigEndian) {
  std::string file =
      "ply\n"
      "format binary_big_endian 1.0\n"
      "element vertex 2\n"
      "property double x\n"
      "property float y\n"
      "property short z\n"
      "property float nx\n"
      "property float ny\n"
      "property float nz\n"
      "property int label\n"
      "property uchar red\n"
      "property uchar green\n"
      "property uchar blue\n"
      "element face 1\n"
      "property list uchar uint vertex_indices\n"
      "end_header\n";
  Body body(true);
  body.put(2.5).put(-3.0f).put<std::int16_t>(-2).put(0.0f).put(0.6f).put(0.8f);
  body.put<std::int32_t>(-123456).put<std::uint8_t>(9).put<std::uint8_t>(99).put<std::uint8_t>(199);
  body.put(-0.125).put(1e5f).put<std::int16_t>(32767).put(1.0f).put(0.0f).put(0.0f);
  body.put<std::int32_t>(7).put<std::uint8_t>(0).put<std::uint8_t>(0).put<std::uint8_t>(255);
  body.put<std::uint8_t>(2).put<std::uint32_t>(0).put<std::uint32_t>(1);
  write_file(path("big.ply"), file + body.bytes());

  const PointCloud cloud = io::read_ply(path("big.ply"));
  ASSERT_EQ(cloud.size(), 2u);
  ASSERT_TRUE(cloud.has_normals());
  ASSERT_TRUE(cloud.has_colors());
  EXPECT_EQ(cloud.points[0], Eigen::Vector3f(2.5f, -3.0f, -2.0f));
  EXPECT_EQ(cloud.points[1], Eigen::Vector3f(-0.125f, 1e5f, 32767.0f));
  EXPECT_EQ(cloud.normals[0], Eigen::Vector3f(0.0f, 0.6f, 0.8f));
  EXPECT_EQ(cloud.normals[1], Eigen::Vector3f(1, 0, 0));
  EXPECT_EQ(cloud.colors[0], (Rgb8{9, 99, 199}));
  EXPECT_EQ(cloud.colors[1], (Rgb8{0, 0, 255}));
}

// ---------------------------------------------------------------------------------------------
// PLY: errors

constexpr std::string_view kXyz = "property float x\nproperty float y\nproperty float z\n";

TEST_F(IoPly, MissingEmptyAndDirectory) {
  EXPECT_ERROR_MENTIONS(io::read_ply(path("missing.ply")), "PLY file", quoted(path("missing.ply")),
                        "no such file");
  EXPECT_ERROR_MENTIONS(io::read_ply(dir_), quoted(dir_), "is a directory, not a file");
  write_file(path("empty.ply"), "");
  EXPECT_ERROR_MENTIONS(io::read_ply(path("empty.ply")), quoted(path("empty.ply")),
                        "not a PLY file");
  std::mt19937_64 rng(10);
  io::write_png(path("image.png"), random_rgb(8, 8, rng));
  EXPECT_ERROR_MENTIONS(io::read_ply(path("image.png")), quoted(path("image.png")),
                        "not a PLY file");
}

TEST_F(IoPly, BadHeadersSayWhatAndWhere) {
  struct Case {
    std::string name;
    std::string text;
    std::vector<std::string> parts;
  };
  const std::string xyz(kXyz);
  const std::vector<Case> cases = {
      {"uppercase magic", "PLY\nformat ascii 1.0\nend_header\n", {"not a PLY file"}},
      {"no end_header",
       "ply\nformat ascii 1.0\nelement vertex 1\n" + xyz,
       {"the header has no 'end_header' line"}},
      {"no format",
       "ply\nelement vertex 1\n" + xyz + "end_header\n1 2 3\n",
       {"the header has no 'format' line"}},
      {"unknown format",
       "ply\nformat binary_middle_endian 1.0\nend_header\n",
       {"header line 2", "unknown format 'binary_middle_endian'"}},
      {"bad version",
       "ply\nformat ascii 2.0\nend_header\n",
       {"header line 2", "unsupported PLY version '2.0'"}},
      {"short format",
       "ply\nformat ascii\nend_header\n",
       {"header line 2", "expected 'format <type> 1.0'"}},
      {"unknown keyword",
       "ply\nformat ascii 1.0\nelemnt vertex 1\nend_header\n",
       {"header line 3", "unknown keyword 'elemnt'"}},
      {"property first",
       "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
       {"header line 3", "property before any element"}},
      {"unknown type",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property floot z\nend_header\n1 2 3\n",
       {"header line 6", "unknown property type 'floot'"}},
      {"short property",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float\nend_header\n",
       {"header line 4", "expected 'property <type> <name>'"}},
      {"negative count",
       "ply\nformat ascii 1.0\nelement vertex -1\n" + xyz + "end_header\n",
       {"header line 3", "element count '-1' is not a non-negative integer"}},
      {"count with junk",
       "ply\nformat ascii 1.0\nelement vertex 3x\n" + xyz + "end_header\n",
       {"element count '3x' is not a non-negative integer"}},
      {"float list count",
       "ply\nformat ascii 1.0\nelement face 1\nproperty list float int idx\nend_header\n",
       {"header line 4", "list count type must be an integer type"}},
      {"no vertex element",
       "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int idx\nend_header\n3 0 1 "
       "2\n",
       {"has no 'vertex' element"}},
      {"no z",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "end_header\n1 2\n",
       {"vertex element has no 'z' property"}},
      {"partial normal",
       "ply\nformat ascii 1.0\nelement vertex 1\n" + xyz +
           "property float nx\nend_header\n1 2 3 4\n",
       {"vertex element has no 'ny' property"}},
      {"float colour",
       "ply\nformat ascii 1.0\nelement vertex 1\n" + xyz +
           "property float red\nproperty float green\nproperty float blue\nend_header\n"
           "1 2 3 0.5 0.5 0.5\n",
       {"vertex property 'red' is float; only uchar colours are supported"}},
      {"list coordinate",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\nproperty float y\n"
       "property float z\nend_header\n1 1 2 3\n",
       {"vertex property 'x' is a list, expected a scalar"}},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(cases[i].name);
    const fs::path file = path("case" + std::to_string(i) + ".ply");
    write_file(file, cases[i].text);
    const std::string message = error_message([&] { io::read_ply(file); });
    expect_mentions(message, {"PLY file", quoted(file)});
    for (const std::string& part : cases[i].parts) expect_mentions(message, {part});
  }
}

TEST_F(IoPly, BadAsciiBodiesSayWhichLine) {
  struct Case {
    std::string name;
    std::string header;
    std::string body;
    std::vector<std::string> parts;
  };
  const std::string xyz_header =
      "ply\nformat ascii 1.0\nelement vertex 3\n" + std::string(kXyz) + "end_header\n";  // 7 lines
  const std::string rgb_header = "ply\nformat ascii 1.0\nelement vertex 1\n" + std::string(kXyz) +
                                 "property uchar red\nproperty uchar green\nproperty uchar "
                                 "blue\nend_header\n";  // 10 lines
  const std::vector<Case> cases = {
      {"too few",
       xyz_header,
       "1 2 3\n4 5\n6 7 8\n",
       {"line 9: vertex index 1 (of 3): too few values (missing 'z')"}},
      {"too many",
       xyz_header,
       "1 2 3\n4 5 6\n7 8 9 10\n",
       {"line 10: vertex index 2 (of 3): 4 values, expected 3"}},
      {"not a number",
       xyz_header,
       "1 2 abc\n4 5 6\n7 8 9\n",
       {"line 8: vertex index 0 (of 3): 'z' is 'abc', not a number"}},
      {"uchar too large",
       rgb_header,
       "1 2 3 300 0 0\n",
       {"line 11", "'red' is '300', not a valid uchar"}},
      {"uchar fraction", rgb_header, "1 2 3 0 1.5 0\n", {"'green' is '1.5', not a valid uchar"}},
      {"uchar negative", rgb_header, "1 2 3 0 0 -1\n", {"'blue' is '-1', not a valid uchar"}},
      {"list too long",
       "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int idx\nelement vertex 1\n" +
           std::string(kXyz) + "end_header\n",
       "200 1 2\n1 2 3\n",
       {"line 10", "face index 0 (of 1)", "impossible length"}},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(cases[i].name);
    const fs::path file = path("case" + std::to_string(i) + ".ply");
    write_file(file, cases[i].header + cases[i].body);
    const std::string message = error_message([&] { io::read_ply(file); });
    expect_mentions(message, {quoted(file)});
    for (const std::string& part : cases[i].parts) expect_mentions(message, {part});
  }
}

TEST_F(IoPly, TruncatedBinarySaysWhere) {
  PointCloud cloud;
  cloud.points = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}};
  cloud.normals = {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}};
  cloud.colors = {{1, 1, 1}, {2, 2, 2}, {3, 3, 3}};
  io::write_ply(path("full.ply"), cloud);
  const std::string full = read_text(path("full.ply"));
  const std::size_t header = expected_header(3, true, true).size();
  ASSERT_EQ(full.size(), header + 3 * 27);

  write_file(path("cut.ply"), std::string_view(full).substr(0, full.size() - 5));
  EXPECT_ERROR_MENTIONS(io::read_ply(path("cut.ply")), quoted(path("cut.ply")),
                        "byte offset " + std::to_string(header + 2 * 27),
                        "truncated: vertex index 2 (of 3) extends past the end of the file (" +
                            std::to_string(full.size() - 5) + " bytes)");

  // Cut inside the header.
  write_file(path("cut-header.ply"), std::string_view(full).substr(0, 60));
  EXPECT_ERROR_MENTIONS(io::read_ply(path("cut-header.ply")), quoted(path("cut-header.ply")),
                        "no 'end_header' line");

  // Nothing after the header at all.
  write_file(path("no-body.ply"), std::string_view(full).substr(0, header));
  EXPECT_ERROR_MENTIONS(io::read_ply(path("no-body.ply")), "byte offset " + std::to_string(header),
                        "vertex index 0 (of 3)");
}

TEST_F(IoPly, ElementCountsLargerThanTheFile) {
  // A huge count must fail quickly at the end of the data, not try to allocate for it.
  Body body(false);
  body.put(1.0f).put(2.0f).put(3.0f).put(4.0f).put(5.0f).put(6.0f);
  write_file(path("huge.ply"),
             "ply\nformat binary_little_endian 1.0\nelement vertex "
             "99999999999999\n" +
                 std::string(kXyz) + "end_header\n" + body.bytes());
  EXPECT_ERROR_MENTIONS(io::read_ply(path("huge.ply")), quoted(path("huge.ply")), "truncated",
                        "vertex index 2 (of 99999999999999)");

  // The same for an element skipped before the vertices.
  write_file(path("huge-faces.ply"),
             "ply\nformat binary_little_endian 1.0\nelement face 18446744073709551615\n"
             "property list uchar int vertex_indices\nelement vertex 1\n" +
                 std::string(kXyz) + "end_header\n" + body.bytes());
  EXPECT_ERROR_MENTIONS(io::read_ply(path("huge-faces.ply")), "truncated", "face index");

  write_file(path("ascii.ply"), "ply\nformat ascii 1.0\nelement vertex 3\n" + std::string(kXyz) +
                                    "end_header\n1 2 3\n4 5 6\n");
  EXPECT_ERROR_MENTIONS(
      io::read_ply(path("ascii.ply")), quoted(path("ascii.ply")),
      "truncated: the file ends after line 9 but vertex index 2 (of 3) is missing");

  // A count that does not fit in 64 bits is a header error.
  write_file(path("overflow.ply"),
             "ply\nformat ascii 1.0\nelement vertex "
             "99999999999999999999999\n" +
                 std::string(kXyz) + "end_header\n1 2 3\n");
  EXPECT_ERROR_MENTIONS(io::read_ply(path("overflow.ply")), "header line 3", "element count");
}

// ---------------------------------------------------------------------------------------------
// Atomic writes

bool has_temp_file(const std::set<std::string>& names) {
  return std::any_of(names.begin(), names.end(), [](const std::string& name) {
    return name.find(".tmp-") != std::string::npos;
  });
}

// Every writer, each writing a small valid file to the given path.
std::vector<std::pair<std::string, std::function<void(const fs::path&)>>> all_writers() {
  return {
      {"gray png", [](const fs::path& p) { io::write_png(p, GrayImage(3, 2, 7)); }},
      {"rgb png",
       [](const fs::path& p) {
         io::write_png(p, RgbImage(3, 2, Rgb8{1, 2, 3}));
       }},
      {"depth png", [](const fs::path& p) { io::write_png(p, DepthImage(3, 2, 1000)); }},
      {"image ply",
       [](const fs::path& p) { io::write_ply(p, PointImage(2, 2, Point4f(1, 2, 3, 1))); }},
      {"cloud ply",
       [](const fs::path& p) {
         PointCloud cloud;
         cloud.points = {{1, 2, 3}};
         io::write_ply(p, cloud);
       }},
  };
}

TEST_F(IoAtomic, WritesAndOverwritesLeaveOnlyTheTarget) {
  std::set<std::string> expected;
  for (const auto& [name, write] : all_writers()) {
    SCOPED_TRACE(name);
    const std::string file = "out " + std::to_string(expected.size());
    write_file(path(file),
               "old content that is longer than some of the new files, "
               "so a missing truncation would show ..................................");
    write(path(file));
    expected.insert(file);
    EXPECT_EQ(entries(), expected);
    const std::string text = read_text(path(file));
    EXPECT_EQ(text.find("old content"), std::string::npos) << "the old file was not replaced";
  }
  EXPECT_EQ(io::read_depth_png(path("out 2"))(2, 1), 1000);
  EXPECT_EQ(io::read_ply(path("out 4")).points.at(0), Eigen::Vector3f(1, 2, 3));
}

TEST_F(IoAtomic, TargetThatIsADirectoryIsLeftAlone) {
  const fs::path target = path("target");
  fs::create_directories(target);
  write_file(target / "keep.txt", "keep me");
  for (const auto& [name, write] : all_writers()) {
    SCOPED_TRACE(name);
    EXPECT_ERROR_MENTIONS(write(target), "cannot write " + quoted(target), "cannot rename");
    EXPECT_TRUE(fs::is_directory(target));
    EXPECT_EQ(read_text(target / "keep.txt"), "keep me");
    EXPECT_EQ(entries(), std::set<std::string>{"target"}) << "a temporary file was left behind";
  }
}

TEST_F(IoAtomic, MissingParentDirectoryCreatesNothing) {
  const fs::path target = path("no-such-dir") / "file";
  for (const auto& [name, write] : all_writers()) {
    SCOPED_TRACE(name);
    EXPECT_ERROR_MENTIONS(write(target), "cannot write " + quoted(target),
                          "cannot create temporary file", "No such file or directory");
  }
  EXPECT_TRUE(entries().empty());
}

TEST_F(IoAtomic, RejectedInputLeavesTheExistingFileUntouched) {
  write_file(path("cloud.ply"), "previous cloud");
  write_file(path("image.png"), "previous image");
  const PointImage points(2, 2, Point4f(1, 2, 3, 1));
  const NormalImage wrong_size(3, 3, invalid_point());
  EXPECT_ERROR_MENTIONS(io::write_ply(path("cloud.ply"), points, &wrong_size),
                        "the normals are 3x3");
  EXPECT_ERROR_MENTIONS(io::write_png(path("image.png"), DepthImage()), "the image is empty");
  EXPECT_EQ(read_text(path("cloud.ply")), "previous cloud");
  EXPECT_EQ(read_text(path("image.png")), "previous image");
  EXPECT_EQ(entries(), (std::set<std::string>{"cloud.ply", "image.png"}));
}

// Lowers this process's file size limit (writes past it fail with EFBIG rather than SIGXFSZ)
// until destroyed.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    previous_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    ok_ = ::getrlimit(RLIMIT_FSIZE, &previous_) == 0;
    if (!ok_) return;
    rlimit limited = previous_;
    limited.rlim_cur = std::min(bytes, previous_.rlim_max);
    ok_ = ::setrlimit(RLIMIT_FSIZE, &limited) == 0;
  }
  ~FileSizeLimit() {
    if (ok_) ::setrlimit(RLIMIT_FSIZE, &previous_);
    std::signal(SIGXFSZ, previous_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;
  bool ok() const { return ok_; }

 private:
  rlimit previous_{};
  void (*previous_handler_)(int) = SIG_DFL;
  bool ok_ = false;
};

TEST_F(IoAtomic, WriteFailingHalfwayKeepsTheOldFileAndLeavesNoPartialOne) {
  // Big enough to exceed the limit below: ~1.8 MB of PLY, ~0.5 MB of incompressible PNG.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> coordinate(-1, 1);
  PointCloud cloud;
  for (int i = 0; i < 150000; ++i) {
    cloud.points.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
  }
  const DepthImage depth = random_depth(512, 512, rng);
  write_file(path("cloud.ply"), "previous cloud");
  write_file(path("depth.png"), "previous depth");

  std::string ply_error;
  std::string png_error;
  {
    FileSizeLimit limit(64 * 1024);
    ASSERT_TRUE(limit.ok()) << "cannot lower RLIMIT_FSIZE";
    ply_error = error_message([&] { io::write_ply(path("cloud.ply"), cloud); });
    png_error = error_message([&] { io::write_png(path("depth.png"), depth); });
    io::write_png(path("small.png"), DepthImage(4, 4, 5));  // a small file still fits
  }
  expect_mentions(ply_error, {"cannot write " + quoted(path("cloud.ply")), "write failed"});
  expect_mentions(png_error, {"cannot write " + quoted(path("depth.png"))});
  EXPECT_EQ(read_text(path("cloud.ply")), "previous cloud");
  EXPECT_EQ(read_text(path("depth.png")), "previous depth");
  EXPECT_EQ(entries(), (std::set<std::string>{"cloud.ply", "depth.png", "small.png"}));

  // Without the limit the same writes succeed.
  io::write_ply(path("cloud.ply"), cloud);
  io::write_png(path("depth.png"), depth);
  EXPECT_EQ(io::read_ply(path("cloud.ply")).size(), cloud.size());
  EXPECT_EQ(count_differences(io::read_depth_png(path("depth.png")), depth), 0u);
  EXPECT_FALSE(has_temp_file(entries()));
}

// ---------------------------------------------------------------------------------------------
// Real data

TEST_F(IoRealData, RedKitchenDepthFrameIsMillimetres) {
  const fs::path file = testing::data_dir() / "7scenes_redkitchen/frames/frame-000000.depth.png";
  const DepthImage depth = io::read_depth_png(file);
  ASSERT_EQ(depth.width(), 640);
  ASSERT_EQ(depth.height(), 480);
  std::vector<std::uint16_t> measured;
  for (std::uint16_t d : depth.pixels()) {
    if (d != 0) measured.push_back(d);
  }
  EXPECT_GT(measured.size(), 200000u);
  ASSERT_FALSE(measured.empty());
  auto middle = measured.begin() + static_cast<std::ptrdiff_t>(measured.size() / 2);
  std::nth_element(measured.begin(), middle, measured.end());
  EXPECT_GE(*middle, 500) << "median depth should be a room-scale distance in millimetres";
  EXPECT_LE(*middle, 4000) << "median depth should be a room-scale distance in millimetres";

  // Written and read back, the frame is unchanged.
  io::write_png(path("copy.png"), depth);
  EXPECT_EQ(count_differences(io::read_depth_png(path("copy.png")), depth), 0u);
}

TEST_F(IoRealData, RedKitchenColorFrameIsAPicture) {
  const fs::path file = testing::data_dir() / "7scenes_redkitchen/frames/frame-000000.color.jpg";
  const RgbImage color = io::read_color_image(file);
  ASSERT_EQ(color.width(), 640);
  ASSERT_EQ(color.height(), 480);
  // Not blank: brightness spreads over a good part of the range.
  std::array<std::size_t, 256> histogram{};
  for (const Rgb8& p : color.pixels()) ++histogram[(p[0] + p[1] + p[2]) / 3];
  const auto used =
      std::count_if(histogram.begin(), histogram.end(), [](std::size_t n) { return n > 0; });
  EXPECT_GT(used, 64);
  EXPECT_ERROR_MENTIONS(io::read_depth_png(file), "is 8-bit");
}

}  // namespace
}  // namespace kartograf

namespace kartograf {
namespace {

class IoPlyMesh : public testing::TempDirTest {};

TEST_F(IoPlyMesh, TrianglesAndColoursAreWrittenAsBinaryLittleEndian) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f}};
  mesh.colors = {0x0000ffu, 0x00ff00u, 0xff0000u};
  mesh.triangles = {{0, 1, 2}};
  const auto file = dir() / "mesh.ply";
  io::write_mesh_ply(file, mesh);
  const std::string text = testing::read_text(file);
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment written by Kartograf\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\nproperty uchar red\n"
      "property uchar green\nproperty uchar blue\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  ASSERT_EQ(text.substr(0, header.size()), header);
  ASSERT_EQ(text.size(), header.size() + 3 * 15 + 13);
  float z = 0;
  std::memcpy(&z, text.data() + header.size() + 2 * 15 + 8, 4);
  EXPECT_EQ(z, 0.5f);
  EXPECT_EQ(static_cast<unsigned char>(text[header.size() + 2 * 15 + 12 + 2]), 0xffu);  // blue
  const std::string face = text.substr(header.size() + 45);
  EXPECT_EQ(face[0], 3);
  std::int32_t last = 0;
  std::memcpy(&last, face.data() + 9, 4);
  EXPECT_EQ(last, 2);
  // The cloud reader skips the faces and reads the vertices back.
  EXPECT_EQ(io::read_ply(file).size(), 3u);
}

TEST_F(IoPlyMesh, BadIndicesAndColourCountsAreErrorsAndWriteNothing) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 3}};
  EXPECT_ERROR_MENTIONS(io::write_mesh_ply(dir() / "bad.ply", mesh), "bad.ply",
                        "beyond the 3 vertices");
  mesh.triangles = {{0, 1, 2}};
  mesh.colors = {1, 2};
  EXPECT_ERROR_MENTIONS(io::write_mesh_ply(dir() / "bad.ply", mesh), "2 colours for 3 vertices");
  EXPECT_FALSE(std::filesystem::exists(dir() / "bad.ply"));
}

}  // namespace
}  // namespace kartograf
