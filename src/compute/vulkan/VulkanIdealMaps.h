#pragma once
// Batched closest ideal maps (projective-maps paper, App. A) on the device:
// shaders/ideal_maps.comp, the math of src/projective/IdealMapFit.cpp (the fit's in-plane
// Jacobian, its closest rotation by a one-sided Jacobi SVD, the corner-set fallback), one
// invocation per face, fp64.
#include "compute/Backend.h"
#include "compute/vulkan/VulkanSequence.h"

namespace plano::vk {

class IdealMapsKernel {
 public:
  explicit IdealMapsKernel(Context& context);

  /// compute::Backend::closestIdealMaps. Throws Error(Usage) for #F != fitted.size() or
  /// position arrays of different sizes, Error(Device) when the positions exceed the
  /// device's storage-buffer range.
  /// `residentFitted` and `residentTarget`, when not null, are device arrays that hold
  /// `fitted` and `*target` already (vk::ProjectiveFitKernel::mapsHolding, targetHolding:
  /// a deformation's fits and the positions they were fitted to): they are bound instead
  /// of uploading those inputs.
  void run(const FaceList& faces, const Positions& source, std::span<const Eigen::Matrix4d> fitted,
           const Positions* target, bool similar, compute::IdealMaps& out,
           const Array<double>* residentFitted = nullptr, const Array<double>* residentTarget = nullptr);
  /// The same for fits that exist only on the device (vk::ProjectiveFitKernel::runResident:
  /// a deformation's local step, whose fits never cross to the host), with `target` the
  /// positions they were fitted to (`residentTarget`, when not null, the device array that
  /// holds it). Throws Error(Usage) when `fitted` does not hold #F maps in one binding.
  void runOnResidentFits(const FaceList& faces, const Positions& source, const Array<double>& fitted,
                         const Positions& target, const Array<double>* residentTarget, bool similar,
                         compute::IdealMaps& out);

 private:
  /// Both runs, after their input checks: `fitted` is read only without `residentFitted`.
  void mapChunks(const FaceList& faces, const Positions& source, std::span<const Eigen::Matrix4d> fitted,
               const Positions* target, bool similar, compute::IdealMaps& out, const Array<double>* residentFitted,
               const Array<double>* residentTarget);

  Context& context_;
  Pipeline pipeline_;
  // Reused across calls (grow-only): a deformation loop allocates once and uploads its
  // source and topology once.
  CachedArray<double> source_;
  Array<double> target_;
  CachedArray<Index> offsets_, indices_;
  Array<double> fitted_, ideal_;
  Array<std::int32_t> methods_;
};

}  // namespace plano::vk
