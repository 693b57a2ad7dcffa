#pragma once
// Vulkan entry points resolved at run time from libvulkan.so.1 (never linked), and an RAII
// instance that probing and devices share.
#define VK_NO_PROTOTYPES
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

namespace kartograf::compute::detail {

#define KARTOGRAF_VK_GLOBAL_FUNCTIONS(X)                                               \
  X(vkCreateInstance) X(vkEnumerateInstanceLayerProperties)                             \
  X(vkEnumerateInstanceExtensionProperties) X(vkEnumerateInstanceVersion)

#define KARTOGRAF_VK_INSTANCE_FUNCTIONS(X)                                             \
  X(vkDestroyInstance) X(vkEnumeratePhysicalDevices) X(vkGetPhysicalDeviceProperties)  \
  X(vkGetPhysicalDeviceProperties2) X(vkGetPhysicalDeviceFeatures2)                    \
  X(vkGetPhysicalDeviceMemoryProperties) X(vkGetPhysicalDeviceQueueFamilyProperties)   \
  X(vkEnumerateDeviceExtensionProperties) X(vkCreateDevice) X(vkGetDeviceProcAddr)

#define KARTOGRAF_VK_DEBUG_FUNCTIONS(X) \
  X(vkCreateDebugUtilsMessengerEXT) X(vkDestroyDebugUtilsMessengerEXT)

#define KARTOGRAF_VK_DEVICE_FUNCTIONS(X)                                                    \
  X(vkDestroyDevice) X(vkGetDeviceQueue) X(vkCreateBuffer) X(vkDestroyBuffer)               \
  X(vkGetBufferMemoryRequirements) X(vkAllocateMemory) X(vkFreeMemory) X(vkBindBufferMemory) \
  X(vkMapMemory) X(vkUnmapMemory) X(vkCreateShaderModule) X(vkDestroyShaderModule)          \
  X(vkCreateDescriptorSetLayout) X(vkDestroyDescriptorSetLayout) X(vkCreatePipelineLayout)  \
  X(vkDestroyPipelineLayout) X(vkCreateComputePipelines) X(vkDestroyPipeline)               \
  X(vkCreateDescriptorPool) X(vkDestroyDescriptorPool) X(vkResetDescriptorPool)             \
  X(vkAllocateDescriptorSets) X(vkUpdateDescriptorSets) X(vkCreateCommandPool)              \
  X(vkDestroyCommandPool) X(vkResetCommandPool) X(vkAllocateCommandBuffers)                 \
  X(vkBeginCommandBuffer) X(vkEndCommandBuffer) X(vkCmdBindPipeline)                        \
  X(vkCmdBindDescriptorSets) X(vkCmdPushConstants) X(vkCmdDispatch)                         \
  X(vkCmdPipelineBarrier) X(vkCmdCopyBuffer) X(vkCmdFillBuffer) X(vkQueueSubmit)            \
  X(vkCreateFence) X(vkDestroyFence) X(vkWaitForFences) X(vkResetFences)                    \
  X(vkDeviceWaitIdle) X(vkCreateQueryPool) X(vkDestroyQueryPool) X(vkGetQueryPoolResults)     \
  X(vkCmdResetQueryPool) X(vkCmdWriteTimestamp) X(vkCmdUpdateBuffer)

#define KARTOGRAF_VK_MEMBER(name) PFN_##name name = nullptr;

struct VulkanInstance {
  KARTOGRAF_VK_INSTANCE_FUNCTIONS(KARTOGRAF_VK_MEMBER)
  KARTOGRAF_VK_DEBUG_FUNCTIONS(KARTOGRAF_VK_MEMBER)
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  bool validation = false;
  std::atomic<std::uint64_t> validation_errors{0};

  // The process's instance for this validation setting (made on first use). Throws Error with the
  // reason when there is no loader, no driver, or instance creation fails.
  static std::shared_ptr<VulkanInstance> create(bool want_validation);
  ~VulkanInstance();

 private:
  static std::shared_ptr<VulkanInstance> create_new(bool want_validation);
};

struct VulkanDeviceApi {
  KARTOGRAF_VK_DEVICE_FUNCTIONS(KARTOGRAF_VK_MEMBER)
  void load(const VulkanInstance& instance, VkDevice device);
};

#undef KARTOGRAF_VK_MEMBER

std::string vk_result_name(VkResult result);
// Throws Error("Vulkan: <what> failed: <result>") unless result is VK_SUCCESS.
void vk_check(VkResult result, const std::string& what);

}  // namespace kartograf::compute::detail
