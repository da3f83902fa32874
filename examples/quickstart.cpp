// Plano from C++: subdivide a cube into planar quads (projective-maps paper, §5), pull one
// corner of the result up while its bottom stays (§6.1), and count the degrees of freedom
// of the deformed mesh's affine space (linear-spaces paper, §2).
//
// Built with the project (target plano_quickstart) and, once Plano is installed, by any
// CMake project with
//   find_package(Plano REQUIRED)
//   target_link_libraries(app PRIVATE Plano::plano)
//
// Usage: plano_quickstart [OUT.obj]   (default quickstart.obj)
#include <iostream>
#include <string>
#include <vector>

#include "compute/Backend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "projective/Deformation.h"
#include "projective/PqSubdivision.h"
#include "subspace/LinearSpace.h"

int main(int argc, char** argv) {
  using namespace plano;
  const std::string output = argc > 1 ? argv[1] : "quickstart.obj";
  try {
    // Auto: Vulkan on a real GPU, else the CPU reference (the warning says why).
    std::string warnings;
    const auto backend = compute::createBackend(compute::BackendChoice::Auto, &warnings);
    std::cerr << warnings;

    // Two Catmull-Clark-like levels whose faces stay planar: 6 -> 96 quads.
    projective::PqSubdivisionSettings subdivision;
    subdivision.levels = 2;
    const projective::PqSubdivisionResult subdivided =
        projective::subdividePlanarQuads(*backend, generate::cube(), subdivision);
    const PolygonMesh mesh = subdivided.finestMesh();
    std::cout << "subdivided: " << mesh.faceCount() << " faces, max planarity " << planarityStats(mesh).max
              << " % after " << subdivided.info.totalIterations << " local/global iterations\n";

    // Fix the bottom vertices, lift the highest vertex of the x = y = max corner.
    const double bottom = mesh.vertices.col(2).minCoeff();
    PositionalConstraints constraints;
    Index corner = 0;
    for (Index v = 0; v < mesh.vertexCount(); ++v) {
      if (mesh.vertices(v, 2) < bottom + 1e-9) constraints.fixed.push_back(v);
      if (mesh.vertices.row(v).sum() > mesh.vertices.row(corner).sum()) corner = v;
    }
    constraints.handles.push_back({corner, mesh.vertices.row(corner).transpose() + Eigen::Vector3d(0.0, 0.0, 0.3)});
    const projective::DeformationResult deformed = projective::deform(*backend, mesh, constraints);
    std::cout << "deformed (" << projective::toString(deformed.info.status) << "): max planarity "
              << deformed.info.planarity.max << " %, handle off by " << deformed.info.maxConstraintError << "\n";

    // The meshes whose every face is an affine image of the deformed one's: null(B).
    const std::vector<subspace::FaceSpace> affine(deformed.mesh.faceCount(), subspace::FaceSpace::Affine);
    const subspace::LinearSpace space = subspace::buildLinearSpace(deformed.mesh, affine);
    std::cout << "affine space: dimension " << space.dof.dimension << " (lower bound " << space.dof.lowerBound
              << ")\n";

    writeMesh(output, deformed.mesh);
    std::cout << "wrote " << output << "\n";
    return deformed.info.status == projective::DeformationStatus::Converged ? 0 : exitCode(ErrorKind::Numerical);
  } catch (const Error& e) {
    std::cerr << "quickstart: " << e.what() << "\n";
    return exitCode(e.kind());
  }
}
