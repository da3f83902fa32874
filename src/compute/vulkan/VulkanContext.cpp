#include "compute/vulkan/VulkanContext.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>

#include "core/Error.h"

namespace plano::vk {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

/// Lower is better: the order in which device types are preferred.
int typeRank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

bool hasLayer(const char* name) {
  std::uint32_t count = 0;
  vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  return std::any_of(layers.begin(), layers.end(),
                     [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

/// A compute-capable queue family, preferring one without graphics (a dedicated
/// compute queue runs beside the display on real GPUs); -1 when there is none.
int computeQueueFamily(VkPhysicalDevice device) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  int best = -1;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (!(families[i].queueFlags & VK_QUEUE_COMPUTE_BIT)) continue;
    if (best < 0 || !(families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT)) best = static_cast<int>(i);
  }
  return best;
}

}  // namespace

ContextSettings ContextSettings::fromEnvironment(DeviceSelection selection) {
  ContextSettings settings;
  settings.selection = selection;
  if (const char* device = std::getenv("PLANO_VULKAN_DEVICE")) settings.deviceOverride = device;
  if (const char* validation = std::getenv("PLANO_VULKAN_VALIDATION")) {
    settings.validation = std::string(validation) == "1";
  }
  settings.faults = SimulatedFaults::fromEnvironment();
  return settings;
}

const char* resultName(VkResult result) {
  switch (result) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_INCOMPLETE: return "VK_INCOMPLETE";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED: return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_OUT_OF_POOL_MEMORY: return "VK_ERROR_OUT_OF_POOL_MEMORY";
    default: return "VkResult error";
  }
}

void Context::check(VkResult result, const char* what) {
  if (result == VK_SUCCESS) return;
  std::string message = std::string("Vulkan: ") + what + " failed: " + resultName(result);
  if (result == VK_ERROR_DEVICE_LOST) message += " (device lost: the results of this run are void)";
  if (result == VK_ERROR_OUT_OF_DEVICE_MEMORY || result == VK_ERROR_OUT_OF_HOST_MEMORY) {
    message += " (try a smaller mesh or the CPU backend)";
  }
  throwDevice(message);
}

Context::Context(const ContextSettings& settings) : settings_(settings) {
  try {
    createInstance();
    choosePhysicalDevice();
    createDevice();
  } catch (...) {
    destroy();
    throw;
  }
}

Context::~Context() { destroy(); }

void Context::destroy() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    if (commandPool_) vkDestroyCommandPool(device_, commandPool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroyMessenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroyMessenger) destroyMessenger(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
  commandPool_ = VK_NULL_HANDLE;
  device_ = VK_NULL_HANDLE;
  messenger_ = VK_NULL_HANDLE;
  instance_ = VK_NULL_HANDLE;
}

VKAPI_ATTR VkBool32 VKAPI_CALL Context::onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                       VkDebugUtilsMessageTypeFlagsEXT,
                                                       const VkDebugUtilsMessengerCallbackDataEXT* data, void* self) {
  auto* context = static_cast<Context*>(self);
  const char* level = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning";
  std::lock_guard lock(context->messagesMutex_);
  context->messages_.push_back(std::string(level) + ": " + (data && data->pMessage ? data->pMessage : ""));
  return VK_FALSE;  // never abort the call that triggered the message
}

void Context::createInstance() {
  auto app = vkStruct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  app.pApplicationName = "plano";
  app.pEngineName = "plano";
  app.apiVersion = VK_API_VERSION_1_1;

  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  if (settings_.validation) {
    if (!hasLayer(kValidationLayer)) {
      throwDevice(std::string("PLANO_VULKAN_VALIDATION=1 but the validation layer ") + kValidationLayer +
                  " is not installed (Debian package vulkan-validationlayers)");
    }
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }

  // Chained into the instance so that instance creation itself is validated too.
  auto messengerInfo = vkStruct<VkDebugUtilsMessengerCreateInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
  messengerInfo.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messengerInfo.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messengerInfo.pfnUserCallback = &Context::onDebugMessage;
  messengerInfo.pUserData = this;

  auto info = vkStruct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  if (settings_.validation) info.pNext = &messengerInfo;

  const VkResult result = vkCreateInstance(&info, nullptr, &instance_);
  if (result == VK_ERROR_INCOMPATIBLE_DRIVER) {
    throwDevice("Vulkan: no Vulkan driver found (vkCreateInstance: VK_ERROR_INCOMPATIBLE_DRIVER); install a driver "
                "(mesa-vulkan-drivers provides lavapipe) or check VK_DRIVER_FILES");
  }
  check(result, "creating the Vulkan instance");

  if (settings_.validation) {
    auto createMessenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    if (!createMessenger) throwDevice("Vulkan: VK_EXT_debug_utils is not available for the validation messenger");
    check(createMessenger(instance_, &messengerInfo, nullptr, &messenger_), "creating the debug messenger");
  }
}

void Context::choosePhysicalDevice() {
  std::uint32_t count = 0;
  VkResult result = vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  if (result == VK_ERROR_INITIALIZATION_FAILED || count == 0) {
    throwDevice("Vulkan: no Vulkan device found (no driver reports a physical device; check VK_DRIVER_FILES)");
  }
  check(result, "enumerating physical devices");
  std::vector<VkPhysicalDevice> devices(count);
  check(vkEnumeratePhysicalDevices(instance_, &count, devices.data()), "enumerating physical devices");

  struct Candidate {
    std::uint32_t index;
    VkPhysicalDeviceProperties properties;
    VkPhysicalDeviceFeatures features;
    int queueFamily;
  };
  std::vector<Candidate> candidates;
  for (std::uint32_t i = 0; i < count; ++i) {
    Candidate c{i, {}, {}, computeQueueFamily(devices[i])};
    vkGetPhysicalDeviceProperties(devices[i], &c.properties);
    vkGetPhysicalDeviceFeatures(devices[i], &c.features);
    if (settings_.faults.noFloat64) c.features.shaderFloat64 = VK_FALSE;
    candidates.push_back(c);
  }
  auto describe = [](const Candidate& c) {
    return "device " + std::to_string(c.index) + " '" + std::string(c.properties.deviceName) + "'";
  };
  auto usable = [&](const Candidate& c, std::string* why) {
    if (c.queueFamily < 0) {
      if (why) *why = describe(c) + " has no compute queue";
      return false;
    }
    if (!c.features.shaderFloat64) {
      if (why) {
        *why = describe(c) + " lacks shaderFloat64 (Plano's kernels are double precision)" +
               (settings_.faults.noFloat64 ? " [simulated by PLANO_VULKAN_SIMULATE_NO_FLOAT64]" : "");
      }
      return false;
    }
    if (settings_.selection == DeviceSelection::RealGpuOnly &&
        c.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) {
      if (why) *why = describe(c) + " is a CPU implementation, not a GPU";
      return false;
    }
    return true;
  };

  const Candidate* chosen = nullptr;
  if (!settings_.deviceOverride.empty()) {
    const std::string& wanted = settings_.deviceOverride;
    const bool isIndex = std::all_of(wanted.begin(), wanted.end(), [](unsigned char ch) { return std::isdigit(ch); });
    for (const auto& c : candidates) {
      const bool match = isIndex ? std::to_string(c.index) == wanted
                                 : lower(c.properties.deviceName).find(lower(wanted)) != std::string::npos;
      if (match) {
        chosen = &c;
        break;
      }
    }
    if (!chosen) {
      std::string list;
      for (const auto& c : candidates) list += (list.empty() ? "" : ", ") + describe(c);
      throwDevice("Vulkan: PLANO_VULKAN_DEVICE='" + wanted + "' matches no device (available: " + list + ")");
    }
    std::string why;
    if (!usable(*chosen, &why)) throwDevice("Vulkan: PLANO_VULKAN_DEVICE selects " + why);
  } else {
    std::string reasons;
    for (const auto& c : candidates) {
      std::string why;
      if (!usable(c, &why)) {
        reasons += (reasons.empty() ? "" : "; ") + why;
        continue;
      }
      if (!chosen || typeRank(c.properties.deviceType) < typeRank(chosen->properties.deviceType)) chosen = &c;
    }
    if (!chosen) throwDevice("Vulkan: no suitable device: " + reasons);
  }

  physicalDevice_ = devices[chosen->index];
  queueFamily_ = static_cast<std::uint32_t>(chosen->queueFamily);
  vkGetPhysicalDeviceMemoryProperties(physicalDevice_, &memory_);

  const VkPhysicalDeviceLimits& limits = chosen->properties.limits;
  info_.name = chosen->properties.deviceName;
  info_.type = chosen->properties.deviceType;
  info_.index = chosen->index;
  info_.shaderFloat64 = chosen->features.shaderFloat64;
  info_.shaderInt64 = chosen->features.shaderInt64;
  info_.maxStorageBufferRange = limits.maxStorageBufferRange;
  info_.maxStorageBuffersPerStage = limits.maxPerStageDescriptorStorageBuffers;
  for (int d = 0; d < 3; ++d) {
    info_.maxWorkGroupCount[d] = limits.maxComputeWorkGroupCount[d];
    if (settings_.maxWorkGroups > 0) info_.maxWorkGroupCount[d] = std::min(info_.maxWorkGroupCount[d], settings_.maxWorkGroups);
  }
  info_.maxWorkGroupInvocations = limits.maxComputeWorkGroupInvocations;
  info_.maxSharedMemoryBytes = limits.maxComputeSharedMemorySize;
  info_.minStorageBufferOffsetAlignment = limits.minStorageBufferOffsetAlignment;

  std::uint32_t familyCount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice_, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice_, &familyCount, families.data());
  if (families[queueFamily_].timestampValidBits > 0 && limits.timestampComputeAndGraphics) {
    info_.timestampPeriodNs = limits.timestampPeriod;
  }
  for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
    const VkMemoryPropertyFlags flags = memory_.memoryTypes[i].propertyFlags;
    if ((flags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) && (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) &&
        (flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)) {
      // Only a true unified memory (integrated GPU, CPU device) counts: a small BAR window
      // on a discrete GPU is no place for mesh-sized buffers.
      const VkDeviceSize heapSize = memory_.memoryHeaps[memory_.memoryTypes[i].heapIndex].size;
      if (info_.type != VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU || heapSize >= (VkDeviceSize(1) << 32)) {
        info_.unifiedMemory = true;
      }
    }
  }
}

void Context::createDevice() {
  const float priority = 1.0f;
  auto queueInfo = vkStruct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
  queueInfo.queueFamilyIndex = queueFamily_;
  queueInfo.queueCount = 1;
  queueInfo.pQueuePriorities = &priority;

  VkPhysicalDeviceFeatures features{};
  features.shaderFloat64 = VK_TRUE;
  features.shaderInt64 = info_.shaderInt64 ? VK_TRUE : VK_FALSE;

  auto info = vkStruct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queueInfo;
  info.pEnabledFeatures = &features;
  check(vkCreateDevice(physicalDevice_, &info, nullptr, &device_), "creating the logical device");
  vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);

  auto poolInfo = vkStruct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  poolInfo.queueFamilyIndex = queueFamily_;
  check(vkCreateCommandPool(device_, &poolInfo, nullptr, &commandPool_), "creating the command pool");
}

std::uint32_t Context::memoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                                  VkMemoryPropertyFlags preferred) const {
  int fallback = -1;
  for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
    if (!(typeBits & (1u << i))) continue;
    const VkMemoryPropertyFlags flags = memory_.memoryTypes[i].propertyFlags;
    if ((flags & required) != required) continue;
    if ((flags & preferred) == preferred) return i;
    if (fallback < 0) fallback = static_cast<int>(i);
  }
  if (fallback < 0) throwDevice("Vulkan: the device has no memory type with the properties a buffer needs");
  return static_cast<std::uint32_t>(fallback);
}

void Context::reserveMemory(VkDeviceSize bytes, std::uint32_t memoryType, const char* what) {
  const std::uint32_t heap = memory_.memoryTypes[memoryType].heapIndex;
  const VkDeviceSize heapSize = memory_.memoryHeaps[heap].size;
  std::lock_guard lock(allocationMutex_);
  const std::string request = "Vulkan: allocating " + std::to_string(bytes) + " bytes for " + what;
  if (bytes > heapSize || heapUsage_[heap] > heapSize - bytes) {
    throwDevice(request + " would bring memory heap " + std::to_string(heap) + " to " +
                std::to_string(heapUsage_[heap] + bytes) + " bytes, over its size of " + std::to_string(heapSize) +
                " bytes (try a smaller mesh or the CPU backend)");
  }
  const std::uint64_t limit = settings_.faults.memoryLimit;
  if (limit > 0 && (bytes > limit || totalUsage_ > limit - bytes)) {
    throwDevice(request + " would bring device allocations to " + std::to_string(totalUsage_ + bytes) +
                " bytes, over the memory limit of " + std::to_string(limit) +
                " bytes [simulated by PLANO_VULKAN_MEMORY_LIMIT] (try a smaller mesh or the CPU backend)");
  }
  heapUsage_[heap] += bytes;
  totalUsage_ += bytes;
  peakUsage_ = std::max(peakUsage_, totalUsage_);
}

VkDeviceSize Context::allocatedBytes() const {
  std::lock_guard lock(allocationMutex_);
  return totalUsage_;
}

VkDeviceSize Context::peakAllocatedBytes() const {
  std::lock_guard lock(allocationMutex_);
  return peakUsage_;
}

void Context::resetPeakAllocatedBytes() {
  std::lock_guard lock(allocationMutex_);
  peakUsage_ = totalUsage_;
}

void Context::countTransfer(bool upload, std::size_t bytes) {
  std::lock_guard lock(allocationMutex_);
  if (upload) {
    transfers_.uploadedBytes += bytes;
    ++transfers_.uploads;
    transfers_.largestUpload = std::max<std::uint64_t>(transfers_.largestUpload, bytes);
  } else {
    transfers_.downloadedBytes += bytes;
    ++transfers_.downloads;
    transfers_.largestDownload = std::max<std::uint64_t>(transfers_.largestDownload, bytes);
  }
}

void Context::resetLargestTransfers() {
  std::lock_guard lock(allocationMutex_);
  transfers_.largestUpload = 0;
  transfers_.largestDownload = 0;
}

TransferCounts Context::transfers() const {
  std::lock_guard lock(allocationMutex_);
  return transfers_;
}

void Context::releaseMemory(VkDeviceSize bytes, std::uint32_t memoryType) {
  const std::uint32_t heap = memory_.memoryTypes[memoryType].heapIndex;
  std::lock_guard lock(allocationMutex_);
  heapUsage_[heap] -= std::min(bytes, heapUsage_[heap]);
  totalUsage_ -= std::min(bytes, totalUsage_);
}

VkResult Context::submissionResult(VkResult result) {
  std::lock_guard lock(allocationMutex_);
  ++submissions_;
  const std::uint64_t lostAt = settings_.faults.deviceLostAtSubmit;
  // A lost device stays lost, as a real one does.
  if (lostAt > 0 && submissions_ >= lostAt) return VK_ERROR_DEVICE_LOST;
  return result;
}

std::vector<std::string> Context::validationMessages() const {
  std::lock_guard lock(messagesMutex_);
  return messages_;
}

std::size_t Context::validationMessageCount() const {
  std::lock_guard lock(messagesMutex_);
  return messages_.size();
}

}  // namespace plano::vk
