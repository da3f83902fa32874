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

}  // namespace plano::vk
