#include "compute/vulkan/VulkanProjectiveFit.h"

#include <algorithm>
#include <string>

#include "compute/vulkan/VulkanDeviceMatrix.h"
#include "compute/vulkan/VulkanInputChecks.h"
#include "compute/vulkan/VulkanLinearAlgebra.h"
#include "core/Error.h"

namespace plano::vk {
namespace {

struct ProjectiveFitPush {
  std::uint32_t firstFace;
  std::uint32_t faceCount;
  double rankThreshold;
};

static_assert(sizeof(Eigen::Matrix4d) == 16 * sizeof(double), "Matrix4d must be 16 packed doubles");
static_assert(sizeof(int) == sizeof(std::int32_t), "ranks are 32-bit on the device");

// Workgroup size of shaders/projective_fit.comp (FIT_GROUP_SIZE).
constexpr std::uint32_t kFitGroupSize = 64;

struct InducedScalesPush {
  std::uint32_t faceCount;
  std::uint32_t unused;
  double vanishingScale;
};

}  // namespace

ProjectiveFitKernel::ProjectiveFitKernel(Context& context, ProjectiveFitSettings settings)
    : context_(context), settings_(settings), pipeline_(context, "projective_fit", 8, sizeof(ProjectiveFitPush)) {}

void ProjectiveFitKernel::run(const FaceList& faces, const Positions& source, const Positions& target,
                              compute::ProjectiveFits& out) {
  fit(faces, source, &target, nullptr, &out);
}

const Array<double>* ProjectiveFitKernel::runResident(const FaceList& faces, const Positions& source,
                                                      const Positions& target) {
  return fit(faces, source, &target, nullptr, nullptr) ? &maps_ : nullptr;
}

const Array<double>* ProjectiveFitKernel::runResidentOn(const FaceList& faces, const Positions& source,
                                                        const Array<double>& target) {
  if (target.count() < static_cast<std::size_t>(source.size())) {
    throwUsage("fitProjectiveMaps: the device's target positions are fewer than the source's");
  }
  return fit(faces, source, nullptr, &target, nullptr) ? &maps_ : nullptr;
}

bool ProjectiveFitKernel::fit(const FaceList& faces, const Positions& source, const Positions* target,
                              const Array<double>* residentTarget, compute::ProjectiveFits* out) {
  if (target) compute::checkFitInputs(source, *target);
  *mapsGeneration_ = nextArrayGeneration();  // maps_ is rewritten (or reallocated) below
  const std::size_t faceCount = static_cast<std::size_t>(faces.size());
  if (out) {
    out->maps.resize(faceCount);
    out->reciprocalScales.resize(faces.cornerCount());
    out->residuals.resize(faceCount);
    out->ranks.resize(faceCount);
  }
  lastMaps_.clear();
  if (faceCount == 0) return out != nullptr;
  checkFaces(faces, static_cast<Index>(source.rows()), "fitProjectiveMaps");

  const std::size_t range = context_.info().maxStorageBufferRange;
  const std::size_t positionBytes = static_cast<std::size_t>(source.size()) * sizeof(double);
  checkMeshFitsOneBinding(faces, static_cast<Index>(source.rows()), range);

  // Faces per chunk: the maps (128 bytes a face) and the chunk's corner scales must each
  // fit one storage binding.
  const std::vector<Index>& offset = faces.offsets();
  const std::size_t maxFaces = std::min(faceCount, range / kFaceMapBytes);
  std::vector<std::size_t> chunkEnds;
  std::size_t maxCorners = 0;
  for (std::size_t first = 0; first < faceCount;) {
    std::size_t last = std::min(faceCount, first + maxFaces);
    while (static_cast<std::size_t>(offset[last] - offset[first]) * sizeof(double) > range) --last;
    maxCorners = std::max<std::size_t>(maxCorners, offset[last] - offset[first]);
    chunkEnds.push_back(last);
    first = last;
  }
  // Fits kept on the device must all be in the maps' array at once.
  if (!out && chunkEnds.size() > 1) return false;

  source_.assign(context_, {source.data(), static_cast<std::size_t>(source.size())}, "source positions");
  if (target) target_.assign(context_, {target->data(), static_cast<std::size_t>(target->size())}, "target positions");
  const Array<double>& targetArray = target ? target_.array() : *residentTarget;
  offsets_.assign(context_, faces.offsets(), "face offsets");
  indices_.assign(context_, faces.indices(), "face corners");
  ensureCapacity(maps_, context_, maxFaces * 16, "projective maps");
  ensureCapacity(scales_, context_, maxCorners, "reciprocal scales");
  ensureCapacity(residuals_, context_, maxFaces, "fit residuals");
  ensureCapacity(ranks_, context_, maxFaces, "fit ranks");
  DescriptorSet set(context_, pipeline_,
                    {BufferRange(source_.array(), 0, positionBytes), BufferRange(targetArray, 0, positionBytes),
                     BufferRange(offsets_.array()), BufferRange(indices_.array()),
                     BufferRange(maps_, 0, maxFaces * kFaceMapBytes),
                     BufferRange(scales_, 0, maxCorners * sizeof(double)),
                     BufferRange(residuals_, 0, maxFaces * sizeof(double)),
                     BufferRange(ranks_, 0, maxFaces * sizeof(std::int32_t))});
  Sequence sequence(context_);
  std::size_t first = 0;
  for (const std::size_t last : chunkEnds) {
    const std::size_t n = last - first;
    sequence.begin();
    sequence.dispatch(pipeline_, set,
                      ProjectiveFitPush{static_cast<std::uint32_t>(first), static_cast<std::uint32_t>(n), settings_.rankThreshold},
                      groupsFor(context_, n, kFitGroupSize));
    sequence.end();
    sequence.run();
    if (out) {
      maps_.Buffer::download(out->maps.data() + first, n * kFaceMapBytes);
      scales_.download(std::span<double>(out->reciprocalScales).subspan(offset[first], offset[last] - offset[first]));
      residuals_.download(std::span<double>(out->residuals).subspan(first, n));
      ranks_.download(std::span<std::int32_t>(out->ranks.data() + first, n));
    }
    first = last;
  }
  if (out && chunkEnds.size() == 1) lastMaps_ = out->maps;  // maps_ holds them all
  return true;
}

bool ProjectiveFitKernel::keep(const FaceList& faces, const Positions& source, const Positions* target,
                               const Array<double>* residentTarget, double vanishingScale,
                               compute::DeviceProjectiveFits& out) {
  if (!target && (!residentTarget || residentTarget->count() < static_cast<std::size_t>(source.size()))) {
    throwUsage("fitProjectiveMaps: the device's target positions are fewer than the source's");
  }
  out = compute::DeviceProjectiveFits{};
  const std::size_t faceCount = static_cast<std::size_t>(faces.size());
  if (faceCount == 0 || !fit(faces, source, target, residentTarget, nullptr)) return false;
  const std::uint32_t corners = elementCount(faces.cornerCount(), "the corner count");
  if (!inducedScales_) {
    inducedScales_ = std::make_unique<Pipeline>(context_, "induced_scales", 6, sizeof(InducedScalesPush));
  }
  *scalesGeneration_ = nextArrayGeneration();
  ensureCapacity(cornerScales_, context_, corners, "induced reciprocal scales");
  ensureCapacity(scaleTallies_, context_, 2, "induced scale tallies");
  Sequence s(context_);
  s.begin();
  s.zero(scaleTallies_, 2 * sizeof(std::uint32_t));
  s.dispatch(*inducedScales_,
             {BufferRange(source_.array(), 0, static_cast<std::size_t>(source.size()) * sizeof(double)),
              BufferRange(offsets_.array()), BufferRange(indices_.array()),
              BufferRange(maps_, 0, faceCount * kFaceMapBytes), BufferRange(cornerScales_, 0, corners * sizeof(double)),
              BufferRange(scaleTallies_)},
             InducedScalesPush{static_cast<std::uint32_t>(faceCount), 0, vanishingScale}, groupsFor(context_, faceCount));
  s.end();
  s.run();
  std::uint32_t tally[2] = {};
  scaleTallies_.download({tally, 2});
  out.nonPositiveScales = static_cast<Index>(tally[0]);
  out.firstVanishingCorner = tally[1] > 0 ? static_cast<Index>(0xffffffffu - tally[1]) : -1;
  const auto rows = 4 * static_cast<Eigen::Index>(faceCount);
  out.linearColumns = compute::DeviceMatrix(
      rows, 3,
      std::make_shared<const ArraySource>(context_, maps_, ArrayLayout::FaceMapColumns, rows, 3, *mapsGeneration_,
                                          mapsGeneration_));
  out.reciprocalScales = compute::DeviceMatrix(
      corners, 1,
      std::make_shared<const ArraySource>(context_, cornerScales_, ArrayLayout::ColumnMajor, corners, 1,
                                          *scalesGeneration_, scalesGeneration_));
  return true;
}

const Array<double>* ProjectiveFitKernel::mapsHolding(std::span<const Eigen::Matrix4d> maps) const {
  const bool same = !lastMaps_.empty() && lastMaps_.size() == maps.size() &&
                    std::equal(maps.begin(), maps.end(), lastMaps_.begin());
  return same ? &maps_ : nullptr;
}

const Array<double>* ProjectiveFitKernel::targetHolding(const Positions& target) const {
  return target_.holds({target.data(), static_cast<std::size_t>(target.size())}) ? &target_.array() : nullptr;
}

}  // namespace plano::vk
