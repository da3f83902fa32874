#pragma once
// A recorded sequence of device operations (Kompute's Sequence): copies, dispatches and
// barriers recorded once into a command buffer and submitted as one batch, as often as
// needed. Timestamps at the start and end of each recording give the device time.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "compute/vulkan/VulkanPipeline.h"

namespace plano::vk {

class Sequence {
 public:
  explicit Sequence(Context& context);
  ~Sequence();
  Sequence(const Sequence&) = delete;
  Sequence& operator=(const Sequence&) = delete;

  /// Start (re)recording; discards the previous recording.
  void begin();
  /// Record a dispatch of `groupsX` x `groupsY` workgroups with the given push constants.
  void dispatch(const Pipeline& pipeline, const DescriptorSet& set, std::span<const std::byte> pushConstants,
                std::uint32_t groupsX, std::uint32_t groupsY = 1);
  template <class Push>
  void dispatch(const Pipeline& pipeline, const DescriptorSet& set, const Push& push, std::uint32_t groupsX,
                std::uint32_t groupsY = 1) {
    dispatch(pipeline, set, std::as_bytes(std::span<const Push>(&push, 1)), groupsX, groupsY);
  }
  /// Record a dispatch with the given buffers bound; the sequence keeps their descriptor
  /// set alive until the next begin().
  template <class Push>
  void dispatch(const Pipeline& pipeline, std::initializer_list<BufferRange> buffers, const Push& push,
                std::uint32_t groupsX, std::uint32_t groupsY = 1) {
    dispatch(pipeline, keep(pipeline, buffers), push, groupsX, groupsY);
  }
  /// A descriptor set of `buffers` for `pipeline` that the sequence keeps alive until the
  /// next begin(): one set for many dispatches of a recording on the same buffers.
  const DescriptorSet& keep(const Pipeline& pipeline, std::initializer_list<BufferRange> buffers) {
    sets_.push_back(std::make_unique<DescriptorSet>(context_, pipeline, buffers));
    return *sets_.back();
  }
  /// Record a dispatch whose workgroup counts (three uint32) are read from `arguments` at
  /// byte `offset` when it runs: a kernel recorded earlier can size it, or make it empty.
  template <class Push>
  void dispatchIndirect(const Pipeline& pipeline, const DescriptorSet& set, const Push& push, const Buffer& arguments,
                        std::size_t offset) {
    bind(pipeline, set, std::as_bytes(std::span<const Push>(&push, 1)));
    dispatchIndirect(arguments, offset);
  }
  /// Make every earlier shader or transfer write visible to every later shader, transfer
  /// or indirect dispatch.
  void barrier();
  void copy(const Buffer& source, const Buffer& destination, std::size_t bytes, std::size_t sourceOffset = 0,
            std::size_t destinationOffset = 0);
  /// Zero the first `bytes` bytes (a multiple of 4) of `buffer` on the device.
  void zero(const Buffer& buffer, std::size_t bytes);
  /// Finish recording (writes the end timestamp and a host-visibility barrier).
  void end();

  /// Submit the recording and wait for it. Throws Error(Device) on device loss. There is
  /// no host-side timeout: giving up on running work would leave its buffers in use, and
  /// drivers report a hung device as lost.
  void run();

  /// Device time of the last run() in seconds, from timestamp queries; a negative value
  /// when the queue has no timestamps.
  double lastDeviceSeconds() const;

 private:
  void bind(const Pipeline& pipeline, const DescriptorSet& set, std::span<const std::byte> pushConstants);
  void dispatchIndirect(const Buffer& arguments, std::size_t offset);

  Context& context_;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkQueryPool queries_ = VK_NULL_HANDLE;
  std::vector<std::unique_ptr<DescriptorSet>> sets_;
  bool recording_ = false;
  bool recorded_ = false;
  bool ran_ = false;
};

}  // namespace plano::vk
