#include "mesh/Planarity.h"

#include <gtest/gtest.h>

#include "mesh/Generators.h"

namespace plano {
namespace {

TEST(Planarity, PlanarQuadIsZero) {
  EXPECT_NEAR(quadPlanarity({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}), 0.0, 1e-14);
}

TEST(Planarity, SkewedQuadMatchesHandComputedDiagonalDistance) {
  // Diagonals (0,0,0)-(1,1,0) and (1,0,h)-(0,1,h): parallel planes z = 0 and z = h,
  // so the lines are h apart; both diagonals have length sqrt(2).
  const double h = 0.1;
  const double expected = 100.0 * h / std::sqrt(2.0);
  EXPECT_NEAR(quadPlanarity({0, 0, 0}, {1, 0, h}, {1, 1, 0}, {0, 1, h}), expected, 1e-12);
}

TEST(Planarity, ScaleInvariant) {
  const double a = quadPlanarity({0, 0, 0}, {1, 0, 0.2}, {1, 1, 0}, {0, 1, 0.1});
  const double b = quadPlanarity({0, 0, 0}, {1e3, 0, 200}, {1e3, 1e3, 0}, {0, 1e3, 100});
  EXPECT_NEAR(a, b, 1e-12);
}

TEST(Planarity, HexagonIsMeanOverRunsOfFourCorners) {
  Positions v(6, 3);
  v << 1, 0, 0, 0.5, 0.8, 0.1, -0.5, 0.8, 0, -1, 0, 0.1, -0.5, -0.8, 0, 0.5, -0.8, 0.1;
  const std::vector<Index> face = {0, 1, 2, 3, 4, 5};
  double sum = 0.0, worst = 0.0;
  for (int i = 0; i < 6; ++i) {
    const double q = quadPlanarity(v.row(i).transpose(), v.row((i + 1) % 6).transpose(), v.row((i + 2) % 6).transpose(),
                                   v.row((i + 3) % 6).transpose());
    sum += q;
    worst = std::max(worst, q);
  }
  const FacePlanarity p = facePlanarity(v, face);
  EXPECT_NEAR(p.mean, sum / 6.0, 1e-14);
  EXPECT_NEAR(p.max, worst, 1e-14);
  EXPECT_GT(p.mean, 0.0);
}

TEST(Planarity, TriangleIsPlanar) {
  Positions v(3, 3);
  v << 0, 0, 0, 1, 0, 0, 0, 1, 5;
  const std::vector<Index> face = {0, 1, 2};
  EXPECT_EQ(facePlanarity(v, face).mean, 0.0);
}

TEST(Planarity, StatsCountFacesOverTolerance) {
  const PlanarityStats s = summarizePlanarity({0.0, 0.5, 2.0, 3.0}, 1.0);
  EXPECT_EQ(s.overTolerance, 2);
  EXPECT_DOUBLE_EQ(s.max, 3.0);
  EXPECT_DOUBLE_EQ(s.mean, 1.375);
  EXPECT_DOUBLE_EQ(s.p95, 3.0);
}

TEST(Planarity, PlaneFitResidualIsZeroForPlanarAndPositiveForSkewedFaces) {
  const PolygonMesh flat = generate::translationalSurface(3, 3);
  EXPECT_LT(planarityStats(flat).maxPlaneFitResidual, 1e-12);
  const PolygonMesh twisted = generate::hyparGrid(3, 1.0);
  EXPECT_GT(planarityStats(twisted).maxPlaneFitResidual, 1e-3);
}

}  // namespace
}  // namespace plano
