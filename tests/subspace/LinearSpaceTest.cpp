// Constraint matrix, degrees of freedom and null-space basis (linear-spaces paper, §2, §4).
#include <gtest/gtest.h>

#include "core/Error.h"
#include "mesh/MeshIO.h"
#include "subspace/SubspaceTopology.h"
#include "support/TestMeshes.h"
#include "subspace/SubspaceTestSupport.h"

namespace plano::subspace {
namespace {

using test::maxPlanarity;
using test::randomCoefficients;

struct NamedMesh {
  const char* name;
  PolygonMesh mesh;
};

std::vector<NamedMesh> meshFamilies() {
  return {{"quads", generate::translationalSurface(5, 4)},
          {"pentagons", generate::dodecahedron()},
          {"hexagons", generate::hexagonalDome(2)},
          {"revolution", generate::surfaceOfRevolution(8, 4)}};
}

std::vector<FaceSpace> randomMixedAssignment(Index faces, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, 2);
  std::vector<FaceSpace> spaces(static_cast<std::size_t>(faces));
  for (auto& s : spaces) s = static_cast<FaceSpace>(pick(rng));
  return spaces;
}

/// Theorem 1/2: a X + b Z stays polyhedral for members X, Z of the space.
void expectCombinationsPolyhedral(const PolygonMesh& mesh, std::span<const FaceSpace> spaces, const char* what) {
  const LinearSpace space = buildLinearSpace(mesh, spaces);
  ASSERT_GT(space.N.dimension(), 0) << what;
  const Positions base = space.N.project(mesh.vertices);
  const double scale = boundingBoxDiagonal(mesh.vertices);
  const Positions X = base + 0.3 * scale * space.N.shape(randomCoefficients(space.N.dimension(), 1));
  const Positions Z = base + 0.3 * scale * space.N.shape(randomCoefficients(space.N.dimension(), 2));
  for (const auto& [a, b] : std::vector<std::pair<double, double>>{{1, 0}, {0, 1}, {0.5, 0.5}, {2.0, -0.7}, {-0.4, 1.3}}) {
    const Positions C = a * X + b * Z;
    EXPECT_LE(maxPlanarity(mesh, C), 1e-9) << what << " a=" << a << " b=" << b;
    EXPECT_LE(space.B.residual(C), 1e-9 * C.norm()) << what;
  }
}

TEST(LinearSpace, CombinationsOfMembersArePolyhedralInEverySpace) {
  for (const auto& [name, mesh] : meshFamilies()) {
    for (SpaceKind kind : {SpaceKind::Affine, SpaceKind::Parallel, SpaceKind::Vertical}) {
      const auto spaces = uniformAssignment(kind, mesh.faceCount());
      expectCombinationsPolyhedral(mesh, spaces, (std::string(name) + " " + toString(kind)).c_str());
    }
  }
}

TEST(LinearSpace, CombinationsOfMembersArePolyhedralInMixedSpaces) {
  unsigned seed = 11;
  for (const auto& [name, mesh] : meshFamilies()) {
    const auto spaces = randomMixedAssignment(mesh.faceCount(), seed++);
    expectCombinationsPolyhedral(mesh, spaces, name);
  }
}

TEST(LinearSpace, SourceMeshLiesInItsOwnSpaces) {
  const PolygonMesh mesh = generate::hexagonalDome(2);
  for (SpaceKind kind : {SpaceKind::Affine, SpaceKind::Parallel, SpaceKind::Vertical}) {
    const auto spaces = uniformAssignment(kind, mesh.faceCount());
    const ConstraintMatrix B = buildConstraintMatrix(mesh, spaces);
    EXPECT_LE(B.residual(mesh.vertices), 1e-12 * mesh.vertices.norm()) << toString(kind);
  }
}

TEST(LinearSpace, DodecahedronAffineSpaceHasDimensionTwelve) {
  const PolygonMesh mesh = generate::dodecahedron();
  const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(SpaceKind::Affine, mesh.faceCount()));
  EXPECT_TRUE(space.B.separable);
  EXPECT_EQ(space.N.dimension(), 12);
  EXPECT_LE(space.basisInfo.residual, 1e-12);
}

TEST(LinearSpace, ParallelSpaceOfClosedThreeRegularMeshIsFacePlaneOffsets) {
  const PolygonMesh cube = generate::cube();
  EXPECT_EQ(buildLinearSpace(cube, uniformAssignment(SpaceKind::Parallel, 6)).N.dimension(), 6);
  const PolygonMesh dodecahedron = generate::dodecahedron();
  EXPECT_EQ(buildLinearSpace(dodecahedron, uniformAssignment(SpaceKind::Parallel, 12)).N.dimension(), 12);
}

TEST(LinearSpace, ClosedQuadMeshInGeneralPositionHasOnlyGlobalAffineMotions) {
  const PolygonMesh hexahedron = test::projectiveImage(generate::cube());
  const LinearSpace space = buildLinearSpace(hexahedron, uniformAssignment(SpaceKind::Affine, 6));
  EXPECT_EQ(space.N.dimension(), 12);
  // The twelve motions are exactly X = A Y + t: the basis spans the same space as the
  // columns of (Y, 1) (x) I_3.
  Eigen::MatrixXd affine(hexahedron.vertexCount(), 4);
  affine << hexahedron.vertices, Eigen::VectorXd::Ones(hexahedron.vertexCount());
  const Eigen::MatrixXd& N1 = space.N.columns();
  EXPECT_LE((affine - N1 * (N1.transpose() * affine)).norm(), 1e-9);
}

TEST(LinearSpace, AffineSpaceOfARealClosedMeshContainsTheGlobalAffineMotions) {
  // The genus-2 polycube has large flat regions tiled by several quads, so it is not in
  // general position: it has more than the twelve global motions, never fewer.
  PLANO_REQUIRE_SHARED_MESH(path, "double_torus_quads.off");
  const PolygonMesh mesh = test::projectiveImage(readMesh(path));
  const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(SpaceKind::Affine, mesh.faceCount()));
  EXPECT_GE(space.N.dimension(), 12);
  EXPECT_GE(space.dof.dimension, space.dof.lowerBound);
  Eigen::MatrixXd affine(mesh.vertexCount(), 4);
  affine << mesh.vertices, Eigen::VectorXd::Ones(mesh.vertexCount());
  const Eigen::MatrixXd& N1 = space.N.columns();
  EXPECT_LE((affine - N1 * (N1.transpose() * affine)).norm(), 1e-9 * affine.norm());
}

TEST(LinearSpace, FullMatrixOfASeparableSpaceActsOnEveryCoordinateAsItsOneCoordinateMatrix) {
  for (const NamedMesh& family : meshFamilies()) {
    SCOPED_TRACE(family.name);
    const ConstraintMatrix B = buildConstraintMatrix(family.mesh, uniformAssignment(SpaceKind::Affine, family.mesh.faceCount()));
    ASSERT_TRUE(B.separable);
    const compute::SparseMatrix full = B.fullMatrix();
    ASSERT_EQ(full.rows(), 3 * B.matrix.rows());
    ASSERT_EQ(full.cols(), 3 * B.matrix.cols());
    EXPECT_EQ(full.nonZeros(), 3 * B.matrix.nonZeros());
    const Positions X = Positions::Random(family.mesh.vertexCount(), 3);
    const Eigen::Map<const Eigen::VectorXd> x(X.data(), X.size());  // (x0, y0, z0, x1, ...)
    const Eigen::VectorXd product = full * x;
    const Eigen::MatrixXd perCoordinate = B.matrix * X;
    for (Eigen::Index r = 0; r < B.matrix.rows(); ++r)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(product[3 * r + c], perCoordinate(r, c), 1e-12);
  }
}

TEST(LinearSpace, ProductWithTheRowsOfSomeVerticesIsTheProductWithTheirCoordinateRowsWrittenOut) {
  const SubspaceBasis separable(Eigen::MatrixXd::Random(7, 4), true);
  const SubspaceBasis full(Eigen::MatrixXd::Random(21, 5), false);
  const std::vector<Index> vertices = {6, 1, 4, 1};  // Out of order and repeated.
  std::vector<Index> coordinates;
  for (Index v : vertices)
    for (int c = 0; c < 3; ++c) coordinates.push_back(3 * v + c);
  const Eigen::MatrixXd M = Eigen::MatrixXd::Random(3, static_cast<Eigen::Index>(coordinates.size()));
  for (const SubspaceBasis* basis : {&separable, &full}) {
    const Eigen::MatrixXd expected = M * basis->coordinateRows(coordinates);
    const Eigen::MatrixXd product = basis->timesVertexRows(M, basis->storedRows(vertices));
    ASSERT_EQ(product.rows(), expected.rows());
    ASSERT_EQ(product.cols(), basis->dimension());
    EXPECT_LE((product - expected).cwiseAbs().maxCoeff(), 1e-14);
  }
}

TEST(LinearSpace, DimensionIsNeverBelowTheLowerBound) {
  for (const auto& [name, mesh] : meshFamilies()) {
    for (SpaceKind kind : {SpaceKind::Affine, SpaceKind::Parallel, SpaceKind::Vertical}) {
      const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(kind, mesh.faceCount()));
      EXPECT_GE(space.dof.dimension, space.dof.lowerBound) << name << " " << toString(kind);
      EXPECT_DOUBLE_EQ(space.dof.freeVertices, space.dof.dimension / 3.0);
    }
  }
}

TEST(LinearSpace, LowerBoundsMatchThePaperFormulas) {
  const PolygonMesh mesh = generate::hexagonalDome(2);
  const Index nv = mesh.vertexCount(), nf = mesh.faceCount(), nc = mesh.faces.cornerCount();
  auto bound = [&](SpaceKind kind) {
    return subspaceLowerBound(mesh.faces, nv, uniformAssignment(kind, nf));
  };
  EXPECT_EQ(bound(SpaceKind::Affine), 3 * (nv + 3 * nf - nc));
  EXPECT_EQ(bound(SpaceKind::Parallel), 3 * nv - nc + nf);
  EXPECT_EQ(bound(SpaceKind::Vertical), 3 * nv - 2 * (nc - 2 * nf));
}

TEST(LinearSpace, SparseQrAndDenseSvdAgreeOnTheDimension) {
  const PolygonMesh mesh = generate::translationalSurface(6, 5);
  for (SpaceKind kind : {SpaceKind::Affine, SpaceKind::Parallel, SpaceKind::Vertical}) {
    LinearSpaceSettings dense, sparse;
    dense.basis.method = BasisMethod::DenseSvd;
    sparse.basis.method = BasisMethod::SparseQr;
    const auto spaces = uniformAssignment(kind, mesh.faceCount());
    const LinearSpace a = buildLinearSpace(mesh, spaces, dense);
    const LinearSpace b = buildLinearSpace(mesh, spaces, sparse);
    EXPECT_EQ(a.N.dimension(), b.N.dimension()) << toString(kind);
    EXPECT_LE(b.basisInfo.residual, 1e-10) << toString(kind);
    EXPECT_LE(b.N.orthogonalityError(), 1e-10) << toString(kind);
  }
}

TEST(LinearSpace, ABasisLargerThanItsMemoryLimitIsRefusedNamingItsSize) {
  // A surface of revolution's parallel space: 3 #V unknowns, dimension 41 above its
  // topological lower bound 36, in a basis and a selector of 8 bytes an entry. Under a
  // limit below the bound's columns it is refused before the sparse QR, naming the bound;
  // under one between the two, once the QR has given the dimension; above, built.
  const PolygonMesh mesh = generate::surfaceOfRevolution(12, 6);
  const auto spaces = uniformAssignment(SpaceKind::Parallel, mesh.faceCount());
  LinearSpaceSettings settings;
  settings.basis.method = BasisMethod::SparseQr;
  const LinearSpace space = buildLinearSpace(mesh, spaces, settings);
  const Index unknowns = 3 * mesh.vertexCount();
  const Index dimension = space.N.dimension();
  const Index bound = space.dof.lowerBound;
  ASSERT_LT(bound, dimension);
  ASSERT_GT(bound, 0);
  const auto bytes = [&](Index columns) { return static_cast<std::uint64_t>(2 * unknowns * columns * sizeof(double)); };
  const auto refusal = [&](std::uint64_t limit) {
    settings.basis.memoryLimitBytes = limit;
    try {
      buildLinearSpace(mesh, spaces, settings);
    } catch (const OutOfMemory& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string unknownsText = "out of memory: the null-space basis (" + std::to_string(unknowns) + " unknowns x ";
  std::string message = refusal(bytes(bound) - 1);
  EXPECT_NE(message.find(unknownsText + "at least " + std::to_string(bound) + " dimensions, the topological lower bound"),
            std::string::npos)
      << message;
  message = refusal(bytes(dimension) - 1);
  EXPECT_NE(message.find(unknownsText + std::to_string(dimension) + " dimensions, formed"), std::string::npos) << message;
  settings.basis.memoryLimitBytes = bytes(dimension);
  EXPECT_EQ(buildLinearSpace(mesh, spaces, settings).N.dimension(), dimension);
}

TEST(LinearSpace, HorizontalFacesOfAVerticalSpaceFallBackToParallel) {
  const PolygonMesh cube = generate::cube();
  const ConstraintMatrix B = buildConstraintMatrix(cube, uniformAssignment(SpaceKind::Vertical, 6));
  EXPECT_EQ(B.horizontalFaceCount(), 2);
}

TEST(LinearSpace, DegenerateFaceIsReportedByIndex) {
  PolygonMesh mesh = generate::translationalSurface(2, 2);
  // Collapse face 3 onto a line.
  const auto face = mesh.faces[3];
  for (Index i = 0; i < 4; ++i) mesh.vertices.row(face[i]) = Eigen::RowVector3d(0.1 * i, 0.0, 0.0);
  try {
    buildConstraintMatrix(mesh, uniformAssignment(SpaceKind::Affine, mesh.faceCount()));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("face"), std::string::npos);
  }
}

TEST(SubspaceTopology, CountsOfAnOpenGridAndAClosedCube) {
  const PolygonMesh grid = generate::translationalSurface(3, 2);
  const SubspaceTopology t = computeTopology(grid.faces, grid.vertexCount());
  EXPECT_EQ(t.edgeCount(), 3 * 3 + 4 * 2);
  EXPECT_EQ(t.boundaryLoopCount(), 1);
  EXPECT_EQ(t.boundaryVertices, 10);
  EXPECT_EQ(t.genus, 0);
  const PolygonMesh cube = generate::cube();
  const SubspaceTopology c = computeTopology(cube.faces, 8);
  EXPECT_EQ(c.edgeCount(), 12);
  EXPECT_EQ(c.boundaryLoopCount(), 0);
  EXPECT_EQ(c.genus, 0);
}

}  // namespace
}  // namespace plano::subspace
