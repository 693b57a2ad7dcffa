#include "raw_image_file.hpp"

#include <bit>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "kartograf/core/error.hpp"

namespace kartograf::testing::raw {

namespace {

static_assert(std::endian::native == std::endian::little, "raw files are little-endian");
static_assert(sizeof(Rgb8) == 3 && sizeof(CellState) == 1);

constexpr const char* kMagic = "kartograf-raw";
constexpr int kVersion = 1;
constexpr int kMaxSide = 1 << 15;

// What a file of one kind holds per pixel.
struct Layout {
  const char* kind;
  int channels;
  const char* type;
  std::size_t pixel_bytes;
};
constexpr Layout kDepth{"depth", 1, "u16", 2};
constexpr Layout kColor{"color", 3, "u8", 3};
constexpr Layout kOccupancy{"occupancy", 1, "u8", 1};

std::string named(const std::filesystem::path& path) {
  return "raw device test data '" + path.string() + "'";
}

template <class Pixel>
void write_raw(const std::filesystem::path& path, const Layout& layout, const Image<Pixel>& image) {
  static_assert(std::is_trivially_copyable_v<Pixel>);
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << kMagic << ' ' << kVersion << ' ' << layout.kind << ' ' << image.width() << ' '
      << image.height() << ' ' << layout.channels << ' ' << layout.type << '\n';
  out.write(reinterpret_cast<const char*>(image.data()),
            static_cast<std::streamsize>(image.size() * sizeof(Pixel)));
  out.close();
  require(static_cast<bool>(out), named(path) + ": cannot be written");
}

// The header's image size after checking that it is a file of `layout`, then the pixels.
template <class Pixel>
Image<Pixel> read_raw(const std::filesystem::path& path, const Layout& layout) {
  std::ifstream in(path, std::ios::binary);
  require(static_cast<bool>(in),
          named(path) +
              ": no such file (export it with kartograf_export_device_data OUT_DIR "
              "and set KARTOGRAF_DATA_DIR=OUT_DIR)");
  std::string header;
  std::getline(in, header);
  std::istringstream fields(header);
  std::string magic, kind, type;
  int version = 0, width = 0, height = 0, channels = 0;
  fields >> magic >> version >> kind >> width >> height >> channels >> type;
  require(!fields.fail() && in && magic == kMagic && version == kVersion,
          named(path) + ": not a kartograf-raw " + std::to_string(kVersion) + " file (header '" +
              header.substr(0, 80) + "')");
  require(kind == layout.kind && channels == layout.channels && type == layout.type,
          named(path) + ": holds '" + kind + " " + std::to_string(channels) + " " + type +
              "', expected '" + layout.kind + " " + std::to_string(layout.channels) + " " +
              layout.type + "'");
  require(
      width > 0 && height > 0 && width <= kMaxSide && height <= kMaxSide,
      named(path) + ": bad image size " + std::to_string(width) + " x " + std::to_string(height));
  Image<Pixel> image(width, height);
  const std::size_t expected = image.size() * layout.pixel_bytes;
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
  require(bytes.size() == expected, named(path) + ": " + std::to_string(bytes.size()) +
                                        " bytes of pixels, expected " + std::to_string(expected) +
                                        " (truncated or not a raw copy)");
  std::memcpy(static_cast<void*>(image.data()), bytes.data(), expected);
  return image;
}

}  // namespace

void write_depth(const std::filesystem::path& path, const DepthImage& image) {
  write_raw(path, kDepth, image);
}

void write_color(const std::filesystem::path& path, const RgbImage& image) {
  write_raw(path, kColor, image);
}

void write_occupancy(const std::filesystem::path& path, const Image<CellState>& cells) {
  write_raw(path, kOccupancy, cells);
}

DepthImage read_depth(const std::filesystem::path& path) {
  return read_raw<std::uint16_t>(path, kDepth);
}

RgbImage read_color(const std::filesystem::path& path) {
  return read_raw<Rgb8>(path, kColor);
}

Image<CellState> read_occupancy(const std::filesystem::path& path) {
  Image<CellState> cells = read_raw<CellState>(path, kOccupancy);
  for (const CellState cell : cells.pixels()) {
    require(cell <= CellState::occupied, named(path) + ": a cell value " +
                                             std::to_string(static_cast<int>(cell)) +
                                             " is not a CellState (0, 1 or 2)");
  }
  return cells;
}

}  // namespace kartograf::testing::raw
