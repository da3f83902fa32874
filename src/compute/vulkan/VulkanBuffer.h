#pragma once
// Storage buffers on a Context, with a declared memory class (Kompute's typed tensors).
// Device buffers live in device-local memory; where that memory is also host visible
// (lavapipe, integrated GPUs) they are mapped and written directly, otherwise every
// upload/download goes through a temporary staging buffer.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "compute/vulkan/VulkanContext.h"

namespace plano::vk {

enum class MemoryClass {
  Device,  ///< Device-local; mapped when the device has unified memory, else staged.
  Host,    ///< Host-visible and coherent (staging, small read-backs).
};

class Buffer {
 public:
  Buffer() = default;
  /// A buffer of `bytes` bytes (at least 16, Vulkan forbids empty buffers). `what`
  /// names its content in error messages. Throws Error(Device) on allocation failure and,
  /// before allocating, when the buffer is larger than the device's maxStorageBufferRange
  /// or would not fit in its memory heap (or the simulated limit, VulkanFaultSimulation.h).
  Buffer(Context& context, std::size_t bytes, MemoryClass memoryClass, const char* what);
  ~Buffer();
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  VkBuffer handle() const { return buffer_; }
  std::size_t bytes() const { return bytes_; }
  bool mapped() const { return mapped_ != nullptr; }

  /// Copy `bytes` bytes from host memory into the buffer at `offset` (blocking).
  void upload(const void* data, std::size_t bytes, std::size_t offset = 0);
  /// Copy `bytes` bytes at `offset` of the buffer into host memory (blocking; the
  /// caller has waited for the work that wrote it).
  void download(void* data, std::size_t bytes, std::size_t offset = 0) const;

 private:
  void release();
  void checkRange(std::size_t bytes, std::size_t offset, const char* operation) const;

  Context* context_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  void* mapped_ = nullptr;
  VkDeviceSize reserved_ = 0;     ///< Bytes accounted for in the context (Context::reserveMemory).
  std::uint32_t memoryType_ = 0;  ///< Memory type of the reservation.
  std::size_t bytes_ = 0;
  const char* what_ = "";
};

/// A Buffer of `count` elements of T (double, int32, uint32, ...).
template <class T>
class Array : public Buffer {
 public:
  Array() = default;
  Array(Context& context, std::size_t count, MemoryClass memoryClass, const char* what)
      : Buffer(context, count * sizeof(T), memoryClass, what), count_(count) {}
  std::size_t count() const { return count_; }
  void upload(std::span<const T> values, std::size_t first = 0) {
    Buffer::upload(values.data(), values.size_bytes(), first * sizeof(T));
  }
  void download(std::span<T> values, std::size_t first = 0) const {
    Buffer::download(values.data(), values.size_bytes(), first * sizeof(T));
  }

 private:
  std::size_t count_ = 0;
};

/// Grow-only reuse: (re)allocate `array` as a Device buffer when it holds fewer than
/// `count` elements, so that kernels called every iteration of a solver allocate once.
template <class T>
void ensureCapacity(Array<T>& array, Context& context, std::size_t count, const char* what) {
  if (array.handle() == VK_NULL_HANDLE || array.count() < count) {
    array = Array<T>();  // release first: old and new need not fit in memory together
    array = Array<T>(context, count, MemoryClass::Device, what);
  }
}

/// A Device array that a kernel called every iteration of a loop fills with inputs that
/// often repeat (a mesh's topology, a loop's fixed source positions): the upload is skipped
/// when the values equal the last upload's, compared with a host copy kept for that.
/// Comparing costs a pass over host memory; on a discrete GPU the skipped copy is a PCIe
/// transfer and a synchronisation.
template <class T>
class CachedArray {
 public:
  /// Make the device array hold `values` (grown as ensureCapacity grows).
  void assign(Context& context, std::span<const T> values, const char* what) {
    if (holds(values)) return;
    last_.clear();  // an upload that throws leaves nothing claimed
    ensureCapacity(array_, context, values.size(), what);
    array_.upload(values);
    last_.assign(values.begin(), values.end());
  }
  Array<T>& array() { return array_; }
  const Array<T>& array() const { return array_; }
  /// Whether the device array holds exactly `values`.
  bool holds(std::span<const T> values) const {
    return array_.handle() != VK_NULL_HANDLE && last_.size() == values.size() &&
           std::equal(values.begin(), values.end(), last_.begin());
  }

 private:
  Array<T> array_;
  std::vector<T> last_;
};

}  // namespace plano::vk
