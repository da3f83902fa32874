#include <gtest/gtest.h>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "projective/PqSubdivision.h"
#include "support/TestMeshes.h"

namespace plano::projective {
namespace {

/// Positions after `levels` steps of the linear scheme alone.
Positions linearOnly(const PolygonMesh& base, SubdivisionScheme scheme, int levels) {
  PolygonMesh mesh = base;
  for (int l = 0; l < levels; ++l) {
    const QuadRefinement r = refineQuads(mesh.faces, mesh.vertexCount());
    mesh.vertices = linearSubdivision(scheme, mesh.faces, mesh.vertices, r);
    mesh.faces = r.fineFaces;
  }
  return mesh.vertices;
}

/// Max distance between corresponding vertices over the bounding-box diagonal: an upper
/// bound of the (vertex-sampled) Hausdorff distance between the two surfaces.
double relativeDistance(const Positions& a, const Positions& b) {
  return (a - b).rowwise().norm().maxCoeff() / boundingBoxDiagonal(b);
}

/// A projective image of a planar-quad mesh is planar-quad, but the linear schemes do
/// not commute with it: the linear targets are not planar.
PolygonMesh perspectiveWarped(PolygonMesh mesh, const Eigen::Vector3d& w) {
  for (Index v = 0; v < mesh.vertexCount(); ++v) {
    const Eigen::RowVector3d p = mesh.vertices.row(v);
    mesh.vertices.row(v) = p / (1.0 + p.dot(w.transpose()));
  }
  return mesh;
}

/// Every ε attempt of every global step, in order, with its level.
std::vector<std::pair<int, EpsilonAttempt>> attemptsOf(const PqSubdivisionResult& result) {
  std::vector<std::pair<int, EpsilonAttempt>> all;
  for (const PqLevelInfo& level : result.info.levels) {
    for (const PqIteration& it : level.iterations) {
      for (const EpsilonAttempt& attempt : it.attempts) all.emplace_back(level.level, attempt);
    }
  }
  return all;
}

class SubdivisionPq : public ::testing::Test {
 protected:
  /// Two levels with the paper's planarity bound for `scheme`, expected to converge.
  /// `dualToleranceScale`: the global steps' (PqSubdivisionSettings::globalStep; 1 is the
  /// ADMM's own dual tolerance, where the ε schedule's rules below were measured).
  PqSubdivisionResult twoLevels(const PolygonMesh& base, SubdivisionScheme scheme = SubdivisionScheme::CatmullClark,
                                double dualToleranceScale = PqSubdivisionSettings{}.globalStep.qp.dualToleranceScale) {
    PqSubdivisionSettings settings;
    settings.levels = 2;
    settings.scheme = scheme;
    settings.globalStep.qp.dualToleranceScale = dualToleranceScale;
    settings.planarityTolerance = isInterpolating(scheme) ? 0.5 : 0.1;
    PqSubdivisionResult result = subdividePlanarQuads(backend, base, settings);
    EXPECT_EQ(result.info.status, PqSubdivisionStatus::Converged);
    return result;
  }

  compute::CpuBackend backend;
};

TEST_F(SubdivisionPq, CubeThreeCatmullClarkLevelsEndPlanarInAtMostNineIterations) {
  PqSubdivisionSettings settings;
  settings.levels = 3;
  const PolygonMesh cube = generate::cube(1.0);
  const PqSubdivisionResult result = subdividePlanarQuads(backend, cube, settings);
  EXPECT_EQ(result.info.status, PqSubdivisionStatus::Converged);
  ASSERT_EQ(result.info.levels.size(), 3u);
  EXPECT_LE(result.info.totalIterations, 9);
  for (const PqLevelInfo& level : result.info.levels) {
    EXPECT_LT(level.planarity.max, 0.1) << "level " << level.level;
    EXPECT_GT(level.linearMaxPlanarity, 0.4) << "Catmull-Clark alone is far from planar";
    for (const PqIteration& it : level.iterations) {
      EXPECT_GE(it.epsilon, 0.0);
      // The tiny-ε attempts of a level's later iterations stop as stalled; each ran into the
      // cap before (8000 and 7160 ADMM iterations in the second iterations of levels 1 and 2).
      EXPECT_LT(it.admmIterations, settings.globalStep.qp.maxIterations) << "level " << level.level;
    }
  }
  const PolygonMesh fine = result.finestMesh();
  EXPECT_EQ(fine.faceCount(), 6 * 64);
  EXPECT_LT(planarityStats(fine).max, 0.1);
  // Close to the Catmull-Clark surface (measured 0.65 %; reference 0.6 % of the diagonal).
  EXPECT_LT(relativeDistance(fine.vertices, linearOnly(cube, SubdivisionScheme::CatmullClark, 3)), 0.02);
}

TEST_F(SubdivisionPq, HexagonalDomeTwoCatmullClarkLevelsConvergeWithoutCappedAttempts) {
  // A stalled attempt drives rho to its clamp; when the next eps's attempt started there,
  // level 2 ran 13 local/global iterations (15 in all, 102 550 ADMM iterations, most
  // attempts to the cap). The next attempt now starts at the stalled one's starting rho:
  // 3 iterations (1 + 2), 8 060 ADMM iterations.
  const PqSubdivisionResult result = twoLevels(generate::hexagonalDome(2));
  EXPECT_LE(result.info.totalIterations, 5);
  for (const PqLevelInfo& level : result.info.levels) EXPECT_LT(level.planarity.max, 0.1) << "level " << level.level;
  for (const auto& [level, attempt] : attemptsOf(result)) {
    EXPECT_NE(attempt.status, BoxQpStatus::MaxIterationsReached) << "level " << level;
  }
}

TEST_F(SubdivisionPq, FeasibleNearOptimalAttemptsAreKeptOnAThreeRingDome) {
  // The dome's small attempts reach feasibility (primal residual ~1e-11) while their dual
  // residual creeps at 1.5-4x its tolerance until the cap. Each global step then fell back
  // to eps = its initial violation, which the targets themselves satisfy: no progress but
  // the corners' averaging, 18 local/global iterations (80 230 ADMM iterations) to reach
  // 0.0997 %. Kept as solved-inaccurate: 2 iterations, 8 240 (5 380 once such attempts stop
  // when their dual residual falls too slowly for the cap), max planarity 0.085 % / 0.065 %.
  const PqSubdivisionResult result = twoLevels(generate::hexagonalDome(3), SubdivisionScheme::CatmullClark, 1.0);
  EXPECT_LE(result.info.totalIterations, 4);
  for (const PqLevelInfo& level : result.info.levels) {
    EXPECT_LT(level.planarity.max, 0.1) << "level " << level.level;
    for (const PqIteration& it : level.iterations) EXPECT_LE(it.constraintResidual, it.epsilon + 1e-6);
  }
  int inaccurate = 0;
  for (const auto& [level, attempt] : attemptsOf(result)) inaccurate += attempt.status == BoxQpStatus::SolvedInaccurate;
  EXPECT_GT(inaccurate, 0);
}

TEST_F(SubdivisionPq, ALooserDualToleranceHalvesTheAdmmIterationsOfATwoRingDomeWithTheSameIterations) {
  // The global steps' dual tolerance at 10x the ADMM's (the default): the schedule's small
  // attempts converge, or end solved-inaccurate, hundreds of ADMM iterations sooner; their
  // constraints, which make the faces planar, are held as tightly. Measured: 6 770 -> 3 350
  // ADMM iterations, the same 1 + 2 local/global iterations, max planarity within 1e-3 %.
  const PolygonMesh dome = generate::hexagonalDome(2);
  const PqSubdivisionResult tight = twoLevels(dome, SubdivisionScheme::CatmullClark, 1.0);
  const PqSubdivisionResult loose = twoLevels(dome);
  ASSERT_EQ(loose.info.levels.size(), tight.info.levels.size());
  int admmTight = 0, admmLoose = 0;
  for (const auto& [level, attempt] : attemptsOf(tight)) admmTight += attempt.iterations;
  for (const auto& [level, attempt] : attemptsOf(loose)) admmLoose += attempt.iterations;
  EXPECT_LT(admmLoose, 0.6 * admmTight);
  for (std::size_t l = 0; l < loose.info.levels.size(); ++l) {
    const PqLevelInfo& level = loose.info.levels[l];
    EXPECT_EQ(level.iterations.size(), tight.info.levels[l].iterations.size()) << "level " << level.level;
    EXPECT_LT(level.planarity.max, 0.1) << "level " << level.level;
    for (const PqIteration& it : level.iterations) EXPECT_LE(it.constraintResidual, it.epsilon + 1e-6);
  }
  const double apart = relativeDistance(loose.positions.back(), tight.positions.back());
  EXPECT_LT(apart, 1e-4);
}

TEST_F(SubdivisionPq, AttemptsThatStalledInTwoStepsAreSkippedWithTheSameResult) {
  // A 3-ring dome's level held to 0.005 %: five iterations, whose small attempts stall step
  // after step. Skipping those that stalled in the last two steps
  // (GlobalStepSettings::stalledAttemptSkips) leaves every iterate as it was: a skipped
  // attempt would have stalled, and the next one starts at the same rho either way.
  PqSubdivisionSettings settings;
  settings.planarityTolerance = 0.005;
  settings.maxIterationsPerLevel = 8;
  const PolygonMesh dome = generate::hexagonalDome(3);
  PqSubdivisionSettings everyAttempt = settings;
  everyAttempt.globalStep.stalledAttemptSkips = 0;
  const PqSubdivisionResult tried = subdividePlanarQuads(backend, dome, everyAttempt);
  const PqSubdivisionResult skipping = subdividePlanarQuads(backend, dome, settings);
  ASSERT_EQ(skipping.info.levels[0].iterations.size(), tried.info.levels[0].iterations.size());
  EXPECT_TRUE(skipping.positions.back() == tried.positions.back());

  int skipped = 0, admmSkipping = 0, admmTried = 0;
  for (std::size_t i = 0; i < tried.info.levels[0].iterations.size(); ++i) {
    const PqIteration& a = tried.info.levels[0].iterations[i];
    const PqIteration& b = skipping.info.levels[0].iterations[i];
    admmTried += a.admmIterations;
    admmSkipping += b.admmIterations;
    ASSERT_EQ(a.attempts.size(), b.attempts.size()) << "iteration " << i + 1;
    for (std::size_t k = 0; k < a.attempts.size(); ++k) {
      EXPECT_EQ(a.attempts[k].epsilon, b.attempts[k].epsilon);
      EXPECT_FALSE(a.attempts[k].skipped);
      if (!b.attempts[k].skipped) continue;
      ++skipped;
      EXPECT_EQ(b.attempts[k].iterations, 0);
      // Skipped only where the full schedule's attempt stalled, and never in the first two steps.
      EXPECT_TRUE(a.attempts[k].status == BoxQpStatus::Stalled ||
                  a.attempts[k].status == BoxQpStatus::MaxIterationsReached)
          << "iteration " << i + 1 << ", attempt " << k + 1 << ": " << toString(a.attempts[k].status);
      EXPECT_GE(i, 2u);
    }
  }
  EXPECT_GT(skipped, 0);
  EXPECT_LT(admmSkipping, admmTried);
}

TEST_F(SubdivisionPq, DodecahedronFourPointAttemptsTooSlowForTheCapStopEarly) {
  // Level 1's second global step has an attempt whose primal residual falls ~2 % per 200
  // ADMM iterations at rho's clamp: it ran to the 4000-iteration cap (5 870 ADMM iterations
  // over both levels). It now stops as stalled once its rate cannot reach the tolerance
  // within the cap: 2 100, with the same eps per step.
  const PqSubdivisionResult result = twoLevels(generate::dodecahedron(), SubdivisionScheme::FourPoint);
  for (const PqLevelInfo& level : result.info.levels) EXPECT_LT(level.planarity.max, 0.05) << "level " << level.level;
  int admmIterations = 0;
  for (const auto& [level, attempt] : attemptsOf(result)) {
    EXPECT_NE(attempt.status, BoxQpStatus::MaxIterationsReached) << "level " << level;
    admmIterations += attempt.iterations;
  }
  EXPECT_LT(admmIterations, 3000);
}

TEST_F(SubdivisionPq, AttemptsFarFromOptimalAndTooSlowForTheCapStopEarlyOnATwoRingDome) {
  // Both levels have attempts whose dual residual, hundreds of times its tolerance, falls
  // too slowly to meet it within the cap: they ran on (7 700 ADMM iterations over both
  // levels, the same number of local/global iterations) until they stalled or hit the cap.
  // They now stop at their first window that shows it (AdmmSettings::farDualFactor): 4 570.
  const PqSubdivisionResult result = twoLevels(generate::hexagonalDome(2), SubdivisionScheme::FourPoint, 1.0);
  EXPECT_LE(result.info.totalIterations, 3);
  for (const PqLevelInfo& level : result.info.levels) EXPECT_LT(level.planarity.max, 0.5) << "level " << level.level;
  int admmIterations = 0;
  for (const auto& [level, attempt] : attemptsOf(result)) admmIterations += attempt.iterations;
  EXPECT_LT(admmIterations, 6000);
}

TEST_F(SubdivisionPq, TheCallbackSeesEveryIterationOfEveryLevelInOrder) {
  PqSubdivisionSettings settings;
  settings.levels = 2;
  std::vector<std::pair<int, int>> seen;
  std::vector<double> planarity;
  const PqSubdivisionResult result = subdividePlanarQuads(
      backend, generate::cube(1.0), settings, [&](int level, int iteration, const PqIteration& it) {
        seen.emplace_back(level, iteration);
        planarity.push_back(it.maxPlanarity);
      });
  std::vector<std::pair<int, int>> expected;
  std::vector<double> recorded;
  for (const PqLevelInfo& level : result.info.levels) {
    for (std::size_t i = 0; i < level.iterations.size(); ++i) {
      expected.emplace_back(level.level, static_cast<int>(i) + 1);
      recorded.push_back(level.iterations[i].maxPlanarity);
    }
  }
  EXPECT_EQ(seen, expected);
  EXPECT_EQ(planarity, recorded);
  EXPECT_EQ(static_cast<int>(seen.size()), result.info.totalIterations);
}

TEST_F(SubdivisionPq, CubeThreeFourPointLevelsEndBelowHalfAPercent) {
  PqSubdivisionSettings settings;
  settings.levels = 3;
  settings.scheme = SubdivisionScheme::FourPoint;
  settings.planarityTolerance = 0.5;
  const PolygonMesh cube = generate::cube(1.0);
  const PqSubdivisionResult result = subdividePlanarQuads(backend, cube, settings);
  EXPECT_EQ(result.info.status, PqSubdivisionStatus::Converged);
  for (const PqLevelInfo& level : result.info.levels) EXPECT_LT(level.planarity.max, 0.5) << "level " << level.level;
  // Measured: 0.55 % of the diagonal from the four-point surface.
  EXPECT_LT(relativeDistance(result.positions.back(), linearOnly(cube, SubdivisionScheme::FourPoint, 3)), 0.02);
}

TEST_F(SubdivisionPq, PlanarQuadSurfacesOfRevolutionAndTranslationStayPlanarAndOnTheLinearSurface) {
  // Both linear schemes map these conjugate nets to nets of the same kind, which are
  // planar: the iteration must leave them (nearly) untouched.
  for (const auto scheme : {SubdivisionScheme::CatmullClark, SubdivisionScheme::FourPoint}) {
    for (const PolygonMesh& mesh : {generate::surfaceOfRevolution(6, 2), generate::translationalSurface(4, 3)}) {
      PqSubdivisionSettings settings;
      settings.levels = 3;
      settings.scheme = scheme;
      const PqSubdivisionResult result = subdividePlanarQuads(backend, mesh, settings);
      for (const PqLevelInfo& level : result.info.levels) {
        EXPECT_LT(level.planarity.max, 0.1) << toString(scheme) << " level " << level.level;
      }
      EXPECT_LT(relativeDistance(result.positions.back(), linearOnly(mesh, scheme, 3)), 1e-6) << toString(scheme);
    }
  }
}

TEST_F(SubdivisionPq, PerspectiveWarpedPlanarQuadMeshesStayPlanarNearTheLinearSurface) {
  struct Case {
    PolygonMesh mesh;
    int levels;
  };
  // Measured: 0.08 % and 0.007 % of the diagonal from Catmull-Clark.
  const Case cases[] = {
      {perspectiveWarped(generate::translationalSurface(3, 3), {0.4, 0.3, 0.0}), 2},
      {perspectiveWarped(generate::surfaceOfRevolution(5, 2), {0.06, 0.0, 0.04}), 1},
  };
  for (const Case& c : cases) {
    PqSubdivisionSettings settings;
    settings.levels = c.levels;
    const PqSubdivisionResult result = subdividePlanarQuads(backend, c.mesh, settings);
    for (const PqLevelInfo& level : result.info.levels) EXPECT_LT(level.planarity.max, 0.1) << "level " << level.level;
    const Positions linear = linearOnly(c.mesh, SubdivisionScheme::CatmullClark, c.levels);
    EXPECT_LT(relativeDistance(result.positions.back(), linear), 2e-3);
  }
}

TEST_F(SubdivisionPq, LinearOnlySettingReturnsTheLinearScheme) {
  PqSubdivisionSettings settings;
  settings.levels = 2;
  settings.planarize = false;
  const PolygonMesh cube = generate::cube(1.0);
  const PqSubdivisionResult result = subdividePlanarQuads(backend, cube, settings);
  EXPECT_EQ(result.info.status, PqSubdivisionStatus::LinearOnly);
  EXPECT_EQ(result.info.totalIterations, 0);
  EXPECT_EQ(result.positions.back(), linearOnly(cube, SubdivisionScheme::CatmullClark, 2));
  EXPECT_NEAR(result.info.levels[0].planarity.max, 4.43, 0.006);
}

TEST_F(SubdivisionPq, LevelsThatCannotFitTheMemoryLimitAreRefusedBeforeAnyIsBuilt) {
  // Five linear levels of the cube: 6 144 faces, at least 250 B each (1.54 MB); planarized,
  // two levels: 96 faces, at least 2 KiB each (197 kB).
  const PolygonMesh cube = generate::cube(1.0);
  const auto refusal = [&](const PqSubdivisionSettings& settings) -> std::string {
    try {
      subdividePlanarQuads(backend, cube, settings);
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Numerical);
      return e.what();
    }
    return "";
  };
  PqSubdivisionSettings linear;
  linear.levels = 5;
  linear.planarize = false;
  linear.memoryLimitBytes = 1'500'000;
  EXPECT_NE(refusal(linear).find("out of memory: subdividing 6 faces 5 times (6144 faces at the finest level)"),
            std::string::npos)
      << refusal(linear);
  linear.memoryLimitBytes = 2'000'000;
  EXPECT_EQ(refusal(linear), "");
  PqSubdivisionSettings planarized;
  planarized.levels = 2;
  planarized.memoryLimitBytes = 150'000;
  EXPECT_NE(refusal(planarized).find("(96 faces at the finest level, planarized)"), std::string::npos)
      << refusal(planarized);
  planarized.memoryLimitBytes = 250'000;
  EXPECT_EQ(refusal(planarized), "");
}

TEST_F(SubdivisionPq, AnInputTooNonPlanarForTheBoundIsRejectedNamingItsWorstFace) {
  // Every face of a level is a projective image of its base face: from faces 2.6 % non-planar
  // after the trivial refinement no iteration reached 0.1 % (20 iterations at 2.65 %).
  const PolygonMesh hypar = generate::hyparGrid(4, 0.5);
  PqSubdivisionSettings settings;
  settings.maxIterationsPerLevel = 1;
  try {
    subdividePlanarQuads(backend, hypar, settings);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    const std::string message = e.what();
    EXPECT_NE(message.find("not planar enough"), std::string::npos) << message;
    EXPECT_NE(message.find("input face"), std::string::npos) << message;
  }
  // The linear scheme alone, and a bound above the base's planarity, take it.
  settings.planarize = false;
  EXPECT_NO_THROW(subdividePlanarQuads(backend, hypar, settings));
  settings.planarize = true;
  settings.planarityTolerance = 50.0;
  EXPECT_NO_THROW(subdividePlanarQuads(backend, hypar, settings));
}

TEST_F(SubdivisionPq, ALevelWhoseScheduleKeptItsTargetsGoesOnWithIntermediateAttempts) {
  PLANO_REQUIRE_SHARED_MESH(path, "double_torus_quads.off");
  const PolygonMesh torus = readMesh(path.string());
  PqSubdivisionSettings settings;
  settings.intermediateAttempts = 0;  // the paper's schedule: 0.185 % after 20 iterations
  settings.maxIterationsPerLevel = 12;
  const PqSubdivisionResult paper = subdividePlanarQuads(backend, torus, settings);
  EXPECT_EQ(paper.info.status, PqSubdivisionStatus::IterationLimit);
  EXPECT_GT(paper.info.levels[0].planarity.max, 0.15);
  for (const PqIteration& it : paper.info.levels[0].iterations) EXPECT_LE(it.attempts.size(), 3u);

  settings.intermediateAttempts = 3;
  const PqSubdivisionResult refined = subdividePlanarQuads(backend, torus, settings);
  EXPECT_EQ(refined.info.status, PqSubdivisionStatus::Converged);
  EXPECT_LE(refined.info.levels[0].planarity.max, 0.1);
  EXPECT_LT(refined.info.levels[0].distanceToLinear, 0.03);
  std::size_t attempts = 0;
  for (const PqIteration& it : refined.info.levels[0].iterations) attempts = std::max(attempts, it.attempts.size());
  EXPECT_GE(attempts, 4u);  // some step went past the paper's three

  settings.intermediateAttempts = -1;
  EXPECT_THROW(subdividePlanarQuads(backend, torus, settings), Error);
}

TEST_F(SubdivisionPq, ZeroLevelsReturnTheInputAndBadSettingsAreRejected) {
  PqSubdivisionSettings settings;
  settings.levels = 0;
  const PolygonMesh cube = generate::cube(1.0);
  const PqSubdivisionResult result = subdividePlanarQuads(backend, cube, settings);
  EXPECT_EQ(result.positions.size(), 1u);
  EXPECT_EQ(result.finestMesh().vertices, cube.vertices);
  settings.levels = -1;
  EXPECT_THROW(subdividePlanarQuads(backend, cube, settings), Error);
  settings.levels = 1;
  settings.planarityTolerance = 0.0;
  EXPECT_THROW(subdividePlanarQuads(backend, cube, settings), Error);
}

}  // namespace
}  // namespace plano::projective
