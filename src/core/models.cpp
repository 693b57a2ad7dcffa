#include "kartograf/core/models.hpp"

#include <cstdlib>

namespace kartograf {

std::filesystem::path models_dir() {
  // A relocated install (the Python package) says where its copy is.
  const char* configured = std::getenv("KARTOGRAF_MODELS_DIR");
  if (configured && *configured) return configured;
  const std::filesystem::path source(KARTOGRAF_SOURCE_MODELS_DIR);
  std::error_code ignored;
  if (std::filesystem::is_directory(source, ignored)) return source;
  return KARTOGRAF_INSTALLED_MODELS_DIR;
}

}  // namespace kartograf
