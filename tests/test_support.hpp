#pragma once
// Shared by the tests that run on the backends: the backends under test and contexts with Vulkan
// validation, with everything of test_support_core.hpp.
#include <memory>
#include <optional>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "test_support_core.hpp"

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

#define KARTOGRAF_INSTANTIATE_BACKEND_TESTS(fixture)                                         \
  INSTANTIATE_TEST_SUITE_P(Backends, fixture,                                                \
                           ::testing::ValuesIn(::kartograf::testing::backends_under_test()), \
                           ::kartograf::testing::backend_test_name)

}  // namespace kartograf::testing
