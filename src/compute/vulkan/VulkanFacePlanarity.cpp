#include "compute/vulkan/VulkanFacePlanarity.h"

#include <algorithm>
#include <string>

#include "compute/vulkan/VulkanInputChecks.h"
#include "core/Error.h"

namespace plano::vk {

FacePlanarityKernel::FacePlanarityKernel(Context& context)
    : context_(context), pipeline_(context, "face_planarity", 4, sizeof(FacePlanarityPush)) {}

void FacePlanarityKernel::run(const PolygonMesh& mesh, std::span<double> out) {
  const std::size_t faceCount = static_cast<std::size_t>(mesh.faceCount());
  if (out.size() != faceCount) {
    throwUsage("facePlanarity: output has " + std::to_string(out.size()) + " entries for " +
               std::to_string(faceCount) + " faces");
  }
  if (faceCount == 0) return;
  checkFaces(mesh.faces, mesh.vertexCount(), "facePlanarity");
  const std::size_t range = context_.info().maxStorageBufferRange;
  const std::size_t positionBytes = static_cast<std::size_t>(mesh.vertices.size()) * sizeof(double);
  const std::size_t cornerBytes = mesh.faces.indices().size() * sizeof(Index);
  if (positionBytes > range || cornerBytes > range) {
    throwDevice("Vulkan: the mesh (" + std::to_string(mesh.vertexCount()) + " vertices, " +
                std::to_string(mesh.faces.cornerCount()) + " corners) exceeds the device's storage-buffer range of " +
                std::to_string(range) + " bytes; use the CPU backend");
  }

  ensureCapacity(positions_, context_, mesh.vertices.size(), "vertex positions");
  positions_.upload({mesh.vertices.data(), static_cast<std::size_t>(mesh.vertices.size())});
  offsets_.assign(context_, mesh.faces.offsets(), "face offsets");
  indices_.assign(context_, mesh.faces.indices(), "face corners");

  // The output is the one per-face array; split the faces so each chunk's fits one binding.
  const std::size_t chunk = std::min(faceCount, range / sizeof(double));
  ensureCapacity(values_, context_, chunk, "face planarity");
  DescriptorSet set(context_, pipeline_,
                    {BufferRange(positions_, 0, positionBytes), BufferRange(offsets_.array()),
                     BufferRange(indices_.array()), BufferRange(values_, 0, chunk * sizeof(double))});
  Sequence sequence(context_);
  for (std::size_t first = 0; first < faceCount; first += chunk) {
    const std::size_t count = std::min(chunk, faceCount - first);
    sequence.begin();
    sequence.dispatch(pipeline_, set, FacePlanarityPush{static_cast<std::uint32_t>(first), static_cast<std::uint32_t>(count)},
                      groupsFor(context_, count));
    sequence.end();
    sequence.run();
    values_.download(out.subspan(first, count));
  }
}

}  // namespace plano::vk
