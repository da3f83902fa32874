#pragma once
// Internal: the data every planarization method starts from. The input is checked,
// centred and divided by the mean face size so that weights are dimensionless; faces
// that carry a planarity constraint (degree >= 4, non-zero size) are listed with their
// size; fixed vertices are taken out of the unknowns.
#include <span>
#include <vector>

#include "planarize/PlanarizeTypes.h"

namespace plano::planarize::detail {

struct Problem {
  const FaceList* faces = nullptr;
  Positions input;  ///< #V x 3, normalized input positions (also the closeness target).
  Positions original;  ///< #V x 3, the input as given (fixed vertices are copied from it exactly).
  Eigen::RowVector3d center = Eigen::RowVector3d::Zero();
  double scale = 1.0;  ///< Original = normalized * scale + center.
  double boundingBoxDiagonal = 0.0;  ///< Of the input, original units.
  /// Faces with a planarity constraint and their mean diagonal (normalized units), the
  /// denominator of the planarity measure: residuals divided by it are relative.
  std::vector<Index> constrainedFaces;
  std::vector<double> faceSize;  ///< One per constrained face.
  std::vector<Index> freeIndex;  ///< Per vertex: its row among the unknowns, or -1 if fixed.
  Index freeCount = 0;
};

/// Validate and normalize. Throws Error(BadInput) for a non-finite coordinate, a face
/// index out of range, a fixed vertex out of range or listed twice, and Error(Usage) for
/// negative weights or tolerance, or a ShapeUp problem without any anchor (zero closeness
/// and no fixed vertex leaves translations free).
Problem makeProblem(const FaceList& faces, const Positions& input, const Settings& settings);

/// Mean diagonal length of a face of degree >= 4 (mean over runs of four corners of the
/// mean of the two diagonals), as in the planarity measure.
double meanDiagonal(const Positions& vertices, std::span<const Index> face);

/// Least-squares plane of a face: unit normal n and centroid c (points x with n.(x - c) = 0).
struct FacePlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
};
FacePlane bestFitPlane(const Positions& vertices, std::span<const Index> face);

/// Normalized to original coordinates and back; toOriginal copies fixed vertices from
/// the original input bit for bit.
Positions toOriginal(const Problem& problem, const Positions& normalized);
Positions toNormalized(const Problem& problem, const Positions& original);

/// The common start of every planarizer's solve: `vertices` (the caller's initial guess)
/// normalized, with the fixed vertices at their input positions whatever the guess says.
Positions startingPoint(const Problem& problem, const Positions& vertices);

/// Max and mean vertex displacement from the input, over the input's bounding-box diagonal.
void measureDisplacement(const Problem& problem, const Positions& normalized, Info& info);

/// The common end of every planarizer's solve: status, displacement, and the normalized
/// iterate mapped back into `vertices`. `seconds` is the total time spent.
void finishSolve(const Problem& problem, const Positions& normalized, bool converged, double seconds, Info& info,
                 Positions& vertices);

}  // namespace plano::planarize::detail
