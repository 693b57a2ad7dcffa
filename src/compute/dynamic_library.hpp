#pragma once
// A shared library opened with dlopen, so that Kartograf never links libvulkan or libOpenCL and
// starts on machines that have neither.
#include <dlfcn.h>

#include <string>
#include <utility>

namespace kartograf::compute::detail {

class DynamicLibrary {
 public:
  DynamicLibrary() = default;
  explicit DynamicLibrary(const char* soname) : handle_(dlopen(soname, RTLD_NOW | RTLD_LOCAL)) {
    if (!handle_) {
      const char* why = dlerror();
      error_ = why ? why : "unknown dlopen error";
    }
  }
  DynamicLibrary(const DynamicLibrary&) = delete;
  DynamicLibrary& operator=(const DynamicLibrary&) = delete;
  DynamicLibrary(DynamicLibrary&& other) noexcept
      : handle_(std::exchange(other.handle_, nullptr)), error_(std::move(other.error_)) {}
  ~DynamicLibrary() {
    if (handle_) dlclose(handle_);
  }

  bool loaded() const { return handle_ != nullptr; }
  const std::string& error() const { return error_; }

  template <class Function>
  Function symbol(const char* name) const {
    return handle_ ? reinterpret_cast<Function>(dlsym(handle_, name)) : nullptr;
  }

 private:
  void* handle_ = nullptr;
  std::string error_;
};

}  // namespace kartograf::compute::detail
