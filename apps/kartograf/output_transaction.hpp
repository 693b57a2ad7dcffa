#pragma once
// Outputs all or nothing, for every command that writes results. The output location is checked
// when the transaction is made, before any computing (an empty path, a parent that is a file or
// cannot be created, a file where a folder is expected, no permission, an earlier run's files
// without --force). The results are written into a staging folder beside the target, on the same
// file system (".<name>.kartograf-staging-<pid>"), and moved in by commit():
//   - a folder (`--out DIR`): swapped in as a whole (renameat2 RENAME_EXCHANGE, else old away and
//     new in), so that --force replaces the previous set as a whole; the folder is marked as a
//     Kartograf run's (kRunMarker), and --force replaces nothing else;
//   - files (`odometry --out FILE --stats FILE`, `rooms-eval --csv FILE`): each renamed in.
// Interrupts (interrupts.hpp) remove the staging folder while computing and wait for a commit to
// finish; a failed write or an error removes it too. Staging folders of a process that died
// (SIGKILL, power loss) are removed by the next run that writes to the same place.
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace kartograf::cli {

// Written into every output folder; its presence tells --force the folder is Kartograf's.
inline constexpr const char* kRunMarker = ".kartograf-run";

// Where a run's files go before they are moved in: a fresh folder beside the target. Removed on
// destruction (and on an interrupt) unless released.
class StagingFolder {
 public:
  // target: absolute. for_file: the target is a file, written as path() / its name.
  StagingFolder(std::string_view command, const std::filesystem::path& target, bool for_file);
  ~StagingFolder();
  StagingFolder(const StagingFolder&) = delete;
  StagingFolder& operator=(const StagingFolder&) = delete;

  const std::filesystem::path& path() const { return path_; }
  const std::filesystem::path& target() const { return target_; }  // absolute
  // The staging folder is no longer this run's to remove (it was moved in or away).
  void release();

 private:
  std::filesystem::path target_, path_;
  std::vector<std::filesystem::path> created_parents_;  // outermost first
  bool released_ = false;
};

// `--out DIR` of a command. Throws Error naming the path and the problem.
class OutputFolder {
 public:
  // known_files: the names a run of `command` writes; a folder without kRunMarker that holds
  // only those (a run of an earlier version) also counts as an earlier run.
  OutputFolder(std::string_view command, const std::filesystem::path& target, bool force,
               const std::vector<std::string>& known_files = {});

  // Where to write the files now (the staging folder).
  const std::filesystem::path& dir() const { return staging_.path(); }
  // Marks the folder and moves it in; interrupts wait until it is in place.
  void commit();

 private:
  std::string command_;
  StagingFolder staging_;
};

// Single files named by options. add() checks each (before computing) and says where to write it.
class OutputFiles {
 public:
  OutputFiles(std::string_view command, bool force) : command_(command), force_(force) {}
  std::filesystem::path add(std::string_view option, const std::filesystem::path& target);
  // Renames every written file into place; interrupts wait until all are.
  void commit();

 private:
  std::string command_;
  bool force_;
  std::vector<std::unique_ptr<StagingFolder>> staging_;
};

// An error's message with staging paths replaced by the targets they stand for, and a note that
// the outputs were left as they were (main() prints it).
std::string describe_output_error(std::string message);

}  // namespace kartograf::cli
