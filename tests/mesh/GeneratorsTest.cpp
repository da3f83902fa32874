#include "mesh/Generators.h"

#include <gtest/gtest.h>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"

namespace plano {
namespace {

double maxPlanarity(const PolygonMesh& mesh) { return planarityStats(mesh).max; }

TEST(Generators, TranslationalSurfaceHasPlanarQuads) {
  const PolygonMesh mesh = generate::translationalSurface(12, 9);
  EXPECT_EQ(mesh.faceCount(), 12 * 9);
  EXPECT_EQ(mesh.vertexCount(), 13 * 10);
  EXPECT_LT(maxPlanarity(mesh), 1e-10);
}

TEST(Generators, SurfaceOfRevolutionHasPlanarQuadsAndClosesAroundTheAxis) {
  const PolygonMesh mesh = generate::surfaceOfRevolution(16, 6);
  EXPECT_EQ(mesh.faceCount(), 16 * 6);
  EXPECT_EQ(mesh.vertexCount(), 16 * 7);
  EXPECT_LT(maxPlanarity(mesh), 1e-10);
}

TEST(Generators, HyparGridIsNotPlanar) {
  EXPECT_GT(maxPlanarity(generate::hyparGrid(8, 0.5)), 0.1);
}

TEST(Generators, CubeAndDodecahedronArePlanarClosedPolyhedra) {
  const PolygonMesh c = generate::cube(2.0);
  EXPECT_EQ(c.vertexCount(), 8);
  EXPECT_EQ(c.faceCount(), 6);
  EXPECT_LT(maxPlanarity(c), 1e-12);
  const PolygonMesh d = generate::dodecahedron();
  EXPECT_EQ(d.vertexCount(), 20);
  EXPECT_EQ(d.faceCount(), 12);
  EXPECT_EQ(d.faces.maxDegree(), 5);
  EXPECT_LT(maxPlanarity(d), 1e-10);
  // Euler characteristic of a sphere: V - E + F = 2 with E = corners / 2.
  EXPECT_EQ(d.vertexCount() - d.faces.cornerCount() / 2 + d.faceCount(), 2);
  EXPECT_EQ(c.vertexCount() - c.faces.cornerCount() / 2 + c.faceCount(), 2);
}

TEST(Generators, HexagonalDomeHasPlanarHexagonsOnTangentPlanes) {
  const PolygonMesh mesh = generate::hexagonalDome(3);
  EXPECT_EQ(mesh.faceCount(), 1 + 6 + 12 + 18);
  EXPECT_EQ(mesh.faces.maxDegree(), 6);
  EXPECT_LT(maxPlanarity(mesh), 1e-9);
  // Not flat: the dome has height.
  EXPECT_GT(mesh.vertices.col(2).maxCoeff() - mesh.vertices.col(2).minCoeff(), 0.1);
}

TEST(Generators, HexagonalPlaneIsFlat) {
  const PolygonMesh mesh = generate::hexagonalPlane(2);
  EXPECT_EQ(mesh.faceCount(), 19);
  EXPECT_LT(mesh.vertices.col(2).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(Generators, UnknownKindIsAUsageError) {
  try {
    generate::byName("klein-bottle", 4);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
    EXPECT_NE(std::string(e.what()).find("klein-bottle"), std::string::npos);
  }
}

}  // namespace
}  // namespace plano

namespace plano {
namespace {

/// Clears a cancellation request when the test ends, whatever happens in it.
struct CancellationRequested {
  CancellationRequested() { requestCancellation(); }
  ~CancellationRequested() { clearCancellation(); }
};

TEST(Generators, GeneratingMeasuringAndFormattingAMeshStopAtARequestedCancellation) {
  // Loops over millions of elements take seconds each (plano generate -n 3000): a Ctrl-C
  // is looked at inside them, not after them.
  const PolygonMesh mesh = generate::translationalSurface(4, 4);
  const PolygonMesh hexagons = generate::hexagonalPlane(2);
  const CancellationRequested cancelled;
  EXPECT_THROW(generate::translationalSurface(4, 4), Interrupted);
  EXPECT_THROW(generate::hexagonalPlane(2), Interrupted);
  EXPECT_THROW(planarityStats(mesh), Interrupted);
  for (const MeshFormat format : {MeshFormat::Obj, MeshFormat::Off, MeshFormat::Ply}) {
    EXPECT_THROW(formatMesh(hexagons, format), Interrupted) << static_cast<int>(format);
  }
}

}  // namespace
}  // namespace plano
