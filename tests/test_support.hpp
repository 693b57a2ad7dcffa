#pragma once
// Shared by every test: the backends under test, contexts with Vulkan validation, real data,
// whole-file reads and writes, and checks of what an Error says.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <memory>
#include <optional>
#include <ostream>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "kartograf/compute/context.hpp"

namespace kartograf::compute {
// So that test names and ctest show "vulkan", not a byte dump.
inline void PrintTo(BackendKind kind, std::ostream* out) {
  *out << to_string(kind);
}
}  // namespace kartograf::compute

namespace kartograf::testing {

// Every backend, unless KARTOGRAF_TEST_BACKENDS (e.g. "cpu,opencl") names fewer. A listed backend
// that cannot be created fails its tests: CI must not pass with a backend silently missing.
std::vector<compute::BackendKind> backends_under_test();

// A context for `kind`, with Vulkan validation and synchronization validation on.
compute::Context make_context(compute::BackendKind kind);

// ../shared/data (or KARTOGRAF_DATA_DIR): fails the test if missing.
std::filesystem::path data_dir();

// For RecordProperty: an error figure in %.3e form (std::to_string would print 0.000001).
std::string scientific(double value);

std::string backend_test_name(const ::testing::TestParamInfo<compute::BackendKind>& info);

// Whole files, in binary mode (read_text: the bytes as a string). A file that cannot be opened or
// written fails the test.
std::vector<std::uint8_t> read_bytes(const std::filesystem::path& path);
std::string read_text(const std::filesystem::path& path);
void write_file(const std::filesystem::path& path, std::string_view contents);
void write_file(const std::filesystem::path& path, const std::vector<std::uint8_t>& contents);

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

// Fixture: one context per test on the parameter's backend; after the test, the Vulkan validation
// layer must have reported no error.
class BackendTest : public ::testing::TestWithParam<compute::BackendKind> {
 protected:
  void SetUp() override;
  void TearDown() override;
  compute::Context& context() { return *context_; }

  std::mt19937_64 rng{20261121};

 private:
  std::unique_ptr<compute::Context> context_;
};

// Sets KARTOGRAF_CPU_THREADS (the CPU backend's threads) for one scope, restoring it after.
class ScopedCpuThreads {
 public:
  explicit ScopedCpuThreads(const char* value);
  ~ScopedCpuThreads();
  ScopedCpuThreads(const ScopedCpuThreads&) = delete;
  ScopedCpuThreads& operator=(const ScopedCpuThreads&) = delete;

 private:
  std::optional<std::string> old_;
};

// Fixture: a fresh temporary directory per test, removed afterwards.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

#define KARTOGRAF_INSTANTIATE_BACKEND_TESTS(fixture)                                         \
  INSTANTIATE_TEST_SUITE_P(Backends, fixture,                                                \
                           ::testing::ValuesIn(::kartograf::testing::backends_under_test()), \
                           ::kartograf::testing::backend_test_name)

}  // namespace kartograf::testing
