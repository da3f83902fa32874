#include "projective/MultiresConstraints.h"

#include <algorithm>

#include "core/Error.h"

namespace plano::projective {
namespace {

void checkVertex(Index v, Index count, const char* what) {
  if (v < 0 || v >= count) {
    throwBadInput(std::string(what) + " vertex " + std::to_string(v) + " does not exist on the finest level (" +
                  std::to_string(count) + " vertices)");
  }
}

void checkConstraints(const SubdivisionHierarchy& hierarchy, const PositionalConstraints& constraints) {
  const Index count = hierarchy.vertexCount(hierarchy.finestLevel());
  for (const Index v : constraints.fixed) checkVertex(v, count, "fixed");
  for (const Handle& h : constraints.handles) checkVertex(h.vertex, count, "handle");
}

/// Per handle: the ancestors on `level` of the finest faces around the handle vertex,
/// without repetitions.
std::vector<std::vector<Index>> attachedFaces(const SubdivisionHierarchy& hierarchy,
                                              const PositionalConstraints& constraints, int level) {
  const int finest = hierarchy.finestLevel();
  const FaceList& faces = hierarchy.faces(finest);
  const auto& ancestors = hierarchy.ancestorsOfFinestFaces(level);
  std::vector<Index> handleOf(hierarchy.vertexCount(finest), -1);
  for (std::size_t h = 0; h < constraints.handles.size(); ++h) {
    handleOf[constraints.handles[h].vertex] = static_cast<Index>(h);
  }
  std::vector<std::vector<Index>> attached(constraints.handles.size());
  for (Index f = 0; f < faces.size(); ++f) {
    for (const Index v : faces[f]) {
      if (handleOf[v] >= 0) attached[handleOf[v]].push_back(ancestors[f]);
    }
  }
  for (auto& list : attached) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return attached;
}

LevelCheck checkLevel(const SubdivisionHierarchy& hierarchy, const PositionalConstraints& constraints, int level) {
  LevelCheck check;
  check.level = level;
  if (level == hierarchy.finestLevel()) return check;  // handles are vertex constraints here
  const FaceList& faces = hierarchy.faces(level);
  std::vector<Index> handleOnFace(faces.size(), -1);
  const auto attached = attachedFaces(hierarchy, constraints, level);
  auto reject = [&](Index face, std::string reason) {
    check.admissible = false;
    check.conflictFace = face;
    check.reason = std::move(reason);
  };
  for (std::size_t h = 0; h < attached.size() && check.admissible; ++h) {
    for (const Index f : attached[h]) {
      if (handleOnFace[f] >= 0) {
        reject(f, "face " + std::to_string(f) + " carries handles " + std::to_string(handleOnFace[f]) + " and " +
                      std::to_string(h));
        break;
      }
      handleOnFace[f] = static_cast<Index>(h);
    }
  }
  if (!check.admissible) return check;
  std::vector<char> fixed(hierarchy.vertexCount(level), 0);
  for (const Index v : constraints.fixed) {
    if (v < hierarchy.vertexCount(level)) fixed[v] = 1;  // coarse counterparts keep their index
  }
  for (Index f = 0; f < faces.size(); ++f) {
    if (handleOnFace[f] < 0) continue;
    for (const Index v : faces[f]) {
      if (fixed[v]) {
        reject(f, "face " + std::to_string(f) + " carries handle " + std::to_string(handleOnFace[f]) +
                      " and fixed vertex " + std::to_string(v));
        return check;
      }
    }
  }
  return check;
}

}  // namespace

CoarseConstraints coarsenConstraints(const SubdivisionHierarchy& hierarchy, const Positions& finest,
                                     const PositionalConstraints& constraints, int level) {
  const int finestLevel = hierarchy.finestLevel();
  if (level < 0 || level > finestLevel) {
    throwUsage("coarsen constraints: level " + std::to_string(level) + " is outside the hierarchy (levels 0.." +
               std::to_string(finestLevel) + ")");
  }
  if (finest.rows() != hierarchy.vertexCount(finestLevel)) {
    throwUsage("coarsen constraints: " + std::to_string(finest.rows()) + " finest positions for " +
               std::to_string(hierarchy.vertexCount(finestLevel)) + " vertices");
  }
  checkConstraints(hierarchy, constraints);
  CoarseConstraints coarse;
  coarse.level = level;
  for (const Index v : constraints.fixed) {
    if (v < hierarchy.vertexCount(level)) coarse.fixed.push_back(v);
  }
  std::sort(coarse.fixed.begin(), coarse.fixed.end());
  const auto attached = attachedFaces(hierarchy, constraints, level);
  for (std::size_t h = 0; h < attached.size(); ++h) {
    for (const Index f : attached[h]) {
      MapPointConstraint c;
      c.face = f;
      c.handle = static_cast<Index>(h);
      c.point = finest.row(constraints.handles[h].vertex).transpose();
      c.target = constraints.handles[h].position;
      coarse.handles.push_back(c);
    }
  }
  return coarse;
}

std::vector<LevelCheck> checkDeformationLevels(const SubdivisionHierarchy& hierarchy,
                                               const PositionalConstraints& constraints) {
  checkConstraints(hierarchy, constraints);
  std::vector<LevelCheck> checks;
  for (int level = 0; level <= hierarchy.finestLevel(); ++level) {
    checks.push_back(checkLevel(hierarchy, constraints, level));
  }
  return checks;
}

int chooseDeformationLevel(const SubdivisionHierarchy& hierarchy, const PositionalConstraints& constraints) {
  for (const LevelCheck& check : checkDeformationLevels(hierarchy, constraints)) {
    if (check.admissible) return check.level;
  }
  return hierarchy.finestLevel();
}

}  // namespace plano::projective
