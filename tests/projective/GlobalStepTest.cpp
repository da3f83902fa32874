#include "projective/GlobalStep.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "projective/IdealMaps.h"
#include "projective/LocalStep.h"
#include "projective/ProjectiveTestHelpers.h"
#include "support/TestMeshes.h"

namespace plano::projective {
namespace {

double maxMapDifference(const std::vector<Eigen::Matrix4d>& a, const std::vector<Eigen::Matrix4d>& b) {
  double worst = 0.0;
  for (std::size_t f = 0; f < a.size(); ++f) worst = std::max(worst, (a[f] - b[f]).cwiseAbs().maxCoeff());
  return worst;
}

double maxPlanarity(const Positions& vertices, const FaceList& faces) {
  return planarityStats(PolygonMesh{vertices, faces}).max;
}

/// Targets that disagree: the identity on half of the faces, a rotation about the
/// z-axis on the others.
std::vector<Eigen::Matrix4d> conflictingTargets(const ShapeSpace& space, double angle = 0.2) {
  std::vector<Eigen::Matrix4d> targets(space.faceCount(), Eigen::Matrix4d::Identity());
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (Index f = 0; f < space.faceCount(); f += 2) targets[f].topLeftCorner<3, 3>() = R;
  return targets;
}

class GlobalStepTest : public ::testing::Test {
 protected:
  compute::CpuBackend backend;
};

TEST_F(GlobalStepTest, CompatibleMapsComeBackUnchangedInOneStep) {
  for (const PolygonMesh& mesh : {generate::translationalSurface(6, 5), generate::hexagonalDome(2)}) {
    const ShapeSpace space(mesh);
    const Positions target =
        space.normalization().toWorld(test::applyProjectiveMap(space.basePositions(), test::samplePerspective()));
    const LocalStepResult fit = fitFaceMaps(backend, space, target);
    GlobalStep global(backend, space, {});
    FaceMaps result;
    const GlobalStepInfo info = global.solve(fit.fits.maps, Positions(), result);
    EXPECT_EQ(info.status, GlobalStepStatus::Unchanged);
    EXPECT_EQ(info.admmIterations, 0);
    EXPECT_LT(maxMapDifference(result.maps, fit.fits.maps), 1e-14);
    EXPECT_LT(test::maxAbsDifference(space.positions(result.maps), target), 1e-10);
  }
}

TEST_F(GlobalStepTest, IdentityTargetsGiveTheIdentity) {
  const ShapeSpace space(generate::surfaceOfRevolution(8, 4));
  const std::vector<Index> fixed = {0, 5, 17};
  Positions at(3, 3);
  for (int i = 0; i < 3; ++i) at.row(i) = space.baseMesh().vertices.row(fixed[i]);
  GlobalStep global(backend, space, fixed);
  FaceMaps result;
  const GlobalStepInfo info = global.solve(space.identityMaps().maps, at, result);
  EXPECT_LT(maxMapDifference(result.maps, space.identityMaps().maps), 1e-14);
  EXPECT_EQ(info.initialViolation, 0.0);
}

TEST_F(GlobalStepTest, PolyhedralInputConvergesAtOnce) {
  // §4.2: local and global steps between two polyhedral meshes reproduce the target, and
  // a second iteration changes nothing.
  const ShapeSpace space(generate::translationalSurface(8, 6));
  const Positions target =
      space.normalization().toWorld(test::applyProjectiveMap(space.basePositions(), test::samplePerspective()));
  GlobalStep global(backend, space, {});
  FaceMaps first;
  global.solve(fitFaceMaps(backend, space, target).fits.maps, Positions(), first);
  const Positions once = space.positions(first.maps);
  EXPECT_LT(test::maxAbsDifference(once, target), 1e-10);
  FaceMaps second;
  const GlobalStepInfo info = global.solve(fitFaceMaps(backend, space, once).fits.maps, Positions(), second);
  EXPECT_LE(info.admmIterations, 0);
  EXPECT_LT(test::maxAbsDifference(space.positions(second.maps), once), 1e-10);
}

TEST_F(GlobalStepTest, PositionalConstraintsHoldAndTheScheduleIsRecorded) {
  const PolygonMesh mesh = generate::translationalSurface(6, 6);
  const ShapeSpace space(mesh);
  const std::vector<Index> constrained = {0, 1, 2, 3, 4, 5, 6, 48};
  Positions at(constrained.size(), 3);
  for (std::size_t i = 0; i < constrained.size(); ++i) at.row(i) = mesh.vertices.row(constrained[i]);
  at.row(7) += Eigen::RowVector3d(0.1, 0.05, 0.2);
  GlobalStep global(backend, space, constrained);
  FaceMaps result;
  const GlobalStepInfo info = global.solve(conflictingTargets(space), at, result);
  ASSERT_FALSE(info.attempts.empty());
  EXPECT_GT(info.initialViolation, 0.0);
  EXPECT_NEAR(info.attempts.front().epsilon, 1e-2 * info.initialViolation, 1e-15);
  EXPECT_EQ(info.attempts.back().status, BoxQpStatus::Solved);
  EXPECT_LE(info.constraintResidual, info.epsilon + 1e-9);
  EXPECT_LT(info.positionalResidual, 1e-9);
  const Positions p = space.positions(result.maps);
  for (std::size_t i = 0; i < constrained.size(); ++i) {
    EXPECT_LT((p.row(constrained[i]) - at.row(i)).norm(), 1e-9 * space.normalization().scale) << "vertex " << constrained[i];
  }
}

TEST_F(GlobalStepTest, TargetsCompatibleToTheAdmmsToleranceAreKeptWithoutIterations) {
  const ShapeSpace space(generate::translationalSurface(6, 6));
  const std::vector<Eigen::Matrix4d> targets = conflictingTargets(space, 2e-8);
  GlobalStep global(backend, space, {});
  FaceMaps result;
  const GlobalStepInfo info = global.solve(targets, Positions(), result);
  ASSERT_GT(info.initialViolation, 0.0);
  ASSERT_LE(info.initialViolation, GlobalStepSettings{}.compatibleViolation);
  ASSERT_EQ(info.attempts.size(), 1u);
  EXPECT_EQ(info.attempts.front().epsilon, info.initialViolation);
  EXPECT_EQ(info.status, GlobalStepStatus::Unchanged);
  EXPECT_EQ(info.admmIterations, 0);
  EXPECT_EQ(maxMapDifference(result.maps, targets), 0.0);

  // Without the rule the schedule starts at 1e-2 of the violation, which the ADMM must resolve.
  GlobalStepSettings paper;
  paper.compatibleViolation = 0.0;
  GlobalStep strict(backend, space, {}, paper);
  FaceMaps resolved;
  const GlobalStepInfo strictInfo = strict.solve(targets, Positions(), resolved);
  EXPECT_NEAR(strictInfo.attempts.front().epsilon, 1e-2 * strictInfo.initialViolation, 1e-22);
  EXPECT_GT(strictInfo.admmIterations, 0);
  EXPECT_LE(strictInfo.constraintResidual, strictInfo.epsilon * 1.1);
}

TEST_F(GlobalStepTest, IntermediateAttemptsComeBeforeTheEpsilonThatKeepsTheTargets) {
  // Attempts capped after 10 ADMM iterations fail below the targets' violation; the
  // schedule's third eps, the violation itself, keeps the targets.
  const ShapeSpace space(generate::translationalSurface(6, 6));
  const std::vector<Eigen::Matrix4d> targets = conflictingTargets(space);
  GlobalStepSettings settings;
  settings.qp.maxIterations = 10;
  const auto epsilonsOf = [&](int intermediate) {
    settings.intermediateAttempts = intermediate;
    GlobalStep global(backend, space, {}, settings);
    FaceMaps result;
    const GlobalStepInfo info = global.solve(targets, Positions(), result);
    EXPECT_EQ(info.status, GlobalStepStatus::Unchanged);
    EXPECT_EQ(maxMapDifference(result.maps, targets), 0.0);
    std::vector<double> relative;
    for (const EpsilonAttempt& attempt : info.attempts) relative.push_back(attempt.epsilon / info.initialViolation);
    return relative;
  };
  const std::vector<double> paper = epsilonsOf(0);
  ASSERT_EQ(paper.size(), 3u);
  EXPECT_NEAR(paper[1], 0.1, 1e-12);
  const std::vector<double> refined = epsilonsOf(3);
  ASSERT_EQ(refined.size(), 6u);
  for (int j = 1; j <= 3; ++j) EXPECT_NEAR(refined[1 + j], 0.1 * std::pow(10.0, j / 4.0), 1e-12) << j;
  EXPECT_NEAR(refined.back(), 1.0, 1e-12);

  // Set on a step object, and rejected when negative.
  GlobalStep global(backend, space, {}, settings);
  EXPECT_THROW(global.setIntermediateAttempts(-1), Error);
  settings.intermediateAttempts = -1;
  EXPECT_THROW(GlobalStep(backend, space, {}, settings), Error);
}

TEST_F(GlobalStepTest, ANegativeCompatibleViolationIsAUsageError) {
  GlobalStepSettings settings;
  settings.compatibleViolation = -1e-6;
  const ShapeSpace space(generate::translationalSurface(3, 3));
  EXPECT_THROW(GlobalStep(backend, space, {}, settings), Error);
}

TEST_F(GlobalStepTest, AnAttemptAfterAStalledOneStartsAtTheStalledOnesRho) {
  // The boundary of a grid fixed and its centre lifted: no compatible maps with the
  // targets' scale factors meet that within a small eps. With an infeasibility tolerance
  // too coarse to certify it, the small eps's attempt stalls, its rho driven far up. The
  // next attempt starts at the rho the stalled one started at (here the initial rho), so
  // the eps that solves gives the ADMM iteration of a step that tries it first.
  const PolygonMesh mesh = generate::translationalSurface(6, 6);
  const ShapeSpace space(mesh);
  std::vector<Index> constrained;
  for (Index v = 0; v < space.vertexCount(); ++v) {
    const Index i = v % 7, j = v / 7;
    if (i == 0 || j == 0 || i == 6 || j == 6) constrained.push_back(v);
  }
  constrained.push_back(24);  // the centre, (3, 3)
  Positions at(constrained.size(), 3);
  for (std::size_t i = 0; i < constrained.size(); ++i) at.row(i) = mesh.vertices.row(constrained[i]);
  at.bottomRows(1) += Eigen::RowVector3d(0.0, 0.0, 1e-4);
  GlobalStepSettings settings;
  settings.qp.infeasibilityTolerance = 1e-2;
  GlobalStep scheduled(backend, space, constrained, settings);
  FaceMaps afterStall;
  const GlobalStepInfo first = scheduled.solve(space.identityMaps().maps, at, afterStall);
  ASSERT_EQ(first.attempts.size(), 2u);
  ASSERT_EQ(first.attempts.front().status, BoxQpStatus::Stalled);
  ASSERT_EQ(first.attempts.back().status, BoxQpStatus::Solved);

  settings.initialEpsilonFraction *= settings.epsilonGrowth;
  GlobalStep direct(backend, space, constrained, settings);
  FaceMaps fresh;
  const GlobalStepInfo second = direct.solve(space.identityMaps().maps, at, fresh);
  ASSERT_EQ(second.attempts.size(), 1u);
  EXPECT_NEAR(second.epsilon, first.epsilon, 1e-12 * first.epsilon);
  EXPECT_EQ(second.attempts.front().iterations, first.attempts.back().iterations);
  EXPECT_LT(maxMapDifference(fresh.maps, afterStall.maps), 1e-12);
}

TEST_F(GlobalStepTest, ExactFirstGivesExactlyPlanarFacesWhenFeasible) {
  // Rigid targets of a polyhedral (parallelogram) grid with one row fixed: the affine
  // shape space contains exact solutions, so eps = 0 is feasible.
  const PolygonMesh mesh = generate::translationalSurface(6, 6);
  const ShapeSpace space(mesh);
  const std::vector<Index> fixed = {0, 1, 2, 3, 4, 5, 6};
  Positions at(fixed.size(), 3);
  for (std::size_t i = 0; i < fixed.size(); ++i) at.row(i) = mesh.vertices.row(fixed[i]);
  GlobalStepSettings settings;
  settings.epsilonStart = EpsilonStart::ExactFirst;
  settings.qp.equalitySolve = EqualitySolve::Admm;
  GlobalStep global(backend, space, fixed, settings);
  FaceMaps result;
  const GlobalStepInfo info = global.solve(conflictingTargets(space), at, result);
  EXPECT_EQ(info.epsilon, 0.0);
  EXPECT_LT(info.constraintResidual, 1e-12);
  EXPECT_LT(maxPlanarity(space.positions(result.maps), mesh.faces), 1e-8);
  EXPECT_GT(maxMapDifference(result.maps, space.identityMaps().maps), 1e-3);  // it did move
  EXPECT_GT(info.admmIterations, 0);
  // Every row an equality row: the three coordinate columns share their active set, so
  // one polish refinement serves all three, and the residual reaches rounding within a
  // few (the polish ran 30 per column, 90, before it stopped there).
  ASSERT_TRUE(info.polished);
  EXPECT_GE(info.polishRefinements, 1);
  EXPECT_LE(info.polishRefinements, 12);

  // Solved directly (the CPU factors K, so Automatic does): no ADMM iteration, the same
  // maps to rounding, and as few refinements.
  settings.qp.equalitySolve = EqualitySolve::Automatic;
  GlobalStep direct(backend, space, fixed, settings);
  FaceMaps directResult;
  const GlobalStepInfo directInfo = direct.solve(conflictingTargets(space), at, directResult);
  EXPECT_EQ(directInfo.epsilon, 0.0);
  EXPECT_EQ(directInfo.status, GlobalStepStatus::Solved);
  EXPECT_EQ(directInfo.admmIterations, 0);
  ASSERT_EQ(directInfo.attempts.size(), 1u);
  EXPECT_TRUE(directInfo.attempts[0].direct);
  EXPECT_FALSE(info.attempts[0].direct);
  EXPECT_GE(directInfo.polishRefinements, 1);
  EXPECT_LE(directInfo.polishRefinements, 12);
  EXPECT_LT(directInfo.constraintResidual, 1e-12);
  EXPECT_LT(maxMapDifference(directResult.maps, result.maps), 1e-9);
}

/// On a real mesh: the exact step of conflicting targets, solved directly and by the
/// ADMM (and polish), gives the same mesh to the problem's conditioning. These meshes'
/// exact steps are ill-conditioned (no constrained vertex; nearly redundant rows): both
/// stop at residuals of 1e-9 to 1e-7, within the ADMM's 1e-6, the method of multipliers
/// contracting slowly (30 refinements on Yas Island) or stagnating at the stiff system's
/// rounding (Enneper), and solutions with such residuals differ by up to 1.5e-4 of the
/// diagonal (measured with rhoP 1e5 to 1e7). Direct vs ADMM: 1.8e-5 of the diagonal on
/// Yas Island, 5.3e-7 on Enneper.
void expectDirectAndAdmmAgreeOn(const std::filesystem::path& path) {
  const PolygonMesh mesh = readMesh(path);
  const ShapeSpace space(mesh);
  GlobalStepSettings settings;
  settings.epsilonStart = EpsilonStart::ExactFirst;
  compute::CpuBackend cpu;
  FaceMaps admmMaps, directMaps;
  settings.qp.equalitySolve = EqualitySolve::Admm;
  const GlobalStepInfo admm = GlobalStep(cpu, space, {}, settings).solve(conflictingTargets(space), {}, admmMaps);
  settings.qp.equalitySolve = EqualitySolve::Automatic;
  const GlobalStepInfo direct = GlobalStep(cpu, space, {}, settings).solve(conflictingTargets(space), {}, directMaps);
  EXPECT_EQ(admm.epsilon, 0.0);
  EXPECT_EQ(direct.epsilon, 0.0);
  EXPECT_GT(admm.admmIterations, 0);
  EXPECT_EQ(direct.admmIterations, 0);
  ASSERT_FALSE(direct.attempts.empty());
  EXPECT_TRUE(direct.attempts.back().direct);
  EXPECT_LT(direct.constraintResidual, 1e-6);
  const Positions admmPositions = space.positions(admmMaps.maps);
  const Positions directPositions = space.positions(directMaps.maps);
  const double difference = (admmPositions - directPositions).rowwise().norm().maxCoeff();
  EXPECT_LT(difference, 5e-5 * boundingBoxDiagonal(mesh.vertices));
  EXPECT_GT(maxMapDifference(directMaps.maps, space.identityMaps().maps), 1e-3);  // it did move
}

TEST_F(GlobalStepTest, DirectAndAdmmExactStepsAgreeOnYasIsland) {
  PLANO_REQUIRE_SHARED_MESH(path, "yas_island.off");
  expectDirectAndAdmmAgreeOn(path);
}

TEST_F(GlobalStepTest, DirectAndAdmmExactStepsAgreeOnHexagonsOfAnEnneperSurface) {
  PLANO_REQUIRE_SHARED_MESH(path, "enneper_hex.off");
  expectDirectAndAdmmAgreeOn(path);
}

TEST_F(GlobalStepTest, CornerAtInfinityIsANumericalError) {
  const ShapeSpace space(generate::cube());
  std::vector<Eigen::Matrix4d> targets(space.faceCount(), Eigen::Matrix4d::Identity());
  const Eigen::RowVector3d p = space.basePositions().row(0);
  for (auto& T : targets) T.block<3, 1>(0, 3) = -p.transpose() / p.squaredNorm();
  GlobalStep global(backend, space, {});
  FaceMaps result;
  try {
    global.solve(targets, Positions(), result);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Numerical);
    EXPECT_NE(std::string(e.what()).find("vertex 0"), std::string::npos) << e.what();
  }
}

TEST_F(GlobalStepTest, ProjectiveFitsByTheirColumnsAndScalesGiveTheSameStepAsTheMaps) {
  // Projective fits of a perturbed similarity (their scales are not 1), with fixed vertices.
  const PolygonMesh mesh = generate::translationalSurface(6, 5);
  const ShapeSpace space(mesh);
  const std::vector<Index> fixed = {0, 1, 2, 3, 4, 5, 6};  // the first row, where it is
  const Positions at = mesh.vertices.topRows(7);
  const Positions target = test::rotatedScaledAndPerturbed(mesh.vertices, 1.1, 0.03, 5);
  const LocalStepResult local = fitFaceMaps(backend, space, target);
  compute::DeviceProjectiveFits fits;
  backend.fitProjectiveMapsOnDevice(mesh.faces, space.basePositions(), normalizedTargetPositions(space, target),
                                    GlobalStep::kMinimumReciprocalScale, fits);

  FaceMaps byMaps;
  compute::DeviceMatrix byFits;
  const GlobalStepInfo a = GlobalStep(backend, space, fixed).solve(local.fits.maps, at, byMaps);
  const GlobalStepInfo b = GlobalStep(backend, space, fixed).solve(fits, at, byFits);
  EXPECT_GT(a.admmIterations + a.polishRefinements, 0);  // not a trivial step
  EXPECT_EQ(a.initialViolation, b.initialViolation);
  EXPECT_EQ(a.epsilon, b.epsilon);
  EXPECT_EQ(a.admmIterations, b.admmIterations);
  EXPECT_EQ(a.nonPositiveScales, b.nonPositiveScales);
  ASSERT_EQ(byFits.rows(), 4 * space.faceCount());
  for (Index f = 0; f < space.faceCount(); ++f) {
    EXPECT_EQ(Eigen::MatrixXd(byMaps.maps[f].leftCols<3>()), Eigen::MatrixXd(byFits.values().middleRows<4>(4 * f)))
        << "face " << f;
  }

  // A corner sent to infinity names its face and vertex; fits of the wrong size are a usage error.
  const Index corner = space.faces().offsets()[4] + 1;
  fits.firstVanishingCorner = corner;
  try {
    GlobalStep(backend, space, fixed).solve(fits, at, byFits);
    ADD_FAILURE() << "expected Error(Numerical)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Numerical);
    EXPECT_NE(std::string(e.what()).find("face 4 sends vertex " + std::to_string(space.faces().indices()[corner])),
              std::string::npos)
        << e.what();
  }
  fits.firstVanishingCorner = -1;
  fits.reciprocalScales = Eigen::MatrixXd::Ones(3, 1);
  try {
    GlobalStep(backend, space, fixed).solve(fits, at, byFits);
    ADD_FAILURE() << "expected Error(Usage)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
  }
}

TEST_F(GlobalStepTest, AffineTargetsByTheirColumnsGiveTheSameStepAsTheMaps) {
  // Ideal maps of a perturbed rigid motion (affine), with fixed vertices: an ε schedule
  // with ADMM attempts, then the direct solve.
  const PolygonMesh mesh = generate::translationalSurface(6, 5);
  const ShapeSpace space(mesh);
  const std::vector<Index> fixed = {0, 1, 2, 3, 4, 5, 6};  // the first row, where it is
  const Positions at = mesh.vertices.topRows(7);
  const Positions target = test::rotatedScaledAndPerturbed(mesh.vertices, 1.0, 0.03, 4);
  const auto ideal = fittedIdealMaps(backend, space, target, IdealMapKind::Rigid);
  Eigen::MatrixXd columns(4 * space.faceCount(), 3);
  for (Index f = 0; f < space.faceCount(); ++f) columns.middleRows<4>(4 * f) = ideal[f].leftCols<3>();

  FaceMaps byMaps, byColumns;
  const GlobalStepInfo a = GlobalStep(backend, space, fixed).solve(ideal, at, byMaps);
  const GlobalStepInfo b = GlobalStep(backend, space, fixed).solveAffine(columns, at, byColumns);
  EXPECT_GT(a.admmIterations + a.polishRefinements, 0);  // not a trivial step
  EXPECT_EQ(a.initialViolation, b.initialViolation);
  EXPECT_EQ(a.epsilon, b.epsilon);
  EXPECT_EQ(a.admmIterations, b.admmIterations);
  ASSERT_EQ(byMaps.maps.size(), byColumns.maps.size());
  for (std::size_t f = 0; f < byMaps.maps.size(); ++f) EXPECT_EQ(byMaps.maps[f], byColumns.maps[f]) << "face " << f;
  EXPECT_EQ(byMaps.reciprocalScales, byColumns.reciprocalScales);

  // A non-finite target names its face; columns of the wrong size are a usage error.
  columns(4 * 3 + 1, 2) = std::nan("");
  try {
    GlobalStep(backend, space, fixed).solveAffine(columns, at, byColumns);
    ADD_FAILURE() << "expected Error(Numerical)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Numerical);
    EXPECT_NE(std::string(e.what()).find("face 3 "), std::string::npos) << e.what();
  }
  try {
    GlobalStep(backend, space, fixed).solveAffine(Eigen::MatrixXd::Zero(8, 3), at, byColumns);
    ADD_FAILURE() << "expected Error(Usage)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
  }
}

TEST_F(GlobalStepTest, RejectsRepeatedConstrainedVertices) {
  const ShapeSpace space(generate::cube());
  EXPECT_THROW(GlobalStep(backend, space, {1, 1}), Error);
  EXPECT_THROW(GlobalStep(backend, space, {8}), Error);
}

}  // namespace
}  // namespace plano::projective
