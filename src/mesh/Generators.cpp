#include "mesh/Generators.h"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <map>
#include <numbers>

#include "core/Cancellation.h"
#include "core/Error.h"

namespace plano::generate {
namespace {

constexpr double kPi = std::numbers::pi;

/// Quad grid faces over an (nu+1) x (nv+1) vertex lattice, vertex (i, j) = i * (nv + 1) + j,
/// oriented counter-clockwise seen from +z for an xy-grid.
FaceList gridFaces(Index nu, Index nv, bool wrapU) {
  FaceList faces;
  const Index rows = nv + 1;
  const Index uVertices = wrapU ? nu : nu + 1;
  faces.reserve(static_cast<std::size_t>(nu) * nv, static_cast<std::size_t>(nu) * nv * 4);
  for (Index i = 0; i < nu; ++i) {
    throwIfCancelled("generating the mesh");
    const Index i1 = (i + 1) % uVertices;
    for (Index j = 0; j < nv; ++j) {
      faces.addFace({i * rows + j, i1 * rows + j, i1 * rows + j + 1, i * rows + j + 1});
    }
  }
  return faces;
}

void requireAtLeast(Index n, Index minimum, const char* what) {
  if (n < minimum) {
    throwUsage(std::string(what) + " must be at least " + std::to_string(minimum) + " (got " + std::to_string(n) + ")");
  }
}

}  // namespace

PolygonMesh translationalSurface(Index nu, Index nv, double amplitude) {
  requireAtLeast(nu, 1, "translational surface: quads along u");
  requireAtLeast(nv, 1, "translational surface: quads along v");
  PolygonMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(nu + 1) * (nv + 1), 3);
  for (Index i = 0; i <= nu; ++i) {
    throwIfCancelled("generating the mesh");
    const double u = static_cast<double>(i) / nu;
    const Eigen::Vector3d a(u, 0.0, amplitude * std::sin(kPi * u));
    for (Index j = 0; j <= nv; ++j) {
      const double v = static_cast<double>(j) / nv;
      const Eigen::Vector3d b(0.1 * amplitude * std::sin(2.0 * kPi * v), v, amplitude * std::sin(kPi * v) * 0.7);
      mesh.vertices.row(i * (nv + 1) + j) = (a + b).transpose();
    }
  }
  mesh.faces = gridFaces(nu, nv, false);
  return mesh;
}

PolygonMesh surfaceOfRevolution(Index around, Index along, double radius, double height) {
  requireAtLeast(around, 3, "surface of revolution: quads around the axis");
  requireAtLeast(along, 1, "surface of revolution: quads along the meridian");
  PolygonMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(around) * (along + 1), 3);
  for (Index i = 0; i < around; ++i) {
    const double theta = 2.0 * kPi * i / around;
    for (Index j = 0; j <= along; ++j) {
      const double t = static_cast<double>(j) / along;
      const double r = radius * (1.0 + 0.3 * std::sin(kPi * t));
      mesh.vertices.row(i * (along + 1) + j) << r * std::cos(theta), r * std::sin(theta), height * t;
    }
  }
  mesh.faces = gridFaces(around, along, true);
  return mesh;
}

PolygonMesh hyparGrid(Index n, double twist) {
  requireAtLeast(n, 1, "hypar grid: quads per side");
  PolygonMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(n + 1) * (n + 1), 3);
  for (Index i = 0; i <= n; ++i) {
    const double x = -1.0 + 2.0 * i / n;
    for (Index j = 0; j <= n; ++j) {
      const double y = -1.0 + 2.0 * j / n;
      mesh.vertices.row(i * (n + 1) + j) << x, y, twist * x * y;
    }
  }
  mesh.faces = gridFaces(n, n, false);
  return mesh;
}

PolygonMesh cube(double size) {
  PolygonMesh mesh;
  const double h = 0.5 * size;
  mesh.vertices.resize(8, 3);
  for (Index i = 0; i < 8; ++i) {
    mesh.vertices.row(i) << ((i & 1) ? h : -h), ((i & 2) ? h : -h), ((i & 4) ? h : -h);
  }
  // Outward-oriented faces (counter-clockwise seen from outside).
  mesh.faces = FaceList({{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}});
  return mesh;
}

PolygonMesh dodecahedron() {
  // The dodecahedron is the polar dual of the icosahedron: one vertex per icosahedron face
  // (its normalized centroid), one pentagon per icosahedron vertex.
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> ico = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0},
                                      {0, -1, phi}, {0, 1, phi}, {0, -1, -phi}, {0, 1, -phi},
                                      {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
  const std::vector<std::array<Index, 3>> icoFaces = {
      {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},   {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  PolygonMesh mesh;
  mesh.vertices.resize(20, 3);
  for (std::size_t t = 0; t < icoFaces.size(); ++t) {
    Eigen::Vector3d c = (ico[icoFaces[t][0]] + ico[icoFaces[t][1]] + ico[icoFaces[t][2]]) / 3.0;
    mesh.vertices.row(static_cast<Index>(t)) = c.normalized().transpose();
  }
  // For each icosahedron vertex, order its five incident triangles around it.
  for (Index v = 0; v < 12; ++v) {
    std::vector<Index> ring;
    for (std::size_t t = 0; t < icoFaces.size(); ++t) {
      for (Index k = 0; k < 3; ++k) {
        if (icoFaces[t][k] == v) ring.push_back(static_cast<Index>(t));
      }
    }
    const Eigen::Vector3d axis = ico[v].normalized();
    const Eigen::Vector3d e1 = axis.unitOrthogonal();
    const Eigen::Vector3d e2 = axis.cross(e1);
    std::sort(ring.begin(), ring.end(), [&](Index a, Index b) {
      const Eigen::Vector3d pa = mesh.vertices.row(a).transpose();
      const Eigen::Vector3d pb = mesh.vertices.row(b).transpose();
      return std::atan2(pa.dot(e2), pa.dot(e1)) < std::atan2(pb.dot(e2), pb.dot(e1));
    });
    mesh.faces.addFace(std::span<const Index>(ring));
  }
  return mesh;
}

namespace {

/// Lattice points of a hexagonal patch: axial coordinates (q, r) with |q|, |r|, |q+r| <= R.
struct Lattice {
  std::map<std::pair<Index, Index>, Index> index;
  std::vector<std::pair<Index, Index>> coords;
};

Lattice hexLattice(Index R) {
  Lattice lattice;
  for (Index q = -R; q <= R; ++q) {
    throwIfCancelled("generating the mesh");
    for (Index r = -R; r <= R; ++r) {
      if (std::abs(q + r) > R) continue;
      lattice.index[{q, r}] = static_cast<Index>(lattice.coords.size());
      lattice.coords.emplace_back(q, r);
    }
  }
  return lattice;
}

/// Hexagon mesh dual to the triangulated lattice: a vertex per lattice triangle, a hexagon
/// per interior lattice point. `vertexOf(a, b, c)` places the vertex of triangle abc.
template <class VertexOf>
PolygonMesh hexagonsFromLattice(Index rings, VertexOf vertexOf) {
  const Index R = rings + 1;  // lattice radius: interior points are the hexagon centres
  const Lattice lattice = hexLattice(R);
  // The six neighbours of a lattice point, counter-clockwise.
  const std::array<std::pair<Index, Index>, 6> dirs = {{{1, 0}, {0, 1}, {-1, 1}, {-1, 0}, {0, -1}, {1, -1}}};
  std::map<std::array<Index, 3>, Index> triangleVertex;
  std::vector<Eigen::Vector3d> points;
  PolygonMesh mesh;
  long long point = 0;
  for (const auto& [q, r] : lattice.coords) {
    throwIfCancelledAt(point++, "generating the mesh");
    if (std::abs(q) >= R || std::abs(r) >= R || std::abs(q + r) >= R) continue;  // boundary point
    const Index centre = lattice.index.at({q, r});
    std::vector<Index> face;
    for (Index k = 0; k < 6; ++k) {
      const auto [dq1, dr1] = dirs[k];
      const auto [dq2, dr2] = dirs[(k + 1) % 6];
      const Index a = lattice.index.at({q + dq1, r + dr1});
      const Index b = lattice.index.at({q + dq2, r + dr2});
      std::array<Index, 3> key = {centre, a, b};
      std::sort(key.begin(), key.end());
      auto it = triangleVertex.find(key);
      if (it == triangleVertex.end()) {
        it = triangleVertex.emplace(key, static_cast<Index>(points.size())).first;
        points.push_back(vertexOf(lattice.coords[centre], lattice.coords[a], lattice.coords[b]));
      }
      face.push_back(it->second);
    }
    mesh.faces.addFace(std::span<const Index>(face));
  }
  mesh.vertices.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) mesh.vertices.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  return mesh;
}

Eigen::Vector2d latticePoint(std::pair<Index, Index> c) {
  return {c.first + 0.5 * c.second, std::sqrt(3.0) / 2.0 * c.second};
}

}  // namespace

PolygonMesh hexagonalPlane(Index rings) {
  requireAtLeast(rings, 0, "hexagonal plane: rings");
  return hexagonsFromLattice(rings, [](auto a, auto b, auto c) {
    const Eigen::Vector2d m = (latticePoint(a) + latticePoint(b) + latticePoint(c)) / 3.0;
    return Eigen::Vector3d(m.x(), m.y(), 0.0);
  });
}

PolygonMesh hexagonalDome(Index rings, double capAngle) {
  requireAtLeast(rings, 0, "hexagonal dome: rings");
  if (!(capAngle > 0.0 && capAngle < kPi / 2.0)) throwUsage("hexagonal dome: cap angle must be in (0, pi/2)");
  const double R = static_cast<double>(rings + 1);
  // Unit-sphere point of a lattice point: the lattice radius maps to the polar angle capAngle.
  auto spherePoint = [&](std::pair<Index, Index> c) {
    const Eigen::Vector2d p = latticePoint(c);
    const double rho = p.norm();
    const double polar = capAngle * rho / R;
    const Eigen::Vector2d dir = rho > 0.0 ? Eigen::Vector2d(p / rho) : Eigen::Vector2d(1.0, 0.0);
    return Eigen::Vector3d(std::sin(polar) * dir.x(), std::sin(polar) * dir.y(), std::cos(polar));
  };
  return hexagonsFromLattice(rings, [&](auto a, auto b, auto c) {
    // Common point of the three tangent planes n . x = 1.
    Eigen::Matrix3d normals;
    normals.row(0) = spherePoint(a).transpose();
    normals.row(1) = spherePoint(b).transpose();
    normals.row(2) = spherePoint(c).transpose();
    return Eigen::Vector3d(normals.partialPivLu().solve(Eigen::Vector3d::Ones()));
  });
}

const std::vector<GeneratorInfo>& generatorKinds() {
  static const std::vector<GeneratorInfo> kinds = {
      {"translational", "translational surface, n x n planar quads"},
      {"revolution", "surface of revolution, 2n around x n along, planar quads"},
      {"hypar", "hyperbolic paraboloid grid, n x n non-planar quads"},
      {"cube", "cube, 6 quads (n ignored)"},
      {"dodecahedron", "dodecahedron, 12 pentagons, 3-valent (n ignored)"},
      {"hexdome", "planar hexagons on a spherical cap, n rings"},
      {"hexplane", "flat regular hexagons, n rings"},
  };
  return kinds;
}

PolygonMesh byName(const std::string& kind, Index n) {
  if (kind == "translational") return translationalSurface(n, n);
  if (kind == "revolution") return surfaceOfRevolution(2 * n, n);
  if (kind == "hypar") return hyparGrid(n);
  if (kind == "cube") return cube();
  if (kind == "dodecahedron") return dodecahedron();
  if (kind == "hexdome") return hexagonalDome(n);
  if (kind == "hexplane") return hexagonalPlane(n);
  std::string known;
  for (const auto& k : generatorKinds()) known += (known.empty() ? "" : ", ") + k.name;
  throwUsage("unknown mesh kind '" + kind + "' (known: " + known + ")");
}

}  // namespace plano::generate
