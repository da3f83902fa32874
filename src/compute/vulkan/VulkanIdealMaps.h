#pragma once
// Batched closest ideal maps (projective-maps paper, App. A) on the device:
// shaders/ideal_maps.comp, the math of src/projective/IdealMapFit.cpp (the fit's in-plane
// Jacobian, its closest rotation by a one-sided Jacobi SVD, the corner-set fallback), one
// invocation per face, fp64.
#include <memory>

#include "compute/Backend.h"
#include "compute/vulkan/VulkanDeviceMatrix.h"
#include "compute/vulkan/VulkanSequence.h"

namespace plano::vk {

/// The face maps (16 doubles a face, column-major) that the ideal-map kernel left in its
/// device array. The backend hands one record to that kernel, which keeps it current, and to
/// the ADMM kernels: a global step's linear term q = -T of exactly those maps (its targets)
/// and its warm start x = T are then formed from the array on the device instead of
/// uploaded (vk::AdmmKernels::start). Two ways to say "exactly those maps":
///  - a DeviceMatrix whose source is this record's columnsSource() of the current
///    generation (a loop that never fetched the maps: nothing mesh-sized crossed; the ADMM
///    binds any such face-map source of its context, the projective fits' too);
///  - host values equal to the host copy the kernel gave when it also downloaded the maps
///    (128 B a face, as exact comparison needs the values, not a digest).
class ResidentFaceMaps {
 public:
  /// `array` holds the maps of `faceCount` faces now (until the next hold or release);
  /// `maps` is their host copy, or empty when they were not downloaded.
  void hold(const Context& context, const Array<double>& array, std::size_t faceCount,
            std::vector<Eigen::Matrix4d> maps);
  void release();
  /// The array when `q` (n x k, k <= 4) is, entry for entry, minus the first k columns of
  /// the held maps stacked four rows a face (q(4 f + r, c) = -M_f(r, c)); else null.
  const Array<double>* holdingNegatedColumns(const Eigen::MatrixXd& q) const;
  /// The held maps' first three columns (4 #F x 3) as a device matrix's source
  /// (ArrayLayout::FaceMapColumns): fetched from the array while this record holds them
  /// (Error(Usage) after).
  std::shared_ptr<const compute::DeviceMatrixSource> columnsSource() const;
  std::uint64_t generation() const { return generation_; }

 private:
  const Context* context_ = nullptr;
  const Array<double>* array_ = nullptr;
  std::size_t faceCount_ = 0;
  std::vector<Eigen::Matrix4d> maps_;
  std::uint64_t generation_ = 0;  ///< Changes with every hold and release.
  /// The source of the current generation (made on first request; one per generation, so
  /// that q = -T and x = T of one step share it; reset by every hold and release).
  mutable std::shared_ptr<const ArraySource> source_;
  /// generation_, watched by the sources (weakly: a source may outlive this record), which
  /// read the array only while it still says their generation.
  std::shared_ptr<std::uint64_t> liveGeneration_ = std::make_shared<std::uint64_t>(0);
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
  /// runOnResidentFits that leaves the maps on the device (compute::Backend::
  /// fitIdealMapsOnDevice): only the methods' tallies (shaders/ideal_map_tally.comp, 12
  /// bytes) come back. Needs the kernel's resident record (Error(Usage) without one).
  /// `target` may be null when `residentTarget` holds the positions.
  void keepOnResidentFits(const FaceList& faces, const Positions& source, const Array<double>& fitted,
                          const Positions* target, const Array<double>* residentTarget, bool similar,
                          compute::DeviceIdealMaps& out);

 private:
  /// The runs, after their input checks: `fitted` is read only without `residentFitted`.
  /// With `kept` (one chunk, a resident record), nothing but the tallies is downloaded and
  /// `out` is left empty.
  void mapChunks(const FaceList& faces, const Positions& source, std::span<const Eigen::Matrix4d> fitted,
               const Positions* target, bool similar, compute::IdealMaps& out, const Array<double>* residentFitted,
               const Array<double>* residentTarget, compute::DeviceIdealMaps* kept = nullptr);

  Context& context_;
  ResidentFaceMaps* resident_;
  Pipeline pipeline_;
  std::unique_ptr<Pipeline> tally_;  ///< Made by the first kept run.
  Array<std::uint32_t> tallies_;
  // Reused across calls (grow-only): a deformation loop allocates once and uploads its
  // source and topology once.
  CachedArray<double> source_;
  Array<double> target_;
  CachedArray<Index> offsets_, indices_;
  Array<double> fitted_, ideal_;
  Array<std::int32_t> methods_;
};

}  // namespace plano::vk
