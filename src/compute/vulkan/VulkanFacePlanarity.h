#pragma once
// Per-face planarity on the device (shaders/face_planarity.comp), the definition of
// src/mesh/Planarity.h, double precision.
#include <cstdint>
#include <span>

#include "compute/vulkan/VulkanSequence.h"
#include "mesh/PolygonMesh.h"

namespace plano::vk {

/// shaders/face_planarity.comp's push constants (its other users record it too).
struct FacePlanarityPush {
  std::uint32_t firstFace;
  std::uint32_t faceCount;
};

class FacePlanarityKernel {
 public:
  /// Builds the pipeline (once per backend).
  explicit FacePlanarityKernel(Context& context);

  /// Planarity in percent of every face of `mesh` into out (#F entries). Uploads the
  /// mesh, runs in chunks of faces that fit the device's storage-buffer range.
  /// Throws Error(Device) when the positions or corners alone exceed that range.
  void run(const PolygonMesh& mesh, std::span<double> out);

 private:
  Context& context_;
  Pipeline pipeline_;
  // Reused across calls (grow-only).
  Array<double> positions_;
  CachedArray<Index> offsets_;  ///< A loop measures one topology every iteration.
  CachedArray<Index> indices_;
  Array<double> values_;
};

}  // namespace plano::vk
