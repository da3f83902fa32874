#include "compute/vulkan/VulkanBuffer.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <utility>

#include "compute/vulkan/VulkanSequence.h"
#include "core/Error.h"

namespace plano::vk {

Buffer::Buffer(Context& context, std::size_t bytes, MemoryClass memoryClass, const char* what)
    : context_(&context), bytes_(std::max<std::size_t>(bytes, 16)), what_(what) {
  VkDevice device = context.device();
  // Kernels bind whole buffers as storage buffers: a larger one cannot be bound, whatever
  // vkCreateBuffer says.
  if (bytes_ > context.info().maxStorageBufferRange) {
    context_ = nullptr;
    throwDevice(std::string("Vulkan: a ") + std::to_string(bytes_) + "-byte buffer for " + what_ +
                " exceeds the device's maxStorageBufferRange of " +
                std::to_string(context.info().maxStorageBufferRange) + " bytes (try a smaller mesh or the CPU backend)");
  }
  auto info = vkStruct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  info.size = bytes_;
  // Indirect: kernels may size later dispatches (the device ADMM's inner PCG).
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
               VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  const VkResult created = vkCreateBuffer(device, &info, nullptr, &buffer_);
  if (created != VK_SUCCESS) {
    buffer_ = VK_NULL_HANDLE;
    context_ = nullptr;
    throwDevice(std::string("Vulkan: creating a ") + std::to_string(bytes_) + "-byte buffer for " + what_ +
                " failed: " + resultName(created));
  }

  VkMemoryRequirements requirements;
  vkGetBufferMemoryRequirements(device, buffer_, &requirements);
  const bool direct = memoryClass == MemoryClass::Host ||
                      (context.info().unifiedMemory && !context.settings().forceStaging);
  VkMemoryPropertyFlags required = 0;
  VkMemoryPropertyFlags preferred = 0;
  if (direct) {
    required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    preferred = required | (memoryClass == MemoryClass::Device ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT
                                                               : VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
  } else {
    required = preferred = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  }
  auto allocation = vkStruct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
  allocation.allocationSize = requirements.size;
  try {
    allocation.memoryTypeIndex = context.memoryType(requirements.memoryTypeBits, required, preferred);
    context.reserveMemory(requirements.size, allocation.memoryTypeIndex, what_);
    reserved_ = requirements.size;
    memoryType_ = allocation.memoryTypeIndex;
    const VkResult result = vkAllocateMemory(device, &allocation, nullptr, &memory_);
    if (result != VK_SUCCESS) {
      throwDevice(std::string("Vulkan: allocating ") + std::to_string(bytes_) + " bytes for " + what_ +
                  " failed: " + resultName(result) + " (try a smaller mesh or the CPU backend)");
    }
    Context::check(vkBindBufferMemory(device, buffer_, memory_, 0), "binding buffer memory");
    if (direct) Context::check(vkMapMemory(device, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "mapping a buffer");
  } catch (...) {
    release();
    throw;
  }
}

Buffer::~Buffer() { release(); }

Buffer::Buffer(Buffer&& other) noexcept { *this = std::move(other); }

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    release();
    context_ = std::exchange(other.context_, nullptr);
    buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    mapped_ = std::exchange(other.mapped_, nullptr);
    reserved_ = std::exchange(other.reserved_, 0);
    memoryType_ = other.memoryType_;
    bytes_ = std::exchange(other.bytes_, 0);
    what_ = other.what_;
  }
  return *this;
}

void Buffer::release() {
  if (!context_) return;
  VkDevice device = context_->device();
  if (mapped_) vkUnmapMemory(device, memory_);
  if (buffer_) vkDestroyBuffer(device, buffer_, nullptr);
  if (memory_) vkFreeMemory(device, memory_, nullptr);
  if (reserved_ > 0) context_->releaseMemory(reserved_, memoryType_);
  reserved_ = 0;
  mapped_ = nullptr;
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  context_ = nullptr;
}

void Buffer::checkRange(std::size_t bytes, std::size_t offset, const char* operation) const {
  if (offset > bytes_ || bytes > bytes_ - offset) {
    throwDevice(std::string("Vulkan: ") + operation + " of " + std::to_string(bytes) + " bytes at offset " +
                std::to_string(offset) + " overruns the " + std::to_string(bytes_) + "-byte buffer for " + what_);
  }
}

void Buffer::upload(const void* data, std::size_t bytes, std::size_t offset) {
  if (bytes == 0) return;
  checkRange(bytes, offset, "upload");
  context_->countTransfer(true, bytes);
  if (mapped_) {
    std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
    return;
  }
  Buffer staging(*context_, bytes, MemoryClass::Host, "a staging buffer");
  std::memcpy(staging.mapped_, data, bytes);  // host-visible; the copy below is the transfer counted
  Sequence sequence(*context_);
  sequence.begin();
  sequence.copy(staging, *this, bytes, 0, offset);
  sequence.end();
  sequence.run();
}

void Buffer::download(void* data, std::size_t bytes, std::size_t offset) const {
  if (bytes == 0) return;
  checkRange(bytes, offset, "download");
  context_->countTransfer(false, bytes);
  if (mapped_) {
    std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
    return;
  }
  Buffer staging(*context_, bytes, MemoryClass::Host, "a staging buffer");
  Sequence sequence(*context_);
  sequence.begin();
  sequence.copy(*this, staging, bytes, offset, 0);
  sequence.end();
  sequence.run();
  std::memcpy(data, staging.mapped_, bytes);
}

}  // namespace plano::vk
