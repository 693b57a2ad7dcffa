// The raw copies that kartograf_device_tests reads instead of the original files
// (device_data_files.hpp, raw_image_file.hpp): exported, they equal what kartograf_io reads, and a
// missing or malformed copy is an error naming the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "device_data_files.hpp"
#include "raw_image_file.hpp"
#include "real_data.hpp"
#include "test_support_core.hpp"

namespace kartograf::testing {
namespace {

template <class Pixel>
void expect_same_image(const Image<Pixel>& expected, const Image<Pixel>& actual,
                       std::string_view file) {
  ASSERT_EQ(actual.width(), expected.width()) << file;
  ASSERT_EQ(actual.height(), expected.height()) << file;
  EXPECT_TRUE(
      std::equal(expected.pixels().begin(), expected.pixels().end(), actual.pixels().begin()))
      << file;
}

class RealData : public TempDirTest {};

TEST_F(RealData, ExportedCopiesEqualTheOriginals) {
  export_device_data(data_dir(), dir());
  for (const DeviceDataFile& file : kDeviceDataFiles) {
    const std::filesystem::path original = data_dir() / file.path, copy = dir() / file.path;
    switch (file.kind) {
      case DeviceDataKind::depth:
        expect_same_image(read_depth(original), raw::read_depth(raw_copy_path(copy)), file.path);
        break;
      case DeviceDataKind::color:
        expect_same_image(read_color(original), raw::read_color(raw_copy_path(copy)), file.path);
        break;
      case DeviceDataKind::occupancy_map:
        expect_same_image(read_occupancy_map(original, 0.05).cells,
                          raw::read_occupancy(raw_copy_path(copy)), file.path);
        break;
      case DeviceDataKind::text:
        EXPECT_EQ(read_text(copy), read_text(original)) << file.path;
        break;
    }
  }
}

TEST_F(RealData, MissingOrMalformedCopiesAreErrorsNamingTheFile) {
  const std::filesystem::path path = dir() / "frame.depth.png.raw";
  EXPECT_ERROR_MENTIONS(raw::read_depth(path), path.string(), "no such file",
                        "kartograf_export_device_data", "KARTOGRAF_DATA_DIR");
  DepthImage depth(4, 3, 1000);
  raw::write_depth(path, depth);
  expect_same_image(depth, raw::read_depth(path), "round trip");
  EXPECT_ERROR_MENTIONS(raw::read_color(path), path.string(), "holds 'depth 1 u16'",
                        "expected 'color 3 u8'");
  const std::string whole = read_text(path);
  write_file(path, whole.substr(0, whole.size() - 1));
  EXPECT_ERROR_MENTIONS(raw::read_depth(path), path.string(), "23 bytes of pixels, expected 24");
  write_file(path, whole + "x");
  EXPECT_ERROR_MENTIONS(raw::read_depth(path), path.string(), "25 bytes of pixels, expected 24");
  write_file(path, "P5 4 3 65535\n" + whole.substr(whole.find('\n') + 1));
  EXPECT_ERROR_MENTIONS(raw::read_depth(path), path.string(), "not a kartograf-raw 1 file");
  write_file(path, std::string("kartograf-raw 1 occupancy 2 1 1 u8\n") + '\1' + '\7');
  EXPECT_ERROR_MENTIONS(raw::read_occupancy(path), path.string(), "cell value 7");
  write_file(path, "kartograf-raw 1 depth 0 3 1 u16\n");
  EXPECT_ERROR_MENTIONS(raw::read_depth(path), path.string(), "bad image size 0 x 3");
}

}  // namespace
}  // namespace kartograf::testing
