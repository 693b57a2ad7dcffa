#include "kartograf/formats/text_file.hpp"

#include "formats/atomic_file.hpp"

namespace kartograf::io {

void write_text_file(const std::filesystem::path& path, std::string_view text) {
  detail::write_file_atomically(path, text.data(), text.size());
}

}  // namespace kartograf::io
