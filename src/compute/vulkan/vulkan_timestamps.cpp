#include "compute/vulkan/vulkan_timestamps.hpp"

#include "kartograf/core/error.hpp"

namespace kartograf::compute::detail {

VulkanTimestamps::VulkanTimestamps(const VulkanDeviceApi& api, VkDevice device, double period_ns,
                                   std::uint32_t valid_bits)
    : api_(api),
      device_(device),
      period_ns_(period_ns),
      mask_(valid_bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << valid_bits) - 1) {
  VkQueryPoolCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = kCapacity;
  vk_check(api_.vkCreateQueryPool(device_, &info, nullptr, &pool_), "vkCreateQueryPool");
}

VulkanTimestamps::~VulkanTimestamps() {
  api_.vkDestroyQueryPool(device_, pool_, nullptr);
}

void VulkanTimestamps::begin_recording(VkCommandBuffer commands) {
  api_.vkCmdResetQueryPool(commands, pool_, 0, kCapacity);
  names_.clear();
}

// BOTTOM_OF_PIPE: written once every earlier command has completed, so the pair brackets the
// command itself (the barriers between commands make them run one after another).
void VulkanTimestamps::before(VkCommandBuffer commands, std::string_view name) {
  const auto query = static_cast<std::uint32_t>(2 * names_.size());
  api_.vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, query);
  names_.emplace_back(name);
}

void VulkanTimestamps::after(VkCommandBuffer commands) {
  const auto query = static_cast<std::uint32_t>(2 * names_.size() - 1);
  api_.vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, query);
}

void VulkanTimestamps::collect() {
  if (names_.empty()) return;
  std::vector<std::uint64_t> ticks(2 * names_.size());
  vk_check(api_.vkGetQueryPoolResults(device_, pool_, 0, static_cast<std::uint32_t>(ticks.size()),
                                      ticks.size() * sizeof(std::uint64_t), ticks.data(),
                                      sizeof(std::uint64_t),
                                      VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
           "vkGetQueryPoolResults");
  for (std::size_t i = 0; i < names_.size(); ++i) {
    const std::uint64_t elapsed = ((ticks[2 * i + 1] & mask_) - (ticks[2 * i] & mask_)) & mask_;
    completed_.push_back({names_[i], static_cast<double>(elapsed) * period_ns_ * 1e-6});
  }
  names_.clear();
}

std::vector<DeviceTiming> VulkanTimestamps::take() {
  std::vector<DeviceTiming> result;
  result.swap(completed_);
  return result;
}

}  // namespace kartograf::compute::detail
