#include "compute/cpu_parallel.hpp"

#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>

namespace kartograf::compute::detail {

namespace {

// Helper threads that sleep between calls, for the process's lifetime (never destroyed: they
// end with the process). One call at a time: `busy_` is set for a call's whole run; a second
// caller finds it set and runs its chunks alone.
class ChunkPool {
 public:
  // False when another call holds the pool (a flag, not a mutex: a chunk's own nested call comes
  // from the thread that holds it).
  bool run(std::size_t threads, void (*run_chunk)(const void*, std::size_t), const void* context) {
    bool idle = false;
    if (!busy_.compare_exchange_strong(idle, true)) return false;
    const Release release{busy_};
    const std::size_t wanted = std::min(threads, kCpuChunks) - 1;
    while (helpers_.size() < wanted) {
      const std::size_t index = helpers_.size();
      // It starts from the calls made so far, so that it waits for this one.
      helpers_.emplace_back([this, index, seen = call_.load()] { serve(index, seen); });
    }
    {
      const std::lock_guard lock(mutex_);
      run_chunk_ = run_chunk, context_ = context;
      next_ = 0, helpers_in_call_ = wanted, running_ = wanted;
      ++call_;
    }
    wake_.notify_all();
    std::exception_ptr error;
    try {
      take_chunks();
    } catch (...) {
      error = std::current_exception();
    }
    spin_while([this] { return running_.load(std::memory_order_acquire) != 0; });
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return running_ == 0; });
    lock.unlock();
    if (error) std::rethrow_exception(error);
    return true;
  }

 private:
  struct Release {
    std::atomic<bool>& flag;
    ~Release() { flag = false; }
  };

  void take_chunks() {
    for (std::size_t chunk = next_++; chunk < kCpuChunks; chunk = next_++)
      run_chunk_(context_, chunk);
  }

  // Spins a short while (about 50 microseconds) while `waiting()`: a frame's stages call one
  // after the other, and a helper asleep on the condition variable takes tens of microseconds to
  // wake (the cells mode's plane extraction makes about ten calls a frame).
  template <class Waiting>
  static void spin_while(Waiting&& waiting) {
    for (int spin = 0; spin < kSpins && waiting(); ++spin) {
#if defined(__x86_64__) || defined(__i386__)
      __builtin_ia32_pause();
#endif
    }
  }

  void serve(std::size_t index, std::uint64_t seen) {
    for (;;) {
      spin_while([&] { return call_.load(std::memory_order_acquire) == seen; });
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return call_ != seen; });
      seen = call_;
      if (index >= helpers_in_call_) continue;  // fewer threads asked for this call
      lock.unlock();
      take_chunks();
      lock.lock();
      if (--running_ == 0) done_.notify_one();
    }
  }

  std::atomic<bool> busy_{false};
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::vector<std::thread> helpers_;
  void (*run_chunk_)(const void*, std::size_t) = nullptr;
  const void* context_ = nullptr;
  std::atomic<std::size_t> next_{0};
  static constexpr int kSpins = 2000;
  std::size_t helpers_in_call_ = 0;
  std::atomic<std::size_t> running_{0};
  std::atomic<std::uint64_t> call_{0};
};

// The process's pool; a child process made by fork() (which copies no threads) makes its own.
ChunkPool& pool() {
  static std::mutex guard;
  static ChunkPool* current = nullptr;
  static pid_t owner = 0;
  const std::lock_guard lock(guard);
  if (current == nullptr || owner != getpid()) {
    current = new ChunkPool;  // never deleted (see ChunkPool); a forked child's old one is inert
    owner = getpid();
  }
  return *current;
}

}  // namespace

void run_chunks(std::size_t threads, void (*run_chunk)(const void*, std::size_t),
                const void* context) {
  if (pool().run(threads, run_chunk, context)) return;
  for (std::size_t chunk = 0; chunk < kCpuChunks; ++chunk) run_chunk(context, chunk);
}

}  // namespace kartograf::compute::detail
