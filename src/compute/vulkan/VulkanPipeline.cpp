#include "compute/vulkan/VulkanPipeline.h"

#include <algorithm>
#include <vector>

#include "compute/vulkan/EmbeddedShaders.h"
#include "core/Error.h"

namespace plano::vk {

Pipeline::Pipeline(Context& context, std::string_view shader, std::uint32_t bindingCount,
                   std::uint32_t pushConstantBytes, std::uint32_t workGroupSize)
    : context_(context), name_(shader), bindingCount_(bindingCount), pushConstantBytes_(pushConstantBytes) {
  const std::span<const std::uint32_t> code = embeddedShader(shader);
  if (code.empty()) throwDevice("Vulkan: shader '" + name_ + "' is not embedded in this build");
  VkDevice device = context.device();

  std::vector<VkDescriptorSetLayoutBinding> bindings(bindingCount);
  for (std::uint32_t i = 0; i < bindingCount; ++i) {
    bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  }
  auto setInfo = vkStruct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
  setInfo.bindingCount = bindingCount;
  setInfo.pBindings = bindings.data();

  VkShaderModule module = VK_NULL_HANDLE;
  try {
    Context::check(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &setLayout_),
                   "creating a descriptor-set layout");
    VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes};
    auto layoutInfo = vkStruct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
    layoutInfo.setLayoutCount = 1;
    layoutInfo.pSetLayouts = &setLayout_;
    layoutInfo.pushConstantRangeCount = pushConstantBytes > 0 ? 1 : 0;
    layoutInfo.pPushConstantRanges = &push;
    Context::check(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &layout_), "creating a pipeline layout");

    auto moduleInfo = vkStruct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
    moduleInfo.codeSize = code.size_bytes();
    moduleInfo.pCode = code.data();
    Context::check(vkCreateShaderModule(device, &moduleInfo, nullptr, &module), "creating a shader module");

    auto pipelineInfo = vkStruct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
    pipelineInfo.stage = vkStruct<VkPipelineShaderStageCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
    pipelineInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pipelineInfo.stage.module = module;
    pipelineInfo.stage.pName = "main";
    const VkSpecializationMapEntry sizeEntry{0, 0, sizeof(std::uint32_t)};
    const VkSpecializationInfo specialization{1, &sizeEntry, sizeof(workGroupSize), &workGroupSize};
    if (workGroupSize > 0) pipelineInfo.stage.pSpecializationInfo = &specialization;
    pipelineInfo.layout = layout_;
    const VkResult result = vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &pipelineInfo, nullptr, &pipeline_);
    vkDestroyShaderModule(device, module, nullptr);
    module = VK_NULL_HANDLE;
    if (result != VK_SUCCESS) {
      throwDevice("Vulkan: building the pipeline of shader '" + name_ + "' failed: " + resultName(result));
    }
  } catch (...) {
    if (module) vkDestroyShaderModule(device, module, nullptr);
    if (layout_) vkDestroyPipelineLayout(device, layout_, nullptr);
    if (setLayout_) vkDestroyDescriptorSetLayout(device, setLayout_, nullptr);
    throw;
  }
}

Pipeline::~Pipeline() {
  VkDevice device = context_.device();
  vkDestroyPipeline(device, pipeline_, nullptr);
  vkDestroyPipelineLayout(device, layout_, nullptr);
  vkDestroyDescriptorSetLayout(device, setLayout_, nullptr);
}

DescriptorSet::DescriptorSet(Context& context, const Pipeline& pipeline, std::initializer_list<BufferRange> buffers)
    : context_(context) {
  if (buffers.size() != pipeline.bindingCount()) {
    throwDevice("Vulkan: pipeline '" + pipeline.name() + "' has " + std::to_string(pipeline.bindingCount()) +
                " bindings, " + std::to_string(buffers.size()) + " buffers given");
  }
  std::vector<VkDescriptorBufferInfo> infos;
  for (const BufferRange& range : buffers) {
    const std::size_t bytes = range.bytes > 0 ? range.bytes : range.buffer->bytes() - range.offset;
    if (bytes > context.info().maxStorageBufferRange) {
      throwDevice("Vulkan: a " + std::to_string(bytes) + "-byte binding of pipeline '" + pipeline.name() +
                  "' exceeds the device's maxStorageBufferRange (" +
                  std::to_string(context.info().maxStorageBufferRange) + " bytes)");
    }
    infos.push_back({range.buffer->handle(), range.offset, bytes});
  }
  VkDevice device = context.device();
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, std::max<std::uint32_t>(pipeline.bindingCount(), 1)};
  auto poolInfo = vkStruct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
  poolInfo.maxSets = 1;
  poolInfo.poolSizeCount = 1;
  poolInfo.pPoolSizes = &size;
  Context::check(vkCreateDescriptorPool(device, &poolInfo, nullptr, &pool_), "creating a descriptor pool");

  VkDescriptorSetLayout layout = pipeline.setLayout();
  auto allocation = vkStruct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
  allocation.descriptorPool = pool_;
  allocation.descriptorSetCount = 1;
  allocation.pSetLayouts = &layout;
  const VkResult result = vkAllocateDescriptorSets(device, &allocation, &set_);
  if (result != VK_SUCCESS) {
    vkDestroyDescriptorPool(device, pool_, nullptr);
    Context::check(result, "allocating a descriptor set");
  }
  std::vector<VkWriteDescriptorSet> writes(infos.size());
  for (std::size_t i = 0; i < infos.size(); ++i) {
    writes[i] = vkStruct<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
    writes[i].dstSet = set_;
    writes[i].dstBinding = static_cast<std::uint32_t>(i);
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  vkUpdateDescriptorSets(device, static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
}

DescriptorSet::~DescriptorSet() { vkDestroyDescriptorPool(context_.device(), pool_, nullptr); }

std::uint32_t groupsFor(const Context& context, std::size_t items, std::uint32_t groupSize) {
  const std::size_t groups = (items + groupSize - 1) / groupSize;
  return static_cast<std::uint32_t>(std::clamp<std::size_t>(groups, 1, context.info().maxWorkGroupCount[0]));
}

std::uint32_t sweepGroupsFor(const Context& context, std::size_t items) {
  if (!isCpuDevice(context)) return groupsFor(context, items);
  return groupsFor(context, items, kWorkGroupSize * kCpuSweepItemsPerInvocation);
}

}  // namespace plano::vk
