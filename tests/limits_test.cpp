// Issue 20, Deliver 4 and defects 7, 9, 12: work whose size comes from the input is refused before
// it allocates (core/memory_budget.hpp), with KARTOGRAF_MEMORY_LIMIT making the limit small so
// that no test allocates much; KARTOGRAF_DEVICE is checked; parser messages show no raw bytes.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/core/memory_budget.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/formats/pcd.hpp"
#include "kartograf/formats/ply.hpp"
#include "kartograf/geometry/range_image.hpp"
#include "kartograf/registration/odometry.hpp"
#include "kartograf/rooms/room_methods.hpp"
#include "kartograf/semantic/classify.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

namespace fs = std::filesystem;

// Sets an environment variable for one test and restores it afterwards.
class ScopedEnvironment {
 public:
  ScopedEnvironment(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value, 1);
  }
  ~ScopedEnvironment() {
    if (old_) {
      setenv(name_, old_->c_str(), 1);
    } else {
      unsetenv(name_);
    }
  }
  ScopedEnvironment(const ScopedEnvironment&) = delete;
  ScopedEnvironment& operator=(const ScopedEnvironment&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

// A fresh folder per test, removed afterwards.
class MemoryBudgetFiles : public testing::TempDirTest {};

std::vector<std::uint8_t> bytes_of(const std::string& text) {
  return {text.begin(), text.end()};
}

TEST(MemoryBudget, EnvironmentSetsTheLimit) {
  {
    const ScopedEnvironment limit("KARTOGRAF_MEMORY_LIMIT", "512M");
    EXPECT_EQ(available_memory_bytes(), 512u << 20);
  }
  {
    const ScopedEnvironment limit("KARTOGRAF_MEMORY_LIMIT", "2G");
    EXPECT_EQ(available_memory_bytes(), 2ull << 30);
  }
  {
    const ScopedEnvironment limit("KARTOGRAF_MEMORY_LIMIT", "4096");
    EXPECT_EQ(available_memory_bytes(), 4096u);
  }
  for (const char* bad : {"abc", "12X", "-5", "nan", "1M2"}) {
    const ScopedEnvironment limit("KARTOGRAF_MEMORY_LIMIT", bad);
    EXPECT_ERROR_MENTIONS(available_memory_bytes(), "KARTOGRAF_MEMORY_LIMIT", bad);
  }
  unsetenv("KARTOGRAF_MEMORY_LIMIT");
  EXPECT_GT(available_memory_bytes(), 0u);  // the machine's MemAvailable
}

TEST(MemoryBudget, RefusalSaysWhatNeedsHowMuch) {
  const ScopedEnvironment limit("KARTOGRAF_MEMORY_LIMIT", "1M");
  EXPECT_NO_THROW(require_fits_in_memory(1 << 20, "exactly the limit"));
  EXPECT_ERROR_MENTIONS(require_fits_in_memory(3.5 * (1 << 30), "a huge thing"),
                        "a huge thing needs about 3.5 GB, KARTOGRAF_MEMORY_LIMIT allows 1.0 MB");
  unsetenv("KARTOGRAF_MEMORY_LIMIT");
  EXPECT_ERROR_MENTIONS(require_fits_in_memory(1e18, "an exabyte"),
                        "an exabyte needs about 931322574.6 GB, the machine has ", " GB available");
  EXPECT_EQ(memory_size_text(800 * 1024), "800 kB");
  EXPECT_EQ(memory_size_text(12.0 * (1 << 20)), "12.0 MB");
}

// A 2-MB PNG can declare 20000 x 20000 pixels (issue 20 defect 7): the header's size is checked
// before decoding. The file here is a small PNG whose IHDR says 20000 x 20000.
TEST_F(MemoryBudgetFiles, ImageHeaderSizeIsCheckedBeforeDecoding) {
  const fs::path path = dir() / "huge.png";
  std::string png = std::string("\x89PNG\r\n\x1a\n", 8) + std::string("\0\0\0\x0dIHDR", 8) +
                    std::string("\0\0\x4e\x20\0\0\x4e\x20\x08\0\0\0\0", 13) + "crc!" +
                    std::string("\0\0\0\0IEND\xae\x42\x60\x82", 12);
  testing::write_file(path, png);
  const ScopedEnvironment limit("KARTOGRAF_MEMORY_LIMIT", "64M");
  EXPECT_ERROR_MENTIONS(io::read_map_gray(path), "huge.png", "20000x20000 pixels", "needs about",
                        "64.0 MB");
  // The same for a binary PGM, whose data would be read for the header's size.
  const fs::path pgm = dir() / "huge.pgm";
  testing::write_file(pgm, "P5\n# big\n30000 20000\n255\n\xff\xff");
  EXPECT_ERROR_MENTIONS(io::read_png_map(pgm), "huge.pgm", "30000x20000 pixels", "needs about");
}

TEST_F(MemoryBudgetFiles, MapYamlAndImagesMustBeRegularFiles) {
  const fs::path yaml = dir() / "zero.yaml";
  testing::write_file(yaml,
                      "image: /dev/zero\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
                      "occupied_thresh: 0.65\nfree_thresh: 0.196\n");
  EXPECT_ERROR_MENTIONS(io::read_ros_map(yaml), "/dev/zero", "not a regular file");
  const fs::path link = dir() / "link.yaml";
  fs::remove(link);
  fs::create_symlink("/dev/zero", link);
  EXPECT_ERROR_MENTIONS(io::read_ros_map(link), "link.yaml", "not a regular file");
  const fs::path big = dir() / "big.yaml";
  testing::write_file(big, std::string(2 << 20, '#'));
  EXPECT_ERROR_MENTIONS(io::read_ros_map(big), "big.yaml", "larger than 1 MB");
}

TEST(MemoryBudget, CompressedPcdIsCheckedBeforeDecompressing) {
  // 100000 points of 12 bytes from 20000 bytes of LZF data (it could expand 88 times).
  std::string pcd =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 100000\nHEIGHT 1\n"
      "POINTS 100000\nDATA binary_compressed\n";
  const std::uint32_t compressed = 20000, uncompressed = 1200000;
  pcd.append(reinterpret_cast<const char*>(&compressed), 4);
  pcd.append(reinterpret_cast<const char*>(&uncompressed), 4);
  pcd.append(compressed, '\x01');
  const ScopedEnvironment limit("KARTOGRAF_MEMORY_LIMIT", "1M");
  EXPECT_ERROR_MENTIONS(io::parse_pcd(bytes_of(pcd), "big.pcd"), "big.pcd", "100000 points",
                        "needs about 2.3 MB");
}

TEST_F(MemoryBudgetFiles, PlyVertexCountIsChecked) {
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 200000\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  for (int i = 0; i < 200000; ++i) ply += "0 0 0\n";
  const fs::path path = dir() / "many.ply";
  testing::write_file(path, ply);
  EXPECT_EQ(io::read_ply(path).size(), 200000u);
  const ScopedEnvironment limit("KARTOGRAF_MEMORY_LIMIT", "2M");
  EXPECT_ERROR_MENTIONS(io::read_ply(path), "many.ply", "200000 vertices", "needs about");
}

TEST(MemoryBudget, RangeImageSizeIsCheckedBeforeAllocating) {
  // 0.05 degrees: 7200 x 3000 pixels, about 600 MB.
  geometry::RangeImageParams params;
  params.angular_step_deg = 0.05;
  const std::vector<Eigen::Vector3f> points = {{1, 0, 0}};
  const ScopedEnvironment limit("KARTOGRAF_MEMORY_LIMIT", "64M");
  EXPECT_ERROR_MENTIONS(geometry::make_range_image(points, Eigen::Isometry3d::Identity(), params),
                        "7200 x 3000 pixels", "needs about");
  params.angular_step_deg = 1e-6;  // 360e6 columns would overflow int
  EXPECT_ERROR_MENTIONS(geometry::make_range_image(points, Eigen::Isometry3d::Identity(), params),
                        "angular_step_deg");
}

TEST(MemoryBudget, LabellingRoomsAndOdometryAreCheckedBeforeAllocating) {
  const compute::Context context = compute::Context::cpu();
  const ScopedEnvironment limit("KARTOGRAF_MEMORY_LIMIT", "4M");
  const PointImage points(1000, 1000, invalid_point());
  EXPECT_ERROR_MENTIONS(semantic::label_organized_points(context, points),
                        "semantic labelling of a 1000 x 1000 point image", "needs about");
  OccupancyGrid map;
  map.resolution = 0.05;
  map.cells = Image<CellState>(1000, 1000, CellState::free);
  for (const rooms::RoomMethod method : rooms::all_room_methods()) {
    EXPECT_ERROR_MENTIONS(rooms::segment_rooms(compute::Context::cpu(), map, method),
                          "room segmentation (" + rooms::to_string(method) + ") of a 1000 x 1000",
                          "needs about");
  }
  const PinholeIntrinsics camera{640, 480, 525, 525, 319.5, 239.5};
  EXPECT_ERROR_MENTIONS(registration::RgbdOdometry(context, camera), "odometry: 3 frame pyramids",
                        "640 x 480", "needs about");
}

TEST(DeviceEnvironment, IndexMustNameAnExistingDevice) {
  for (const char* bad : {"abc", "-1", "1.5", " 1", "99999999999"}) {
    const ScopedEnvironment device("KARTOGRAF_DEVICE", bad);
    compute::ContextParams options;
    EXPECT_ERROR_MENTIONS(options.read_device_environment(), "KARTOGRAF_DEVICE", bad);
  }
  const ScopedEnvironment device("KARTOGRAF_DEVICE", "9");
  compute::ContextParams options;
  options.backend = compute::BackendChoice::cpu;
  options.read_device_environment();
  EXPECT_EQ(options.device_index, 9);
  EXPECT_ERROR_MENTIONS(compute::Context{options}, "KARTOGRAF_DEVICE=9", "no such device",
                        "cpu backend has 1 usable device(s): [0] host CPU");
  options.device_index = 0;
  EXPECT_EQ(compute::Context(options).backend(), compute::BackendKind::cpu);
}

TEST(DeviceEnvironment, IndexBeyondTheBackendsDevicesIsAnError) {
  for (const compute::BackendKind kind : testing::backends_under_test()) {
    if (kind == compute::BackendKind::cpu) continue;
    SCOPED_TRACE(compute::to_string(kind));
    compute::ContextParams options;
    options.backend = kind == compute::BackendKind::vulkan ? compute::BackendChoice::vulkan
                                                           : compute::BackendChoice::opencl;
    options.device_index = 0;
    const compute::Context first(options);
    options.device_index = 9;
    options.device_index_source = "KARTOGRAF_DEVICE";
    EXPECT_ERROR_MENTIONS(compute::Context{options}, "KARTOGRAF_DEVICE=9", "no such device",
                          "[0] " + first.device_info().name);
  }
}

TEST(ParserMessages, PcdHeaderBytesAreEscapedAndCut) {
  std::string keyword(300, '\0');
  for (std::size_t i = 0; i < keyword.size(); ++i) keyword[i] = static_cast<char>(0x80 + i % 100);
  const std::string message = testing::error_message(
      [&] { io::parse_pcd(bytes_of("VERSION 0.7\n" + keyword + " 1\n"), "binary.pcd"); });
  testing::expect_mentions(message,
                           {"binary.pcd", "header line 2", "unknown keyword '\\x80\\x81", "...'"});
  EXPECT_LT(message.size(), 300u) << message;
  for (const char c : message) {
    const auto byte = static_cast<unsigned char>(c);
    EXPECT_TRUE(byte >= 0x20 && byte < 0x7f) << "raw byte " << int(byte) << " in: " << message;
  }
  const std::string fields = testing::error_message([&] {
    io::parse_pcd(bytes_of("FIELDS x y z\nSIZE 4 4 4\nTYPE F \x1b[31m\x07 F\nCOUNT 1 1 1\n"
                           "WIDTH 1\nPOINTS 1\nDATA ascii\n"),
                  "escape.pcd");
  });
  testing::expect_mentions(fields, {"TYPE '\\x1b[31m\\x07'", "of field 'y'"});
}

}  // namespace
}  // namespace kartograf
