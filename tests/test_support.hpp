#pragma once
// Shared by every test: the backends under test, contexts with Vulkan validation, real data.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "kartograf/compute/context.hpp"

namespace kartograf::compute {
// So that test names and ctest show "vulkan", not a byte dump.
inline void PrintTo(BackendKind kind, std::ostream* out) { *out << to_string(kind); }
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

// Fixture: a fresh temporary directory per test, removed afterwards.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

#define KARTOGRAF_INSTANTIATE_BACKEND_TESTS(fixture)                                     \
  INSTANTIATE_TEST_SUITE_P(Backends, fixture,                                           \
                           ::testing::ValuesIn(::kartograf::testing::backends_under_test()), \
                           ::kartograf::testing::backend_test_name)

}  // namespace kartograf::testing
