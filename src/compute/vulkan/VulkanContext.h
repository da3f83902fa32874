#pragma once
// The Vulkan runtime's root object (Kompute's "manager"): instance, chosen physical
// device, logical device, one compute queue and a command pool. Every buffer, pipeline
// and sequence is created against a Context; nothing is process-global, so two backends
// (or two tests) never share device state.
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "compute/vulkan/VulkanFaultSimulation.h"

namespace plano::vk {

/// Which physical devices are acceptable.
enum class DeviceSelection {
  Any,          ///< Best available: discrete GPU > integrated > virtual > CPU (lavapipe).
  RealGpuOnly,  ///< Refuse CPU implementations (lavapipe, SwiftShader).
};

struct ContextSettings {
  DeviceSelection selection = DeviceSelection::Any;
  /// Index or case-insensitive name substring of the device to use; empty = best.
  /// fromEnvironment() fills it from PLANO_VULKAN_DEVICE.
  std::string deviceOverride;
  /// Enable VK_LAYER_KHRONOS_validation and a debug messenger that records every
  /// warning and error. fromEnvironment() sets it when PLANO_VULKAN_VALIDATION=1.
  bool validation = false;
  /// Upload and download through staging buffers even when device memory is host
  /// visible (exercises the discrete-GPU path on lavapipe).
  bool forceStaging = false;
  /// Cap on the workgroups of one dispatch dimension (0: the device's limit). Tests lower
  /// it to exercise the kernels' grid-stride loops on small inputs.
  std::uint32_t maxWorkGroups = 0;
  /// Test-only fault injection (VulkanFaultSimulation.h); fromEnvironment() reads it.
  SimulatedFaults faults;

  /// Settings with deviceOverride, validation and faults read from the environment.
  static ContextSettings fromEnvironment(DeviceSelection selection);
};

/// Host <-> device copies through Buffer::upload and Buffer::download since the Context was
/// created: what a loop that is meant to stay on the device still moves (the benchmarks'
/// transfer counters). A copy into or out of mapped memory counts as one, as a staged one.
struct TransferCounts {
  std::uint64_t uploadedBytes = 0;
  std::uint64_t downloadedBytes = 0;
  std::uint64_t uploads = 0;
  std::uint64_t downloads = 0;
  /// The largest single copy each way since the context was made or resetLargestTransfers:
  /// whether a loop still moves a mesh-sized array, whatever its scalars add up to.
  std::uint64_t largestUpload = 0;
  std::uint64_t largestDownload = 0;
};

/// What the chosen device offers; kernels check it before use.
struct DeviceInfo {
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  std::uint32_t index = 0;  ///< Position in vkEnumeratePhysicalDevices.
  bool shaderFloat64 = false;
  bool shaderInt64 = false;
  std::uint32_t maxStorageBufferRange = 0;
  std::uint32_t maxStorageBuffersPerStage = 0;  ///< Storage buffers one kernel may bind.
  std::uint32_t maxWorkGroupCount[3] = {0, 0, 0};  ///< Lowered by ContextSettings::maxWorkGroups.
  std::uint32_t maxWorkGroupInvocations = 0;
  std::uint32_t maxSharedMemoryBytes = 0;
  VkDeviceSize minStorageBufferOffsetAlignment = 1;
  double timestampPeriodNs = 0.0;  ///< 0 when the queue has no timestamps.
  bool unifiedMemory = false;      ///< A heap that is both device-local and host-visible.
};

class Context {
 public:
  /// Create instance and device. Throws Error(Device) naming the reason: no Vulkan
  /// driver, no device, no device with shaderFloat64 and a compute queue, a forced
  /// device that does not exist, a missing validation layer.
  explicit Context(const ContextSettings& settings);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkDevice device() const { return device_; }
  VkPhysicalDevice physicalDevice() const { return physicalDevice_; }
  VkQueue queue() const { return queue_; }
  VkCommandPool commandPool() const { return commandPool_; }
  const DeviceInfo& info() const { return info_; }
  const ContextSettings& settings() const { return settings_; }

  /// Memory type for `typeBits` with all `required` flags, preferring `preferred`;
  /// throws Error(Device) when none exists.
  std::uint32_t memoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                           VkMemoryPropertyFlags preferred) const;

  /// Account for a device allocation of `bytes` in memory type `memoryType` before it is
  /// made. Throws Error(Device) naming the sizes when it would take the allocations in that
  /// type's heap over the heap size, or all allocations over the simulated memory limit.
  void reserveMemory(VkDeviceSize bytes, std::uint32_t memoryType, const char* what);
  /// Give back what reserveMemory accounted for (the allocation was freed).
  void releaseMemory(VkDeviceSize bytes, std::uint32_t memoryType);
  /// Bytes of device memory allocated now, and the most allocated at once since creation
  /// or the last resetPeakAllocatedBytes() (memory counters of the benchmarks).
  VkDeviceSize allocatedBytes() const;
  VkDeviceSize peakAllocatedBytes() const;
  void resetPeakAllocatedBytes();
  /// Account for one host-to-device (upload) or device-to-host copy of `bytes` bytes.
  void countTransfer(bool upload, std::size_t bytes);
  TransferCounts transfers() const;
  /// Start TransferCounts::largestUpload and largestDownload again from zero.
  void resetLargestTransfers();
  /// What a queue submission reports to its caller: `result`, except VK_ERROR_DEVICE_LOST
  /// from the simulated lost submission on (SimulatedFaults::deviceLostAtSubmit).
  VkResult submissionResult(VkResult result);

  /// Validation messages (warnings and errors) received so far; always empty when
  /// validation is off.
  std::vector<std::string> validationMessages() const;
  std::size_t validationMessageCount() const;

  /// Throw Error(Device) "<what>: <VkResult name>" unless result is VK_SUCCESS.
  static void check(VkResult result, const char* what);

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                       VkDebugUtilsMessageTypeFlagsEXT types,
                                                       const VkDebugUtilsMessengerCallbackDataEXT* data, void* self);
  void createInstance();
  void choosePhysicalDevice();
  void createDevice();
  void destroy();

  ContextSettings settings_;
  DeviceInfo info_;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice_ = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memory_{};
  std::uint32_t queueFamily_ = 0;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool commandPool_ = VK_NULL_HANDLE;

  mutable std::mutex allocationMutex_;
  std::array<VkDeviceSize, VK_MAX_MEMORY_HEAPS> heapUsage_{};  ///< Bytes allocated per heap.
  VkDeviceSize totalUsage_ = 0;
  VkDeviceSize peakUsage_ = 0;
  std::uint64_t submissions_ = 0;
  TransferCounts transfers_;

  mutable std::mutex messagesMutex_;
  std::vector<std::string> messages_;
};

/// A zero-initialised Vulkan info structure with its sType set.
template <class T>
T vkStruct(VkStructureType type) {
  T value{};
  value.sType = type;
  return value;
}

/// Name of a VkResult, e.g. "VK_ERROR_DEVICE_LOST".
const char* resultName(VkResult result);

/// Whether the device runs on the host's CPU (lavapipe), where every workgroup and every
/// barrier costs scheduling however little it does.
inline bool isCpuDevice(const Context& context) { return context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU; }

/// Lanes of a kernel that runs in a single workgroup, sweeping rows between barriers: on CPU
/// devices every lane pays for every barrier, so fewer; on GPUs more lanes share the rows.
inline std::uint32_t singleWorkgroupLanes(const Context& context) { return isCpuDevice(context) ? 64 : 256; }

/// llvmpipe ends all loops of an invocation after 65535 back-edges in total: kernels whose
/// loops could run longer split their work over dispatches on CPU devices, each estimated
/// below this (half the limit).
constexpr std::uint64_t kCpuLoopBackEdges = 32768;

}  // namespace plano::vk
