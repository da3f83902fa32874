#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <map>

#include "core/Error.h"
#include "mesh/Generators.h"
#include "projective/MultiresHierarchy.h"
#include "projective/SubdivisionSchemes.h"

namespace plano::projective {
namespace {

TEST(MultiresHierarchy, EveryFinestFaceHasOneAncestorPerLevelAndProgenyGrowsByFour) {
  const PolygonMesh cube = generate::cube();
  const SubdivisionHierarchy h(cube.faces, cube.vertexCount(), 3);
  ASSERT_EQ(h.finestLevel(), 3);
  EXPECT_EQ(h.faces(0).size(), 6);
  EXPECT_EQ(h.faces(3).size(), 6 * 64);
  EXPECT_EQ(h.vertexCount(3), 6 * 64 + 2);  // closed quad mesh of genus 0: V = F + 2
  for (int level = 0; level <= 3; ++level) {
    const auto& ancestors = h.ancestorsOfFinestFaces(level);
    ASSERT_EQ(static_cast<Index>(ancestors.size()), h.faces(3).size());
    std::map<Index, Index> progeny;
    for (Index f = 0; f < h.faces(3).size(); ++f) {
      ASSERT_GE(ancestors[f], 0);
      ASSERT_LT(ancestors[f], h.faces(level).size());
      EXPECT_EQ(h.ancestor(3, f, level), ancestors[f]);
      ++progeny[ancestors[f]];
    }
    EXPECT_EQ(static_cast<Index>(progeny.size()), h.faces(level).size()) << "level " << level;
    for (const auto& [face, count] : progeny) EXPECT_EQ(count, 1 << (2 * (3 - level))) << "face " << face;
  }
  // Ancestry is transitive: the ancestor on level 0 of a level-2 face's ancestor on level 1.
  for (Index f = 0; f < h.faces(2).size(); ++f) EXPECT_EQ(h.ancestor(2, f, 0), h.ancestor(1, h.ancestor(2, f, 1), 0));
}

TEST(MultiresHierarchy, ProgenyLiesInsideItsAncestorAndCoarseVerticesKeepTheirIndex) {
  // Trivial refinement of a planar-quad mesh: every descendant is inside the ancestor's
  // plane, and every coarse vertex is the same point on every finer level.
  const PolygonMesh mesh = generate::surfaceOfRevolution(6, 2);
  const SubdivisionHierarchy h(mesh.faces, mesh.vertexCount(), 2);
  std::vector<Positions> levels = {mesh.vertices};
  for (int l = 1; l <= 2; ++l) {
    levels.push_back(trivialRefinementPositions(h.refinement(l), h.faces(l - 1), levels.back()));
  }
  for (Index v = 0; v < h.vertexCount(0); ++v) {
    EXPECT_EQ(levels[2].row(h.fineCounterpart(0, v)), levels[0].row(v));
  }
  const auto& ancestors = h.ancestorsOfFinestFaces(0);
  for (Index f = 0; f < h.faces(2).size(); ++f) {
    const auto coarse = mesh.faces[ancestors[f]];
    const Eigen::Vector3d p0 = mesh.vertices.row(coarse[0]);
    const Eigen::Vector3d normal =
        (Eigen::Vector3d(mesh.vertices.row(coarse[2])) - p0).cross(Eigen::Vector3d(mesh.vertices.row(coarse[1])) - p0)
            .normalized();
    for (const Index v : h.faces(2)[f]) {
      EXPECT_NEAR((Eigen::Vector3d(levels[2].row(v)) - p0).dot(normal), 0.0, 1e-12) << "fine face " << f;
    }
  }
}

TEST(MultiresHierarchy, InterpolatingSchemeKeepsCoarseVerticesOnEveryLevel) {
  const PolygonMesh mesh = generate::hyparGrid(3);
  const SubdivisionHierarchy h(mesh.faces, mesh.vertexCount(), 2);
  Positions x = mesh.vertices;
  for (int l = 1; l <= 2; ++l) x = linearSubdivision(SubdivisionScheme::FourPoint, h.faces(l - 1), x, h.refinement(l));
  for (Index v = 0; v < mesh.vertexCount(); ++v) EXPECT_EQ(x.row(h.fineCounterpart(0, v)), mesh.vertices.row(v));
}

TEST(MultiresHierarchy, RejectsLevelsAndElementsOutsideTheHierarchy) {
  const PolygonMesh cube = generate::cube();
  EXPECT_THROW(SubdivisionHierarchy(cube.faces, cube.vertexCount(), -1), Error);
  const SubdivisionHierarchy h(cube.faces, cube.vertexCount(), 1);
  EXPECT_THROW(h.faces(2), Error);
  EXPECT_THROW(h.refinement(0), Error);
  EXPECT_THROW(h.ancestor(0, 0, 1), Error);
  EXPECT_THROW(h.ancestor(1, 24, 0), Error);
  EXPECT_THROW(h.fineCounterpart(0, 8), Error);
  EXPECT_THROW(SubdivisionHierarchy(FaceList({{0, 1, 2, 7}}), 4, 0), Error);
}

}  // namespace
}  // namespace plano::projective
