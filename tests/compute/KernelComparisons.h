#pragma once
// How far a backend's batched per-face kernels are from the CPU reference on one input:
// the comparisons every kernel test (generated, random and the shared real meshes) makes.
#include <vector>

#include "compute/Backend.h"
#include "mesh/PolygonMesh.h"

namespace plano::test {

/// Largest |backend - cpu| / max(|cpu|, 1) of the per-face planarity; planarity is in
/// percent, so the floor of 1 makes exactly planar faces (values at rounding level) compare
/// absolutely.
double planarityDifference(compute::Backend& backend, const PolygonMesh& mesh);

struct FitComparison {
  double maps = 0.0;       ///< Largest |difference| / max(1, |entry|) over map entries.
  /// The same with each face's difference divided by max(1, kappa / 1e3), kappa the 2-norm
  /// condition number of its CPU map. A backward-stable fit errs by about its problem's
  /// condition number times the rounding unit: real meshes have faces whose fits reach
  /// kappa ~ 1e7 (a non-planar quad moved off its projective images), which no two fits
  /// agree on to 1e-10. kappa only estimates the fit's own conditioning (small faces
  /// worsen it too): faces up to kappa = 1e3 are held to 1e-10, worse-conditioned ones in
  /// proportion. Measured on the shared meshes (lavapipe, 2026-12-05): largest raw
  /// difference 1.1e-9 (Spot's control mesh, kappa 4e6), largest ratio 9e-11 (the dome).
  double conditionedMaps = 0.0;
  double largestCondition = 0.0;  ///< Largest kappa of the CPU maps.
  double scales = 0.0;     ///< Same for the reciprocal scales.
  double residuals = 0.0;  ///< Largest absolute difference of RMS residuals.
  int rankMismatches = 0;
  Index faces = 0;
  double largestResidual = 0.0;  ///< Of the CPU fits (to know an example is not trivial).
};
FitComparison compareFits(compute::Backend& backend, const FaceList& faces, const Positions& source,
                          const Positions& target);
/// Maps, reciprocal scales and residuals to 1e-10, the same ranks.
void expectFitAgreement(const FitComparison& c);
/// The same with the maps held to 1e-10 relative to their conditioning (conditionedMaps).
void expectConditionedFitAgreement(const FitComparison& c);

struct RotationComparison {
  double rotations = 0.0;
  double singularValues = 0.0;  ///< Relative to the largest singular value of the matrix.
  double orthogonality = 0.0;   ///< Largest |R^T R - I| of the backend's results.
  double determinant = 0.0;     ///< Largest |det R - 1|.
};
RotationComparison compareRotations(compute::Backend& backend, const std::vector<Eigen::Matrix3d>& matrices);
/// Rotations and singular values to 1e-10, proper rotations to 1e-12.
void expectRotationAgreement(const RotationComparison& c);

struct IdealComparison {
  double maps = 0.0;           ///< Largest |difference| / max(1, |entry|) over map entries.
  int methodMismatches = 0;
  Index fallbacks = 0;         ///< CPU faces with the corner-set Procrustes.
  double largestRotation = 0.0;  ///< max |R - I| of the CPU maps' linear parts (a non-trivial example).
};
IdealComparison compareIdealMaps(compute::Backend& backend, const FaceList& faces, const Positions& source,
                                 const std::vector<Eigen::Matrix4d>& fitted, const Positions* target, bool similar);

}  // namespace plano::test
