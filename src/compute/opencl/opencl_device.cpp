// The OpenCL backend: libOpenCL.so.1 (the ICD loader) is opened at run time; the embedded sources of
// kernels/ are built into one program per device.
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <deque>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "compute/device.hpp"
#include "compute/dynamic_library.hpp"
#include "compute/embedded_kernels.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::compute::detail {
namespace {

// Every OpenCL entry point Kartograf uses, resolved from the loader.
#define KARTOGRAF_CL_FUNCTIONS(X)                                                               \
  X(clGetPlatformIDs) X(clGetPlatformInfo) X(clGetDeviceIDs) X(clGetDeviceInfo)                 \
  X(clCreateContext) X(clReleaseContext) X(clCreateCommandQueue) X(clReleaseCommandQueue)      \
  X(clCreateBuffer) X(clReleaseMemObject) X(clEnqueueWriteBuffer) X(clEnqueueReadBuffer)       \
  X(clEnqueueFillBuffer) X(clCreateProgramWithSource) X(clBuildProgram)                        \
  X(clGetProgramBuildInfo) X(clReleaseProgram) X(clCreateKernel) X(clCreateKernelsInProgram)   \
  X(clReleaseKernel) X(clSetKernelArg) X(clEnqueueNDRangeKernel) X(clFinish) X(clFlush)       \
  X(clEnqueueCopyBuffer) X(clGetEventProfilingInfo) X(clReleaseEvent)

struct OpenclApi {
#define KARTOGRAF_CL_MEMBER(name) decltype(&::name) name = nullptr;
  KARTOGRAF_CL_FUNCTIONS(KARTOGRAF_CL_MEMBER)
#undef KARTOGRAF_CL_MEMBER
  std::string error;  // why the API is unusable; empty when loaded
};

bool writable_directory(const std::string& path) {
  struct stat info {};
  if (stat(path.c_str(), &info) == 0) return S_ISDIR(info.st_mode) && access(path.c_str(), W_OK) == 0;
  // Missing: writable if its parent is (PoCL creates it).
  const auto slash = path.find_last_of('/');
  return slash != std::string::npos && slash > 0 && writable_directory(path.substr(0, slash));
}

// PoCL silently reports zero devices when it cannot write its kernel cache. Give it a writable
// cache before the loader starts it, and remember what was wrong for the error message.
std::string prepare_pocl_cache() {
  if (const char* configured = std::getenv("POCL_CACHE_DIR")) {
    return writable_directory(configured)
               ? std::string()
               : std::string("POCL_CACHE_DIR=") + configured + " is not a writable directory";
  }
  std::string default_dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME")) {
    default_dir = xdg;
  } else if (const char* home = std::getenv("HOME")) {
    default_dir = std::string(home) + "/.cache";
  }
  if (!default_dir.empty() && writable_directory(default_dir)) return {};
  const char* tmp = std::getenv("TMPDIR");
  const std::string fallback = std::string(tmp ? tmp : "/tmp") + "/kartograf-pocl-cache-" +
                               std::to_string(getuid());
  setenv("POCL_CACHE_DIR", fallback.c_str(), 0);
  return {};
}

const OpenclApi& opencl_api() {
  static const OpenclApi api = [] {
    OpenclApi result;
    const std::string cache_problem = prepare_pocl_cache();
    static DynamicLibrary library("libOpenCL.so.1");  // kept loaded for the process's lifetime
    if (!library.loaded()) {
      result.error = "no OpenCL ICD loader (libOpenCL.so.1): " + library.error() +
                     " (install ocl-icd-libopencl1 and a driver such as pocl-opencl-icd)";
      return result;
    }
#define KARTOGRAF_CL_LOAD(name)                                         \
  result.name = library.symbol<decltype(&::name)>(#name);                \
  if (!result.name && result.error.empty()) {                            \
    result.error = "libOpenCL.so.1 lacks " #name " (OpenCL 1.2 needed)"; \
  }
    KARTOGRAF_CL_FUNCTIONS(KARTOGRAF_CL_LOAD)
#undef KARTOGRAF_CL_LOAD
    if (result.error.empty() && !cache_problem.empty()) result.error = cache_problem;
    return result;
  }();
  return api;
}

std::string cl_error_name(cl_int code) {
  switch (code) {
    case CL_DEVICE_NOT_FOUND: return "CL_DEVICE_NOT_FOUND";
    case CL_OUT_OF_RESOURCES: return "CL_OUT_OF_RESOURCES";
    case CL_OUT_OF_HOST_MEMORY: return "CL_OUT_OF_HOST_MEMORY";
    case CL_MEM_OBJECT_ALLOCATION_FAILURE: return "CL_MEM_OBJECT_ALLOCATION_FAILURE";
    case CL_BUILD_PROGRAM_FAILURE: return "CL_BUILD_PROGRAM_FAILURE";
    case CL_INVALID_VALUE: return "CL_INVALID_VALUE";
    case CL_INVALID_KERNEL_NAME: return "CL_INVALID_KERNEL_NAME";
    case CL_INVALID_KERNEL_ARGS: return "CL_INVALID_KERNEL_ARGS";
    case CL_INVALID_ARG_SIZE: return "CL_INVALID_ARG_SIZE";
    case CL_INVALID_WORK_GROUP_SIZE: return "CL_INVALID_WORK_GROUP_SIZE";
    case CL_INVALID_BUFFER_SIZE: return "CL_INVALID_BUFFER_SIZE";
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";
    default: return "OpenCL error " + std::to_string(code);
  }
}

void check(cl_int code, const std::string& what) {
  if (code != CL_SUCCESS) throw Error("OpenCL: " + what + " failed: " + cl_error_name(code));
}

std::string platform_string(cl_platform_id platform, cl_platform_info param) {
  size_t size = 0;
  if (opencl_api().clGetPlatformInfo(platform, param, 0, nullptr, &size) != CL_SUCCESS) return {};
  std::string value(size, '\0');
  opencl_api().clGetPlatformInfo(platform, param, size, value.data(), nullptr);
  while (!value.empty() && value.back() == '\0') value.pop_back();
  return value;
}

std::string device_string(cl_device_id device, cl_device_info param) {
  size_t size = 0;
  if (opencl_api().clGetDeviceInfo(device, param, 0, nullptr, &size) != CL_SUCCESS) return {};
  std::string value(size, '\0');
  opencl_api().clGetDeviceInfo(device, param, size, value.data(), nullptr);
  while (!value.empty() && value.back() == '\0') value.pop_back();
  return value;
}

template <class T>
T device_value(cl_device_id device, cl_device_info param) {
  T value{};
  opencl_api().clGetDeviceInfo(device, param, sizeof(T), &value, nullptr);
  return value;
}

// Limits and optional features for `kartograf devices` and the benchmarks' reports.
DeviceLimits read_limits(cl_device_id id, const std::string& extensions) {
  DeviceLimits limits;
  limits.compute_units = device_value<cl_uint>(id, CL_DEVICE_MAX_COMPUTE_UNITS);
  limits.max_workgroup_invocations =
      static_cast<std::uint32_t>(device_value<size_t>(id, CL_DEVICE_MAX_WORK_GROUP_SIZE));
  limits.shared_memory_bytes = device_value<cl_ulong>(id, CL_DEVICE_LOCAL_MEM_SIZE);
  limits.max_buffer_bytes = device_value<cl_ulong>(id, CL_DEVICE_MAX_MEM_ALLOC_SIZE);
  const auto has = [&](const char* name) { return extensions.find(name) != std::string::npos; };
  limits.fp64 = has("cl_khr_fp64");
  limits.int64 = true;  // long is core OpenCL C
  limits.int64_atomics = has("cl_khr_int64_base_atomics");
  // OpenCL 1.2 has no subgroups; NVIDIA tells its warp size (CL_DEVICE_WARP_SIZE_NV).
  constexpr cl_device_info kWarpSizeNv = 0x4003;
  if (has("cl_nv_device_attribute_query")) limits.subgroup_size = device_value<cl_uint>(id, kWarpSizeNv);
  limits.device_timestamps = true;  // profiling events are core OpenCL
  return limits;
}

struct FoundDevice {
  cl_device_id id = nullptr;
  DeviceInfo info;
};

struct Enumeration {
  std::vector<FoundDevice> devices;
  std::string problem;  // why there is no device at all
};

Enumeration enumerate_devices() {
  Enumeration result;
  const OpenclApi& cl = opencl_api();
  if (!cl.error.empty()) {
    result.problem = cl.error;
    return result;
  }
  cl_uint platform_count = 0;
  const cl_int status = cl.clGetPlatformIDs(0, nullptr, &platform_count);
  if (status != CL_SUCCESS || platform_count == 0) {
    result.problem = "no OpenCL platform (" + cl_error_name(status) +
                     "): no ICD in /etc/OpenCL/vendors or OCL_ICD_VENDORS, e.g. pocl-opencl-icd";
    return result;
  }
  std::vector<cl_platform_id> platforms(platform_count);
  cl.clGetPlatformIDs(platform_count, platforms.data(), nullptr);
  std::string empty_platforms;
  for (cl_platform_id platform : platforms) {
    const std::string platform_name = platform_string(platform, CL_PLATFORM_NAME);
    cl_uint count = 0;
    if (cl.clGetDeviceIDs(platform, CL_DEVICE_TYPE_ALL, 0, nullptr, &count) != CL_SUCCESS ||
        count == 0) {
      empty_platforms += (empty_platforms.empty() ? "" : ", ") + platform_name;
      continue;
    }
    std::vector<cl_device_id> ids(count);
    cl.clGetDeviceIDs(platform, CL_DEVICE_TYPE_ALL, count, ids.data(), nullptr);
    for (cl_device_id id : ids) {
      FoundDevice found;
      found.id = id;
      DeviceInfo& info = found.info;
      info.backend = BackendKind::opencl;
      info.name = device_string(id, CL_DEVICE_NAME);
      info.api_version = device_string(id, CL_DEVICE_VERSION);
      info.driver = platform_name + " " + device_string(id, CL_DRIVER_VERSION);
      info.memory_bytes = device_value<cl_ulong>(id, CL_DEVICE_GLOBAL_MEM_SIZE);
      info.unified_memory = device_value<cl_bool>(id, CL_DEVICE_HOST_UNIFIED_MEMORY) == CL_TRUE;
      const auto type = device_value<cl_device_type>(id, CL_DEVICE_TYPE);
      if (type & CL_DEVICE_TYPE_GPU) {
        info.type = info.unified_memory ? DeviceType::integrated_gpu : DeviceType::discrete_gpu;
      } else if (type & CL_DEVICE_TYPE_CPU) {
        info.type = DeviceType::cpu;
      } else {
        info.type = DeviceType::other;
      }
      const std::string extensions = device_string(id, CL_DEVICE_EXTENSIONS);
      info.limits = read_limits(id, extensions);
      for (const char* needed : {"cl_khr_fp64", "cl_khr_int64_base_atomics"}) {
        if (extensions.find(needed) == std::string::npos) {
          info.usable = false;
          info.unusable_reason += std::string(info.unusable_reason.empty() ? "" : ", ") +
                                  "lacks " + needed;
        }
      }
      result.devices.push_back(std::move(found));
    }
  }
  if (result.devices.empty()) {
    result.problem = "OpenCL platform(s) " + empty_platforms + " report zero devices";
    if (empty_platforms.find("Portable Computing Language") != std::string::npos) {
      const char* cache = std::getenv("POCL_CACHE_DIR");
      result.problem += std::string(" (PoCL does so when its kernel cache is not writable: POCL_CACHE_DIR=") +
                        (cache ? cache : "<unset>") + ")";
    }
  }
  return result;
}

class OpenclBuffer final : public DeviceBuffer {
 public:
  explicit OpenclBuffer(cl_mem memory) : memory_(memory) {}
  ~OpenclBuffer() override { opencl_api().clReleaseMemObject(memory_); }
  cl_mem memory() const { return memory_; }

 private:
  cl_mem memory_;
};

cl_mem memory_of(const DeviceBuffer& buffer) {
  return static_cast<const OpenclBuffer&>(buffer).memory();
}

class OpenclDevice final : public Device {
 public:
  OpenclDevice(cl_device_id id, DeviceInfo info, bool profile)
      : id_(id), info_(std::move(info)), profile_(profile) {
    const OpenclApi& cl = opencl_api();
    cl_int status = CL_SUCCESS;
    context_ = cl.clCreateContext(nullptr, 1, &id_, nullptr, nullptr, &status);
    check(status, "clCreateContext on " + info_.name);
    queue_ = cl.clCreateCommandQueue(context_, id_, profile ? CL_QUEUE_PROFILING_ENABLE : 0, &status);
    check(status, "clCreateCommandQueue on " + info_.name);
    placeholder_ = create_buffer(16);
  }

  ~OpenclDevice() override {
    const OpenclApi& cl = opencl_api();
    cl.clFinish(queue_);
    for (const auto& [name, event] : pending_) {
      if (event) cl.clReleaseEvent(event);
    }
    placeholder_.reset();
    for (auto& [name, kernel] : kernels_) cl.clReleaseKernel(kernel);
    if (program_) cl.clReleaseProgram(program_);
    cl.clReleaseCommandQueue(queue_);
    cl.clReleaseContext(context_);
  }

  const DeviceInfo& info() const override { return info_; }

  std::unique_ptr<DeviceBuffer> create_buffer(std::size_t bytes) override {
    cl_int status = CL_SUCCESS;
    cl_mem memory = opencl_api().clCreateBuffer(context_, CL_MEM_READ_WRITE, bytes, nullptr, &status);
    check(status, "clCreateBuffer of " + std::to_string(bytes) + " bytes");
    return std::make_unique<OpenclBuffer>(memory);
  }

  void write(DeviceBuffer& buffer, std::size_t offset, const void* source,
             std::size_t bytes) override {
    check(opencl_api().clEnqueueWriteBuffer(queue_, memory_of(buffer), CL_TRUE, offset, bytes,
                                            source, 0, nullptr, event_for("upload")),
          "clEnqueueWriteBuffer");
  }

  void read(const DeviceBuffer& buffer, std::size_t offset, void* destination,
            std::size_t bytes) override {
    check(opencl_api().clEnqueueReadBuffer(queue_, memory_of(buffer), CL_TRUE, offset, bytes,
                                           destination, 0, nullptr, event_for("download")),
          "clEnqueueReadBuffer");
  }

  void fill_zero(DeviceBuffer& buffer, std::size_t offset, std::size_t bytes) override {
    const cl_uint zero = 0;
    check(opencl_api().clEnqueueFillBuffer(queue_, memory_of(buffer), &zero, sizeof(zero), offset,
                                           bytes, 0, nullptr, event_for("fill")),
          "clEnqueueFillBuffer");
  }

  void copy(const DeviceBuffer& source, std::size_t source_offset, DeviceBuffer& target,
            std::size_t target_offset, std::size_t bytes) override {
    check(opencl_api().clEnqueueCopyBuffer(queue_, memory_of(source), memory_of(target),
                                           source_offset, target_offset, bytes, 0, nullptr,
                                           event_for("copy")),
          "clEnqueueCopyBuffer");
  }

  std::vector<DeviceTiming> take_device_timings() override {
    finish();
    collect_timings();
    std::vector<DeviceTiming> result;
    result.swap(completed_);
    return result;
  }

  void dispatch(const KernelSpec& spec, std::span<DeviceBuffer* const> buffers,
                std::span<const std::byte> params, GroupCount groups) override {
    const OpenclApi& cl = opencl_api();
    cl_kernel kernel = kernel_named(spec.name);
    const std::string name(spec.name);
    cl_uint arg = 0;
    for (DeviceBuffer* buffer : buffers) {
      cl_mem memory = memory_of(buffer ? *buffer : *placeholder_);
      check(cl.clSetKernelArg(kernel, arg, sizeof(cl_mem), &memory),
            name + ": setting buffer argument " + std::to_string(arg));
      ++arg;
    }
    if (!params.empty()) {
      check(cl.clSetKernelArg(kernel, arg, params.size(), params.data()),
            name + ": setting the parameter block (argument " + std::to_string(arg) + ")");
    }
    // PoCL has no non-uniform work-groups: the global size is a whole number of groups.
    const size_t local[2] = {spec.local_x, spec.local_y};
    const size_t global[2] = {size_t{groups.x} * spec.local_x, size_t{groups.y} * spec.local_y};
    check(cl.clEnqueueNDRangeKernel(queue_, kernel, 2, nullptr, global, local, 0, nullptr,
                                    event_for(spec.name)),
          name + ": clEnqueueNDRangeKernel");
  }

  void finish() override { check(opencl_api().clFinish(queue_), "clFinish"); }

  void build_all_kernels() override {
    build_program();
    const OpenclApi& cl = opencl_api();
    cl_uint count = 0;
    check(cl.clCreateKernelsInProgram(program_, 0, nullptr, &count), "clCreateKernelsInProgram");
    std::vector<cl_kernel> all(count);
    check(cl.clCreateKernelsInProgram(program_, count, all.data(), nullptr),
          "clCreateKernelsInProgram");
    for (cl_kernel kernel : all) cl.clReleaseKernel(kernel);
  }

 private:
  // With profiling, the event of the next command (named for the report); else none. Long runs
  // are collected on the way, so the number of live events stays bounded.
  cl_event* event_for(std::string_view command) {
    if (!profile_) return nullptr;
    if (pending_.size() >= kMaxPendingEvents) {
      finish();
      collect_timings();
    }
    pending_.emplace_back(std::string(command), nullptr);
    return &pending_.back().second;
  }

  // After clFinish: the pending commands' device times, in issue order.
  void collect_timings() {
    const OpenclApi& cl = opencl_api();
    for (const auto& [name, event] : pending_) {
      if (!event) continue;  // its enqueue failed (and threw)
      cl_ulong start = 0, end = 0;
      check(cl.clGetEventProfilingInfo(event, CL_PROFILING_COMMAND_START, sizeof(start), &start,
                                       nullptr),
            "clGetEventProfilingInfo");
      check(cl.clGetEventProfilingInfo(event, CL_PROFILING_COMMAND_END, sizeof(end), &end, nullptr),
            "clGetEventProfilingInfo");
      cl.clReleaseEvent(event);
      completed_.push_back({name, static_cast<double>(end - start) * 1e-6});
    }
    pending_.clear();
  }

  void build_program() {
    std::lock_guard lock(build_mutex_);
    if (program_) return;
    const OpenclApi& cl = opencl_api();
    const std::vector<std::string> sources = program_sources();
    std::vector<const char*> texts;
    for (const std::string& source : sources) texts.push_back(source.c_str());
    cl_int status = CL_SUCCESS;
    cl_program program = cl.clCreateProgramWithSource(
        context_, static_cast<cl_uint>(texts.size()), texts.data(), nullptr, &status);
    check(status, "clCreateProgramWithSource");
    // KARTOGRAF_OPENCL_BUILD_OPTIONS: extra compiler options, e.g. NVIDIA's -cl-nv-verbose
    // (registers and spills per kernel in the log); KARTOGRAF_OPENCL_BUILD_LOG: a file that
    // receives the log.
    const char* extra = std::getenv("KARTOGRAF_OPENCL_BUILD_OPTIONS");
    const std::string options = std::string("-cl-std=CL1.2 ") + (extra ? extra : "");
    status = cl.clBuildProgram(program, 1, &id_, options.c_str(), nullptr, nullptr);
    if (status != CL_SUCCESS) {
      const std::string log = build_log(program);
      cl.clReleaseProgram(program);
      throw Error("OpenCL: building the kernels for " + info_.name + " failed (" +
                  cl_error_name(status) + "):\n" + log);
    }
    if (const char* log_path = std::getenv("KARTOGRAF_OPENCL_BUILD_LOG")) {
      std::ofstream(log_path, std::ios::app) << "options: " << options << "\n"
                                             << build_log(program);
    }
    program_ = program;
  }

  // The embedded sources; with KARTOGRAF_OPENCL_SOURCE_DIR set, a file of the same name there
  // (includes expanded) replaces one: kernel variants tried on a machine without a build.
  static std::vector<std::string> program_sources() {
    const char* override_dir = std::getenv("KARTOGRAF_OPENCL_SOURCE_DIR");
    std::vector<std::string> sources;
    for (const EmbeddedText& source : embedded_opencl_sources()) {
      std::ifstream replacement;
      if (override_dir && *override_dir) {
        replacement.open(std::string(override_dir) + "/" + std::string(source.name));
      }
      if (!replacement.is_open()) {
        sources.emplace_back(source.text);
        continue;
      }
      sources.emplace_back(std::istreambuf_iterator<char>(replacement),
                           std::istreambuf_iterator<char>());
    }
    return sources;
  }

  std::string build_log(cl_program program) const {
    const OpenclApi& cl = opencl_api();
    size_t size = 0;
    cl.clGetProgramBuildInfo(program, id_, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size);
    std::string log(size, '\0');
    cl.clGetProgramBuildInfo(program, id_, CL_PROGRAM_BUILD_LOG, size, log.data(), nullptr);
    return log;
  }

  cl_kernel kernel_named(std::string_view name) {
    auto found = kernels_.find(name);
    if (found != kernels_.end()) return found->second;
    build_program();
    cl_int status = CL_SUCCESS;
    const std::string name_string(name);
    cl_kernel kernel = opencl_api().clCreateKernel(program_, name_string.c_str(), &status);
    check(status, "clCreateKernel '" + name_string + "'");
    kernels_.emplace(name_string, kernel);
    return kernel;
  }

  cl_device_id id_;
  DeviceInfo info_;
  cl_context context_ = nullptr;
  cl_command_queue queue_ = nullptr;
  cl_program program_ = nullptr;
  std::mutex build_mutex_;
  std::map<std::string, cl_kernel, std::less<>> kernels_;
  std::unique_ptr<DeviceBuffer> placeholder_;
  static constexpr std::size_t kMaxPendingEvents = 4096;
  bool profile_ = false;
  std::deque<std::pair<std::string, cl_event>> pending_;  // deque: event_for's pointers stay valid
  std::vector<DeviceTiming> completed_;
};

}  // namespace

BackendStatus probe_opencl() {
  BackendStatus status;
  status.backend = BackendKind::opencl;
  Enumeration found = enumerate_devices();
  for (FoundDevice& device : found.devices) status.devices.push_back(device.info);
  status.available = !found.devices.empty();
  status.reason = found.problem;
  if (status.available) {
    bool any_usable = false;
    for (const DeviceInfo& device : status.devices) any_usable |= device.usable;
    if (!any_usable) {
      status.available = false;
      status.reason = "no OpenCL device has fp64 and 64-bit integer atomics";
    }
  }
  return status;
}

std::shared_ptr<Device> create_opencl_device(const ContextParams& options) {
  Enumeration found = enumerate_devices();
  if (found.devices.empty()) throw Error("OpenCL backend unavailable: " + found.problem);
  std::vector<FoundDevice*> usable;
  for (FoundDevice& device : found.devices) {
    if (device.info.usable) usable.push_back(&device);
  }
  if (usable.empty()) {
    throw Error("OpenCL backend unavailable: " + found.devices.front().info.name + " " +
                found.devices.front().info.unusable_reason);
  }
  std::vector<const DeviceInfo*> infos;
  for (const FoundDevice* device : usable) infos.push_back(&device->info);
  const std::size_t index = choose_device(infos, options, "OpenCL");
  return std::make_shared<OpenclDevice>(usable[index]->id, usable[index]->info, options.profile);
}

}  // namespace kartograf::compute::detail
