#include "projective/MultiresCoarseStep.h"

#include <cmath>
#include <sstream>

#include "core/Error.h"

namespace plano::projective {
namespace {

std::string number(double value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

compute::SparseMatrix smoothnessMatrix(const ShapeSpace& space, double alpha) {
  const Index n = 4 * space.faceCount();
  std::vector<Eigen::Triplet<double>> entries;
  for (Index i = 0; i < n; ++i) entries.emplace_back(i, i, 1.0);
  if (alpha > 0.0) {
    for (const auto& [f, g] : space.adjacentFaces()) {
      for (Index r = 0; r < 4; ++r) {
        entries.emplace_back(4 * f + r, 4 * f + r, alpha);
        entries.emplace_back(4 * g + r, 4 * g + r, alpha);
        entries.emplace_back(4 * f + r, 4 * g + r, -alpha);
        entries.emplace_back(4 * g + r, 4 * f + r, -alpha);
      }
    }
  }
  compute::SparseMatrix P(n, n);
  P.setFromTriplets(entries.begin(), entries.end());
  return P;
}

}  // namespace

MultiresCoarseStep::MultiresCoarseStep(compute::Backend& backend, const ShapeSpace& space, std::vector<Index> fixed,
                                       std::vector<MapPointConstraint> handles, const GlobalStepSettings& settings)
    : backend_(backend), space_(space), handles_(std::move(handles)), settings_(settings) {
  if (!(settings_.smoothness >= 0.0) || !std::isfinite(settings_.smoothness)) {
    throwUsage("coarse global step: smoothness must be a finite number >= 0, got " + number(settings_.smoothness));
  }
  if (!(settings_.epsilonGrowth > 1.0)) throwUsage("coarse global step: epsilon growth must exceed 1");
  if (!(settings_.compatibleViolation >= 0.0) || !std::isfinite(settings_.compatibleViolation)) {
    throwUsage("coarse global step: the compatible violation must be a finite number >= 0");
  }
  std::vector<char> isFixed(space_.vertexCount(), 0);
  for (const Index v : fixed) {
    if (v < 0 || v >= space_.vertexCount()) {
      throwBadInput("coarse global step: fixed vertex " + std::to_string(v) + " is out of range (" +
                    std::to_string(space_.vertexCount()) + " vertices)");
    }
    if (isFixed[v]) throwBadInput("coarse global step: vertex " + std::to_string(v) + " is fixed twice");
    isFixed[v] = 1;
  }
  for (MapPointConstraint& h : handles_) {
    if (h.face < 0 || h.face >= space_.faceCount()) {
      throwBadInput("coarse global step: handle " + std::to_string(h.handle) + " is attached to face " +
                    std::to_string(h.face) + ", out of range (" + std::to_string(space_.faceCount()) + " faces)");
    }
    if (!h.point.allFinite() || !h.target.allFinite()) {
      throwBadInput("coarse global step: handle " + std::to_string(h.handle) + " has a non-finite point or target");
    }
    h.point = space_.normalization().toNormalized(Eigen::RowVector3d(h.point.transpose())).transpose();
    h.target = space_.normalization().toNormalized(Eigen::RowVector3d(h.target.transpose())).transpose();
  }

  const auto& offsets = space_.vertexCornerOffsets();
  const auto& corners = space_.cornersOfVertex();
  for (Index v = 0; v < space_.vertexCount(); ++v) {
    const Index begin = offsets[v];
    const Index end = offsets[v + 1];
    if (isFixed[v]) {
      for (Index k = begin; k < end; ++k) rows_.push_back({RowKind::Fixed, v, corners[k], -1, -1});
    } else {
      for (Index k = begin + 1; k < end; ++k) rows_.push_back({RowKind::Compatibility, v, corners[begin], corners[k], -1});
    }
  }
  for (std::size_t h = 0; h < handles_.size(); ++h) {
    rows_.push_back({RowKind::MapPoint, -1, -1, -1, static_cast<Index>(h)});
  }
  // Scales: the corners' reciprocal scale factors, then one per handle (its point's).
  std::vector<ScaledConstraintMatrix::Term> terms;
  terms.reserve(2 * rows_.size());
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    const auto i = static_cast<Index>(r);
    if (row.kind == RowKind::MapPoint) {
      const MapPointConstraint& h = handles_[row.handle];
      const Eigen::RowVector4d p(h.point.x(), h.point.y(), h.point.z(), 1.0);
      terms.push_back({i, h.face, p, space_.cornerCount() + row.handle});
      continue;
    }
    const Eigen::RowVector4d p = homogeneous(space_.basePositions().row(row.vertex));
    terms.push_back({i, space_.cornerFace(row.cornerA), p, row.cornerA});
    if (row.kind == RowKind::Compatibility) terms.push_back({i, space_.cornerFace(row.cornerB), -p, row.cornerB});
  }
  constraints_ = ScaledConstraintMatrix(static_cast<Index>(rows_.size()), space_.faceCount(),
                                        space_.cornerCount() + static_cast<Index>(handles_.size()), terms);
  P_ = smoothnessMatrix(space_, settings_.smoothness);
}

GlobalStepInfo MultiresCoarseStep::solveAffine(const compute::DeviceMatrix& linearColumns,
                                               compute::DeviceMatrix& resultColumns) {
  const Index faceCount = space_.faceCount();
  if (linearColumns.rows() != 4 * static_cast<Eigen::Index>(faceCount) || linearColumns.cols() != 3) {
    throwUsage("coarse global step: affine targets of " + std::to_string(linearColumns.rows()) + " x " +
               std::to_string(linearColumns.cols()) + " for " + std::to_string(faceCount) + " faces (need 4 #F x 3)");
  }
  // Fourth columns (0, 0, 0, 1): every corner's and every handle point's scale is 1.
  const std::vector<double> scales(space_.cornerCount() + handles_.size(), 1.0);
  const auto m = static_cast<Eigen::Index>(rows_.size());
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(m, 3);
  std::vector<char> relaxed(m, 0);
  for (Eigen::Index r = 0; r < m; ++r) {
    const Row& row = rows_[r];
    if (row.kind == RowKind::MapPoint) {
      d.row(r) = handles_[row.handle].target.transpose();
    } else if (row.kind == RowKind::Compatibility) {
      relaxed[r] = 1;
    } else {
      d.row(r) = space_.basePositions().row(row.vertex);
    }
  }
  constraints_.fill(scales);
  // C's pattern depends on the topology (and the constraints) only: one solver for the
  // object's lifetime.
  BoxQpSettings qpSettings = settings_.qp;
  qpSettings.preconditionerBlock = 4;  // rows 4f..4f+3: the entries of face f's map, coupled in K
  qpSettings.returnDuals = false;      // zero duals or those the ADMM keeps (solveEpsilonSchedule)
  BoxQpSolver& qp = keptSolver(qp_, backend_, P_, constraints_, scales, qpSettings);
  GlobalStepInfo info;
  compute::RelaxedBounds bounds{std::move(d), std::move(relaxed), 0.0};
  solveEpsilonSchedule(qp, linearColumns, bounds, settings_, "coarse global step", info, resultColumns,
                       &scheduleMemory_);
  return info;
}

}  // namespace plano::projective
