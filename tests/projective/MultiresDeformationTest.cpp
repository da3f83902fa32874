#include <gtest/gtest.h>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/Planarity.h"
#include "projective/MultiresDeformation.h"
#include "projective/PqSubdivision.h"

namespace plano::projective {
namespace {

/// A 4 x 4 translational surface subdivided twice (256 planar quads), with the finest
/// row y = 0 fixed and the corner (1, 1) lifted.
class MultiresDeformation : public ::testing::TestWithParam<SubdivisionScheme> {
 protected:
  MultiresDeformation() {
    PqSubdivisionSettings settings;
    settings.levels = 2;
    settings.scheme = GetParam();
    settings.planarityTolerance = 0.5;
    subdivision_ = subdividePlanarQuads(backend_, generate::translationalSurface(4, 4), settings);
  }
  const Positions& finest() const { return subdivision_.positions.back(); }
  Index closestVertex(const Eigen::Vector3d& p) const {
    Index best = 0;
    (finest().rowwise() - p.transpose()).rowwise().squaredNorm().minCoeff(&best);
    return best;
  }
  PositionalConstraints rowFixedCornerLifted(double lift) const {
    PositionalConstraints c;
    const double yMin = finest().col(1).minCoeff();
    for (Index v = 0; v < finest().rows(); ++v) {
      if (finest()(v, 1) < yMin + 1e-9) c.fixed.push_back(v);
    }
    const Index corner = closestVertex({1.2, 1.2, 0.0});
    c.handles.push_back({corner, finest().row(corner).transpose() + Eigen::Vector3d(0.0, 0.0, lift)});
    return c;
  }

  compute::CpuBackend backend_;
  PqSubdivisionResult subdivision_{SubdivisionHierarchy(FaceList({{0, 1, 2}}), 3, 0), {}, {}};
};

TEST_P(MultiresDeformation, ReachesHandlesKeepsFixedVerticesAndStaysPlanarOnTheChosenLevel) {
  const PositionalConstraints c = rowFixedCornerLifted(0.25);
  const MultiresResult result = multiresDeform(backend_, subdivision_.hierarchy, subdivision_.positions, c);
  EXPECT_EQ(result.info.level, chooseDeformationLevel(subdivision_.hierarchy, c));
  EXPECT_EQ(result.info.level, 0);
  EXPECT_EQ(result.info.status, MultiresStatus::Converged);
  EXPECT_LT(result.info.maxHandleError, 1e-6);
  EXPECT_LT(result.info.maxFixedError, 1e-6);
  EXPECT_LT(result.info.planarity.max, 1.0);
  EXPECT_LT(planarityStats(PolygonMesh{result.positions, subdivision_.hierarchy.faces(2)}).max, 1.0);
  // The lift spreads over the mesh: vertices between the fixed row and the handle rose.
  const Index middle = closestVertex({0.6, 0.6, 0.0});
  EXPECT_GT(result.positions(middle, 2) - finest()(middle, 2), 0.01);
}

TEST_P(MultiresDeformation, EveryForcedLevelMeetsTheConstraints) {
  const PositionalConstraints c = rowFixedCornerLifted(0.15);
  for (int level = 0; level <= 2; ++level) {
    MultiresSettings settings;
    settings.level = level;
    const MultiresResult result = multiresDeform(backend_, subdivision_.hierarchy, subdivision_.positions, c, settings);
    EXPECT_EQ(result.info.level, level);
    EXPECT_TRUE(result.info.levelChecks.empty());
    EXPECT_LT(result.info.maxHandleError, 1e-6) << "level " << level;
    EXPECT_LT(result.info.maxFixedError, 1e-6) << "level " << level;
    EXPECT_LT(result.info.planarity.max, 1.0) << "level " << level;
  }
}

TEST_P(MultiresDeformation, WithoutHandlesNothingMoves) {
  PositionalConstraints c = rowFixedCornerLifted(0.0);
  const MultiresResult result = multiresDeform(backend_, subdivision_.hierarchy, subdivision_.positions, c);
  EXPECT_LT((result.positions - finest()).cwiseAbs().maxCoeff(), 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Multires, MultiresDeformation,
                         ::testing::Values(SubdivisionScheme::CatmullClark, SubdivisionScheme::FourPoint),
                         [](const auto& info) { return info.param == SubdivisionScheme::CatmullClark ? "CatmullClark" : "FourPoint"; });

TEST(MultiresDeformationInput, RejectsMismatchedPositionsAndLevels) {
  compute::CpuBackend backend;
  const PolygonMesh cube = generate::cube();
  const SubdivisionHierarchy h(cube.faces, cube.vertexCount(), 1);
  PositionalConstraints c;
  EXPECT_THROW(multiresDeform(backend, h, {cube.vertices}, c), Error);
  const Positions fine = Positions::Zero(h.vertexCount(1), 3);
  MultiresSettings settings;
  settings.level = 2;
  EXPECT_THROW(multiresDeform(backend, h, {cube.vertices, fine}, c, settings), Error);
  c.fixed = {h.vertexCount(1)};
  EXPECT_THROW(multiresDeform(backend, h, {cube.vertices, fine}, c), Error);
}

}  // namespace
}  // namespace plano::projective
