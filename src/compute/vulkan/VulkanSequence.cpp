#include "compute/vulkan/VulkanSequence.h"

#include <cmath>
#include <string>

#include "core/Error.h"

namespace plano::vk {

Sequence::Sequence(Context& context) : context_(context) {
  VkDevice device = context.device();
  auto allocation = vkStruct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
  allocation.commandPool = context.commandPool();
  allocation.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocation.commandBufferCount = 1;
  Context::check(vkAllocateCommandBuffers(device, &allocation, &commands_), "allocating a command buffer");
  auto fenceInfo = vkStruct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
  VkResult result = vkCreateFence(device, &fenceInfo, nullptr, &fence_);
  if (result == VK_SUCCESS && context.info().timestampPeriodNs > 0.0) {
    auto queryInfo = vkStruct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
    queryInfo.queryType = VK_QUERY_TYPE_TIMESTAMP;
    queryInfo.queryCount = 2;
    result = vkCreateQueryPool(device, &queryInfo, nullptr, &queries_);
  }
  if (result != VK_SUCCESS) {
    if (fence_) vkDestroyFence(device, fence_, nullptr);
    vkFreeCommandBuffers(device, context.commandPool(), 1, &commands_);
    Context::check(result, "creating a fence or query pool");
  }
}

Sequence::~Sequence() {
  VkDevice device = context_.device();
  if (queries_) vkDestroyQueryPool(device, queries_, nullptr);
  vkDestroyFence(device, fence_, nullptr);
  vkFreeCommandBuffers(device, context_.commandPool(), 1, &commands_);
}

void Sequence::begin() {
  Context::check(vkResetCommandBuffer(commands_, 0), "resetting a command buffer");
  sets_.clear();
  auto info = vkStruct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  Context::check(vkBeginCommandBuffer(commands_, &info), "beginning a command buffer");
  if (queries_) {
    vkCmdResetQueryPool(commands_, queries_, 0, 2);
    vkCmdWriteTimestamp(commands_, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries_, 0);
  }
  recording_ = true;
  recorded_ = false;
  ran_ = false;
}

void Sequence::dispatch(const Pipeline& pipeline, const DescriptorSet& set, std::span<const std::byte> pushConstants,
                        std::uint32_t groupsX, std::uint32_t groupsY) {
  bind(pipeline, set, pushConstants);
  vkCmdDispatch(commands_, groupsX, groupsY, 1);
}

void Sequence::dispatchIndirect(const Buffer& arguments, std::size_t offset) {
  if (offset % 4 != 0 || offset + 3 * sizeof(std::uint32_t) > arguments.bytes()) {
    throwDevice("Vulkan: indirect dispatch arguments at byte " + std::to_string(offset) + " of a " +
                std::to_string(arguments.bytes()) + "-byte buffer");
  }
  vkCmdDispatchIndirect(commands_, arguments.handle(), offset);
}

void Sequence::bind(const Pipeline& pipeline, const DescriptorSet& set, std::span<const std::byte> pushConstants) {
  if (!recording_) throwDevice("Vulkan: dispatch of '" + pipeline.name() + "' outside begin()/end()");
  if (pushConstants.size() != pipeline.pushConstantBytes()) {
    throwDevice("Vulkan: pipeline '" + pipeline.name() + "' takes " + std::to_string(pipeline.pushConstantBytes()) +
                " bytes of push constants, " + std::to_string(pushConstants.size()) + " given");
  }
  vkCmdBindPipeline(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.handle());
  VkDescriptorSet handle = set.handle();
  vkCmdBindDescriptorSets(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.layout(), 0, 1, &handle, 0, nullptr);
  if (!pushConstants.empty()) {
    vkCmdPushConstants(commands_, pipeline.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                       static_cast<std::uint32_t>(pushConstants.size()), pushConstants.data());
  }
}

void Sequence::barrier() {
  auto memory = vkStruct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  memory.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  memory.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                         VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
  const VkPipelineStageFlags stages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
  vkCmdPipelineBarrier(commands_, stages, stages | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT, 0, 1, &memory, 0, nullptr, 0,
                       nullptr);
}

void Sequence::copy(const Buffer& source, const Buffer& destination, std::size_t bytes, std::size_t sourceOffset,
                    std::size_t destinationOffset) {
  if (!recording_) throwDevice("Vulkan: buffer copy outside begin()/end()");
  if (bytes == 0) return;  // Vulkan forbids empty copy regions (empty vectors: no constraint rows)
  VkBufferCopy region{sourceOffset, destinationOffset, bytes};
  vkCmdCopyBuffer(commands_, source.handle(), destination.handle(), 1, &region);
}

void Sequence::zero(const Buffer& buffer, std::size_t bytes) {
  if (!recording_) throwDevice("Vulkan: buffer fill outside begin()/end()");
  if (bytes == 0) return;  // as for copies
  vkCmdFillBuffer(commands_, buffer.handle(), 0, bytes, 0u);
}

void Sequence::end() {
  // Device writes must be visible to host reads of mapped memory after the fence.
  auto memory = vkStruct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  memory.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  memory.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &memory, 0, nullptr, 0, nullptr);
  if (queries_) vkCmdWriteTimestamp(commands_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, 1);
  Context::check(vkEndCommandBuffer(commands_), "ending a command buffer");
  recording_ = false;
  recorded_ = true;
}

void Sequence::run() {
  if (!recorded_) throwDevice("Vulkan: run() of a sequence that was not recorded (begin()/end())");
  VkDevice device = context_.device();
  Context::check(vkResetFences(device, 1, &fence_), "resetting a fence");
  auto submit = vkStruct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &commands_;
  Context::check(vkQueueSubmit(context_.queue(), 1, &submit, fence_), "submitting work to the compute queue");
  // Waited for even when a loss is simulated, so that no resource is freed while in use.
  const VkResult waited = vkWaitForFences(device, 1, &fence_, VK_TRUE, UINT64_MAX);
  Context::check(context_.submissionResult(waited), "waiting for the compute queue");
  ran_ = true;
}

double Sequence::lastDeviceSeconds() const {
  if (!queries_ || !ran_) return -1.0;
  std::uint64_t stamps[2] = {0, 0};
  const VkResult result = vkGetQueryPoolResults(context_.device(), queries_, 0, 2, sizeof(stamps), stamps,
                                                sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT);
  if (result != VK_SUCCESS) return -1.0;
  return static_cast<double>(stamps[1] - stamps[0]) * context_.info().timestampPeriodNs * 1e-9;
}

}  // namespace plano::vk
