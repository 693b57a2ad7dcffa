#include "kartograf/core/models.hpp"

namespace kartograf {

std::filesystem::path models_dir() {
  const std::filesystem::path source(KARTOGRAF_SOURCE_MODELS_DIR);
  std::error_code ignored;
  if (std::filesystem::is_directory(source, ignored)) return source;
  return KARTOGRAF_INSTALLED_MODELS_DIR;
}

}  // namespace kartograf
