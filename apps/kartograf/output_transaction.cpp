#include "output_transaction.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <system_error>
#include <utility>

#include "interrupts.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/text_file.hpp"

namespace kartograf::cli {

namespace {

namespace fs = std::filesystem;

std::string in_quotes(const fs::path& path) {
  std::string text(1, '\'');
  text += path.string();
  text += '\'';
  return text;
}

// Staging paths and what they stand for, to name the targets in error messages.
std::vector<std::pair<std::string, std::string>>& shown_paths() {
  static std::vector<std::pair<std::string, std::string>> paths;
  return paths;
}

std::string pid_text() {
  return std::to_string(::getpid());
}

// ".<name>.kartograf-<kind>-<pid>" beside the target.
fs::path sibling(const fs::path& target, std::string_view kind, const std::string& pid) {
  // Appended piecewise: "." + string trips GCC 12's false -Wrestrict positive at -O3.
  std::string name(1, '.');
  name += target.filename().string();
  name += ".kartograf-";
  name += kind;
  name += '-';
  name += pid;
  return target.parent_path() / name;
}

bool process_is_gone(const std::string& digits) {
  if (digits.empty() || digits.size() > 9 ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return false;
  const pid_t pid = static_cast<pid_t>(std::stol(digits));
  return pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH;
}

// Staging (and swapped-out) folders of earlier runs that died before they could remove them.
void remove_stale_staging(const fs::path& target) {
  std::string prefix(1, '.');
  prefix += target.filename().string();
  prefix += ".kartograf-";
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(target.parent_path(), error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    for (const std::string kind : {"staging-", "old-"}) {
      if (rest.rfind(kind, 0) == 0 && process_is_gone(rest.substr(kind.size()))) {
        std::error_code ignored;
        fs::remove_all(entry.path(), ignored);
      }
    }
  }
}

// Creates the missing folders above target (returned outermost first); the nearest existing one
// must be a folder.
std::vector<fs::path> create_parents(std::string_view command, const fs::path& target) {
  std::vector<fs::path> missing;
  fs::path folder = target.parent_path();
  std::error_code error;
  while (!fs::exists(fs::symlink_status(folder, error)) && folder != folder.parent_path()) {
    missing.push_back(folder);
    folder = folder.parent_path();
  }
  require(fs::is_directory(folder, error), std::string(command) + ": cannot write " +
                                               in_quotes(target) + ": " + in_quotes(folder) +
                                               " is not a folder");
  std::reverse(missing.begin(), missing.end());
  for (const fs::path& parent : missing) {
    if (::mkdir(parent.c_str(), 0777) != 0 && errno != EEXIST) {
      const std::string reason = std::strerror(errno);
      for (auto it = missing.rbegin(); it != missing.rend(); ++it) fs::remove(*it, error);
      throw Error(std::string(command) + ": cannot create the folder " + in_quotes(parent) +
                  " for " + in_quotes(target) + ": " + reason);
    }
  }
  return missing;
}

// The absolute path of a target as the user named it ("out/" and "out" are the same).
fs::path absolute_target(std::string_view command, std::string_view option,
                         const fs::path& target) {
  require(!target.empty(), std::string(command) + ": " + std::string(option) +
                               " is empty: name where the results should go");
  fs::path path = fs::absolute(target).lexically_normal();
  if (!path.has_filename()) path = path.parent_path();
  require(path.has_filename() && path != path.parent_path(),
          std::string(command) + ": " + std::string(option) + " " + in_quotes(target) +
              " cannot take results: name a folder below it");
  return path;
}

// True when every entry is one Kartograf writes: its marker, or (a run of an earlier version) a
// known name or an atomic writer's leftover "<known>.tmp-<pid>". first_foreign: the first other.
bool holds_only_kartograf_files(const fs::path& dir, const std::vector<std::string>& known,
                                std::string& first_foreign) {
  std::error_code error;
  if (fs::exists(dir / kRunMarker, error)) return true;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, error)) {
    const std::string name = entry.path().filename().string();
    const bool is_known = std::any_of(known.begin(), known.end(), [&](const std::string& k) {
      return name == k || name.rfind(k + ".tmp-", 0) == 0;
    });
    if (!is_known) {
      first_foreign = name;
      return false;
    }
  }
  return true;
}

// The checks of a `--out DIR` that exists, before any computing.
fs::path checked_folder(std::string_view command, const fs::path& target, bool force,
                        const std::vector<std::string>& known) {
  const fs::path path = absolute_target(command, "--out", target);
  const std::string name = std::string(command) + ": --out " + in_quotes(target);
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (!fs::exists(status)) return path;
  require(fs::is_directory(status), name + " exists and is not a folder");
  require(::access(path.c_str(), R_OK | W_OK | X_OK) == 0,
          name + ": cannot replace its files: " + std::strerror(errno));
  const bool empty = fs::is_empty(path, error);
  require(!error, name + ": cannot read it: " + error.message());
  if (empty) return path;
  std::string foreign;
  const bool ours = holds_only_kartograf_files(path, known, foreign);
  require(ours, name + " holds files that no Kartograf run wrote (e.g. '" + foreign +
                    "'): --force replaces only an earlier run's folder; choose another folder");
  require(force, name + " holds the files of an earlier run: use --force to replace them");
  return path;
}

// The checks of a single-file target (odometry --out), before any computing.
fs::path checked_file(std::string_view command, std::string_view option, const fs::path& target,
                      bool force) {
  const fs::path path = absolute_target(command, option, target);
  const std::string name =
      std::string(command) + ": " + std::string(option) + " " + in_quotes(target);
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (!fs::exists(status)) return path;
  require(!fs::is_directory(status), name + " is a folder: name a file");
  require(force, name + " exists (an earlier run?): use --force to replace it");
  return path;
}

[[noreturn]] void fail_to_move(std::string_view command, const fs::path& from, const fs::path& to) {
  throw Error(std::string(command) + ": cannot move the results from " + in_quotes(from) + " to " +
              in_quotes(to) + ": " + std::strerror(errno));
}

}  // namespace

StagingFolder::StagingFolder(std::string_view command, const fs::path& target, bool for_file)
    : target_(target), path_(sibling(target, "staging", pid_text())) {
  created_parents_ = create_parents(command, target_);
  for (const fs::path& parent : created_parents_) remove_on_interrupt(parent, false);
  remove_stale_staging(target_);
  remove_on_interrupt(path_);
  if (::mkdir(path_.c_str(), 0777) != 0) {
    const std::string reason = std::strerror(errno);
    release();
    std::error_code ignored;
    for (auto it = created_parents_.rbegin(); it != created_parents_.rend(); ++it)
      fs::remove(*it, ignored);
    throw Error(std::string(command) + ": cannot write " + in_quotes(target_) +
                ": cannot create a folder in " + in_quotes(target_.parent_path()) + ": " + reason);
  }
  if (for_file)
    shown_paths().emplace_back((path_ / target_.filename()).string(), target_.string());
  else
    shown_paths().emplace_back(path_.string(), target_.string());
}

StagingFolder::~StagingFolder() {
  if (released_) return;
  std::error_code ignored;
  fs::remove_all(path_, ignored);
  for (auto it = created_parents_.rbegin(); it != created_parents_.rend(); ++it)
    fs::remove(*it, ignored);  // only while empty
  release();
}

void StagingFolder::release() {
  released_ = true;
  keep_on_interrupt(path_);
  for (const fs::path& parent : created_parents_) keep_on_interrupt(parent);
}

OutputFolder::OutputFolder(std::string_view command, const fs::path& target, bool force,
                           const std::vector<std::string>& known_files)
    : command_(command),
      staging_(command, checked_folder(command, target, force, known_files), false) {}

void OutputFolder::commit() {
  const InterruptsDeferred deferred;  // the swap is never cut in half
  exit_if_interrupted();              // a signal while writing: this run's files are dropped
  io::write_text_file(dir() / kRunMarker, "kartograf " + command_ + "\n");
  const fs::path& target = staging_.target();
  const fs::path& staging = staging_.path();
  std::error_code error;
  fs::path previous;  // where the previous set went
  if (!fs::exists(fs::symlink_status(target, error))) {
    if (::rename(staging.c_str(), target.c_str()) != 0) fail_to_move(command_, staging, target);
  } else if (::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) ==
             0) {
    previous = staging;
  } else if (errno == EINVAL || errno == ENOSYS) {  // a file system without exchange
    previous = sibling(target, "old", pid_text());
    if (::rename(target.c_str(), previous.c_str()) != 0) fail_to_move(command_, target, previous);
    if (::rename(staging.c_str(), target.c_str()) != 0) {
      const int reason = errno;
      ::rename(previous.c_str(), target.c_str());
      errno = reason;
      fail_to_move(command_, staging, target);
    }
  } else {
    fail_to_move(command_, staging, target);
  }
  staging_.release();
  if (!previous.empty()) fs::remove_all(previous, error);  // a leftover goes with the next run
}

fs::path OutputFiles::add(std::string_view option, const fs::path& target) {
  const fs::path path = checked_file(command_, option, target, force_);
  for (const auto& s : staging_)
    require(s->target() != path,
            command_ + ": " + std::string(option) + " " + in_quotes(target) + " is named twice");
  staging_.push_back(std::make_unique<StagingFolder>(command_, path, true));
  return staging_.back()->path() / path.filename();
}

void OutputFiles::commit() {
  const InterruptsDeferred deferred;
  exit_if_interrupted();
  std::error_code error;
  for (const auto& s : staging_) {
    const fs::path written = s->path() / s->target().filename();
    if (!fs::exists(written, error)) continue;
    if (::rename(written.c_str(), s->target().c_str()) != 0)
      fail_to_move(command_, written, s->target());
  }
  for (const auto& s : staging_) {
    fs::remove(s->path(), error);
    s->release();
  }
}

std::string describe_output_error(std::string message) {
  std::string untouched;
  for (const auto& [staging, target] : shown_paths()) {
    for (std::size_t at = message.find(staging); at != std::string::npos;
         at = message.find(staging, at + target.size())) {
      message.replace(at, staging.size(), target);
      untouched = target;
    }
  }
  if (!untouched.empty()) message += " (" + in_quotes(untouched) + " was left untouched)";
  return message;
}

}  // namespace kartograf::cli
