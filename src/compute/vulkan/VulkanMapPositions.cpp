#include "compute/vulkan/VulkanMapPositions.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "compute/vulkan/VulkanFacePlanarity.h"
#include "compute/vulkan/VulkanInputChecks.h"
#include "core/Error.h"

namespace plano::vk {
namespace {

struct MapPositionsPush {
  std::uint32_t vertexCount;
  std::uint32_t rows;
  std::uint32_t weighted;
};

std::span<const double> positionValues(const Positions& positions) {
  return {positions.data(), static_cast<std::size_t>(positions.size())};
}

}  // namespace

MapPositionsKernel::MapPositionsKernel(Context& context)
    : context_(context),
      algebra_(context),
      positions_(context, "map_positions", 9, sizeof(MapPositionsPush)),
      planarity_(context, "face_planarity", 4, sizeof(FacePlanarityPush)),
      generations_{std::make_shared<std::uint64_t>(0), std::make_shared<std::uint64_t>(0)} {}

MapPositionsKernel::~MapPositionsKernel() = default;

void MapPositionsKernel::run(const FaceList& faces, const Positions& base, const compute::VertexCorners& corners,
                             const compute::DeviceMatrix& mapColumns, const compute::DeviceMatrix& cornerWeights,
                             const compute::DeviceMatrix& previous, compute::MapPositions& out) {
  const std::uint32_t vertexCount = elementCount(base.rows(), "the vertex count");
  if (vertexCount == 0) {
    out = compute::MapPositions{compute::DeviceMatrix(Eigen::MatrixXd(0, 3)), 0.0, 0.0};
    return;
  }
  const std::uint32_t faceCount = elementCount(faces.size(), "the face count");
  const std::uint32_t rows = elementCount(mapColumns.rows(), "the map columns' rows");
  checkFaces(faces, static_cast<Index>(base.rows()), "mapPositions");
  checkMeshFitsOneBinding(faces, static_cast<Index>(base.rows()), context_.info().maxStorageBufferRange);
  const std::size_t positionCount = std::size_t{vertexCount} * 3;

  base_.assign(context_, positionValues(base), "base positions");
  vertexOffsets_.assign(context_, {corners.offsets.data(), corners.offsets.size()}, "vertex corner offsets");
  vertexCorners_.assign(context_, {corners.corners.data(), corners.corners.size()}, "vertex corners");
  cornerFace_.assign(context_, {corners.cornerFace.data(), corners.cornerFace.size()}, "corner faces");
  faceOffsets_.assign(context_, faces.offsets(), "face offsets");
  faceCorners_.assign(context_, faces.indices(), "face corners");

  // The inputs where they are: the ADMM's solution and this kernel's last positions.
  const Array<double>* columns = arrayOf(mapColumns, context_, ArrayLayout::ColumnMajor);
  if (!columns) {
    const Eigen::MatrixXd& values = mapColumns.values();  // column-major, as the shader reads
    ensureCapacity(uploadedColumns_, context_, std::max<std::size_t>(values.size(), 1), "map columns");
    uploadedColumns_.upload({values.data(), static_cast<std::size_t>(values.size())});
    columns = &uploadedColumns_;
  }
  // Weights: the fit kernel's induced scales; none for affine maps (a bound, unread array).
  const bool weighted = cornerWeights.size() != 0;
  const Array<double>* weights = weighted ? arrayOf(cornerWeights, context_, ArrayLayout::ColumnMajor) : columns;
  if (!weights) {
    const Eigen::MatrixXd& values = cornerWeights.values();
    ensureCapacity(uploadedWeights_, context_, static_cast<std::size_t>(values.size()), "corner weights");
    uploadedWeights_.upload({values.data(), static_cast<std::size_t>(values.size())});
    weights = &uploadedWeights_;
  }
  const Array<double>* before = arrayOf(previous, context_, ArrayLayout::RowMajor);
  if (before == &outputs_[next_]) next_ = 1 - next_;  // never write over the positions read
  if (!before) {
    const Positions values = previous.values();
    ensureCapacity(uploadedPrevious_, context_, positionCount, "previous positions");
    uploadedPrevious_.upload(positionValues(values));
    before = &uploadedPrevious_;
  }

  Array<double>& output = outputs_[next_];
  *generations_[next_] = nextArrayGeneration();  // what this array held is overwritten below
  ensureCapacity(output, context_, positionCount, "vertex positions");
  if (!distance_ || distance_->n() != vertexCount) {
    distance_ = std::make_unique<DeviceVectors>(context_, vertexCount, 1, "vertex displacements");
  }
  if (!planarityValues_ || planarityValues_->n() != faceCount) {
    planarityValues_ = std::make_unique<DeviceVectors>(context_, std::max<std::uint32_t>(faceCount, 1), 1,
                                                        "face planarity");
  }
  if (!measures_) measures_ = std::make_unique<DeviceScalars>(context_, 2, 1, std::max(vertexCount, faceCount));

  Sequence s(context_);
  s.begin();
  s.dispatch(positions_,
             {BufferRange(*columns, 0, std::max<std::size_t>(rows, 1) * 3 * sizeof(double)), BufferRange(base_.array()),
              BufferRange(vertexOffsets_.array()), BufferRange(vertexCorners_.array()), BufferRange(cornerFace_.array()),
              BufferRange(*before, 0, positionCount * sizeof(double)), BufferRange(output, 0, positionCount * sizeof(double)),
              BufferRange(distance_->data()), BufferRange(*weights)},
             MapPositionsPush{vertexCount, rows, weighted ? 1u : 0u}, groupsFor(context_, vertexCount));
  s.barrier();
  if (faceCount > 0) {
    s.dispatch(planarity_,
               {BufferRange(output, 0, positionCount * sizeof(double)), BufferRange(faceOffsets_.array()),
                BufferRange(faceCorners_.array()), BufferRange(planarityValues_->data())},
               FacePlanarityPush{0, faceCount}, groupsFor(context_, faceCount));
    s.barrier();
  }
  algebra_.maxAbs(s, *distance_, *measures_, 0);
  if (faceCount > 0) algebra_.maxAbs(s, *planarityValues_, *measures_, 1);
  s.end();
  s.run();
  const std::vector<double> measured = measures_->read();
  out.displacement = measures_->at(measured, 0, 0);
  out.maxPlanarity = faceCount > 0 ? measures_->at(measured, 1, 0) : 0.0;
  // A non-finite position makes its distance non-finite (the reduction keeps NaN).
  if (!std::isfinite(out.displacement)) {
    throwNumerical("mapPositions: a vertex position from the maps is not finite");
  }
  const auto vertexRows = static_cast<Eigen::Index>(vertexCount);
  out.positions = compute::DeviceMatrix(
      vertexRows, 3,
      std::make_shared<const ArraySource>(context_, output, ArrayLayout::RowMajor, vertexRows, 3, *generations_[next_],
                                          generations_[next_]));
  next_ = 1 - next_;
}

}  // namespace plano::vk
