#include "compute/vulkan/VulkanInputChecks.h"

#include "core/Error.h"

namespace plano::vk {

void checkFaces(const FaceList& faces, Index vertexCount, const std::string& operation) {
  for (Index f = 0; f < faces.size(); ++f) {
    const auto face = faces[f];
    if (face.size() < 3) {
      throwBadInput(operation + ": face " + std::to_string(f) + " has " + std::to_string(face.size()) +
                    " corners (at least 3 needed)");
    }
    for (std::size_t i = 0; i < face.size(); ++i) {
      if (face[i] < 0 || face[i] >= vertexCount) {
        throwBadInput(operation + ": corner " + std::to_string(i) + " of face " + std::to_string(f) +
                      " refers to vertex " + std::to_string(face[i]) + ", but the mesh has " +
                      std::to_string(vertexCount) + " vertices");
      }
    }
  }
}

void checkMeshFitsOneBinding(const FaceList& faces, Index vertexCount, std::size_t maxStorageBufferRange) {
  const std::size_t positionBytes = static_cast<std::size_t>(vertexCount) * 3 * sizeof(double);
  if (positionBytes > maxStorageBufferRange || faces.indices().size() * sizeof(Index) > maxStorageBufferRange) {
    throwDevice("Vulkan: the mesh (" + std::to_string(vertexCount) + " vertices, " +
                std::to_string(faces.cornerCount()) + " corners) exceeds the device's storage-buffer range of " +
                std::to_string(maxStorageBufferRange) + " bytes; use the CPU backend");
  }
}

}  // namespace plano::vk
