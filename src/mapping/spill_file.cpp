#include "kartograf/mapping/spill_file.hpp"

#include <utility>

#include "kartograf/core/error.hpp"

namespace kartograf::mapping {

SpillFile::SpillFile(std::string what) : what_(std::move(what)) {}

std::size_t SpillFile::append(std::span<const std::uint8_t> bytes) {
  const std::span<const std::uint8_t> pieces[] = {bytes};
  return append(std::span<const std::span<const std::uint8_t>>(pieces));
}

std::size_t SpillFile::append(std::span<const std::span<const std::uint8_t>> pieces) {
  const std::lock_guard lock(mutex_);
  if (!file_) {
    file_.reset(std::tmpfile());
    require(file_ != nullptr, what_ + ": cannot create a temporary file");
  }
  bool written = std::fseek(file_.get(), static_cast<long>(end_), SEEK_SET) == 0;
  std::size_t length = 0;
  for (const std::span<const std::uint8_t> piece : pieces) {
    written = written && std::fwrite(piece.data(), 1, piece.size(), file_.get()) == piece.size();
    length += piece.size();
  }
  require(written, what_ + ": writing to the temporary file failed (disk full?)");
  const std::size_t offset = end_;
  end_ += length;
  return offset;
}

void SpillFile::read(std::size_t offset, std::span<std::uint8_t> out) const {
  const std::lock_guard lock(mutex_);
  require(file_ != nullptr && offset + out.size() <= end_,
          what_ + ": reading past the end of the temporary file");
  const bool read = std::fseek(file_.get(), static_cast<long>(offset), SEEK_SET) == 0 &&
                    std::fread(out.data(), 1, out.size(), file_.get()) == out.size();
  require(read, what_ + ": reading back from the temporary file failed");
}

}  // namespace kartograf::mapping
