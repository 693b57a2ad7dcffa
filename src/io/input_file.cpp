#include "io/input_file.hpp"

#include <cerrno>
#include <cstring>
#include <iterator>
#include <system_error>

#include "io/atomic_file.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::io::detail {

std::vector<std::uint8_t> read_file_bytes(const std::filesystem::path& path,
                                          const std::string& name) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found) throw Error(name + ": no such file");
  if (error) throw Error(name + ": cannot access: " + error.message());
  if (std::filesystem::is_directory(status)) throw Error(name + ": is a directory, not a file");
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw Error(name + ": cannot open: " + std::strerror(errno));
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(stream)),
                                  std::istreambuf_iterator<char>());
  if (stream.bad()) throw Error(name + ": read failed: " + std::strerror(errno));
  return bytes;
}

std::ifstream open_text_file(const std::filesystem::path& path) {
  std::ifstream stream(path);
  require(stream.is_open(), quoted(path) + ": cannot open");
  return stream;
}

}  // namespace kartograf::io::detail
