// Strict streaming OBJ reader and exact writer (why not OpenMesh: see ObjFormat.h).
#include "mesh/io/ObjFormat.h"

#include <array>
#include <cstdint>

#include "mesh/io/MeshAssembly.h"
#include "mesh/io/TextCursor.h"
#include "mesh/io/TextWriter.h"

namespace plano::io {
namespace {

/// Statements that carry no polygon data (attributes, grouping, free-form geometry).
bool isSkippedStatement(std::string_view keyword) {
  static constexpr std::string_view kSkipped[] = {
      "vt",       "vn",     "vp",     "g",      "o",          "s",         "usemtl", "mtllib", "l",
      "p",        "cstype", "deg",    "bmat",   "step",       "curv",      "curv2",  "surf",   "parm",
      "trim",     "hole",   "scrv",   "sp",     "end",        "con",       "mg",     "bevel",  "c_interp",
      "d_interp", "lod",    "maplib", "usemap", "shadow_obj", "trace_obj", "ctech",  "stech"};
  for (auto k : kSkipped) {
    if (k == keyword) return true;
  }
  return false;
}

class ObjParser {
 public:
  ObjParser(std::string_view text, const std::string& source, std::vector<std::string>* warnings)
      : cursor_(text, source), warnings_(warnings) {}

  PolygonMesh parse() {
    while (!cursor_.atEnd()) {
      std::string_view keyword;
      next(keyword);
      if (keyword == "v") {
        parseVertex();
      } else if (keyword == "f" || keyword == "fo") {
        parseFace();
      } else if (isSkippedStatement(keyword)) {
        skipStatement();
      } else {
        if (warnings_ && unknownStatements_++ < 10) {
          warnings_->push_back(cursor_.source() + ":" + std::to_string(cursor_.line()) + ": unknown statement " +
                               quotedToken(keyword) + " ignored");
        }
        skipStatement();
      }
    }
    checkIndices();
    return assembleMesh(coordinates_, std::move(faces_));
  }

 private:
  /// Next token of the current statement, following '\' continuation lines.
  bool next(std::string_view& token) {
    while (cursor_.tokenOnLine(token)) {
      if (token != "\\") return true;
      std::string_view after;
      if (cursor_.tokenOnLine(after)) cursor_.fail("'\\' must end the line to continue a statement");
      cursor_.skipLine();
    }
    return false;
  }

  void skipStatement() {
    std::string_view token;
    while (next(token)) {
    }
    cursor_.skipLine();
  }

  void parseVertex() {
    std::array<double, 3> p{};
    std::string_view token;
    int count = 0;
    while (next(token)) {
      const double value = cursor_.toDouble(token, "vertex coordinate");
      if (count < 3) p[count] = value;
      ++count;
    }
    // x y z, x y z w (rational weight), x y z r g b, x y z r g b a.
    if (count < 3) cursor_.fail("vertex has " + std::to_string(count) + " coordinates (3 needed)");
    if (count > 7) cursor_.fail("vertex has " + std::to_string(count) + " values (at most 7: x y z and a colour)");
    if (static_cast<std::int64_t>(coordinates_.size() / 3) >= kMaxCount) cursor_.fail("too many vertices");
    coordinates_.insert(coordinates_.end(), p.begin(), p.end());
    cursor_.skipLine();
  }

  /// The vertex index of a face token "i", "i/t", "i//n" or "i/t/n", 0-based.
  Index vertexIndex(std::string_view token) {
    const auto slash = token.find('/');
    const std::string_view head = token.substr(0, slash);
    if (slash != std::string_view::npos) {
      // Texture and normal indices are not used, but must be well formed.
      std::string_view rest = token.substr(slash + 1);
      const auto second = rest.find('/');
      std::string_view parts[2] = {rest.substr(0, second),
                                   second == std::string_view::npos ? std::string_view{} : rest.substr(second + 1)};
      if (second != std::string_view::npos && parts[1].find('/') != std::string_view::npos) {
        cursor_.fail("face corner " + quotedToken(token) + " has more than three '/'-separated parts");
      }
      for (auto part : parts) {
        if (!part.empty()) cursor_.toInteger(part, "texture/normal index");
      }
    }
    const std::int64_t raw = cursor_.toInteger(head, "vertex index");
    const auto defined = static_cast<std::int64_t>(coordinates_.size() / 3);
    if (raw == 0) cursor_.fail("vertex index 0 is invalid (OBJ indices start at 1)");
    if (raw < 0) {
      const std::int64_t resolved = defined + raw;
      if (resolved < 0) {
        cursor_.fail("relative vertex index " + std::to_string(raw) + " refers before the first vertex (" +
                     std::to_string(defined) + " vertices defined so far)");
      }
      return static_cast<Index>(resolved);
    }
    if (raw > kMaxCount) cursor_.fail("vertex index " + std::to_string(raw) + " is too large");
    // Checked against the final vertex count once the whole file is read.
    return static_cast<Index>(raw - 1);
  }

  void parseFace() {
    const std::size_t line = cursor_.line();
    face_.clear();
    std::string_view token;
    while (next(token)) face_.push_back(vertexIndex(token));
    if (face_.size() < 3) {
      cursor_.fail("face has " + std::to_string(face_.size()) + " vertices (at least 3 needed)");
    }
    if (static_cast<std::int64_t>(faces_.cornerCount()) + static_cast<std::int64_t>(face_.size()) > kMaxCount) {
      cursor_.fail("too many face corners");
    }
    faces_.addFace(std::span<const Index>(face_));
    faceLines_.push_back(line);
    cursor_.skipLine();
  }

  void checkIndices() const {
    const auto vertexCount = static_cast<Index>(coordinates_.size() / 3);
    for (Index f = 0; f < faces_.size(); ++f) {
      for (Index v : faces_[f]) {
        if (v >= vertexCount) {
          cursor_.failAt(faceLines_[f], "face " + std::to_string(f) + ": vertex index " + std::to_string(v + 1) +
                                            " out of range (the file has " + std::to_string(vertexCount) +
                                            " vertices)");
        }
      }
    }
  }

  TextCursor cursor_;
  std::vector<std::string>* warnings_;
  std::vector<double> coordinates_;
  FaceList faces_;
  std::vector<std::size_t> faceLines_;
  std::vector<Index> face_;
  int unknownStatements_ = 0;
};

}  // namespace

PolygonMesh parseObj(std::string_view text, const std::string& source, std::vector<std::string>* warnings) {
  return ObjParser(text, source, warnings).parse();
}

std::string formatObj(const PolygonMesh& mesh) {
  std::string out;
  out.reserve(static_cast<std::size_t>(mesh.vertexCount()) * 60 +
              static_cast<std::size_t>(mesh.faces.cornerCount()) * 8);
  for (Index v = 0; v < mesh.vertexCount(); ++v) {
    throwIfCancelledAt(v, "writing the mesh");
    out += "v";
    for (int a = 0; a < 3; ++a) {
      out += ' ';
      appendDouble(out, mesh.vertices(v, a));
    }
    out += '\n';
  }
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    throwIfCancelledAt(f, "writing the mesh");
    out += "f";
    for (Index v : mesh.faces[f]) {
      out += ' ';
      appendInteger(out, static_cast<long long>(v) + 1);
    }
    out += '\n';
  }
  return out;
}

}  // namespace plano::io
