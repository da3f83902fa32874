#pragma once
// Parametric generators of polygon meshes of any size, for the demo, tests and
// benchmarks. Unless said otherwise, the faces are exactly planar (up to rounding).
#include <string>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano::generate {

/// Translational surface x(u, v) = a(u) + b(v) over a (nu x nv)-quad grid: every quad is
/// a parallelogram, hence planar. a and b are sine-modulated profile curves of the
/// given amplitude; the grid spans [0, 1] x [0, 1] in the xy-plane.
PolygonMesh translationalSurface(Index nu, Index nv, double amplitude = 0.2);

/// Surface of revolution around z: `around` quads around the axis (closed in that
/// direction) and `along` quads along the meridian r(t) = radius * (1 + 0.3 sin(pi t)),
/// z(t) = height * t. Quads between two meridians and two parallels are planar trapezoids.
PolygonMesh surfaceOfRevolution(Index around, Index along, double radius = 1.0, double height = 2.0);

/// Non-planar grid on the hyperbolic paraboloid z = twist * x * y over [-1, 1]^2
/// (n x n quads): input for planarization and subdivision.
PolygonMesh hyparGrid(Index n, double twist = 0.5);

/// Axis-aligned cube of the given edge length centred at the origin: 8 vertices, 6 quads,
/// outward orientation.
PolygonMesh cube(double size = 1.0);

/// Regular dodecahedron centred at the origin with circumradius 1: a closed mesh with
/// 3-valent vertices and 12 planar pentagons.
PolygonMesh dodecahedron();

/// Planar-hexagon mesh approximating a spherical cap: each hexagon lies in the tangent
/// plane of the sphere at a point of a triangular lattice, and each vertex is the common
/// point of three such planes. `rings` hexagon rings around the centre hexagon;
/// `capAngle` is the polar angle (radians) spanned by the lattice.
PolygonMesh hexagonalDome(Index rings, double capAngle = 1.0);

/// Flat hexagonal tiling (regular hexagons in the xy-plane) with `rings` rings around a
/// centre hexagon.
PolygonMesh hexagonalPlane(Index rings);

/// The generator kinds known to `plano generate`, with a one-line description each.
struct GeneratorInfo {
  std::string name;
  std::string description;
};
const std::vector<GeneratorInfo>& generatorKinds();

/// Build a mesh of a named kind with a resolution parameter `n` (quads per side, rings,
/// ...); the meaning of n per kind is in generatorKinds(). Throws Error(Usage) for an
/// unknown kind or n out of range.
PolygonMesh byName(const std::string& kind, Index n);

}  // namespace plano::generate
