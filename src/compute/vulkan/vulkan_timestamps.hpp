#pragma once
// Device times of recorded Vulkan commands: a timestamp when every earlier command has finished
// and one when the command itself has, read back once the command buffer completed.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "compute/vulkan/vulkan_api.hpp"
#include "kartograf/compute/context.hpp"

namespace kartograf::compute::detail {

class VulkanTimestamps {
 public:
  // period_ns: VkPhysicalDeviceLimits::timestampPeriod; valid_bits: the queue family's.
  VulkanTimestamps(const VulkanDeviceApi& api, VkDevice device, double period_ns,
                   std::uint32_t valid_bits);
  ~VulkanTimestamps();
  VulkanTimestamps(const VulkanTimestamps&) = delete;
  VulkanTimestamps& operator=(const VulkanTimestamps&) = delete;

  // No room for another command in this command buffer: submit it first.
  bool full() const { return 2 * names_.size() + 2 > kCapacity; }
  // At the start of every command buffer: the pool's queries are reset there.
  void begin_recording(VkCommandBuffer commands);
  void before(VkCommandBuffer commands, std::string_view name);
  void after(VkCommandBuffer commands);
  // After the command buffer completed: its commands' times join the completed list.
  void collect();
  std::vector<DeviceTiming> take();

 private:
  static constexpr std::uint32_t kCapacity = 4096;  // queries: two per command
  const VulkanDeviceApi& api_;
  VkDevice device_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
  double period_ns_;
  std::uint64_t mask_;
  std::vector<std::string> names_;  // of the commands recorded in the current command buffer
  std::vector<DeviceTiming> completed_;
};

}  // namespace kartograf::compute::detail
