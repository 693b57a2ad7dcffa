// Run by ctest with a backend broken through the environment (see tests/CMakeLists.txt):
// KARTOGRAF_BROKEN_BACKEND names it; it must be reported unavailable with a reason that says why,
// asking for it must be a clear Error, and the other backends must still work.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "kartograf/compute/backend.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf {
namespace {

std::string env(const char* name) {
  const char* value = std::getenv(name);
  return value ? value : "";
}

TEST(MissingBackend, IsReportedWithItsReasonAndOthersStillWork) {
  const std::string broken = env("KARTOGRAF_BROKEN_BACKEND");
  const std::string expected_reason = env("KARTOGRAF_EXPECTED_REASON");
  ASSERT_FALSE(broken.empty()) << "set KARTOGRAF_BROKEN_BACKEND";
  const auto kind = compute::parse_backend_choice(broken, "KARTOGRAF_BROKEN_BACKEND");
  for (const auto& status : compute::probe_backends()) {
    const bool is_broken = compute::to_string(status.backend) == broken;
    std::cout << compute::to_string(status.backend) << ": "
              << (status.available ? "available" : "unavailable: " + status.reason) << "\n";
    if (is_broken) {
      EXPECT_FALSE(status.available);
      EXPECT_NE(status.reason.find(expected_reason), std::string::npos) << status.reason;
    } else {
      EXPECT_TRUE(status.available) << status.reason;
    }
  }
  compute::ContextParams options;
  options.backend = kind;
  try {
    compute::Context context(options);
    FAIL() << "a context was created on the broken backend";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find(expected_reason), std::string::npos) << error.what();
  }
  // Automatic selection still starts.
  EXPECT_NO_THROW(compute::Context{compute::ContextParams{}});
}

}  // namespace
}  // namespace kartograf
