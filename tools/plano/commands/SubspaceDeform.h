#pragma once
// `plano deform --space S`: handle-based ASAP/ARAP deformation inside a linear space of
// polyhedral meshes (linear-spaces paper, §3, Fig. 8). The deform command parses its
// options into a request and calls runSubspaceDeform.
#include <string>

#include "plano/Command.h"
#include "plano/LinearSpaceOptions.h"

namespace plano::cli {

struct SubspaceDeformRequest {
  std::string mesh;              ///< Input polyhedral mesh.
  std::string constraints;       ///< Constraints JSON (mesh/Constraints.h).
  LinearSpaceOptions linearSpace;  ///< --space, --faces-file, --up.
  std::string energy = "asap";   ///< asap | arap
  std::string output;            ///< Output mesh.
  std::string report;            ///< JSON report path (optional).
  bool keepPartial = false;      ///< Write the last iterate even when the iteration cap was hit.
  int maxIterations = 100;
  double tolerance = 1e-8;       ///< Relative energy decrease that stops the iteration.
};

/// Run the deformation and write the output (and report). Returns the exit code; throws
/// plano::Error for bad input (mesh, constraints, space) or a numerical failure (the
/// iteration cap reached before the energy settled, a failed factorization, NaN).
int runSubspaceDeform(const SubspaceDeformRequest& request, const GlobalOptions& global);

}  // namespace plano::cli
