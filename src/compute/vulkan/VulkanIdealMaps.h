#pragma once
// Batched closest ideal maps (projective-maps paper, App. A) on the device:
// shaders/ideal_maps.comp, the math of src/projective/IdealMapFit.cpp (the fit's in-plane
// Jacobian, its closest rotation by a one-sided Jacobi SVD, the corner-set fallback), one
// invocation per face, fp64.
#include "compute/Backend.h"
#include "compute/vulkan/VulkanSequence.h"

namespace plano::vk {

/// The face maps (16 doubles a face, column-major) that the ideal-map kernel left in its
/// device array, with the host copy of what that array holds. The backend hands one record
/// to that kernel, which keeps it current, and to the ADMM kernels: a global step's linear
/// term q = -T of exactly those maps (its targets) is then formed from the array on the
/// device instead of uploaded (vk::AdmmKernels::start). The host copy costs 128 B a face,
/// as the fit kernel's of its maps (exact comparison needs the values, not a digest).
class ResidentFaceMaps {
 public:
  /// `array` holds `maps` now (until the next hold or release).
  void hold(const Array<double>& array, std::vector<Eigen::Matrix4d> maps) {
    array_ = &array;
    maps_ = std::move(maps);
  }
  void release() {
    array_ = nullptr;
    maps_.clear();
  }
  /// The array when `q` (n x k, k <= 4) is, entry for entry, minus the first k columns of
  /// the held maps stacked four rows a face (q(4 f + r, c) = -M_f(r, c)); else null.
  const Array<double>* holdingNegatedColumns(const Eigen::MatrixXd& q) const;

 private:
  const Array<double>* array_ = nullptr;
  std::vector<Eigen::Matrix4d> maps_;
};

class IdealMapsKernel {
 public:
  /// `resident`, when not null, is kept holding the last run's ideal maps (it must outlive
  /// this kernel).
  explicit IdealMapsKernel(Context& context, ResidentFaceMaps* resident = nullptr);
  ~IdealMapsKernel();
  IdealMapsKernel(const IdealMapsKernel&) = delete;
  IdealMapsKernel& operator=(const IdealMapsKernel&) = delete;

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
  ResidentFaceMaps* resident_;
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
