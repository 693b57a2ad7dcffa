#include "compute/vulkan/vulkan_api.hpp"

#include <cstdio>
#include <cstring>
#include <mutex>
#include <vector>

#include "compute/dynamic_library.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::compute::detail {
namespace {

struct GlobalApi {
  PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;
#define KARTOGRAF_VK_MEMBER(name) PFN_##name name = nullptr;
  KARTOGRAF_VK_GLOBAL_FUNCTIONS(KARTOGRAF_VK_MEMBER)
#undef KARTOGRAF_VK_MEMBER
  std::string error;
};

const GlobalApi& global_api() {
  static const GlobalApi api = [] {
    GlobalApi result;
    static DynamicLibrary library("libvulkan.so.1");  // kept loaded for the process's lifetime
    if (!library.loaded()) {
      result.error = "no Vulkan loader (libvulkan.so.1): " + library.error() +
                     " (install libvulkan1 and a driver such as mesa-vulkan-drivers)";
      return result;
    }
    result.get_instance_proc_addr = library.symbol<PFN_vkGetInstanceProcAddr>("vkGetInstanceProcAddr");
    if (!result.get_instance_proc_addr) {
      result.error = "libvulkan.so.1 has no vkGetInstanceProcAddr";
      return result;
    }
#define KARTOGRAF_VK_LOAD(name) \
  result.name = reinterpret_cast<PFN_##name>(result.get_instance_proc_addr(nullptr, #name));
    KARTOGRAF_VK_GLOBAL_FUNCTIONS(KARTOGRAF_VK_LOAD)
#undef KARTOGRAF_VK_LOAD
    if (!result.vkCreateInstance) result.error = "the Vulkan loader exports no vkCreateInstance";
    return result;
  }();
  return api;
}

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* instance = static_cast<VulkanInstance*>(user);
  if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
    ++instance->validation_errors;
    std::fprintf(stderr, "[vulkan validation error] %s\n", data->pMessage);
  } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    std::fprintf(stderr, "[vulkan validation warning] %s\n", data->pMessage);
  }
  return VK_FALSE;
}

bool has_layer(const char* name) {
  const GlobalApi& api = global_api();
  uint32_t count = 0;
  api.vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  api.vkEnumerateInstanceLayerProperties(&count, layers.data());
  for (const auto& layer : layers) {
    if (std::strcmp(layer.layerName, name) == 0) return true;
  }
  return false;
}

bool has_instance_extension(const char* layer, const char* name) {
  const GlobalApi& api = global_api();
  uint32_t count = 0;
  api.vkEnumerateInstanceExtensionProperties(layer, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  api.vkEnumerateInstanceExtensionProperties(layer, &count, extensions.data());
  for (const auto& extension : extensions) {
    if (std::strcmp(extension.extensionName, name) == 0) return true;
  }
  return false;
}

}  // namespace

std::string vk_result_name(VkResult result) {
  switch (result) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_OUT_OF_POOL_MEMORY: return "VK_ERROR_OUT_OF_POOL_MEMORY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    default: return "VkResult " + std::to_string(static_cast<int>(result));
  }
}

void vk_check(VkResult result, const std::string& what) {
  if (result != VK_SUCCESS) throw Error("Vulkan: " + what + " failed: " + vk_result_name(result));
}

// One instance per validation setting for the whole process, never destroyed: the loader unloads
// the driver with the last instance, and loading NVIDIA's driver again and again exhausts glibc's
// static TLS ("libnvidia-tls.so: cannot allocate memory in static TLS block" after ~30 contexts,
// seen on an H100); it also saves the driver's start-up per context. Kept past static destruction
// (a leak by design): the loader library it calls into stays loaded until the process ends.
// A failure is not kept, so a later call tries again.
std::shared_ptr<VulkanInstance> VulkanInstance::create(bool want_validation) {
  static std::mutex mutex;
  static auto* instances = new std::shared_ptr<VulkanInstance>[2];
  std::lock_guard lock(mutex);
  std::shared_ptr<VulkanInstance>& slot = instances[want_validation ? 1 : 0];
  if (!slot) slot = create_new(want_validation);
  return slot;
}

namespace {
// Warnings and errors of every kind go to on_validation_message, which counts the errors of `owner`.
VkDebugUtilsMessengerCreateInfoEXT messenger_create_info(VulkanInstance* owner) {
  VkDebugUtilsMessengerCreateInfoEXT info{};
  info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  info.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = on_validation_message;
  info.pUserData = owner;
  return info;
}
}  // namespace

std::shared_ptr<VulkanInstance> VulkanInstance::create_new(bool want_validation) {
  const GlobalApi& api = global_api();
  if (!api.error.empty()) throw Error(api.error);

  uint32_t loader_version = VK_API_VERSION_1_0;
  if (api.vkEnumerateInstanceVersion) api.vkEnumerateInstanceVersion(&loader_version);
  if (loader_version < VK_API_VERSION_1_1) {
    throw Error("the Vulkan loader supports only Vulkan 1.0; Kartograf needs 1.1");
  }

  auto result = std::make_shared<VulkanInstance>();
  constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  const bool validation = want_validation && has_layer(kValidationLayer);
  const bool debug_utils = validation && has_instance_extension(nullptr, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  const bool features = validation && has_instance_extension(kValidationLayer,
                                                             VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
  if (validation) layers.push_back(kValidationLayer);
  if (debug_utils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  if (features) extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);

  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "kartograf";
  app.pEngineName = "kartograf";
  app.apiVersion = VK_API_VERSION_1_2;

  // Synchronization validation catches the missing barriers that in-order lavapipe forgives.
  const VkValidationFeatureEnableEXT enables[] = {
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT validation_features{};
  validation_features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
  validation_features.enabledValidationFeatureCount = 1;
  validation_features.pEnabledValidationFeatures = enables;

  VkDebugUtilsMessengerCreateInfoEXT messenger_info = messenger_create_info(result.get());
  if (features) messenger_info.pNext = &validation_features;

  VkInstanceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  if (debug_utils) info.pNext = &messenger_info;  // also reports errors of instance creation

  const VkResult created = api.vkCreateInstance(&info, nullptr, &result->instance);
  if (created == VK_ERROR_INCOMPATIBLE_DRIVER) {
    throw Error("no Vulkan driver (vkCreateInstance: VK_ERROR_INCOMPATIBLE_DRIVER): the loader found "
                "no ICD (install mesa-vulkan-drivers or a GPU driver; check VK_DRIVER_FILES)");
  }
  vk_check(created, "vkCreateInstance");

#define KARTOGRAF_VK_LOAD(name)                     \
  result->name = reinterpret_cast<PFN_##name>(      \
      api.get_instance_proc_addr(result->instance, #name));
  KARTOGRAF_VK_INSTANCE_FUNCTIONS(KARTOGRAF_VK_LOAD)
  KARTOGRAF_VK_DEBUG_FUNCTIONS(KARTOGRAF_VK_LOAD)
#undef KARTOGRAF_VK_LOAD
  if (!result->vkGetPhysicalDeviceFeatures2 || !result->vkCreateDevice) {
    throw Error("the Vulkan instance lacks Vulkan 1.1 entry points");
  }
  if (debug_utils && result->vkCreateDebugUtilsMessengerEXT) {
    messenger_info.pNext = nullptr;
    vk_check(result->vkCreateDebugUtilsMessengerEXT(result->instance, &messenger_info, nullptr,
                                                    &result->messenger),
             "vkCreateDebugUtilsMessengerEXT");
    result->validation = true;
  }
  return result;
}

VulkanInstance::~VulkanInstance() {
  if (messenger != VK_NULL_HANDLE) vkDestroyDebugUtilsMessengerEXT(instance, messenger, nullptr);
  if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
}

void VulkanDeviceApi::load(const VulkanInstance& instance, VkDevice device) {
#define KARTOGRAF_VK_LOAD(name)                                                 \
  name = reinterpret_cast<PFN_##name>(instance.vkGetDeviceProcAddr(device, #name)); \
  if (!name) throw Error("Vulkan: the device lacks " #name);
  KARTOGRAF_VK_DEVICE_FUNCTIONS(KARTOGRAF_VK_LOAD)
#undef KARTOGRAF_VK_LOAD
}

}  // namespace kartograf::compute::detail
