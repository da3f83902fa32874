#include "compute/vulkan/VulkanClosestRotations.h"

#include <algorithm>
#include <string>

#include "core/Error.h"

namespace plano::vk {
namespace {

struct ClosestRotationsPush {
  std::uint32_t count;
};

static_assert(sizeof(Eigen::Matrix3d) == 9 * sizeof(double), "Matrix3d must be 9 packed doubles");
static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "Vector3d must be 3 packed doubles");

}  // namespace

ClosestRotationsKernel::ClosestRotationsKernel(Context& context)
    : context_(context), pipeline_(context, "closest_rotations", 3, sizeof(ClosestRotationsPush)) {}

void ClosestRotationsKernel::run(std::span<const Eigen::Matrix3d> matrices, std::span<Eigen::Matrix3d> rotations,
                                 std::span<Eigen::Vector3d> singularValues) {
  const std::size_t count = matrices.size();
  if (rotations.size() != count || singularValues.size() != count) {
    throwUsage("closestRotations: " + std::to_string(count) + " matrices but " + std::to_string(rotations.size()) +
               " rotations and " + std::to_string(singularValues.size()) + " singular-value slots");
  }
  if (count == 0) return;
  constexpr std::size_t matrixBytes = sizeof(Eigen::Matrix3d);
  const std::size_t chunk = std::min(count, context_.info().maxStorageBufferRange / matrixBytes);
  ensureCapacity(input_, context_, chunk * 9, "3x3 matrices");
  ensureCapacity(output_, context_, chunk * 9, "closest rotations");
  ensureCapacity(singular_, context_, chunk * 3, "singular values");
  DescriptorSet set(context_, pipeline_,
                    {BufferRange(input_, 0, chunk * matrixBytes), BufferRange(output_, 0, chunk * matrixBytes),
                     BufferRange(singular_, 0, chunk * sizeof(Eigen::Vector3d))});
  Sequence sequence(context_);
  for (std::size_t first = 0; first < count; first += chunk) {
    const std::size_t n = std::min(chunk, count - first);
    input_.Buffer::upload(matrices.data() + first, n * matrixBytes);
    sequence.begin();
    sequence.dispatch(pipeline_, set, ClosestRotationsPush{static_cast<std::uint32_t>(n)}, groupsFor(context_, n));
    sequence.end();
    sequence.run();
    output_.Buffer::download(rotations.data() + first, n * matrixBytes);
    singular_.Buffer::download(singularValues.data() + first, n * sizeof(Eigen::Vector3d));
  }
}

}  // namespace plano::vk
