#include <gtest/gtest.h>

#include "core/Error.h"
#include "mesh/Generators.h"
#include "projective/MultiresConstraints.h"
#include "projective/SubdivisionSchemes.h"

namespace plano::projective {
namespace {

/// A flat 2 x 2 grid over [-1, 1]^2 refined three times (16 x 16 quads), with a lookup of
/// finest vertices by their lattice position.
class MultiresConstraints : public ::testing::Test {
 protected:
  MultiresConstraints() : base_(generate::hyparGrid(2, 0.0)), hierarchy_(base_.faces, base_.vertexCount(), 3) {
    finest_ = base_.vertices;
    for (int l = 1; l <= 3; ++l) {
      finest_ = trivialRefinementPositions(hierarchy_.refinement(l), hierarchy_.faces(l - 1), finest_);
    }
  }
  Index vertexAt(double x, double y) const {
    for (Index v = 0; v < finest_.rows(); ++v) {
      if (std::abs(finest_(v, 0) - x) < 1e-12 && std::abs(finest_(v, 1) - y) < 1e-12) return v;
    }
    ADD_FAILURE() << "no vertex at (" << x << ", " << y << ")";
    return 0;
  }
  Handle handleAt(double x, double y) const { return {vertexAt(x, y), Eigen::Vector3d(x, y, 0.3)}; }
  int level(const PositionalConstraints& c) const { return chooseDeformationLevel(hierarchy_, c); }

  PolygonMesh base_;
  SubdivisionHierarchy hierarchy_;
  Positions finest_;
};

TEST_F(MultiresConstraints, OneHandleFarFromTheFixedCornerDeformsOnTheBaseLevel) {
  PositionalConstraints c;
  c.fixed = {vertexAt(-1, -1)};
  c.handles = {handleAt(0.5, 0.5)};
  EXPECT_EQ(level(c), 0);
}

TEST_F(MultiresConstraints, TwoHandlesInOneBaseFaceNeedLevelOne) {
  PositionalConstraints c;
  c.handles = {handleAt(0.25, 0.25), handleAt(0.75, 0.75)};
  const auto checks = checkDeformationLevels(hierarchy_, c);
  ASSERT_EQ(checks.size(), 4u);
  EXPECT_FALSE(checks[0].admissible);
  EXPECT_NE(checks[0].reason.find("handles 0 and 1"), std::string::npos) << checks[0].reason;
  EXPECT_EQ(level(c), 1);
}

TEST_F(MultiresConstraints, CloserHandlesNeedLevelTwo) {
  PositionalConstraints c;
  c.handles = {handleAt(0.125, 0.125), handleAt(0.375, 0.375)};
  EXPECT_EQ(level(c), 2);
}

TEST_F(MultiresConstraints, HandlesOnNeighbouringFineVerticesNeedTheFinestLevel) {
  PositionalConstraints c;
  c.handles = {handleAt(0.125, 0.125), handleAt(0.25, 0.125)};
  EXPECT_EQ(level(c), 3);
}

TEST_F(MultiresConstraints, AHandleAndAFixedVertexOnOneFaceMoveTheLevelUp) {
  PositionalConstraints c;
  c.fixed = {vertexAt(0, 0)};
  c.handles = {handleAt(0.5, 0.5)};
  const auto checks = checkDeformationLevels(hierarchy_, c);
  EXPECT_NE(checks[0].reason.find("fixed vertex"), std::string::npos) << checks[0].reason;
  EXPECT_FALSE(checks[1].admissible);
  EXPECT_EQ(level(c), 2);
  // Several fixed vertices on one face are no conflict.
  PositionalConstraints fixedOnly;
  fixedOnly.fixed = {vertexAt(0, 0), vertexAt(1, 0), vertexAt(0, 1), vertexAt(0.5, 0.5)};
  EXPECT_EQ(level(fixedOnly), 0);
}

TEST_F(MultiresConstraints, CoarseningKeepsFixedCounterpartsAndAttachesHandlesToAncestors) {
  PositionalConstraints c;
  c.fixed = {vertexAt(-1, -1), vertexAt(-0.875, -1), vertexAt(-0.5, -1)};
  c.handles = {handleAt(0.5, 0.5)};
  const CoarseConstraints level0 = coarsenConstraints(hierarchy_, finest_, c, 0);
  EXPECT_EQ(level0.fixed, std::vector<Index>({vertexAt(-1, -1)}));  // the others are not base vertices
  ASSERT_EQ(level0.handles.size(), 1u);  // (0.5, 0.5) is inside one base face
  EXPECT_EQ(level0.handles[0].handle, 0);
  EXPECT_TRUE(level0.handles[0].point.isApprox(Eigen::Vector3d(0.5, 0.5, 0.0)));
  EXPECT_TRUE(level0.handles[0].target.isApprox(Eigen::Vector3d(0.5, 0.5, 0.3)));
  const CoarseConstraints level1 = coarsenConstraints(hierarchy_, finest_, c, 1);
  EXPECT_EQ(level1.fixed.size(), 2u);      // (-0.5, -1) is a level-1 edge point
  EXPECT_EQ(level1.handles.size(), 4u);    // (0.5, 0.5) is a level-1 vertex with four faces
  const CoarseConstraints level3 = coarsenConstraints(hierarchy_, finest_, c, 3);
  EXPECT_EQ(level3.fixed.size(), 3u);
}

TEST_F(MultiresConstraints, RejectsConstraintsOnVerticesThatDoNotExist) {
  PositionalConstraints c;
  c.fixed = {static_cast<Index>(finest_.rows())};
  EXPECT_THROW(chooseDeformationLevel(hierarchy_, c), Error);
  EXPECT_THROW(coarsenConstraints(hierarchy_, finest_, c, 0), Error);
  EXPECT_THROW(coarsenConstraints(hierarchy_, finest_, PositionalConstraints{}, 4), Error);
}

}  // namespace
}  // namespace plano::projective
