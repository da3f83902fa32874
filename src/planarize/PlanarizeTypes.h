#pragma once
// Settings and results shared by the planarization methods (ShapeUpPlanarizer,
// GaussNewtonPlanarizer) and the one-call planarize() in Planarize.h.
//
// Conventions of every method:
// - Planarity is the papers' measure (mesh/Planarity.h): distance between the diagonals
//   over the mean diagonal, percent; a face's value is the mean over its runs of four
//   corners. Triangles are planar by definition and carry no constraint.
// - Coordinates are normalized internally (centred, divided by the mean face size), so
//   every weight is dimensionless and results do not change when the mesh is scaled.
// - Displacement is measured from the input positions, relative to the input's
//   bounding-box diagonal.
#include <string>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano::planarize {

enum class Method {
  ShapeUp,      ///< Plain local/global projection (Bouaziz et al. 2012), the field's reference.
  Anderson,     ///< ShapeUp's fixed point with safeguarded Anderson acceleration.
  GaussNewton,  ///< Gauss-Newton on the diagonal-distance constraints, constraint-space solve.
  Guided,       ///< Gauss-Newton on per-face plane unknowns (guided projection), primal solve.
};

/// "shapeup", "anderson", "gauss-newton" or "guided"; throws Error(Usage) otherwise.
Method parseMethod(const std::string& text);
const char* toString(Method method);

struct Settings {
  Method method = Method::GaussNewton;
  /// Stop once the largest face planarity (percent) is at most this.
  double tolerance = 0.1;
  /// Weight w of the closeness term |X - X_input|^2 (per vertex, in units of the mean face
  /// size). ShapeUp, Anderson and guided: a penalty against the planarity term (corner
  /// distances over the face size); larger keeps the mesh closer to the input and leaves
  /// faces less planar at the fixed point. Gauss-Newton: planarity is a constraint, and
  /// each step aims w / (w + damping) of the way back to the input before projecting
  /// onto it; larger tends to the closest planar mesh, 0 to the smallest steps.
  double closeness = 1e-4;
  int maxIterations = 100;
  /// Vertices that keep their input position exactly (0-based).
  std::vector<Index> fixed;
  /// Anderson only: number of previous iterates the extrapolation combines.
  int andersonDepth = 6;
  /// Weight mu of |X - X_previous|^2. Guided: Levenberg-Marquardt damping (least value; it
  /// grows after a rejected step). Gauss-Newton: sets the pull back to the input, above.
  double damping = 1e-4;
  /// Gauss-Newton only: at most this many chord steps per iteration, each reusing the
  /// iteration's factorization (one back-substitution) on the updated residuals.
  int correctorSteps = 3;
};

enum class Status {
  Converged,       ///< Max planarity <= tolerance.
  IterationLimit,  ///< maxIterations done without reaching the tolerance.
  Stalled,         ///< The iterate stopped changing above the tolerance (closeness too strong).
};
const char* toString(Status status);

struct Info {
  Status status = Status::IterationLimit;
  int iterations = 0;
  /// Max and mean face planarity (percent): entry 0 is the input, entry k after iteration k.
  std::vector<double> maxPlanarity;
  std::vector<double> meanPlanarity;
  /// Vertex displacement from the input over the bounding-box diagonal of the input.
  double maxDisplacement = 0.0;
  double meanDisplacement = 0.0;
  /// Largest relative residual of the global step's linear solves.
  double linearResidual = 0.0;
  /// Steps the safeguard rejected: Anderson extrapolations that raised the energy (the
  /// plain step was taken instead), Gauss-Newton and guided steps retried from the same iterate.
  int rejectedSteps = 0;
  /// Gauss-Newton only: chord steps taken (back-substitutions with an iteration's factor).
  int correctorSteps = 0;
  double seconds = 0.0;  ///< Wall time of precompute + solve.
};

}  // namespace plano::planarize
