#include "SubspaceDeform.h"

#include <chrono>
#include <iostream>

#include "core/Error.h"
#include "mesh/Constraints.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "plano/CommandOutcome.h"
#include "plano/Report.h"
#include "subspace/SubspaceDeformation.h"

namespace plano::cli {

int runSubspaceDeform(const SubspaceDeformRequest& request, const GlobalOptions& global) {
  using namespace plano::subspace;
  const auto start = std::chrono::steady_clock::now();
  if (request.maxIterations < 1) throwUsage("max iterations must be at least 1");
  const PolygonMesh mesh = readMesh(request.mesh);
  std::string warnings;
  const PositionalConstraints constraints = readConstraints(request.constraints, mesh.vertexCount(), &warnings);
  if (!warnings.empty()) std::cerr << warnings;
  if (constraints.empty()) throwBadInput(request.constraints + ": no fixed vertex and no handle");
  const LinearSpace space =
      buildSpaceWithProgress(global, "deform", mesh, request.linearSpace.space,
                             request.linearSpace.assignment(mesh.faceCount()), request.linearSpace.settings());
  auto backend = makeBackend(global);
  SubspaceDeformationSettings settings;
  settings.energy = parseDeformationEnergy(request.energy);
  settings.maxIterations = request.maxIterations;
  settings.tolerance = request.tolerance;
  SubspaceDeformer deformer(space, constraints, *backend, settings);
  Positions X = space.N.project(mesh.vertices);
  const SubspaceDeformationInfo info = deformer.solve(X);
  PolygonMesh out{X, mesh.faces};
  const PlanarityStats stats = planarityStats(out);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json j = baseReport("deform", backend->name(), out, stats, seconds);
  j["space"] = request.linearSpace.space;
  j["energy"] = request.energy;
  j["dimension"] = space.dof.dimension;
  j["free_dimension"] = deformer.freeDimension();
  j["iterations"] = info.iterations;
  j["energy_value"] = info.energy;
  j["constraint_residual"] = info.constraintResidual;
  j["max_handle_distance"] = info.maxHandleDistance;
  j["max_subspace_residual"] = info.maxSubspaceResidual;
  const bool converged = info.status == DeformationStatus::Converged;
  CommandOutcome outcome{converged ? "converged" : "iteration_limit", ""};
  if (!converged) {
    outcome.failure = "the energy did not settle within the cap of " + std::to_string(request.maxIterations) +
                      " iterations";
  }
  finishCommand("deform", outcome, request.keepPartial, {{request.output, &out}}, j, request.report);
  std::cout << "deformed in the " << request.linearSpace.space << " space (dimension " << space.dof.dimension << ") in "
            << info.iterations << " iterations, handle distance " << info.maxHandleDistance << ", max planarity "
            << stats.max << "% -> " << request.output << "\n";
  return 0;
}

}  // namespace plano::cli
