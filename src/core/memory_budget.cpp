#include "kartograf/core/memory_budget.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>

#include "kartograf/core/error.hpp"

namespace kartograf {

namespace {

constexpr char kLimitVariable[] = "KARTOGRAF_MEMORY_LIMIT";

// KARTOGRAF_MEMORY_LIMIT in bytes, if set.
std::optional<std::uint64_t> limit_from_environment() {
  const char* text = std::getenv(kLimitVariable);
  if (text == nullptr || *text == '\0') return std::nullopt;
  char* end = nullptr;
  const double number = std::strtod(text, &end);
  double scale = 1;
  if (end != text && *end != '\0' && end[1] == '\0') {
    switch (*end) {
      case 'K':
      case 'k':
        scale = 1024.0;
        ++end;
        break;
      case 'M':
      case 'm':
        scale = 1024.0 * 1024;
        ++end;
        break;
      case 'G':
      case 'g':
        scale = 1024.0 * 1024 * 1024;
        ++end;
        break;
      default:
        break;
    }
  }
  const double bytes = number * scale;
  require(end != text && *end == '\0' && std::isfinite(bytes) && bytes >= 0 && bytes < 1.8e19,
          std::string(kLimitVariable) + "='" + text +
              "': expected a size in bytes, optionally with a K, M or G suffix (e.g. 512M)");
  return static_cast<std::uint64_t>(bytes);
}

// MemAvailable of /proc/meminfo (RAM the kernel can give without swapping), if readable.
std::optional<std::uint64_t> kernel_available_memory() {
  std::ifstream meminfo("/proc/meminfo");
  std::string line;
  while (std::getline(meminfo, line)) {
    if (line.rfind("MemAvailable:", 0) != 0) continue;
    std::istringstream fields(line.substr(13));
    std::uint64_t kib = 0;
    if (fields >> kib) return kib * 1024;
  }
  return std::nullopt;
}

}  // namespace

std::uint64_t available_memory_bytes() {
  if (const std::optional<std::uint64_t> limit = limit_from_environment()) return *limit;
  std::uint64_t available =
      kernel_available_memory().value_or(std::numeric_limits<std::uint64_t>::max());
  rlimit address_space{};
  if (getrlimit(RLIMIT_AS, &address_space) == 0 && address_space.rlim_cur != RLIM_INFINITY) {
    available = std::min<std::uint64_t>(available, address_space.rlim_cur);
  }
  return available;
}

void require_fits_in_memory(double bytes, const std::string& what) {
  const std::uint64_t available = available_memory_bytes();
  if (!(bytes > static_cast<double>(available))) return;
  const std::string have = memory_size_text(static_cast<double>(available));
  throw Error(what + " needs about " + memory_size_text(bytes) + ", " +
              (limit_from_environment() ? std::string(kLimitVariable) + " allows " + have
                                        : "the machine has " + have + " available"));
}

std::string memory_size_text(double bytes) {
  char text[64];
  const double kib = bytes / 1024;
  if (kib < 1024) {
    std::snprintf(text, sizeof(text), "%.0f kB", std::ceil(kib));
  } else if (kib < 1024.0 * 1024) {
    std::snprintf(text, sizeof(text), "%.1f MB", kib / 1024);
  } else {
    std::snprintf(text, sizeof(text), "%.1f GB", kib / (1024.0 * 1024));
  }
  return text;
}

}  // namespace kartograf
