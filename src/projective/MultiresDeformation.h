#pragma once
// Multi-resolution editing (projective-maps paper, §6.2-§6.5). The user constrains the
// finest mesh M_n of a subdivision hierarchy; the algorithm
//  1. picks the coarsest admissible level k (§6.2 rule, MultiresConstraints.h) unless a
//     level is forced;
//  2. deforms M_k as-rigid (or as-similar) as possible (§6.1): local step = projective fit
//     and closest ideal map, global step = MultiresCoarseStep with the coarsened
//     constraints (fixed coarse vertices at their coarse positions, handles attached to the
//     maps of the ancestors of the fine faces around them), until the max displacement per
//     iteration is below the tolerance;
//  3. prolongs the coarse maps (§6.3): every fine face takes the map of its ancestor
//     (converted between the levels' coordinate normalizations);
//  4. projects them with one fine global step (GlobalStep) holding the user's fixed
//     vertices and handles exactly, with the smoothness term alpha (§6.3, default 3.5),
//     followed, only if the faces are then above the planarity tolerance, by §5
//     projection iterations (projective fit to the current faces, same global step).
// The same steps serve interpolating and approximating hierarchies (§6.5): coarse fixed
// vertices are held where they are on their own level, and handles act on the ambient
// space of the coarse maps in either case. When the rule picks the finest level, the
// single-level deformation (Deformation.h) runs on M_n directly.
#include <functional>
#include <optional>
#include <vector>

#include "compute/Backend.h"
#include "mesh/Constraints.h"
#include "mesh/Planarity.h"
#include "projective/GlobalStep.h"
#include "projective/IdealMaps.h"
#include "projective/MultiresConstraints.h"
#include "projective/MultiresHierarchy.h"

namespace plano::projective {

struct MultiresSettings {
  IdealMapKind energy = IdealMapKind::Rigid;
  /// Deformation level; -1: the coarsest admissible level by the paper's rule.
  int level = -1;
  /// alpha of the smoothness term in the fine global step (§6.3: 3-4 in the paper).
  double smoothness = 3.5;
  int maxCoarseIterations = 100;
  /// Coarse iterations stop when the max vertex displacement per iteration falls below
  /// this fraction of the bounding-box diagonal.
  double tolerance = 1e-4;
  /// Percent: max face planarity the fine result should reach.
  double planarityTolerance = 1.0;
  int maxProjectionIterations = 10;
  /// Global step settings of the coarse and fine levels (smoothness is set from
  /// `smoothness` for the fine step and 0 for the coarse one). Eps = 0 is tried first: the
  /// affine maps of a rigid/similar step are often exactly compatible.
  GlobalStepSettings global = [] {
    GlobalStepSettings s;
    s.epsilonStart = EpsilonStart::ExactFirst;
    return s;
  }();
};

enum class MultiresStatus {
  Converged,             ///< Coarse iterations converged and the fine result meets the planarity bound.
  MaxIterationsReached,  ///< A cap stopped the coarse or the projection iterations (result usable).
};

const char* toString(MultiresStatus status);

struct MultiresInfo {
  MultiresStatus status = MultiresStatus::Converged;
  int level = 0;                      ///< Level the deformation ran on.
  std::vector<LevelCheck> levelChecks;  ///< The rule per level (empty when the level was forced).
  Index coarseFaces = 0;
  Index fineFaces = 0;
  int coarseIterations = 0;
  std::vector<double> coarseEpsilons;  ///< Per coarse global step.
  std::vector<double> coarseDisplacements;
  /// Per coarse iteration and per projection iteration: the copies between host and device
  /// (Backend::transfers; nullopt on a backend that does not count them). When the finest
  /// level is the deformation level, coarseTransfers, like coarseEpsilons, has every
  /// iteration of the single-level deformation, its projection phase included.
  std::vector<std::optional<compute::DeviceTransfers>> coarseTransfers;
  std::vector<std::optional<compute::DeviceTransfers>> projectionTransfers;
  GlobalStepInfo fineStep;            ///< The prolongation's global step.
  int projectionIterations = 0;
  PlanarityStats planarity;           ///< Of the fine result.
  double maxFixedError = 0.0;         ///< World units: max distance of a fixed vertex from its position.
  double maxHandleError = 0.0;        ///< World units: max distance of a handle from its target.
  double coarseSeconds = 0.0;         ///< Coarse setup and deformation.
  double prolongationSeconds = 0.0;   ///< Map prolongation, fine setup, fine global step(s).
  double seconds = 0.0;
};

enum class MultiresPhase {
  Coarse,      ///< A local/global iteration on the deformation level.
  Projection,  ///< A projection iteration of the fine result (§5), after the prolongation.
};

/// One iteration, for progress output and monitoring.
struct MultiresIteration {
  MultiresPhase phase = MultiresPhase::Coarse;
  int iteration = 0;           ///< 1-based, within its phase.
  double epsilon = 0.0;        ///< Coarse: the global step's final eps (0 for a projection iteration).
  double displacement = 0.0;   ///< Coarse: max vertex move / bounding-box diagonal (0 for a projection iteration).
  double maxPlanarity = 0.0;   ///< Percent, of the level the iteration ran on, after it.
  /// Host <-> device copies of the iteration (compute::Backend::transfers; none on the CPU).
  std::optional<compute::DeviceTransfers> transfers;
};

/// Called after every iteration; may be empty.
using MultiresCallback = std::function<void(const MultiresIteration&)>;

struct MultiresResult {
  Positions positions;  ///< #V_n x 3, the deformed finest mesh.
  MultiresInfo info;
};

/// Deform the finest mesh of a hierarchy.
///   hierarchy    in: topology of M_0..M_n.
///   positions    in: positions of every level (#V_l x 3 each, n + 1 entries), e.g.
///                PqSubdivisionResult::positions.
///   constraints  in: fixed vertices and handles on the finest level.
/// Throws Error(Usage) for mismatched positions or a forced level outside the hierarchy,
/// Error(BadInput) for constraints on vertices that do not exist, Error(Numerical) when a
/// global step fails.
MultiresResult multiresDeform(compute::Backend& backend, const SubdivisionHierarchy& hierarchy,
                              const std::vector<Positions>& positions, const PositionalConstraints& constraints,
                              const MultiresSettings& settings = {}, const MultiresCallback& callback = {});

}  // namespace plano::projective
