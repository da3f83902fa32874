// Every batched kernel of the Vulkan backend against the CPU reference on the shared real
// architectural meshes (../shared/data; skipped without it): planarity, projective fits,
// closest rotations and ideal maps, SpMV and PCG on a mesh matrix, and the reduced operator
// of a linear space. Real meshes bring what generated ones lack: faces of mixed degree and
// size, files' rounding, far-from-planar faces (the dome, hypar), boundaries and genus.
#include <gtest/gtest.h>

#include <cctype>
#include <string>

#include "compute/KernelComparisons.h"
#include "compute/MeshMatrices.h"
#include "compute/ReducedOperator.h"
#include "compute/VulkanFixture.h"
#include "compute/cpu/CpuBackend.h"
#include "compute/vulkan/VulkanLinearAlgebra.h"
#include "compute/vulkan/VulkanSequence.h"
#include "mesh/MeshIO.h"
#include "projective/LocalStep.h"
#include "projective/ProjectiveTestHelpers.h"
#include "projective/ShapeSpace.h"
#include "subspace/LinearSpace.h"
#include "subspace/MeshLaplacian.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

class VulkanSharedMesh : public VulkanTest, public ::testing::WithParamInterface<std::string> {
 protected:
  PolygonMesh mesh_;
};

/// Reads the parameter's mesh into `mesh_`, or skips the test without ../shared/data.
#define PLANO_LOAD_SHARED_MESH()                  \
  PLANO_REQUIRE_SHARED_MESH(meshPath, GetParam()); \
  mesh_ = readMesh(meshPath)

/// Mean over the faces of their bounding-box diagonal: the scale of a local step's motion
/// of a face (real meshes' faces span a few thousandths of the mesh's diagonal).
double meanFaceSize(const FaceList& faces, const Positions& positions) {
  double sum = 0.0;
  for (Index f = 0; f < faces.size(); ++f) {
    Eigen::RowVector3d low = positions.row(faces[f][0]), high = low;
    for (const Index v : faces[f]) {
      low = low.cwiseMin(positions.row(v));
      high = high.cwiseMax(positions.row(v));
    }
    sum += (high - low).norm();
  }
  return faces.size() > 0 ? sum / static_cast<double>(faces.size()) : 0.0;
}

/// A rotated, scaled copy of `positions` whose vertices then move by up to 5 % of the mean
/// face size: non-planar targets, as a deformation's local step sees them.
Positions movedTarget(const PolygonMesh& mesh, const Positions& positions, unsigned seed) {
  return rotatedScaledAndPerturbed(positions, 1.2, 0.05 * meanFaceSize(mesh.faces, positions), seed);
}

TEST_P(VulkanSharedMesh, PlanarityIsTheCpus) {
  PLANO_LOAD_SHARED_MESH();
  EXPECT_LT(planarityDifference(backend(), mesh_), 1e-12);
}

TEST_P(VulkanSharedMesh, ProjectiveFitsOfPerspectiveAndNonPlanarTargetsAreTheCpus) {
  PLANO_LOAD_SHARED_MESH();
  // In the shape space's normalized coordinates, as the local step fits them.
  const projective::ShapeSpace space(mesh_);
  const Positions& source = space.basePositions();
  expectFitAgreement(compareFits(backend(), mesh_.faces, source, applyProjectiveMap(source, samplePerspective())));
  // Quads are fitted exactly (four corners, four scales): only the other faces leave
  // residuals. Some fits are ill-conditioned (KernelComparisons.h): measured on lavapipe,
  // condition numbers up to 5e7 (the dome) and map differences up to 1.1e-9 (Spot's control mesh).
  expectConditionedFitAgreement(compareFits(backend(), mesh_.faces, source, movedTarget(mesh_, source, 5)));
}

TEST_P(VulkanSharedMesh, ClosestRotationsAndIdealMapsOfTheFitsAreTheCpus) {
  PLANO_LOAD_SHARED_MESH();
  const projective::ShapeSpace space(mesh_);
  const Positions worldTarget = movedTarget(mesh_, mesh_.vertices, 6);
  compute::CpuBackend cpu;
  const std::vector<Eigen::Matrix4d> fits = projective::fitFaceMaps(cpu, space, worldTarget).fits.maps;
  std::vector<Eigen::Matrix3d> linearParts;
  for (const Eigen::Matrix4d& map : fits) linearParts.push_back(map.topLeftCorner<3, 3>());
  expectRotationAgreement(compareRotations(backend(), linearParts));

  const Positions target = space.normalization().toNormalized(worldTarget);
  for (const bool similar : {false, true}) {
    const IdealComparison c = compareIdealMaps(backend(), mesh_.faces, space.basePositions(), fits, &target, similar);
    EXPECT_LT(c.maps, 1e-10) << "similar " << similar;
    EXPECT_EQ(c.methodMismatches, 0) << "similar " << similar;
    EXPECT_GT(c.largestRotation, 0.1);  // the fits are far from the identity
  }
}

TEST_P(VulkanSharedMesh, SpmvAndPcgOnAMeshMatrixAreTheCpus) {
  PLANO_LOAD_SHARED_MESH();
  const compute::SparseMatrix A = laplacianLikeSpd(mesh_, 0.01);
  const Eigen::MatrixXd X = projective::Normalization::fromBoundingBox(mesh_.vertices).toNormalized(mesh_.vertices);
  vk::DeviceCsrMatrix deviceA(context(), A);
  vk::DeviceVectors x(context(), static_cast<std::uint32_t>(X.rows()), 3, "x");
  vk::DeviceVectors y(context(), static_cast<std::uint32_t>(X.rows()), 3, "y");
  x.upload(X);
  vk::LinearAlgebra algebra(context());
  vk::Sequence s(context());
  s.begin();
  algebra.spmv(s, deviceA, x, y);
  s.end();
  s.run();
  Eigen::MatrixXd Y;
  y.download(Y);
  EXPECT_LT(relativeMaxDifference(Y, A * X), 1e-12);

  compute::LinearSolverSettings settings;
  settings.relativeTolerance = 1e-10;
  Eigen::MatrixXd solution = Eigen::MatrixXd::Zero(X.rows(), 3);
  const compute::LinearSolveInfo info = backend().createSpdSolver(A, settings)->solve(X, solution);
  EXPECT_TRUE(info.converged);
  EXPECT_LE((A * solution - X).norm() / X.norm(), 1.5e-10);
  Eigen::MatrixXd reference;
  compute::CpuBackend().createSpdSolver(A, settings)->solve(X, reference);
  EXPECT_LT((solution - reference).norm() / reference.norm(), 1e-6);  // ||A^-1|| ||r||, A's shift 0.01
}

TEST_P(VulkanSharedMesh, TheReducedOperatorOfTheAffineSpaceIsTheCpus) {
  PLANO_LOAD_SHARED_MESH();
  // The dome's affine space has ~23k dimensions (minutes on the CPU to build): left out.
  if (mesh_.faceCount() > 5000) GTEST_SKIP() << "affine space too large for a unit test";
  const subspace::LinearSpace space =
      subspace::buildLinearSpace(mesh_, subspace::uniformAssignment(subspace::SpaceKind::Affine, mesh_.faceCount()));
  ASSERT_GT(space.N.dimension(), 0);
  // Spot's quads are far from planar: every vertex is free (8 790 dimensions), a dense
  // product of minutes on lavapipe.
  if (space.N.columns().cols() > 1000) GTEST_SKIP() << "a basis of " << space.N.columns().cols() << " columns";
  const compute::SparseMatrix L = subspace::uniformLaplacian(mesh_.faces, mesh_.vertexCount());
  const int coordinates = space.N.separable() ? 1 : 3;
  EXPECT_LT(relativeMaxDifference(space.N.compactReducedOperator(backend(), L),
                                  compute::reducedOperatorReference(L, space.N.columns(), coordinates)),
            1e-12);
}

INSTANTIATE_TEST_SUITE_P(Files, VulkanSharedMesh,
                         ::testing::Values("yas_island.off", "gitter.off", "enneper_hex.off",
                                           "dome_polyhedral_pattern.off", "double_torus_quads.off", "hypar.obj",
                                           "spot_quad.obj", "spot_control.obj"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           // yas_island.off -> YasIsland
                           std::string name;
                           bool upper = true;
                           for (const char c : info.param.substr(0, info.param.find('.'))) {
                             if (c == '_') {
                               upper = true;
                             } else {
                               name += upper ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
                               upper = false;
                             }
                           }
                           return name;
                         });

#undef PLANO_LOAD_SHARED_MESH

}  // namespace
}  // namespace plano::test
