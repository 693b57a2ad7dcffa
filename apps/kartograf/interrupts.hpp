#pragma once
// SIGINT, SIGTERM and SIGHUP, on whichever thread they land, end a run without leaving a mix of
// old and new outputs. main() blocks them before any thread exists (every thread inherits the
// mask) and one watcher thread waits for them (sigwait):
//   - while computing: the registered unfinished outputs (staging folders) are removed and the
//     process exits with 128 + signal;
//   - while files are written or moved in (an InterruptsDeferred lives): the signal waits; at the
//     end of the scope the unfinished outputs are removed and the process exits, unless the
//     outputs were already moved in (then they stay, complete).
// A signal the process was started with ignored (nohup, background jobs of a script) stays ignored.
#include <filesystem>

namespace kartograf::cli {

// Call first thing in main(), before any thread is started.
void start_interrupt_watcher();

// What an interrupt removes: a run's unfinished outputs (a staging folder with its contents), or
// a folder this run created for them (only while it is empty).
void remove_on_interrupt(const std::filesystem::path& path, bool with_contents = true);
void keep_on_interrupt(const std::filesystem::path& path);

// While one lives, an interrupt waits; when the last one ends (not by an exception), a signal
// that came meanwhile removes the unfinished outputs and exits with 128 + signal.
class InterruptsDeferred {
 public:
  InterruptsDeferred();
  ~InterruptsDeferred();
  InterruptsDeferred(const InterruptsDeferred&) = delete;
  InterruptsDeferred& operator=(const InterruptsDeferred&) = delete;
};

// A checkpoint for long writes: when a signal has come, removes the unfinished outputs and exits.
void exit_if_interrupted();

}  // namespace kartograf::cli
