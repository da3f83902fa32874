#include "mesh/Validation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numeric>

#include "core/Error.h"

namespace plano {
namespace {

constexpr std::size_t kKindCount = static_cast<std::size_t>(ValidationIssueKind::IsolatedVertex) + 1;

/// Issues in check order, capped per kind; counts include the ones not stored.
class IssueCollector {
 public:
  explicit IssueCollector(std::size_t cap) : cap_(cap) {}

  /// Counts the issue; builds its message (makeMessage() -> std::string) and stores it
  /// only while the kind is under the cap.
  template <class MakeMessage>
  void add(ValidationIssueKind kind, Severity severity, Index face, Index vertex, const MakeMessage& makeMessage) {
    (severity == Severity::Error ? errors_ : warnings_)++;
    if (stored_[static_cast<std::size_t>(kind)]++ >= cap_) return;
    (severity == Severity::Error ? errorIssues_ : warningIssues_)
        .push_back({severity, kind, face, vertex, makeMessage()});
  }
  ValidationReport finish() {
    ValidationReport report;
    report.issues = std::move(errorIssues_);
    report.issues.insert(report.issues.end(), warningIssues_.begin(), warningIssues_.end());
    report.errorCount = errors_;
    report.warningCount = warnings_;
    report.status = errors_ > 0     ? ValidationStatus::Invalid
                    : warnings_ > 0 ? ValidationStatus::ValidWithWarnings
                                    : ValidationStatus::Valid;
    return report;
  }

 private:
  std::size_t cap_;
  std::array<std::size_t, kKindCount> stored_{};
  std::size_t errors_ = 0, warnings_ = 0;
  std::vector<ValidationIssue> errorIssues_, warningIssues_;
};

std::string number(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

std::string str(Index i) { return std::to_string(i); }

/// State shared by the checks: which vertices and faces are usable for the next checks.
struct Context {
  const PolygonMesh& mesh;
  const ValidationSettings& settings;
  IssueCollector& issues;
  std::vector<unsigned char> badVertex;          ///< Non-finite or huge coordinate.
  std::vector<unsigned char> brokenFace;         ///< Structural problem: skipped later.
  std::vector<unsigned char> touchesBrokenFace;  ///< Vertex (in range) of a broken face.
};

void checkCoordinates(Context& ctx) {
  const Positions& p = ctx.mesh.vertices;
  ctx.badVertex.assign(static_cast<std::size_t>(p.rows()), 0);
  static const char* axis[] = {"x", "y", "z"};
  for (Index v = 0; v < static_cast<Index>(p.rows()); ++v) {
    for (int a = 0; a < 3; ++a) {
      const double x = p(v, a);
      if (!std::isfinite(x)) {
        ctx.badVertex[v] = 1;
        ctx.issues.add(ValidationIssueKind::NonFiniteCoordinate, Severity::Error, -1, v, [&] {
          return "vertex " + str(v) + ": coordinate " + axis[a] + " is " + (std::isnan(x) ? "NaN" : "infinite");
        });
        break;
      }
      if (std::abs(x) > ctx.settings.maxCoordinateMagnitude) {
        ctx.badVertex[v] = 1;
        ctx.issues.add(ValidationIssueKind::HugeCoordinate, Severity::Error, -1, v, [&] {
          return std::string("vertex " + str(v) + ": coordinate " + axis[a] + " = " + number(x) + " exceeds " +
                             number(ctx.settings.maxCoordinateMagnitude) + " in magnitude");
        });
        break;
      }
    }
  }
}

void checkFaceStructure(Context& ctx) {
  const FaceList& faces = ctx.mesh.faces;
  const Index vertexCount = ctx.mesh.vertexCount();
  ctx.brokenFace.assign(static_cast<std::size_t>(faces.size()), 0);
  ctx.touchesBrokenFace.assign(static_cast<std::size_t>(vertexCount), 0);
  std::vector<Index> sorted;
  for (Index f = 0; f < faces.size(); ++f) {
    const auto face = faces[f];
    if (face.size() < 3) {
      ctx.brokenFace[f] = 1;
      ctx.issues.add(ValidationIssueKind::TooFewVertices, Severity::Error, f, -1, [&] {
        return std::string("face " + str(f) + " has " + std::to_string(face.size()) + " vertices (at least 3 needed)");
      });
    }
    const auto outside = std::find_if(face.begin(), face.end(), [&](Index v) { return v < 0 || v >= vertexCount; });
    if (outside != face.end()) {
      ctx.brokenFace[f] = 1;
      ctx.issues.add(ValidationIssueKind::IndexOutOfRange, Severity::Error, f, *outside, [&] {
        return std::string("face " + str(f) + ": vertex index " + str(*outside) + " out of range [0, " +
                           str(vertexCount) + ")");
      });
    }
    sorted.assign(face.begin(), face.end());
    std::sort(sorted.begin(), sorted.end());
    const auto repeated = std::adjacent_find(sorted.begin(), sorted.end());
    if (repeated != sorted.end()) {
      ctx.brokenFace[f] = 1;
      ctx.issues.add(ValidationIssueKind::RepeatedVertex, Severity::Error, f, *repeated,
                     [&] { return std::string("face " + str(f) + " repeats vertex " + str(*repeated)); });
    }
    if (ctx.brokenFace[f]) {
      for (Index v : face) {
        if (v >= 0 && v < vertexCount) ctx.touchesBrokenFace[v] = 1;
      }
    }
  }
}

void checkFaceGeometry(Context& ctx) {
  const FaceList& faces = ctx.mesh.faces;
  const Positions& p = ctx.mesh.vertices;
  for (Index f = 0; f < faces.size(); ++f) {
    if (ctx.brokenFace[f]) continue;
    const auto face = faces[f];
    if (std::any_of(face.begin(), face.end(), [&](Index v) { return ctx.badVertex[v] != 0; })) continue;
    const std::size_t n = face.size();
    auto point = [&](std::size_t k) -> Eigen::Vector3d { return p.row(face[k % n]).transpose(); };

    // Vector area about the centroid (less cancellation than about the origin).
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < n; ++k) centroid += point(k);
    centroid /= static_cast<double>(n);
    Eigen::Vector3d area = Eigen::Vector3d::Zero();
    double perimeter = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      area += (point(k) - centroid).cross(point(k + 1) - centroid);
      perimeter += (point(k + 1) - point(k)).norm();
    }
    if (0.5 * area.norm() <= ctx.settings.zeroAreaTolerance * perimeter * perimeter) {
      ctx.issues.add(ValidationIssueKind::ZeroAreaFace, Severity::Error, f, -1,
                     [&] { return std::string("face " + str(f) + " has zero area"); });
      continue;
    }
    const Severity severity = n <= 4 ? Severity::Error : Severity::Warning;
    // Coincident consecutive corners first: they also make every angle at them look collinear.
    bool coincident = false;
    for (std::size_t k = 0; k < n && !coincident; ++k) {
      if ((point(k + 1) - point(k)).squaredNorm() != 0.0) continue;
      coincident = true;
      ctx.issues.add(ValidationIssueKind::CollinearCorners, severity, f, face[(k + 1) % n], [&] {
        return "face " + str(f) + ": corners " + std::to_string(k) + " and " + std::to_string((k + 1) % n) +
               " (vertices " + str(face[k]) + ", " + str(face[(k + 1) % n]) + ") coincide";
      });
    }
    if (coincident) continue;
    for (std::size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d u = point(k) - point(k + 1);
      const Eigen::Vector3d w = point(k + 2) - point(k + 1);
      if (u.cross(w).norm() <= ctx.settings.collinearSineTolerance * u.norm() * w.norm()) {
        ctx.issues.add(ValidationIssueKind::CollinearCorners, severity, f, face[(k + 1) % n], [&] {
          return std::string("face " + str(f) + ": corners " + std::to_string(k) + ", " + std::to_string((k + 1) % n) +
                             ", " + std::to_string((k + 2) % n) + " (vertices " + str(face[k]) + ", " +
                             str(face[(k + 1) % n]) + ", " + str(face[(k + 2) % n]) + ") are collinear");
        });
        break;
      }
    }
  }
}

/// Non-manifold edges, inconsistent orientation and non-manifold vertices, over the
/// faces without structural problems.
void checkEdgesAndFans(Context& ctx) {
  const FaceList& faces = ctx.mesh.faces;
  const auto& offsets = faces.offsets();
  const auto& idx = faces.indices();
  const Index vertexCount = ctx.mesh.vertexCount();

  std::vector<Index> cornerFace(idx.size());
  std::vector<std::pair<std::uint64_t, Index>> keyed;
  keyed.reserve(idx.size());
  for (Index f = 0; f < faces.size(); ++f) {
    for (Index c = offsets[f]; c < offsets[f + 1]; ++c) cornerFace[c] = f;
    if (ctx.brokenFace[f]) continue;
    for (Index c = offsets[f]; c < offsets[f + 1]; ++c) {
      const Index next = c + 1 == offsets[f + 1] ? offsets[f] : c + 1;
      const auto a = static_cast<std::uint64_t>(idx[c]), b = static_cast<std::uint64_t>(idx[next]);
      keyed.push_back({(std::min(a, b) << 32) | std::max(a, b), c});
    }
  }
  std::sort(keyed.begin(), keyed.end());

  // Vertex-face incidences of the usable faces (CSR, faces increasing per vertex).
  std::vector<Index> incidenceOffsets(static_cast<std::size_t>(vertexCount) + 1, 0);
  for (Index f = 0; f < faces.size(); ++f) {
    if (ctx.brokenFace[f]) continue;
    for (Index v : faces[f]) ++incidenceOffsets[v + 1];
  }
  std::partial_sum(incidenceOffsets.begin(), incidenceOffsets.end(), incidenceOffsets.begin());
  std::vector<Index> incidenceFaces(static_cast<std::size_t>(incidenceOffsets.back()));
  {
    std::vector<Index> fill(incidenceOffsets.begin(), incidenceOffsets.end() - 1);
    for (Index f = 0; f < faces.size(); ++f) {
      if (ctx.brokenFace[f]) continue;
      for (Index v : faces[f]) incidenceFaces[fill[v]++] = f;
    }
  }
  auto incidence = [&](Index v, Index f) {
    const auto first = incidenceFaces.begin() + incidenceOffsets[v];
    const auto last = incidenceFaces.begin() + incidenceOffsets[v + 1];
    return static_cast<Index>(std::lower_bound(first, last, f) - incidenceFaces.begin());
  };
  std::vector<Index> parent(incidenceFaces.size());
  std::iota(parent.begin(), parent.end(), Index{0});
  auto find = [&](Index x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };

  for (std::size_t begin = 0; begin < keyed.size();) {
    std::size_t end = begin + 1;
    while (end < keyed.size() && keyed[end].first == keyed[begin].first) ++end;
    const Index c0 = keyed[begin].second;
    const Index f0 = cornerFace[c0];
    const Index a = static_cast<Index>(keyed[begin].first >> 32);
    const Index b = static_cast<Index>(keyed[begin].first & 0xffffffffu);
    const std::string edge = "edge (" + str(a) + ", " + str(b) + ")";
    if (end - begin > 2) {
      ctx.issues.add(ValidationIssueKind::NonManifoldEdge, Severity::Error, f0, -1, [&] {
        std::string list;
        for (std::size_t i = begin; i < end; ++i) list += (i == begin ? "" : ", ") + str(cornerFace[keyed[i].second]);
        return edge + " is shared by " + std::to_string(end - begin) + " faces (" + list + "): non-manifold edge";
      });
    } else if (end - begin == 2) {
      const Index c1 = keyed[begin + 1].second;
      if (idx[c0] == idx[c1]) {
        const Index f1 = cornerFace[c1];
        ctx.issues.add(ValidationIssueKind::InconsistentOrientation, Severity::Error, f1, -1, [&] {
          return std::string(edge + ": faces " + str(f0) + " and " + str(f1) + " both traverse it from " +
                             str(idx[c0]) + " to " + str(idx[c0] == a ? b : a) + " (inconsistent orientation)");
        });
      }
    }
    // Every face on the edge belongs to the same fan at both of its end vertices.
    for (std::size_t i = begin + 1; i < end; ++i) {
      const Index fi = cornerFace[keyed[i].second];
      for (Index v : {a, b}) {
        const Index x = find(incidence(v, f0)), y = find(incidence(v, fi));
        if (x != y) parent[std::max(x, y)] = std::min(x, y);
      }
    }
    begin = end;
  }

  for (Index v = 0; v < vertexCount; ++v) {
    if (ctx.touchesBrokenFace[v]) continue;  // a missing face would split its fan
    Index fans = 0;
    for (Index i = incidenceOffsets[v]; i < incidenceOffsets[v + 1]; ++i) fans += find(i) == i;
    if (fans > 1) {
      ctx.issues.add(ValidationIssueKind::NonManifoldVertex, Severity::Error, -1, v, [&] {
        return std::string("vertex " + str(v) + " is non-manifold: its faces form " + str(fans) + " separate fans");
      });
    }
  }
}

void checkDuplicateFaces(Context& ctx) {
  const FaceList& faces = ctx.mesh.faces;
  // Sorted copy of every face's vertices (CSR with the faces' offsets).
  std::vector<Index> sorted = faces.indices();
  const auto& offsets = faces.offsets();
  for (Index f = 0; f < faces.size(); ++f) std::sort(sorted.begin() + offsets[f], sorted.begin() + offsets[f + 1]);
  auto key = [&](Index f) { return std::span<const Index>(sorted.data() + offsets[f], faces[f].size()); };
  std::vector<Index> order;
  for (Index f = 0; f < faces.size(); ++f) {
    if (!ctx.brokenFace[f]) order.push_back(f);
  }
  std::stable_sort(order.begin(), order.end(), [&](Index f, Index g) {
    const auto a = key(f), b = key(g);
    if (a.size() != b.size()) return a.size() < b.size();
    return std::lexicographical_compare(a.begin(), a.end(), b.begin(), b.end());
  });
  for (std::size_t i = 1; i < order.size(); ++i) {
    const auto a = key(order[i - 1]), b = key(order[i]);
    if (a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin())) {
      // stable_sort keeps equal faces in increasing order: name the later one, and leave
      // it out of the edge checks (its edges would all look non-manifold or misoriented).
      // Its vertices keep their fans: the first copy is still there.
      ctx.brokenFace[order[i]] = 1;
      ctx.issues.add(ValidationIssueKind::DuplicateFace, Severity::Error, order[i], -1, [&] {
        return std::string("face " + str(order[i]) + " duplicates face " + str(order[i - 1]) + " (same vertices)");
      });
    }
  }
}

void checkIsolatedVertices(Context& ctx) {
  const Index vertexCount = ctx.mesh.vertexCount();
  std::vector<unsigned char> used(static_cast<std::size_t>(vertexCount), 0);
  for (Index v : ctx.mesh.faces.indices()) {
    if (v >= 0 && v < vertexCount) used[v] = 1;
  }
  for (Index v = 0; v < vertexCount; ++v) {
    if (!used[v]) {
      ctx.issues.add(ValidationIssueKind::IsolatedVertex, Severity::Warning, -1, v,
                     [&] { return std::string("vertex " + str(v) + " is isolated (in no face)"); });
    }
  }
}

}  // namespace

const char* toString(ValidationIssueKind kind) {
  switch (kind) {
    case ValidationIssueKind::IndexOutOfRange: return "index_out_of_range";
    case ValidationIssueKind::TooFewVertices: return "too_few_vertices";
    case ValidationIssueKind::RepeatedVertex: return "repeated_vertex";
    case ValidationIssueKind::NonFiniteCoordinate: return "non_finite_coordinate";
    case ValidationIssueKind::HugeCoordinate: return "huge_coordinate";
    case ValidationIssueKind::NonManifoldEdge: return "non_manifold_edge";
    case ValidationIssueKind::NonManifoldVertex: return "non_manifold_vertex";
    case ValidationIssueKind::InconsistentOrientation: return "inconsistent_orientation";
    case ValidationIssueKind::ZeroAreaFace: return "zero_area_face";
    case ValidationIssueKind::CollinearCorners: return "collinear_corners";
    case ValidationIssueKind::DuplicateFace: return "duplicate_face";
    case ValidationIssueKind::IsolatedVertex: return "isolated_vertex";
  }
  return "unknown";
}

const char* toString(Severity severity) { return severity == Severity::Error ? "error" : "warning"; }

ValidationReport validate(const PolygonMesh& mesh, const ValidationSettings& settings) {
  IssueCollector issues(settings.maxIssuesPerKind);
  Context ctx{mesh, settings, issues, {}, {}, {}};
  checkCoordinates(ctx);
  checkFaceStructure(ctx);
  checkDuplicateFaces(ctx);
  checkEdgesAndFans(ctx);
  checkFaceGeometry(ctx);
  checkIsolatedVertices(ctx);
  return issues.finish();
}

void requireValid(const PolygonMesh& mesh, const std::string& source, const ValidationSettings& settings) {
  requireValid(validate(mesh, settings), source);
}

void requireValid(const ValidationReport& report, const std::string& source) {
  if (report.valid()) return;
  constexpr std::size_t kShown = 3;
  std::string message = source + ": ";
  std::size_t shown = 0;
  for (const auto& issue : report.issues) {
    if (issue.severity != Severity::Error || shown == kShown) continue;
    message += (shown++ ? "; " : "") + issue.message;
  }
  if (report.errorCount > shown) message += " (and " + std::to_string(report.errorCount - shown) + " more errors)";
  throwBadInput(message);
}

}  // namespace plano
