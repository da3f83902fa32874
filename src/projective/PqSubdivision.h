#pragma once
// Planar-quad subdivision (projective-maps paper, §5). Each level: refine trivially
// (QuadRefinement.h; the refined mesh is the base of a fresh projective shape space),
// take target positions q from a linear scheme (SubdivisionSchemes.h), then iterate
//   1. local step: the projective map of every face from the base to the targets, both
//      projected onto their best-fitting planes first (fitFaceMaps);
//   2. global step: project the maps onto the compatible shape space with the ε schedule
//      (GlobalStep), giving new positions;
//   3. reuse the new positions as targets;
// until the max planarity is under the bound and the max vertex change between two
// iterations (the first compared with the linear targets) is under `changeTolerance`
// times the bounding-box diagonal. The result of a level is the coarse mesh of the next.
#include <cstdint>
#include <functional>
#include <vector>

#include "compute/Backend.h"
#include "mesh/Planarity.h"
#include "mesh/PolygonMesh.h"
#include "projective/GlobalStep.h"
#include "projective/MultiresHierarchy.h"
#include "projective/SubdivisionSchemes.h"

namespace plano::projective {

struct PqSubdivisionSettings {
  SubdivisionScheme scheme = SubdivisionScheme::CatmullClark;
  int levels = 1;
  /// Bound on the max face planarity (percent); the paper uses 0.1 % (Catmull-Clark) and
  /// relaxes it to 0.5 % for the interpolating four-point scheme.
  double planarityTolerance = 0.1;
  /// Bound on the max vertex change between iterations, relative to the bbox diagonal.
  double changeTolerance = 1e-3;
  int maxIterationsPerLevel = 20;
  /// false: only the linear scheme (no local/global iterations), for comparisons.
  bool planarize = true;
  /// GlobalStepSettings::intermediateAttempts of a level's steps once one of its global
  /// steps kept its targets after failed attempts and its iteration flattened the faces
  /// by less than 5 %: there the paper's schedule (eps from 1e-2 of the targets' violation,
  /// times 10) made no progress, and the refits alone no longer do. On the double torus
  /// (136 quads, 5.4 % linear) the level crept from 0.23 % to 0.185 % over 20 iterations;
  /// with 3 intermediate eps it reaches 0.1 % in 9. Levels whose schedules progress, or
  /// whose refits still flatten, are unaffected: intermediate attempts cost ADMM
  /// iterations (from the first kept targets on, 2-4.5x on the Enneper hexagons, which
  /// ended above the bound either way then; with the 5 % condition 18 % more). 0: never.
  int intermediateAttempts = 3;
  /// The global steps' dual tolerance is 10 times the ADMM's default
  /// (AdmmSettings::dualToleranceScale): their constraints, which make the faces planar,
  /// are met as tightly as before, and only the steps' closeness to the fitted maps, which
  /// the next iteration fits anew, is looser. The ε schedule's small attempts, which crept
  /// towards the tighter tolerance until they stalled, then converge. Measured on the CPU
  /// (README, "Looser optimality in the subdivision loop"): the Enneper hexagons' first
  /// level reaches the 0.1 % bound (0.095 % after 14 iterations, 44 s, where it stopped at
  /// 0.136 % after 20, 125 s); the cube's, dodecahedron's and domes' levels take 16-51 %
  /// fewer ADMM iterations, but one that now makes progress where its first step kept
  /// its targets (2-ring dome, four-point: 6.6x flatter, 39 % more). Deformations keep
  /// the ADMM's own tolerance (their backends' meshes must agree to 1e-6 of the diagonal).
  GlobalStepSettings globalStep = [] {
    GlobalStepSettings s;
    s.qp.dualToleranceScale = 10.0;
    return s;
  }();
  /// Memory the levels may take (bytes; 0: what the system has available). Levels whose
  /// finest faces would need more, by a measured lower bound per face, are refused with
  /// Error(Numerical) before any is built.
  std::uint64_t memoryLimitBytes = 0;
};

enum class PqSubdivisionStatus {
  Converged,       ///< Every level met both stopping bounds.
  IterationLimit,  ///< Some level stopped at maxIterationsPerLevel (result still usable).
  LinearOnly,      ///< planarize = false: the linear scheme's positions.
};

const char* toString(PqSubdivisionStatus status);

/// One local/global iteration.
struct PqIteration {
  double epsilon = 0.0;          ///< ε of the accepted global step.
  double maxPlanarity = 0.0;     ///< Percent, after the global step.
  double maxChange = 0.0;        ///< Max vertex change relative to the diagonal.
  double constraintResidual = 0.0;  ///< max |C_s A - d| of the global step.
  int admmIterations = 0;
  long linearIterations = 0;     ///< Of the ADMM's solves with K (GlobalStepInfo::linearIterations).
  std::vector<EpsilonAttempt> attempts;  ///< The global step's ε schedule, in order.
  /// Host <-> device copies of the iteration (compute::Backend::transfers; none on the CPU).
  std::optional<compute::DeviceTransfers> transfers;
};

struct PqLevelInfo {
  int level = 0;
  Index vertices = 0;
  Index faces = 0;
  bool converged = false;
  std::vector<PqIteration> iterations;
  double linearMaxPlanarity = 0.0;  ///< Max planarity (percent) of the linear scheme's targets.
  /// Max distance between a vertex and its linear-scheme target of this level, relative
  /// to the bounding-box diagonal.
  double distanceToLinear = 0.0;
  PlanarityStats planarity;
  double seconds = 0.0;
};

struct PqSubdivisionInfo {
  PqSubdivisionStatus status = PqSubdivisionStatus::Converged;
  std::vector<PqLevelInfo> levels;  ///< Levels 1..n.
  int totalIterations = 0;          ///< Local/global iterations summed over the levels.
  double seconds = 0.0;
};

struct PqSubdivisionResult {
  SubdivisionHierarchy hierarchy;
  std::vector<Positions> positions;  ///< Per level 0..n (#V_l x 3); level 0 is the input.
  PqSubdivisionInfo info;

  /// The finest mesh.
  PolygonMesh finestMesh() const { return {positions.back(), hierarchy.faces(hierarchy.finestLevel())}; }
};

/// Called after every local/global iteration with its level and its number within the
/// level (both 1-based), for progress output; may be empty.
using PqIterationCallback = std::function<void(int level, int iteration, const PqIteration&)>;

/// Subdivide `base` settings.levels times.
///   backend  in: runs the local fits, planarity and the global step's linear solves.
///   base     in: polygon mesh (any face degrees, oriented 2-manifold, with or without
///            boundary); ideally planar-faced, since level 1 starts from its trivial
///            refinement.
///   callback in: called after each local/global iteration (may be empty).
/// Throws Error(Usage) for levels < 0 or non-positive tolerances, Error(BadInput) for a
/// mesh the refinement rejects, Error(Numerical) when a global step fails.
PqSubdivisionResult subdividePlanarQuads(compute::Backend& backend, const PolygonMesh& base,
                                         const PqSubdivisionSettings& settings = {},
                                         const PqIterationCallback& callback = {});

}  // namespace plano::projective
