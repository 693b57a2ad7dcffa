#include "interrupts.hpp"

#include <pthread.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <exception>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace kartograf::cli {

namespace {

namespace fs = std::filesystem;

constexpr int kHandledSignals[] = {SIGINT, SIGTERM, SIGHUP};

struct InterruptState {
  std::mutex mutex;
  struct Unfinished {
    fs::path path;
    bool with_contents;
  };
  std::vector<Unfinished> unfinished;  // removed on an interrupt, last first
  int deferring = 0;                   // live InterruptsDeferred scopes
  int pending = 0;                     // a signal that came while deferring
};

InterruptState& state() {
  static InterruptState s;
  return s;
}

const char* signal_name(int signal) {
  switch (signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    default:
      return "a signal";
  }
}

// Writers on other threads may still add files to a folder being removed: retry until it is gone.
void remove_unfinished(const fs::path& path, bool with_contents) {
  std::error_code error;
  if (!with_contents) {
    fs::remove(path, error);  // only when empty
    return;
  }
  for (int attempt = 0; attempt < 50; ++attempt) {
    fs::remove_all(path, error);
    if (!fs::exists(fs::symlink_status(path, error))) return;
  }
}

[[noreturn]] void exit_interrupted(InterruptState& s, int signal) {
  const bool removed = !s.unfinished.empty();
  for (auto it = s.unfinished.rbegin(); it != s.unfinished.rend(); ++it)
    remove_unfinished(it->path, it->with_contents);
  std::string message = std::string("\nkartograf: interrupted (") + signal_name(signal) + ")";
  message +=
      removed ? ": this run's unfinished outputs were removed, earlier ones are untouched\n" : "\n";
  // write(2), not iostreams: another thread may be inside std::cerr.
  [[maybe_unused]] const ssize_t ignored = ::write(2, message.data(), message.size());
  ::_exit(128 + signal);
}

void watch(sigset_t signals) {
  for (;;) {
    int signal = 0;
    if (sigwait(&signals, &signal) != 0) continue;
    InterruptState& s = state();
    const std::lock_guard lock(s.mutex);
    if (s.deferring == 0) exit_interrupted(s, signal);
    if (s.pending == 0) s.pending = signal;
  }
}

}  // namespace

void start_interrupt_watcher() {
  sigset_t signals;
  sigemptyset(&signals);
  for (const int signal : kHandledSignals) {
    struct sigaction current {};
    if (sigaction(signal, nullptr, &current) == 0 && current.sa_handler == SIG_IGN) continue;
    sigaddset(&signals, signal);
  }
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::thread(watch, signals).detach();
}

void remove_on_interrupt(const fs::path& path, bool with_contents) {
  InterruptState& s = state();
  const std::lock_guard lock(s.mutex);
  s.unfinished.push_back({path, with_contents});
}

void keep_on_interrupt(const fs::path& path) {
  InterruptState& s = state();
  const std::lock_guard lock(s.mutex);
  s.unfinished.erase(
      std::remove_if(s.unfinished.begin(), s.unfinished.end(),
                     [&](const InterruptState::Unfinished& u) { return u.path == path; }),
      s.unfinished.end());
}

InterruptsDeferred::InterruptsDeferred() {
  InterruptState& s = state();
  const std::lock_guard lock(s.mutex);
  ++s.deferring;
}

InterruptsDeferred::~InterruptsDeferred() {
  InterruptState& s = state();
  const std::lock_guard lock(s.mutex);
  // Unwinding: the error is reported first (main() checks for a signal after it).
  if (--s.deferring == 0 && s.pending != 0 && std::uncaught_exceptions() == 0)
    exit_interrupted(s, s.pending);
}

void exit_if_interrupted() {
  InterruptState& s = state();
  const std::lock_guard lock(s.mutex);
  if (s.pending != 0) exit_interrupted(s, s.pending);
}

}  // namespace kartograf::cli
