#pragma once
// Writing files so that nobody ever sees a partial one (a crash, a full disk, an exception
// halfway): the bytes go to "<path>.tmp-<pid>", which is renamed over <path> only once complete.
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace kartograf::io::detail {

class AtomicFileWriter {
 public:
  // Throws Error naming path when the temporary file cannot be created.
  explicit AtomicFileWriter(std::filesystem::path path);
  // Without commit() the temporary file is deleted and path is left as it was.
  ~AtomicFileWriter();
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  void write(const void* data, std::size_t bytes);
  void write(std::string_view text) { write(text.data(), text.size()); }
  // Flushes the data to disk and renames the temporary file to path.
  void commit();

  const std::filesystem::path& path() const { return path_; }

 private:
  [[noreturn]] void fail(const std::string& problem);
  void discard() noexcept;

  std::filesystem::path path_;
  std::filesystem::path temp_path_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

// One-shot form for data that is already in memory.
void write_file_atomically(const std::filesystem::path& path, const void* data, std::size_t bytes);

// "'<path>'": how messages name files.
std::string quoted(const std::filesystem::path& path);

}  // namespace kartograf::io::detail
