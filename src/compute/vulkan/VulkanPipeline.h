#pragma once
// A compute pipeline built once from embedded SPIR-V (Kompute's "algorithm" without the
// bound data): descriptor-set layout of N storage buffers at bindings 0..N-1, a push
// constant block, the pipeline itself. Buffers are bound through DescriptorSets, so one
// pipeline serves many buffer combinations (e.g. axpy on different vectors).
#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>

#include "compute/vulkan/VulkanBuffer.h"

namespace plano::vk {

class Pipeline {
 public:
  /// Build the pipeline of shaders/<shader>.comp. Throws Error(Device) when the shader
  /// is not embedded or the driver rejects it.
  /// `workGroupSize` > 0 sets the shader's local_size_x_id = 0 specialization constant
  /// (for kernels whose best workgroup size depends on the device).
  Pipeline(Context& context, std::string_view shader, std::uint32_t bindingCount, std::uint32_t pushConstantBytes,
           std::uint32_t workGroupSize = 0);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  VkPipeline handle() const { return pipeline_; }
  VkPipelineLayout layout() const { return layout_; }
  VkDescriptorSetLayout setLayout() const { return setLayout_; }
  std::uint32_t bindingCount() const { return bindingCount_; }
  std::uint32_t pushConstantBytes() const { return pushConstantBytes_; }
  const std::string& name() const { return name_; }

 private:
  Context& context_;
  std::string name_;
  std::uint32_t bindingCount_;
  std::uint32_t pushConstantBytes_;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

/// A byte range of a buffer bound to one binding; bytes = 0 means "to the end".
struct BufferRange {
  const Buffer* buffer = nullptr;
  std::size_t offset = 0;
  std::size_t bytes = 0;
  BufferRange(const Buffer& b, std::size_t offset = 0, std::size_t bytes = 0) : buffer(&b), offset(offset), bytes(bytes) {}
};

/// The buffers bound to a pipeline's bindings 0..N-1, in order. Owns its descriptor pool.
class DescriptorSet {
 public:
  /// Throws Error(Device) when the count does not match the pipeline or a range
  /// exceeds the device's maxStorageBufferRange.
  DescriptorSet(Context& context, const Pipeline& pipeline, std::initializer_list<BufferRange> buffers);
  ~DescriptorSet();
  DescriptorSet(const DescriptorSet&) = delete;
  DescriptorSet& operator=(const DescriptorSet&) = delete;

  VkDescriptorSet handle() const { return set_; }

 private:
  Context& context_;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
};

/// Workgroup size every 1D kernel of shaders/ declares (local_size_x).
inline constexpr std::uint32_t kWorkGroupSize = 64;

/// Number of workgroups for `items` work items of a grid-stride kernel: enough to cover
/// them, capped at the device's maxComputeWorkGroupCount[0] (the kernels loop over the rest).
std::uint32_t groupsFor(const Context& context, std::size_t items, std::uint32_t groupSize = kWorkGroupSize);

/// Items each invocation of a sweep takes on a CPU device (sweepGroupsFor).
inline constexpr std::uint32_t kCpuSweepItemsPerInvocation = 16;

/// Workgroups for a grid-stride sweep over `items` light items (an entry update, a row of a
/// few dozen entries: nothing near llvmpipe's 65 535 loop back-edges per invocation), whose
/// result does not depend on the workgroup count. On GPUs groupsFor; on CPU devices
/// (lavapipe), where a workgroup costs ~1.4 us of scheduling however little it does, each
/// invocation takes kCpuSweepItemsPerInvocation items: with one item each, a ~1k-face global
/// step spent a third of its time on workgroups (104 s against 69 s with three per sweep).
std::uint32_t sweepGroupsFor(const Context& context, std::size_t items);

}  // namespace plano::vk
