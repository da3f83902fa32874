#include "compute/vulkan/VulkanIdealMaps.h"

#include <algorithm>
#include <string>

#include "compute/vulkan/VulkanDeviceMatrix.h"
#include "compute/vulkan/VulkanInputChecks.h"
#include "core/Error.h"

namespace plano::vk {
namespace {

struct IdealMapsPush {
  std::uint32_t firstFace;
  std::uint32_t faceCount;
  std::uint32_t hasTarget;
  std::uint32_t similar;
};

static_assert(sizeof(Eigen::Matrix4d) == 16 * sizeof(double), "Matrix4d must be 16 packed doubles");
static_assert(sizeof(compute::IdealMapMethod) == sizeof(std::int32_t), "methods are 32-bit on the device");

}  // namespace

void ResidentFaceMaps::hold(const Context& context, const Array<double>& array, std::size_t faceCount,
                            std::vector<Eigen::Matrix4d> maps) {
  context_ = &context;
  array_ = &array;
  faceCount_ = faceCount;
  maps_ = std::move(maps);
  *liveGeneration_ = generation_ = nextArrayGeneration();
  source_.reset();
}

void ResidentFaceMaps::release() {
  array_ = nullptr;
  faceCount_ = 0;
  maps_.clear();
  *liveGeneration_ = generation_ = nextArrayGeneration();
  source_.reset();
}

const Array<double>* ResidentFaceMaps::holdingNegatedColumns(const Eigen::MatrixXd& q) const {
  if (!array_ || q.cols() > 4 || maps_.size() != faceCount_ || q.rows() != 4 * static_cast<Eigen::Index>(maps_.size())) {
    return nullptr;
  }
  for (std::size_t f = 0; f < maps_.size(); ++f) {
    const auto row = static_cast<Eigen::Index>(4 * f);
    if (q.middleRows<4>(row) != -maps_[f].leftCols(q.cols())) return nullptr;  // exact: negation rounds nothing
  }
  return array_;
}

std::shared_ptr<const compute::DeviceMatrixSource> ResidentFaceMaps::columnsSource() const {
  if (!array_) throwUsage("ideal maps on the device: none are held");
  if (!source_) {
    source_ = std::make_shared<const ArraySource>(*context_, *array_, ArrayLayout::FaceMapColumns,
                                                  4 * static_cast<Eigen::Index>(faceCount_), 3, generation_,
                                                  liveGeneration_);
  }
  return source_;
}

IdealMapsKernel::IdealMapsKernel(Context& context, ResidentFaceMaps* resident)
    : context_(context), resident_(resident), pipeline_(context, "ideal_maps", 7, sizeof(IdealMapsPush)) {}

IdealMapsKernel::~IdealMapsKernel() {
  if (resident_) resident_->release();
}

void IdealMapsKernel::run(const FaceList& faces, const Positions& source, std::span<const Eigen::Matrix4d> fitted,
                          const Positions* target, bool similar, compute::IdealMaps& out,
                          const Array<double>* residentFitted, const Array<double>* residentTarget) {
  compute::checkIdealMapInputs(faces, source, fitted, target);
  mapChunks(faces, source, fitted, target, similar, out, residentFitted, residentTarget);
}

void IdealMapsKernel::runOnResidentFits(const FaceList& faces, const Positions& source, const Array<double>& fitted,
                                        const Positions& target, const Array<double>* residentTarget, bool similar,
                                        compute::IdealMaps& out) {
  compute::checkFitInputs(source, target);  // the positions the fits were made to
  const std::size_t faceCount = static_cast<std::size_t>(faces.size());
  const std::size_t range = context_.info().maxStorageBufferRange;
  if (fitted.count() < faceCount * 16 || faceCount > range / kFaceMapBytes) {
    throwUsage("closestIdealMaps: the resident fits do not hold the maps of all " + std::to_string(faceCount) +
               " faces in one binding");
  }
  mapChunks(faces, source, {}, &target, similar, out, &fitted, residentTarget);
}

void IdealMapsKernel::mapChunks(const FaceList& faces, const Positions& source, std::span<const Eigen::Matrix4d> fitted,
                              const Positions* target, bool similar, compute::IdealMaps& out,
                              const Array<double>* residentFitted, const Array<double>* residentTarget,
                              compute::DeviceIdealMaps* kept) {
  if (resident_) resident_->release();  // ideal_ changes (or is reallocated) below
  const std::size_t faceCount = static_cast<std::size_t>(faces.size());
  out.maps.resize(kept ? 0 : faceCount);
  out.methods.resize(kept ? 0 : faceCount);
  if (kept) *kept = compute::DeviceIdealMaps{};
  if (faceCount == 0) return;
  checkFaces(faces, static_cast<Index>(source.rows()), "closestIdealMaps");

  const std::size_t range = context_.info().maxStorageBufferRange;
  const std::size_t positionBytes = static_cast<std::size_t>(source.size()) * sizeof(double);
  checkMeshFitsOneBinding(faces, static_cast<Index>(source.rows()), range);
  source_.assign(context_, {source.data(), static_cast<std::size_t>(source.size())}, "source positions");
  // Without a target the shader never reads its binding, which still needs a buffer.
  const bool hasTarget = target || residentTarget;
  if (!residentTarget) {
    ensureCapacity(target_, context_, target ? static_cast<std::size_t>(target->size()) : 1, "target positions");
    if (target) target_.upload({target->data(), static_cast<std::size_t>(target->size())});
  }
  const Array<double>& targetArray = residentTarget ? *residentTarget : target_;
  offsets_.assign(context_, faces.offsets(), "face offsets");
  indices_.assign(context_, faces.indices(), "face corners");

  // Faces per chunk: the fitted and the ideal maps (128 bytes a face each) must fit one
  // storage binding.
  const std::size_t chunk = std::min(faceCount, range / kFaceMapBytes);
  if (chunk < faceCount || (residentFitted && residentFitted->count() < faceCount * 16)) residentFitted = nullptr;
  if (!residentFitted) ensureCapacity(fitted_, context_, chunk * 16, "fitted maps");
  const Array<double>& fittedArray = residentFitted ? *residentFitted : fitted_;
  ensureCapacity(ideal_, context_, chunk * 16, "ideal maps");
  ensureCapacity(methods_, context_, chunk, "ideal map methods");
  DescriptorSet set(context_, pipeline_,
                    {BufferRange(source_.array(), 0, positionBytes),
                     BufferRange(targetArray, 0, hasTarget ? positionBytes : sizeof(double)),
                     BufferRange(offsets_.array()), BufferRange(indices_.array()),
                     BufferRange(fittedArray, 0, chunk * kFaceMapBytes), BufferRange(ideal_, 0, chunk * kFaceMapBytes),
                     BufferRange(methods_, 0, chunk * sizeof(std::int32_t))});
  if (kept && (chunk < faceCount || !resident_)) {
    throwUsage("closestIdealMaps: the ideal maps of " + std::to_string(faceCount) +
               " faces cannot stay on the device (more than one binding, or no record of them)");
  }
  if (kept) {
    if (!tally_) tally_ = std::make_unique<Pipeline>(context_, "ideal_map_tally", 2, sizeof(std::uint32_t));
    ensureCapacity(tallies_, context_, 3, "ideal map tallies");
  }
  Sequence sequence(context_);
  for (std::size_t first = 0; first < faceCount; first += chunk) {
    const std::size_t n = std::min(chunk, faceCount - first);
    if (!residentFitted) fitted_.Buffer::upload(fitted.data() + first, n * kFaceMapBytes);
    sequence.begin();
    if (kept) sequence.zero(tallies_, 3 * sizeof(std::uint32_t));
    sequence.dispatch(pipeline_, set,
                      IdealMapsPush{static_cast<std::uint32_t>(first), static_cast<std::uint32_t>(n), hasTarget ? 1u : 0u,
                           similar ? 1u : 0u},
                      groupsFor(context_, n));
    if (kept) {
      sequence.barrier();
      const auto count = static_cast<std::uint32_t>(n);
      sequence.dispatch(*tally_, {BufferRange(methods_, 0, n * sizeof(std::int32_t)), BufferRange(tallies_)}, count,
                        groupsFor(context_, n));
    }
    sequence.end();
    sequence.run();
    if (kept) break;  // one chunk
    ideal_.Buffer::download(out.maps.data() + first, n * kFaceMapBytes);
    methods_.Buffer::download(out.methods.data() + first, n * sizeof(std::int32_t));
  }
  if (!resident_ || chunk < faceCount) return;
  resident_->hold(context_, ideal_, faceCount, kept ? std::vector<Eigen::Matrix4d>{} : out.maps);  // ideal_ holds them all
  if (!kept) return;
  std::uint32_t tally[3] = {};
  tallies_.download({tally, 3});
  kept->cornerProcrustes = static_cast<Index>(tally[0]);
  kept->centroidsAtInfinity = static_cast<Index>(tally[1]);
  kept->firstCentroidAtInfinity = tally[1] > 0 ? static_cast<Index>(0xffffffffu - tally[2]) : -1;
  kept->linearColumns = compute::DeviceMatrix(4 * static_cast<Eigen::Index>(faceCount), 3, resident_->columnsSource());
}

void IdealMapsKernel::keepOnResidentFits(const FaceList& faces, const Positions& source, const Array<double>& fitted,
                                         const Positions* target, const Array<double>* residentTarget, bool similar,
                                         compute::DeviceIdealMaps& out) {
  if (target) compute::checkFitInputs(source, *target);
  if (!target && (!residentTarget || residentTarget->count() < static_cast<std::size_t>(source.size()))) {
    throwUsage("closestIdealMaps: no target positions for the kept maps' corner fallback");
  }
  const std::size_t faceCount = static_cast<std::size_t>(faces.size());
  if (fitted.count() < faceCount * 16 || faceCount > context_.info().maxStorageBufferRange / kFaceMapBytes) {
    throwUsage("closestIdealMaps: the resident fits do not hold the maps of all " + std::to_string(faceCount) +
               " faces in one binding");
  }
  compute::IdealMaps unused;
  mapChunks(faces, source, {}, target, similar, unused, &fitted, residentTarget, &out);
}

}  // namespace plano::vk
