#include "test_support_core.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>

#include <unistd.h>

#include "kartograf/core/error.hpp"
#include "kartograf/core/pose.hpp"

namespace kartograf::testing {

std::filesystem::path data_dir() {
  const char* configured = std::getenv("KARTOGRAF_DATA_DIR");
  const std::filesystem::path dir = configured ? configured : KARTOGRAF_DEFAULT_DATA_DIR;
  if (!std::filesystem::is_directory(dir)) {
    ADD_FAILURE() << "test data directory " << dir << " is missing (set KARTOGRAF_DATA_DIR)";
  }
  return dir;
}

std::string scientific(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3e", value);
  return text;
}

std::vector<std::uint8_t> read_bytes(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  EXPECT_TRUE(stream) << "cannot open " << path;
  return std::vector<std::uint8_t>((std::istreambuf_iterator<char>(stream)),
                                   std::istreambuf_iterator<char>());
}

std::string read_text(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = read_bytes(path);
  return std::string(bytes.begin(), bytes.end());
}

Eigen::Isometry3d read_pose(const std::filesystem::path& path) {
  std::istringstream in(read_text(path));
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) in >> m(r, c);
  }
  EXPECT_FALSE(in.fail()) << path;
  return orthonormalized_pose(m);
}

void write_file(const std::filesystem::path& path, std::string_view contents) {
  std::ofstream stream(path, std::ios::binary | std::ios::trunc);
  stream.write(contents.data(), static_cast<std::streamsize>(contents.size()));
  EXPECT_TRUE(stream) << "cannot write " << path;
}

void write_file(const std::filesystem::path& path, const std::vector<std::uint8_t>& contents) {
  write_file(path,
             std::string_view(reinterpret_cast<const char*>(contents.data()), contents.size()));
}

std::string error_message(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected a kartograf::Error, but nothing was thrown";
  return "";
}

void expect_mentions(const std::string& message, std::initializer_list<std::string_view> parts) {
  for (std::string_view part : parts) {
    EXPECT_NE(message.find(part), std::string::npos)
        << "the message does not mention \"" << part << "\":\n  " << message;
  }
}

void TempDirTest::SetUp() {
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  dir_ =
      std::filesystem::temp_directory_path() / ("kartograf-test-" + std::to_string(::getpid()) +
                                                "-" + test->test_suite_name() + "-" + test->name());
  std::filesystem::create_directories(dir_);
}

void TempDirTest::TearDown() {
  std::filesystem::remove_all(dir_);
}

}  // namespace kartograf::testing
