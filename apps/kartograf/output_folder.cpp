#include "output_folder.hpp"

#include <string>

#include "kartograf/core/error.hpp"

namespace kartograf::cli {

void check_output_folder(std::string_view command, const std::filesystem::path& dir,
                         std::initializer_list<const char*> files, bool force) {
  check_output_folder(command, dir, std::vector<std::string>(files.begin(), files.end()), force);
}

void check_output_folder(std::string_view command, const std::filesystem::path& dir,
                         const std::vector<std::string>& files, bool force) {
  if (force || !std::filesystem::exists(dir)) return;
  const std::string prefix = std::string(command) + ": ";
  require(std::filesystem::is_directory(dir),
          prefix + "--out " + dir.string() + " exists and is not a folder");
  for (const std::string& file : files) {
    require(!std::filesystem::exists(dir / file),
            prefix + (dir / file).string() + " exists (an earlier run?): use --force to overwrite");
  }
}

}  // namespace kartograf::cli
