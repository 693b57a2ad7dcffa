#pragma once
// Commands that write a folder of results refuse to overwrite an earlier run's files unless told
// to, and say so before any work is done.
#include <filesystem>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

namespace kartograf::cli {

// Throws Error (prefixed with `command`) when `dir` exists and is not a folder, or holds one of
// `files`, unless `force`.
void check_output_folder(std::string_view command, const std::filesystem::path& dir,
                         std::initializer_list<const char*> files, bool force);
void check_output_folder(std::string_view command, const std::filesystem::path& dir,
                         const std::vector<std::string>& files, bool force);

}  // namespace kartograf::cli
