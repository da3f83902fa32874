#pragma once
// Global step of the coarse level of multi-resolution editing (projective-maps paper,
// §6.2): Eq. 4 with the ε relaxation, where the positional constraints are
//  - fixed vertices of the coarse level, held at their base positions (for an
//    approximating scheme these are the coarse positions, not the fine ones, §6.5), and
//  - handles attached to the maps of coarse faces: (p, 1) A_f proportional to (q, 1) for a
//    point p of the ambient space (the handle's fine position) and its target q.
// GlobalStep (GlobalStep.h) constrains mesh vertices only; this step adds the ambient
// point rows and otherwise follows the same structure for the affine targets of the coarse
// loop (every scale factor 1, for a point too: shat = (p, 1) T_f[:, 3] = 1): three QPs for
// columns 0..2 sharing one matrix (BoxQp.h), the paper's ε schedule (solveEpsilonSchedule)
// on the compatibility rows only.
#include <memory>
#include <vector>

#include "compute/Backend.h"
#include "projective/GlobalStep.h"
#include "projective/MultiresConstraints.h"
#include "projective/ScaledConstraintMatrix.h"
#include "projective/ShapeSpace.h"

namespace plano::projective {

class MultiresCoarseStep {
 public:
  /// Precompute the row layout and P = I + alpha L.
  ///   space    in: shape space of the coarse level (kept by reference).
  ///   fixed    in: fixed vertices of the level (unique).
  ///   handles  in: map-point constraints in world coordinates (faces of the level).
  /// Throws Error(BadInput) for an out-of-range or repeated vertex or face, a non-finite
  /// point or target.
  MultiresCoarseStep(compute::Backend& backend, const ShapeSpace& space, std::vector<Index> fixed,
                     std::vector<MapPointConstraint> handles, const GlobalStepSettings& settings = {});

  /// Project affine targets (the ideal maps of the rigid/similar local step: fourth columns
  /// (0, 0, 0, 1), normalized coordinates), given by their first three columns, 4 #F x 3,
  /// which may stay on the device that computed them, onto the compatible maps that satisfy
  /// the constraints. The result's first three columns are left where the QP solved for
  /// them (GlobalStep::solveAffine's contract: readable while this object lives and until
  /// its next solve). Throws Error(Numerical) as GlobalStep::solve does, and Error(Usage)
  /// for targets of the wrong size.
  GlobalStepInfo solveAffine(const compute::DeviceMatrix& linearColumns, compute::DeviceMatrix& resultColumns);

 private:
  enum class RowKind { Compatibility, Fixed, MapPoint };
  struct Row {
    RowKind kind;
    Index vertex;   ///< Compatibility and fixed rows.
    Index cornerA;  ///< Compatibility and fixed rows.
    Index cornerB;  ///< Compatibility rows.
    Index handle;   ///< MapPoint rows: index into handles_.
  };

  compute::Backend& backend_;
  const ShapeSpace& space_;
  std::vector<MapPointConstraint> handles_;  ///< Points and targets in normalized coordinates.
  GlobalStepSettings settings_;
  compute::SparseMatrix P_;
  std::vector<Row> rows_;
  ScaledConstraintMatrix constraints_;  ///< C: its pattern once, its values per solve.
  std::unique_ptr<BoxQpSolver> qp_;  ///< Created by the first solve, kept for the next ones.
  EpsilonScheduleMemory scheduleMemory_;
};

}  // namespace plano::projective
