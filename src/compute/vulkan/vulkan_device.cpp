// The Vulkan backend: compute pipelines from the embedded SPIR-V, one command buffer that records
// dispatches (with a barrier after each) until the host needs a result, and memory that the host
// maps directly on unified-memory devices (lavapipe, integrated GPUs) or reaches through staging
// copies on discrete GPUs.
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "compute/device.hpp"
#include "compute/embedded_kernels.hpp"
#include "compute/vulkan/spirv_reflect.hpp"
#include "compute/vulkan/vulkan_api.hpp"
#include "compute/vulkan/vulkan_timestamps.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::compute::detail {
namespace {

struct PhysicalDevice {
  VkPhysicalDevice handle = VK_NULL_HANDLE;
  uint32_t queue_family = 0;
  uint32_t api_version = 0;
  double timestamp_period_ns = 0;
  uint32_t timestamp_bits = 0;  // of the compute queue family; 0: no timestamps
  DeviceInfo info;
};

std::string version_string(uint32_t version) {
  return std::to_string(VK_API_VERSION_MAJOR(version)) + "." +
         std::to_string(VK_API_VERSION_MINOR(version)) + "." +
         std::to_string(VK_API_VERSION_PATCH(version));
}

DeviceType device_type(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return DeviceType::discrete_gpu;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return DeviceType::integrated_gpu;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return DeviceType::virtual_gpu;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return DeviceType::cpu;
    default: return DeviceType::other;
  }
}

// A memory type both device-local and host-visible-coherent, on a device that shares the host's
// memory (CPU or integrated GPU): buffers are then mapped, never staged. On a discrete GPU such a
// type (resizable BAR) is uncached for host reads, so staging is faster there.
std::optional<uint32_t> unified_memory_type(const VkPhysicalDeviceMemoryProperties& memory,
                                            DeviceType type) {
  if (type != DeviceType::cpu && type != DeviceType::integrated_gpu) return std::nullopt;
  const VkMemoryPropertyFlags wanted = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT |
                                       VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                       VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
    if ((memory.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
  }
  return std::nullopt;
}

// Limits and optional features for `kartograf devices` and the benchmarks' reports.
// timestamp_bits: the compute queue family's timestampValidBits (0 without a compute queue).
DeviceLimits read_limits(const VulkanInstance& vk, VkPhysicalDevice handle,
                         uint32_t timestamp_bits) {
  VkPhysicalDeviceSubgroupProperties subgroup{};
  subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
  VkPhysicalDeviceProperties2 properties{};
  properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
  properties.pNext = &subgroup;
  vk.vkGetPhysicalDeviceProperties2(handle, &properties);
  VkPhysicalDeviceShaderAtomicInt64Features atomics{};
  atomics.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES;
  VkPhysicalDeviceFeatures2 features{};
  features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
  features.pNext = &atomics;
  vk.vkGetPhysicalDeviceFeatures2(handle, &features);

  const VkPhysicalDeviceLimits& l = properties.properties.limits;
  DeviceLimits limits;
  limits.max_workgroup_invocations = l.maxComputeWorkGroupInvocations;
  limits.shared_memory_bytes = l.maxComputeSharedMemorySize;
  limits.max_buffer_bytes = l.maxStorageBufferRange;
  const bool subgroups_in_compute = (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0;
  limits.subgroup_size = subgroups_in_compute ? subgroup.subgroupSize : 0;
  limits.fp64 = features.features.shaderFloat64 == VK_TRUE;
  limits.int64 = features.features.shaderInt64 == VK_TRUE;
  limits.int64_atomics = atomics.shaderBufferInt64Atomics == VK_TRUE;
  limits.device_timestamps = timestamp_bits > 0 && l.timestampPeriod > 0;
  return limits;
}

std::vector<PhysicalDevice> enumerate(const VulkanInstance& vk) {
  uint32_t count = 0;
  vk_check(vk.vkEnumeratePhysicalDevices(vk.instance, &count, nullptr), "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> handles(count);
  vk_check(vk.vkEnumeratePhysicalDevices(vk.instance, &count, handles.data()),
           "vkEnumeratePhysicalDevices");
  std::vector<PhysicalDevice> result;
  for (VkPhysicalDevice handle : handles) {
    PhysicalDevice device;
    device.handle = handle;
    VkPhysicalDeviceDriverProperties driver{};
    driver.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
    VkPhysicalDeviceProperties2 properties{};
    properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    properties.pNext = &driver;
    vk.vkGetPhysicalDeviceProperties2(handle, &properties);
    const VkPhysicalDeviceProperties& p = properties.properties;
    device.api_version = p.apiVersion;

    VkPhysicalDeviceMemoryProperties memory{};
    vk.vkGetPhysicalDeviceMemoryProperties(handle, &memory);

    DeviceInfo& info = device.info;
    info.backend = BackendKind::vulkan;
    info.name = p.deviceName;
    info.type = device_type(p.deviceType);
    info.api_version = "Vulkan " + version_string(p.apiVersion);
    info.driver = std::string(driver.driverName) + " " + driver.driverInfo;
    for (uint32_t i = 0; i < memory.memoryHeapCount; ++i) {
      if (memory.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) {
        info.memory_bytes += memory.memoryHeaps[i].size;
      }
    }
    info.unified_memory = unified_memory_type(memory, info.type).has_value();

    uint32_t family_count = 0;
    vk.vkGetPhysicalDeviceQueueFamilyProperties(handle, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    vk.vkGetPhysicalDeviceQueueFamilyProperties(handle, &family_count, families.data());
    bool has_compute = false;
    for (uint32_t i = 0; i < family_count && !has_compute; ++i) {
      if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
        device.queue_family = i;
        has_compute = true;
      }
    }
    std::vector<std::string> missing;
    if (has_compute) {
      device.timestamp_bits = families[device.queue_family].timestampValidBits;
      device.timestamp_period_ns = p.limits.timestampPeriod;
    }
    info.limits = read_limits(vk, handle, device.timestamp_bits);
    if (p.apiVersion < VK_API_VERSION_1_1) missing.push_back("Vulkan 1.1");
    if (!has_compute) missing.push_back("a compute queue");
    if (!info.limits.fp64) missing.push_back("shaderFloat64");
    if (!info.limits.int64) missing.push_back("shaderInt64");
    if (!info.limits.int64_atomics) missing.push_back("shaderBufferInt64Atomics");
    for (const std::string& what : missing) {
      info.usable = false;
      info.unusable_reason += (info.unusable_reason.empty() ? "lacks " : ", ") + what;
    }
    result.push_back(std::move(device));
  }
  return result;
}

class VulkanDevice;

// Handles of a buffer; freed by its device, which defers that while recorded commands may use it.
struct BufferHandles {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;  // unified memory and staging only
  std::size_t bytes = 0;   // as asked for: the key of the device's pool of freed buffers
  int access = 0;          // VulkanDevice::HostAccess
};

class VulkanBuffer final : public DeviceBuffer {
 public:
  explicit VulkanBuffer(VulkanDevice* owner) : owner(owner) {}
  ~VulkanBuffer() override;

  VulkanDevice* owner;
  BufferHandles handles;
  VkBuffer buffer() const { return handles.buffer; }
  void* mapped() const { return handles.mapped; }
};

VulkanBuffer& as_vulkan(DeviceBuffer& buffer) { return static_cast<VulkanBuffer&>(buffer); }
const VulkanBuffer& as_vulkan(const DeviceBuffer& buffer) {
  return static_cast<const VulkanBuffer&>(buffer);
}

struct Pipeline {
  SpirvShape shape;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
};

class VulkanDevice final : public Device {
 public:
  VulkanDevice(std::shared_ptr<VulkanInstance> instance, const PhysicalDevice& physical, bool profile)
      : instance_(std::move(instance)), physical_(physical.handle), info_(physical.info),
        validation_baseline_(instance_->validation_errors.load()) {
    const VulkanInstance& vk = *instance_;
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{};
    queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queue_info.queueFamilyIndex = physical.queue_family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;

    VkPhysicalDeviceShaderAtomicInt64Features atomics{};
    atomics.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES;
    atomics.shaderBufferInt64Atomics = VK_TRUE;
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features.pNext = &atomics;
    features.features.shaderFloat64 = VK_TRUE;
    features.features.shaderInt64 = VK_TRUE;
    std::vector<const char*> extensions;
    if (physical.api_version < VK_API_VERSION_1_2) {
      extensions.push_back(VK_KHR_SHADER_ATOMIC_INT64_EXTENSION_NAME);
    }

    VkDeviceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    info.pNext = &features;
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queue_info;
    info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    vk_check(vk.vkCreateDevice(physical_, &info, nullptr, &device_), "vkCreateDevice on " + info_.name);
    api_.load(vk, device_);
    api_.vkGetDeviceQueue(device_, physical.queue_family, 0, &queue_);

    VkPhysicalDeviceMemoryProperties memory{};
    vk.vkGetPhysicalDeviceMemoryProperties(physical_, &memory);
    memory_properties_ = memory;
    unified_type_ = unified_memory_type(memory, info_.type);
    // KARTOGRAF_VULKAN_STAGING=1: the discrete-GPU path (staging copies) on any device, so that CI's
    // lavapipe tests the path a real GPU takes.
    const char* staging = std::getenv("KARTOGRAF_VULKAN_STAGING");
    if (staging && std::string(staging) != "0") unified_type_.reset();

    VkCommandPoolCreateInfo pool_info{};
    pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pool_info.queueFamilyIndex = physical.queue_family;
    vk_check(api_.vkCreateCommandPool(device_, &pool_info, nullptr, &command_pool_),
             "vkCreateCommandPool");
    VkCommandBufferAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    allocate.commandPool = command_pool_;
    allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocate.commandBufferCount = 1;
    vk_check(api_.vkAllocateCommandBuffers(device_, &allocate, &commands_), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fence_info{};
    fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    vk_check(api_.vkCreateFence(device_, &fence_info, nullptr, &fence_), "vkCreateFence");
    if (profile && info_.limits.device_timestamps) {
      timestamps_ = std::make_unique<VulkanTimestamps>(api_, device_, physical.timestamp_period_ns,
                                                       physical.timestamp_bits);
    }
    placeholder_ = create_buffer(16);
    fill_zero(*placeholder_, 0, 16);
  }

  ~VulkanDevice() override {
    try {
      flush();
    } catch (const Error&) {
      // Nothing sensible to do while tearing down; the device goes away regardless.
    }
    api_.vkDeviceWaitIdle(device_);
    timestamps_.reset();
    closing_ = true;
    placeholder_.reset();
    staging_.clear();
    for (const auto& [key, handles] : pool_) release(handles);
    for (auto& [name, pipeline] : pipelines_) {
      api_.vkDestroyPipeline(device_, pipeline.pipeline, nullptr);
      api_.vkDestroyPipelineLayout(device_, pipeline.layout, nullptr);
      api_.vkDestroyDescriptorSetLayout(device_, pipeline.set_layout, nullptr);
    }
    for (VkDescriptorPool pool : descriptor_pools_) api_.vkDestroyDescriptorPool(device_, pool, nullptr);
    api_.vkDestroyFence(device_, fence_, nullptr);
    api_.vkDestroyCommandPool(device_, command_pool_, nullptr);
    api_.vkDestroyDevice(device_, nullptr);
  }

  const DeviceInfo& info() const override { return info_; }
  // The instance is the process's (shared by every context): count only this device's errors.
  std::uint64_t validation_errors() const override {
    return instance_->validation_errors.load() - validation_baseline_;
  }
  bool validation_active() const override { return instance_->validation; }

  std::unique_ptr<DeviceBuffer> create_buffer(std::size_t bytes) override {
    return make_buffer(bytes, unified_type_.has_value() ? HostAccess::mapped : HostAccess::none);
  }

  void write(DeviceBuffer& target, std::size_t offset, const void* source,
             std::size_t bytes) override {
    VulkanBuffer& buffer = as_vulkan(target);
    if (buffer.mapped()) {
      flush();  // recorded commands may still read the old contents
      std::memcpy(static_cast<std::byte*>(buffer.mapped()) + offset, source, bytes);
      return;
    }
    // Discrete memory, a small write (ICP's per-iteration pose, parameters): inline in the
    // command buffer, no staging buffer.
    if (bytes <= kInlineUpdateBytes && bytes % 4 == 0 && offset % 4 == 0) {
      timed("upload", [&](VkCommandBuffer commands) {
        api_.vkCmdUpdateBuffer(commands, buffer.buffer(), offset, bytes, source);
      });
      return;
    }
    // Larger ones: stage, then copy in order with the recorded commands.
    auto staging = make_buffer(bytes, HostAccess::staging);
    std::memcpy(staging->mapped(), source, bytes);
    VkBufferCopy region{0, offset, bytes};
    timed("upload", [&](VkCommandBuffer commands) {
      api_.vkCmdCopyBuffer(commands, staging->buffer(), buffer.buffer(), 1, &region);
    });
    staging_.push_back(std::move(staging));
  }

  void read(const DeviceBuffer& source, std::size_t offset, void* destination,
            std::size_t bytes) override {
    const VulkanBuffer& buffer = as_vulkan(source);
    if (buffer.mapped()) {
      flush();
      std::memcpy(destination, static_cast<const std::byte*>(buffer.mapped()) + offset, bytes);
      return;
    }
    auto staging = make_buffer(bytes, HostAccess::staging);
    VkBufferCopy region{offset, 0, bytes};
    timed("download", [&](VkCommandBuffer commands) {
      api_.vkCmdCopyBuffer(commands, buffer.buffer(), staging->buffer(), 1, &region);
    });
    flush();
    std::memcpy(destination, staging->mapped(), bytes);
  }

  void fill_zero(DeviceBuffer& target, std::size_t offset, std::size_t bytes) override {
    timed("fill", [&](VkCommandBuffer commands) {
      api_.vkCmdFillBuffer(commands, as_vulkan(target).buffer(), offset, bytes, 0);
    });
  }

  void copy(const DeviceBuffer& source, std::size_t source_offset, DeviceBuffer& target,
            std::size_t target_offset, std::size_t bytes) override {
    VkBufferCopy region{source_offset, target_offset, bytes};
    timed("copy", [&](VkCommandBuffer commands) {
      api_.vkCmdCopyBuffer(commands, as_vulkan(source).buffer(), as_vulkan(target).buffer(), 1,
                           &region);
    });
  }

  std::vector<DeviceTiming> take_device_timings() override {
    flush();
    return timestamps_ ? timestamps_->take() : std::vector<DeviceTiming>{};
  }

  void dispatch(const KernelSpec& spec, std::span<DeviceBuffer* const> buffers,
                std::span<const std::byte> params, GroupCount groups) override {
    const Pipeline& pipeline = pipeline_named(spec);
    const std::string name(spec.name);
    require(buffers.size() == pipeline.shape.binding_count,
            "Vulkan kernel '" + name + "' declares " + std::to_string(pipeline.shape.binding_count) +
                " buffers, " + std::to_string(buffers.size()) + " given");
    VkDescriptorSet set = allocate_set(pipeline.set_layout);
    std::vector<VkDescriptorBufferInfo> infos(buffers.size());
    std::vector<VkWriteDescriptorSet> writes(buffers.size());
    for (std::size_t i = 0; i < buffers.size(); ++i) {
      const VulkanBuffer& buffer = as_vulkan(buffers[i] ? *buffers[i] : *placeholder_);
      infos[i] = {buffer.buffer(), 0, VK_WHOLE_SIZE};
      writes[i] = {};
      writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
      writes[i].dstSet = set;
      writes[i].dstBinding = static_cast<uint32_t>(i);
      writes[i].descriptorCount = 1;
      writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes[i].pBufferInfo = &infos[i];
    }
    api_.vkUpdateDescriptorSets(device_, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
    timed(spec.name, [&](VkCommandBuffer commands) {
      api_.vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.pipeline);
      api_.vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.layout, 0, 1,
                                   &set, 0, nullptr);
      if (!params.empty()) {
        api_.vkCmdPushConstants(commands, pipeline.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0,
                                static_cast<uint32_t>(params.size()), params.data());
      }
      api_.vkCmdDispatch(commands, groups.x, groups.y, 1);
    });
  }

  void finish() override { flush(); }

  void build_all_kernels() override {
    for (const EmbeddedSpirv& module : embedded_spirv()) pipeline_for(module);
  }

 private:
  enum class HostAccess { none, mapped, staging };

 public:
  // A buffer freed while commands that may use it are recorded lives until they have run.
  void retire(const BufferHandles& handles) {
    if (recording_) {
      retired_.push_back(handles);
    } else {
      destroy(handles);
    }
  }

 private:
  // Freed buffers are kept for reuse by a buffer of the same size and access: allocating device
  // memory costs a driver call of ~0.1-1 ms on a discrete GPU (measured on an H100), and a frame
  // loop frees and allocates the same sizes every frame.
  void destroy(const BufferHandles& handles) {
    if (!closing_ && pooled_bytes_ + handles.bytes <= kPoolLimitBytes) {
      pool_.emplace(std::pair{handles.bytes, handles.access}, handles);
      pooled_bytes_ += handles.bytes;
      return;
    }
    release(handles);
  }

  void release(const BufferHandles& handles) {
    if (handles.mapped) api_.vkUnmapMemory(device_, handles.memory);
    if (handles.buffer) api_.vkDestroyBuffer(device_, handles.buffer, nullptr);
    if (handles.memory) api_.vkFreeMemory(device_, handles.memory, nullptr);
  }

  std::unique_ptr<VulkanBuffer> make_buffer(std::size_t bytes, HostAccess access) {
    auto owned = std::make_unique<VulkanBuffer>(this);
    const auto kept = pool_.find(std::pair{bytes, static_cast<int>(access)});
    if (kept != pool_.end()) {
      owned->handles = kept->second;
      pooled_bytes_ -= bytes;
      pool_.erase(kept);
      return owned;
    }
    BufferHandles* buffer = &owned->handles;
    buffer->bytes = bytes;
    buffer->access = static_cast<int>(access);
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = bytes;
    info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                 VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    vk_check(api_.vkCreateBuffer(device_, &info, nullptr, &buffer->buffer),
             "vkCreateBuffer of " + std::to_string(bytes) + " bytes");
    VkMemoryRequirements requirements{};
    api_.vkGetBufferMemoryRequirements(device_, buffer->buffer, &requirements);

    VkMemoryPropertyFlags wanted = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    if (access == HostAccess::staging) {
      wanted = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    }
    std::optional<uint32_t> type;
    if (access == HostAccess::mapped && (requirements.memoryTypeBits & (1u << *unified_type_))) {
      type = unified_type_;
    }
    for (uint32_t i = 0; i < memory_properties_.memoryTypeCount && !type; ++i) {
      if ((requirements.memoryTypeBits & (1u << i)) &&
          (memory_properties_.memoryTypes[i].propertyFlags & wanted) == wanted) {
        type = i;
      }
    }
    require(type.has_value(), "Vulkan: no memory type for a buffer of " + std::to_string(bytes) +
                                  " bytes on " + info_.name);
    VkMemoryAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = *type;
    vk_check(api_.vkAllocateMemory(device_, &allocate, nullptr, &buffer->memory),
             "vkAllocateMemory of " + std::to_string(bytes) + " bytes");
    vk_check(api_.vkBindBufferMemory(device_, buffer->buffer, buffer->memory, 0), "vkBindBufferMemory");
    if (access != HostAccess::none) {
      vk_check(api_.vkMapMemory(device_, buffer->memory, 0, VK_WHOLE_SIZE, 0, &buffer->mapped),
               "vkMapMemory");
    }
    return owned;
  }

  const Pipeline& pipeline_named(const KernelSpec& spec) {
    auto found = pipelines_.find(spec.name);
    const Pipeline* pipeline = nullptr;
    if (found != pipelines_.end()) {
      pipeline = &found->second;
    } else {
      const EmbeddedSpirv* module = nullptr;
      for (const EmbeddedSpirv& candidate : embedded_spirv()) {
        if (candidate.name == spec.name) module = &candidate;
      }
      require(module != nullptr, "Vulkan: no embedded shader named '" + std::string(spec.name) + "'");
      pipeline = &pipeline_for(*module);
    }
    const uint32_t* local = pipeline->shape.local_size;
    require(local[0] == spec.local_x && local[1] == spec.local_y,
            "Vulkan kernel '" + std::string(spec.name) + "': shader work-group " +
                std::to_string(local[0]) + "x" + std::to_string(local[1]) + " differs from the "
                "operation's " + std::to_string(spec.local_x) + "x" + std::to_string(spec.local_y));
    return *pipeline;
  }

  const Pipeline& pipeline_for(const EmbeddedSpirv& module) {
    const std::string name(module.name);
    auto found = pipelines_.find(name);
    if (found != pipelines_.end()) return found->second;

    Pipeline pipeline;
    pipeline.shape = reflect_spirv(module.words, module.word_count, name);
    std::vector<VkDescriptorSetLayoutBinding> bindings(pipeline.shape.binding_count);
    for (uint32_t i = 0; i < bindings.size(); ++i) {
      bindings[i] = {};
      bindings[i].binding = i;
      bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      bindings[i].descriptorCount = 1;
      bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo set_info{};
    set_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    set_info.bindingCount = static_cast<uint32_t>(bindings.size());
    set_info.pBindings = bindings.data();
    vk_check(api_.vkCreateDescriptorSetLayout(device_, &set_info, nullptr, &pipeline.set_layout),
             "vkCreateDescriptorSetLayout for " + name);

    VkPushConstantRange push{};
    push.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    push.size = static_cast<uint32_t>(kMaxKernelParamBytes);
    VkPipelineLayoutCreateInfo layout_info{};
    layout_info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    layout_info.setLayoutCount = 1;
    layout_info.pSetLayouts = &pipeline.set_layout;
    layout_info.pushConstantRangeCount = pipeline.shape.has_push_constants ? 1 : 0;
    layout_info.pPushConstantRanges = &push;
    vk_check(api_.vkCreatePipelineLayout(device_, &layout_info, nullptr, &pipeline.layout),
             "vkCreatePipelineLayout for " + name);

    VkShaderModuleCreateInfo module_info{};
    module_info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    module_info.codeSize = module.word_count * sizeof(uint32_t);
    module_info.pCode = module.words;
    VkShaderModule shader = VK_NULL_HANDLE;
    vk_check(api_.vkCreateShaderModule(device_, &module_info, nullptr, &shader),
             "vkCreateShaderModule for " + name);
    VkComputePipelineCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = shader;
    info.stage.pName = "main";
    info.layout = pipeline.layout;
    const VkResult created =
        api_.vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline.pipeline);
    api_.vkDestroyShaderModule(device_, shader, nullptr);
    vk_check(created, "vkCreateComputePipelines for " + name);
    return pipelines_.emplace(name, pipeline).first->second;
  }

  VkDescriptorSet allocate_set(VkDescriptorSetLayout layout) {
    for (int attempt = 0; attempt < 2; ++attempt) {
      if (!descriptor_pools_.empty()) {
        VkDescriptorSetAllocateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
        info.descriptorPool = descriptor_pools_.back();
        info.descriptorSetCount = 1;
        info.pSetLayouts = &layout;
        VkDescriptorSet set = VK_NULL_HANDLE;
        const VkResult result = api_.vkAllocateDescriptorSets(device_, &info, &set);
        if (result == VK_SUCCESS) return set;
        if (result != VK_ERROR_OUT_OF_POOL_MEMORY && result != VK_ERROR_FRAGMENTED_POOL) {
          vk_check(result, "vkAllocateDescriptorSets");
        }
      }
      descriptor_pools_.push_back(new_descriptor_pool());
    }
    throw Error("Vulkan: cannot allocate a descriptor set");
  }

  VkDescriptorPool new_descriptor_pool() {
    constexpr uint32_t kSets = 256;
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kSets * 8};
    VkDescriptorPoolCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    info.maxSets = kSets;
    info.poolSizeCount = 1;
    info.pPoolSizes = &size;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    vk_check(api_.vkCreateDescriptorPool(device_, &info, nullptr, &pool), "vkCreateDescriptorPool");
    return pool;
  }

  VkCommandBuffer recording() {
    if (!recording_) {
      VkCommandBufferBeginInfo begin{};
      begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
      begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
      vk_check(api_.vkBeginCommandBuffer(commands_, &begin), "vkBeginCommandBuffer");
      recording_ = true;
      if (timestamps_) timestamps_->begin_recording(commands_);
    }
    return commands_;
  }

  // Records one command followed by a barrier, between timestamps when profiling.
  template <class Record>
  void timed(std::string_view name, const Record& record) {
    if (timestamps_ && timestamps_->full()) flush();
    VkCommandBuffer commands = recording();
    if (timestamps_) timestamps_->before(commands, name);
    record(commands);
    if (timestamps_) timestamps_->after(commands);
    barrier();
  }

  // Every command sees the memory effects of every command recorded before it.
  void barrier(VkPipelineStageFlags destination_stage = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT |
                                                        VK_PIPELINE_STAGE_TRANSFER_BIT,
               VkAccessFlags destination_access =
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                   VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT) {
    VkMemoryBarrier memory{};
    memory.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    memory.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    memory.dstAccessMask = destination_access;
    api_.vkCmdPipelineBarrier(recording(),
                              VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                              destination_stage, 0, 1, &memory, 0, nullptr, 0, nullptr);
  }

  // Submits what was recorded and waits for it.
  void flush() {
    if (!recording_) return;
    barrier(VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);  // results become host-readable
    recording_ = false;
    vk_check(api_.vkEndCommandBuffer(commands_), "vkEndCommandBuffer");
    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &commands_;
    vk_check(api_.vkQueueSubmit(queue_, 1, &submit, fence_), "vkQueueSubmit");
    vk_check(api_.vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    vk_check(api_.vkResetFences(device_, 1, &fence_), "vkResetFences");
    if (timestamps_) timestamps_->collect();
    vk_check(api_.vkResetCommandPool(device_, command_pool_, 0), "vkResetCommandPool");
    for (VkDescriptorPool pool : descriptor_pools_) api_.vkResetDescriptorPool(device_, pool, 0);
    staging_.clear();
    for (const BufferHandles& handles : retired_) destroy(handles);
    retired_.clear();
  }

  std::shared_ptr<VulkanInstance> instance_;
  VkPhysicalDevice physical_;
  DeviceInfo info_;
  std::uint64_t validation_baseline_;
  VkDevice device_ = VK_NULL_HANDLE;
  VulkanDeviceApi api_;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memory_properties_{};
  std::optional<uint32_t> unified_type_;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  bool recording_ = false;
  std::vector<VkDescriptorPool> descriptor_pools_;
  std::vector<std::unique_ptr<VulkanBuffer>> staging_;  // freed once their commands completed
  std::vector<BufferHandles> retired_;                   // likewise
  std::map<std::string, Pipeline, std::less<>> pipelines_;
  std::unique_ptr<DeviceBuffer> placeholder_;
  std::unique_ptr<VulkanTimestamps> timestamps_;  // with ContextParams::profile
  static constexpr std::size_t kPoolLimitBytes = std::size_t{256} << 20;
  static constexpr std::size_t kInlineUpdateBytes = 65536;  // vkCmdUpdateBuffer's limit
  std::multimap<std::pair<std::size_t, int>, BufferHandles> pool_;  // freed, kept for reuse
  std::size_t pooled_bytes_ = 0;
  bool closing_ = false;  // the destructor runs: free for real
};

VulkanBuffer::~VulkanBuffer() { owner->retire(handles); }

}  // namespace

BackendStatus probe_vulkan() {
  BackendStatus status;
  status.backend = BackendKind::vulkan;
  try {
    auto instance = VulkanInstance::create(false);
    for (PhysicalDevice& device : enumerate(*instance)) status.devices.push_back(device.info);
    bool any_usable = false;
    for (const DeviceInfo& device : status.devices) any_usable |= device.usable;
    status.available = any_usable;
    if (status.devices.empty()) {
      status.reason = "the Vulkan loader and driver report zero physical devices";
    } else if (!any_usable) {
      status.reason = "no Vulkan device has what Kartograf needs (" +
                      status.devices.front().unusable_reason + ")";
    }
  } catch (const Error& error) {
    status.available = false;
    status.reason = error.what();
  }
  return status;
}

std::shared_ptr<Device> create_vulkan_device(const ContextParams& options) {
  std::shared_ptr<VulkanInstance> instance;
  try {
    instance = VulkanInstance::create(options.vulkan_validation);
  } catch (const Error& error) {
    throw Error(std::string("Vulkan backend unavailable: ") + error.what());
  }
  std::vector<PhysicalDevice> usable;
  std::string reasons;
  for (PhysicalDevice& device : enumerate(*instance)) {
    if (device.info.usable) {
      usable.push_back(device);
    } else {
      reasons += "; " + device.info.name + " " + device.info.unusable_reason;
    }
  }
  if (usable.empty()) {
    throw Error("Vulkan backend unavailable: no usable physical device" +
                (reasons.empty() ? std::string(" (zero devices)") : reasons));
  }
  std::vector<const DeviceInfo*> infos;
  for (const PhysicalDevice& device : usable) infos.push_back(&device.info);
  const std::size_t index = choose_device(infos, options, "Vulkan");
  return std::make_shared<VulkanDevice>(std::move(instance), usable[index], options.profile);
}

}  // namespace kartograf::compute::detail
