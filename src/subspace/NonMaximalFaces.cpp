#include "subspace/NonMaximalFaces.h"

#include "subspace/FaceConstraintBlocks.h"

namespace plano::subspace {

std::vector<NonMaximalFace> findNonMaximalFaces(const LinearSpace& space, const ConstraintSettings& settings,
                                                double tolerance) {
  std::vector<NonMaximalFace> found;
  const PolygonMesh& mesh = space.source;
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    const Index k = mesh.faces.degree(f);
    if (k == 3) continue;
    const FaceFrame frame = fitFaceFrame(mesh.vertices, mesh.faces[f], f, settings.degeneracy);
    // Gathered once per face: the rows of a column-major N are strided reads.
    const Eigen::MatrixXd rows = space.N.storedRows(mesh.faces[f]);
    const FaceSpace current = space.B.effective[f];
    for (FaceSpace other : {FaceSpace::Affine, FaceSpace::Vertical, FaceSpace::Parallel}) {
      if (other == current) continue;
      if (other == FaceSpace::Vertical && isHorizontal(frame, settings.up, settings.horizontalTolerance)) continue;
      const Eigen::MatrixXd block = faceBlock(frame, other, settings.up);
      const double violation = rows.cols() ? space.N.timesVertexRows(block, rows).cwiseAbs().maxCoeff() : 0.0;
      if (violation <= tolerance) {
        found.push_back({f, current, other});
        break;
      }
    }
  }
  return found;
}

std::vector<FaceSpace> reassignNonMaximalFaces(const PolygonMesh& mesh, std::vector<FaceSpace> spaces,
                                               const ReassignmentSettings& settings, ReassignmentInfo* info) {
  LinearSpace space = buildLinearSpace(mesh, spaces, settings.space);
  ReassignmentInfo local;
  local.dimensionBefore = space.N.dimension();
  for (Index round = 0; round < settings.maxRounds; ++round) {
    const auto faces = findNonMaximalFaces(space, settings.space.constraints, settings.tolerance);
    if (faces.empty()) break;
    std::vector<FaceSpace> candidate = spaces;
    for (const auto& face : faces) candidate[face.face] = face.containedIn;
    LinearSpace next = buildLinearSpace(mesh, candidate, settings.space);
    if (next.N.dimension() <= space.N.dimension()) break;
    spaces = std::move(candidate);
    space = std::move(next);
    local.rounds += 1;
    local.reassignedFaces += static_cast<Index>(faces.size());
  }
  local.dimensionAfter = space.N.dimension();
  if (info) *info = local;
  return spaces;
}

}  // namespace plano::subspace
