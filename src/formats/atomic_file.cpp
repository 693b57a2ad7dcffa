#include "formats/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>
#include <utility>

#include "kartograf/core/error.hpp"

namespace kartograf::io::detail {

std::string quoted(const std::filesystem::path& path) {
  // Appended piecewise: "'" + string trips GCC 12's false -Wrestrict positive at -O3.
  std::string text(1, '\'');
  text += path.string();
  text += '\'';
  return text;
}

AtomicFileWriter::AtomicFileWriter(std::filesystem::path path) : path_(std::move(path)) {
  temp_path_ = path_;
  temp_path_ += ".tmp-" + std::to_string(::getpid());
  file_ = std::fopen(temp_path_.c_str(), "wb");
  if (!file_) {
    throw Error("cannot write " + quoted(path_) + ": cannot create temporary file " +
                quoted(temp_path_) + ": " + std::strerror(errno));
  }
}

AtomicFileWriter::~AtomicFileWriter() {
  if (!committed_) discard();
}

void AtomicFileWriter::discard() noexcept {
  if (file_) {
    std::fclose(file_);
    file_ = nullptr;
  }
  std::error_code ignored;
  std::filesystem::remove(temp_path_, ignored);
}

void AtomicFileWriter::fail(const std::string& problem) {
  const std::string reason = std::strerror(errno);
  discard();
  throw Error("cannot write " + quoted(path_) + ": " + problem + ": " + reason);
}

void AtomicFileWriter::write(const void* data, std::size_t bytes) {
  require(file_ != nullptr && !committed_, "cannot write " + quoted(path_) + ": already closed");
  if (bytes == 0) return;
  if (std::fwrite(data, 1, bytes, file_) != bytes) fail("write failed");
}

void AtomicFileWriter::commit() {
  require(file_ != nullptr && !committed_, "cannot write " + quoted(path_) + ": already closed");
  // fsync before rename: otherwise a crash can leave the new name pointing at empty data.
  if (std::fflush(file_) != 0) fail("write failed");
  if (::fsync(::fileno(file_)) != 0) fail("fsync failed");
  const int close_result = std::fclose(file_);
  file_ = nullptr;
  if (close_result != 0) fail("close failed");
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    fail("cannot rename " + quoted(temp_path_) + " to it");
  }
  committed_ = true;
}

void write_file_atomically(const std::filesystem::path& path, const void* data, std::size_t bytes) {
  AtomicFileWriter writer(path);
  writer.write(data, bytes);
  writer.commit();
}

}  // namespace kartograf::io::detail
