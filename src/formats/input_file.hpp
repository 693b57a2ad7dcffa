#pragma once
// Opening input files for the readers with one set of messages, so that every format says the
// same about a missing file, a directory or a failed read: "<name>: no such file", "<name>: is a
// directory, not a file", "<name>: cannot open: <why>", "<name>: read failed: <why>".
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace kartograf::io::detail {

// Every byte of path. Throws Error starting with `name` (what the file is and its quoted path,
// e.g. "PLY file 'a.ply'") when it cannot be read. An empty file is no error here: each format
// says itself why it is not one of its files.
std::vector<std::uint8_t> read_file_bytes(const std::filesystem::path& path,
                                          const std::string& name);

// path opened for reading text line by line; throws Error "'<path>': cannot open" when it cannot.
std::ifstream open_text_file(const std::filesystem::path& path);

}  // namespace kartograf::io::detail
