#include "formats/input_file.hpp"

#include <cerrno>
#include <cstring>
#include <iterator>
#include <system_error>

#include "formats/atomic_file.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/core/memory_budget.hpp"

namespace kartograf::io::detail {

std::vector<std::uint8_t> read_file_bytes(const std::filesystem::path& path,
                                          const std::string& name) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found) throw Error(name + ": no such file");
  if (error) throw Error(name + ": cannot access: " + error.message());
  if (std::filesystem::is_directory(status)) throw Error(name + ": is a directory, not a file");
  // A device or a pipe (/dev/zero, /dev/stdin) has no size and may never end: regular files only.
  if (!std::filesystem::is_regular_file(status)) {
    throw Error(name + ": is not a regular file (a device, a pipe or a socket)");
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) throw Error(name + ": cannot access: " + error.message());
  require_fits_in_memory(static_cast<double>(size), "reading " + name);
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw Error(name + ": cannot open: " + std::strerror(errno));
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(stream)),
                                  std::istreambuf_iterator<char>());
  if (stream.bad()) throw Error(name + ": read failed: " + std::strerror(errno));
  return bytes;
}

std::ifstream open_text_file(const std::filesystem::path& path) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  // Lines of a device (/dev/zero) never end: only regular files are read line by line.
  require(error || status.type() == std::filesystem::file_type::not_found ||
              std::filesystem::is_regular_file(status),
          quoted(path) + ": is not a regular file (a directory, a device or a pipe)");
  std::ifstream stream(path);
  require(stream.is_open(), quoted(path) + ": cannot open");
  return stream;
}

}  // namespace kartograf::io::detail
