#pragma once
// Shared by every test, backend or not (kartograf_test_support_core: core and GoogleTest only):
// real data, whole-file reads and writes, checks of what an Error says, temporary folders.
// test_support.hpp adds the backends under test.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

namespace kartograf::testing {

// ../shared/data (or KARTOGRAF_DATA_DIR): fails the test if missing.
std::filesystem::path data_dir();

// For RecordProperty: an error figure in %.3e form (std::to_string would print 0.000001).
std::string scientific(double value);

// Whole files, in binary mode (read_text: the bytes as a string). A file that cannot be opened or
// written fails the test.
std::vector<std::uint8_t> read_bytes(const std::filesystem::path& path);
std::string read_text(const std::filesystem::path& path);
void write_file(const std::filesystem::path& path, std::string_view contents);
void write_file(const std::filesystem::path& path, const std::vector<std::uint8_t>& contents);

// A 4x4 camera-to-world matrix in a text file (7-Scenes' frame-XXXXXX.pose.txt), orthonormalised.
Eigen::Isometry3d read_pose(const std::filesystem::path& path);

// The message of the kartograf::Error that f throws; a test failure (and "") if it throws nothing.
// Any other exception escapes and fails the test too.
std::string error_message(const std::function<void()>& f);

// Expects `message` to contain every part; a failure names the missing part and the message.
void expect_mentions(const std::string& message, std::initializer_list<std::string_view> parts);

// EXPECT_ERROR_MENTIONS(statement, "part", ...): statement throws a kartograf::Error whose message
// mentions every part.
#define EXPECT_ERROR_MENTIONS(statement, ...)                                                      \
  do {                                                                                             \
    SCOPED_TRACE(#statement);                                                                      \
    ::kartograf::testing::expect_mentions(::kartograf::testing::error_message([&] { statement; }), \
                                          {__VA_ARGS__});                                          \
  } while (0)

// Fixture: a fresh temporary directory per test, removed afterwards.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

}  // namespace kartograf::testing
