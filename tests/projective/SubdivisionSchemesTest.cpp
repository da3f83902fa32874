#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <optional>

#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/Planarity.h"
#include "projective/SubdivisionSchemes.h"
#include "support/TestMeshes.h"

namespace plano::projective {
namespace {

using Row = Eigen::RowVector3d;

/// A regular (n x n)-quad grid with random heights and jittered xy, and an independent
/// tensor-product evaluation of a subdivision step on its (2n + 1)^2 lattice.
class RegularGrid {
 public:
  explicit RegularGrid(Index n) : n_(n), mesh_(generate::hyparGrid(n, 0.3)) {
    mesh_.vertices = test::perturbed(mesh_.vertices, 0.05, 11);
    refinement_ = refineQuads(mesh_.faces, mesh_.vertexCount());
    for (Index e = 0; e < refinement_.coarseEdges.edgeCount(); ++e) edgeIndex_[refinement_.coarseEdges.edges[e]] = e;
  }
  Index n() const { return n_; }
  const PolygonMesh& mesh() const { return mesh_; }
  const QuadRefinement& refinement() const { return refinement_; }
  Row coarse(Index i, Index j) const { return mesh_.vertices.row(i * (n_ + 1) + j); }

  /// Index of the fine vertex at lattice position (I, J), 0 <= I, J <= 2n.
  Index fineVertex(Index I, Index J) const {
    const Index i = I / 2, j = J / 2;
    auto vertex = [&](Index a, Index b) { return a * (n_ + 1) + b; };
    if (I % 2 == 0 && J % 2 == 0) return vertex(i, j);
    if (I % 2 == 1 && J % 2 == 1) return refinement_.facePoint(i * n_ + j);
    const Index a = vertex(i, j);
    const Index b = I % 2 == 1 ? vertex(i + 1, j) : vertex(i, j + 1);
    return refinement_.edgePoint(edgeIndex_.at({std::min(a, b), std::max(a, b)}));
  }

 private:
  Index n_;
  PolygonMesh mesh_;
  QuadRefinement refinement_;
  std::map<std::array<Index, 2>, Index> edgeIndex_;
};

/// One step of a univariate stationary scheme on an infinite sequence, at fine index I
/// (0 <= I <= 2n), from the coarse values c(i); -1 where the stencil leaves [0, n].
using Coarse1D = std::function<Row(Index)>;
std::optional<Row> bspline1D(const Coarse1D& c, Index I, Index n) {
  const Index i = I / 2;
  if (I % 2 == 1) return 0.5 * (c(i) + c(i + 1));
  if (i < 1 || i > n - 1) return std::nullopt;
  return (c(i - 1) + 6.0 * c(i) + c(i + 1)) / 8.0;
}
std::optional<Row> fourPoint1D(const Coarse1D& c, Index I, Index n) {
  const Index i = I / 2;
  if (I % 2 == 0) return c(i);
  if (i < 1 || i + 2 > n) return std::nullopt;
  return (-c(i - 1) + 9.0 * c(i) + 9.0 * c(i + 1) - c(i + 2)) / 16.0;
}

/// Tensor product of a univariate rule: first along j (for each coarse i), then along i.
std::optional<Row> tensor(const RegularGrid& grid, Index I, Index J,
                          const std::function<std::optional<Row>(const Coarse1D&, Index, Index)>& rule) {
  const Index n = grid.n();
  bool inside = true;
  const Coarse1D column = [&](Index i) -> Row {
    const auto value = rule([&](Index j) { return grid.coarse(i, j); }, J, n);
    if (!value) inside = false;
    return value.value_or(Row::Zero());
  };
  const auto result = rule(column, I, n);
  if (!result || !inside) return std::nullopt;
  return result;
}

TEST(SubdivisionSchemes, CatmullClarkOnARegularGridIsTheUniformCubicBSpline) {
  const RegularGrid grid(6);
  const Positions fine = linearSubdivision(SubdivisionScheme::CatmullClark, grid.mesh().faces, grid.mesh().vertices,
                                           grid.refinement());
  Index compared = 0;
  for (Index I = 0; I <= 12; ++I) {
    for (Index J = 0; J <= 12; ++J) {
      const auto expected = tensor(grid, I, J, bspline1D);
      if (!expected) continue;
      ++compared;
      EXPECT_LT((fine.row(grid.fineVertex(I, J)) - *expected).norm(), 1e-14) << "lattice (" << I << ", " << J << ")";
    }
  }
  EXPECT_EQ(compared, 11 * 11);  // every fine vertex off the boundary
}

TEST(SubdivisionSchemes, CatmullClarkBoundaryIsTheCubicBSplineCurveWithCornersKept) {
  const RegularGrid grid(6);
  const Positions fine = linearSubdivision(SubdivisionScheme::CatmullClark, grid.mesh().faces, grid.mesh().vertices,
                                           grid.refinement());
  for (Index J = 0; J <= 12; ++J) {  // boundary row i = 0
    const Coarse1D curve = [&](Index j) { return grid.coarse(0, j); };
    const Row expected = (J == 0 || J == 12) ? curve(J / 2) : *bspline1D(curve, J, 6);
    EXPECT_LT((fine.row(grid.fineVertex(0, J)) - expected).norm(), 1e-14) << "boundary lattice (0, " << J << ")";
  }
}

TEST(SubdivisionSchemes, FourPointOnARegularGridIsKobbeltsTensorProductRule) {
  const RegularGrid grid(7);
  const Positions fine =
      linearSubdivision(SubdivisionScheme::FourPoint, grid.mesh().faces, grid.mesh().vertices, grid.refinement());
  Index compared = 0;
  for (Index I = 0; I <= 14; ++I) {
    for (Index J = 0; J <= 14; ++J) {
      const auto expected = tensor(grid, I, J, fourPoint1D);
      if (!expected) continue;
      ++compared;
      EXPECT_LT((fine.row(grid.fineVertex(I, J)) - *expected).norm(), 1e-14) << "lattice (" << I << ", " << J << ")";
    }
  }
  EXPECT_GT(compared, 100);
}

TEST(SubdivisionSchemes, FourPointInterpolatesTheCoarseVertices) {
  for (const PolygonMesh& mesh : {generate::cube(2.0), generate::hyparGrid(5), generate::surfaceOfRevolution(7, 3),
                                  generate::dodecahedron(), generate::hexagonalDome(2)}) {
    const QuadRefinement r = refineQuads(mesh.faces, mesh.vertexCount());
    const Positions fine = linearSubdivision(SubdivisionScheme::FourPoint, mesh.faces, mesh.vertices, r);
    EXPECT_EQ(fine.topRows(mesh.vertexCount()), mesh.vertices);
    EXPECT_TRUE(fine.allFinite());
  }
}

TEST(SubdivisionSchemes, BothSchemesReproduceAnAffineGridIncludingItsBoundary) {
  // Affine image of the unit grid: every fine vertex must be the affine image of its
  // lattice parameter, boundary and corners included (linear precision).
  PolygonMesh mesh = generate::hyparGrid(4, 0.0);
  Eigen::Matrix3d A;
  A << 1.0, 0.3, 0.1, -0.2, 0.8, 0.5, 0.4, 0.1, 0.9;
  const Eigen::RowVector3d t(0.3, -1.0, 2.0);
  mesh.vertices = (mesh.vertices * A.transpose()).rowwise() + t;
  const QuadRefinement r = refineQuads(mesh.faces, mesh.vertexCount());
  const Positions trivial = trivialRefinementPositions(r, mesh.faces, mesh.vertices);
  for (const auto scheme : {SubdivisionScheme::CatmullClark, SubdivisionScheme::FourPoint}) {
    const Positions fine = linearSubdivision(scheme, mesh.faces, mesh.vertices, r);
    EXPECT_LT(test::maxAbsDifference(fine, trivial), 1e-14) << toString(scheme);
  }
}

TEST(SubdivisionSchemes, CatmullClarkOfTheCubeMatchesTheKnownExtraordinaryMasks) {
  const PolygonMesh cube = generate::cube(2.0);  // corners at (+-1, +-1, +-1)
  const QuadRefinement r = refineQuads(cube.faces, cube.vertexCount());
  const Positions fine = linearSubdivision(SubdivisionScheme::CatmullClark, cube.faces, cube.vertices, r);
  for (Index v = 0; v < 8; ++v) {
    EXPECT_LT((fine.row(v) - 5.0 / 9.0 * cube.vertices.row(v)).norm(), 1e-15) << "corner " << v;
  }
  for (Index e = 0; e < 12; ++e) {
    // (a + b + F1 + F2) / 4: two coordinates at 3/4, the one along the edge at 0.
    const Eigen::RowVector3d p = fine.row(r.edgePoint(e)).cwiseAbs();
    EXPECT_NEAR(p.sum(), 1.5, 1e-15);
    EXPECT_NEAR(p.maxCoeff(), 0.75, 1e-15);
  }
  for (Index f = 0; f < 6; ++f) EXPECT_NEAR(fine.row(r.facePoint(f)).norm(), 1.0, 1e-15);
}

TEST(SubdivisionSchemes, CatmullClarkPlanarityOfTheCubeMatchesTheReferenceFigures) {
  // Reference: 4.43 %, 1.44 %, 0.51 % max planarity at levels 1-3 (projective notes).
  PolygonMesh mesh = generate::cube(1.0);
  const double expected[] = {4.43, 1.44, 0.51};
  for (const double reference : expected) {
    const QuadRefinement r = refineQuads(mesh.faces, mesh.vertexCount());
    mesh.vertices = linearSubdivision(SubdivisionScheme::CatmullClark, mesh.faces, mesh.vertices, r);
    mesh.faces = r.fineFaces;
    EXPECT_NEAR(planarityStats(mesh).max, reference, 0.006);
  }
}

TEST(SubdivisionSchemes, FourPointRoundsTheCubeSymmetrically) {
  const PolygonMesh cube = generate::cube(2.0);
  const QuadRefinement r = refineQuads(cube.faces, cube.vertexCount());
  const Positions fine = linearSubdivision(SubdivisionScheme::FourPoint, cube.faces, cube.vertices, r);
  // Valence-3 ghosts (isotropic rule) push the edge points out of the cube, symmetrically.
  const double edgeNorm = fine.row(r.edgePoint(0)).norm();
  EXPECT_GT(edgeNorm, std::sqrt(2.0) + 0.05);
  for (Index e = 1; e < 12; ++e) EXPECT_NEAR(fine.row(r.edgePoint(e)).norm(), edgeNorm, 1e-14);
  const double faceNorm = fine.row(r.facePoint(0)).norm();
  EXPECT_GT(faceNorm, 1.0);
  for (Index f = 1; f < 6; ++f) EXPECT_NEAR(fine.row(r.facePoint(f)).norm(), faceNorm, 1e-14);
}

TEST(SubdivisionSchemes, OpenBoxUsesBoundaryCurveRulesOnItsRim) {
  // Cube without its top face (z = +1): the rim is a closed boundary curve of four vertices
  // with two faces each.
  PolygonMesh box = generate::cube(2.0);
  std::vector<std::vector<Index>> faces;
  for (Index f = 0; f < box.faceCount(); ++f) {
    const auto face = box.faces[f];
    bool top = true;
    for (const Index v : face) top = top && box.vertices(v, 2) > 0.0;
    if (!top) faces.emplace_back(face.begin(), face.end());
  }
  box.faces = FaceList(faces);
  ASSERT_EQ(box.faceCount(), 5);
  const QuadRefinement r = refineQuads(box.faces, box.vertexCount());
  const Positions cc = linearSubdivision(SubdivisionScheme::CatmullClark, box.faces, box.vertices, r);
  // Rim vertex (1, 1, 1): neighbours on the rim (-1, 1, 1) and (1, -1, 1).
  for (Index v = 0; v < 8; ++v) {
    if (box.vertices(v, 2) < 0.0) continue;
    const Eigen::RowVector3d p = box.vertices.row(v);
    const Eigen::RowVector3d expected(0.75 * p.x(), 0.75 * p.y(), 1.0);
    EXPECT_LT((cc.row(v) - expected).norm(), 1e-15) << "rim vertex " << v;
  }
  const Positions fp = linearSubdivision(SubdivisionScheme::FourPoint, box.faces, box.vertices, r);
  EXPECT_EQ(fp.topRows(8), box.vertices);
  EXPECT_TRUE(fp.allFinite());
  // Rim edge points: the closed four-point curve through a square bulges out by 1/4.
  for (Index e = 0; e < r.coarseEdges.edgeCount(); ++e) {
    if (!r.coarseEdges.isBoundary(e)) continue;
    EXPECT_NEAR(fp.row(r.edgePoint(e)).head<2>().cwiseAbs().maxCoeff(), 1.25, 1e-15);
    EXPECT_NEAR(fp(r.edgePoint(e), 2), 1.0, 1e-15);
  }
}

TEST(SubdivisionSchemes, ParsesSchemeNamesAndRejectsOthers) {
  EXPECT_EQ(parseSubdivisionScheme("catmull-clark"), SubdivisionScheme::CatmullClark);
  EXPECT_EQ(parseSubdivisionScheme("four-point"), SubdivisionScheme::FourPoint);
  EXPECT_THROW(parseSubdivisionScheme("loop"), Error);
  const PolygonMesh cube = generate::cube();
  const QuadRefinement r = refineQuads(cube.faces, cube.vertexCount());
  const Positions tooFew = cube.vertices.topRows(4);
  EXPECT_THROW(linearSubdivision(SubdivisionScheme::CatmullClark, cube.faces, tooFew, r), Error);
}

}  // namespace
}  // namespace plano::projective
