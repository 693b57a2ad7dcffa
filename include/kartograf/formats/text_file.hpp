#pragma once
// Writing a small text file (JSON statistics, reports) atomically: it appears complete or not at
// all. Throws Error naming the file when it cannot be written.
#include <filesystem>
#include <string_view>

namespace kartograf::io {

void write_text_file(const std::filesystem::path& path, std::string_view text);

}  // namespace kartograf::io
