#pragma once
// Batched projective fits (projective-maps paper §4.1, Eq. 3) on the device:
// shaders/projective_fit.comp, the math of src/projective/LocalFit.cpp, one invocation
// per face, fp64.
#include <memory>

#include "compute/Backend.h"
#include "compute/vulkan/VulkanSequence.h"

namespace plano::vk {

struct ProjectiveFitSettings {
  /// Singular values below rankThreshold * the largest count as zero (the CPU reference's
  /// complete orthogonal decomposition uses the same relative threshold on its pivots).
  double rankThreshold = 1e-10;
};

class ProjectiveFitKernel {
 public:
  explicit ProjectiveFitKernel(Context& context, ProjectiveFitSettings settings = {});

  /// The map of every face from `source` to `target` corners (both #V x 3) into `out`
  /// (maps, reciprocal scales per corner in CSR order, RMS residuals, ranks). Throws
  /// Error(Usage) when the position arrays differ in size, Error(Device) when the
  /// positions exceed the device's storage-buffer range.
  void run(const FaceList& faces, const Positions& source, const Positions& target, compute::ProjectiveFits& out);
  /// The same fits left on the device, nothing read back: the maps' array for the kernel
  /// that takes them next (vk::IdealMapsKernel::runOnResidentFits), or null, with nothing
  /// run, when the maps need more than one storage binding (then use run()). The fits of
  /// no face count as resident (`mapsHolding` holds nothing after it).
  const Array<double>* runResident(const FaceList& faces, const Positions& source, const Positions& target);
  /// runResident with the target positions in a device array of this context (#V x 3,
  /// row-major: vk::MapPositionsKernel's), bound instead of uploaded.
  const Array<double>* runResidentOn(const FaceList& faces, const Positions& source, const Array<double>& target);

  /// runResident (with the target in `target`, or in `residentTarget` when `target` is
  /// null) for a projective global step (compute::Backend::fitProjectiveMapsOnDevice): the
  /// maps' first three columns and the corners' induced reciprocal scales on `source`
  /// (shaders/induced_scales.comp) stay on the device as device matrices, and their tallies
  /// (8 bytes) come back. Both matrices are readable until the next run. False, with
  /// nothing run, where runResident would return null.
  bool keep(const FaceList& faces, const Positions& source, const Positions* target, const Array<double>* residentTarget,
            double vanishingScale, compute::DeviceProjectiveFits& out);

  /// The device array of the last run's maps (16 doubles a face, column-major) when it
  /// holds exactly `maps` (a run of one chunk), else null; and that of its targets when
  /// they were exactly `target`. A kernel of the same context that takes the fits next
  /// (vk::IdealMapsKernel) binds these instead of uploading its inputs again.
  const Array<double>* mapsHolding(std::span<const Eigen::Matrix4d> maps) const;
  const Array<double>* targetHolding(const Positions& target) const;

 private:
  /// run() with `out`, runResident() without (false: more than one chunk, nothing run).
  /// The target as host positions (`target`) or a device array (`residentTarget`, when
  /// `target` is null).
  bool fit(const FaceList& faces, const Positions& source, const Positions* target,
           const Array<double>* residentTarget, compute::ProjectiveFits* out);

  Context& context_;
  ProjectiveFitSettings settings_;
  Pipeline pipeline_;
  // Reused across calls (grow-only): a local/global loop allocates once.
  CachedArray<double> source_;  ///< A loop fits to one source (the base mesh) every iteration.
  CachedArray<double> target_;
  std::vector<Eigen::Matrix4d> lastMaps_;  ///< What maps_ holds after a run of one chunk (else empty).
  CachedArray<Index> offsets_, indices_;
  Array<double> maps_, scales_, residuals_;
  Array<std::int32_t> ranks_;
  /// keep()'s: the induced scales, their tallies, and the generations of what maps_ and
  /// inducedScales_ hold (every run rewrites maps_).
  std::unique_ptr<Pipeline> inducedScales_;
  Array<double> cornerScales_;
  Array<std::uint32_t> scaleTallies_;
  std::shared_ptr<std::uint64_t> mapsGeneration_ = std::make_shared<std::uint64_t>(0);
  std::shared_ptr<std::uint64_t> scalesGeneration_ = std::make_shared<std::uint64_t>(0);
};

}  // namespace plano::vk
