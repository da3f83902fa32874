// Strict streaming OFF reader and exact writer (why not OpenMesh: see OffFormat.h).
#include "mesh/io/OffFormat.h"

#include <cstdint>
#include <optional>

#include "mesh/io/MeshAssembly.h"
#include "mesh/io/TextCursor.h"
#include "mesh/io/TextWriter.h"

namespace plano::io {
namespace {

/// Header keywords: [ST][C][N][4][n]OFF. Returns false for anything else; 4D and n-D
/// variants are recognised so that the message can say they are unsupported.
struct OffHeader {
  bool ok = false;
  bool higherDimension = false;
};

OffHeader parseHeaderKeyword(std::string_view keyword) {
  OffHeader header;
  if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF") return header;
  std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  auto take = [&](std::string_view p) {
    if (prefix.substr(0, p.size()) != p) return false;
    prefix.remove_prefix(p.size());
    return true;
  };
  take("ST");
  take("C");
  take("N");
  if (take("4")) header.higherDimension = true;
  if (take("n")) header.higherDimension = true;
  header.ok = prefix.empty();
  return header;
}

class OffParser {
 public:
  OffParser(std::string_view text, const std::string& source) : cursor_(text, source) {}

  PolygonMesh parse() {
    readHeader();
    readVertices();
    readFaces();
    if (!cursor_.atEnd()) {
      std::string_view token;
      cursor_.token(token);
      cursor_.fail("unexpected data " + quotedToken(token) + " after the " + std::to_string(faceCount_) +
                   " faces declared in the header (the header counts disagree with the body)");
    }
    checkIndices();
    return assembleMesh(coordinates_, std::move(faces_));
  }

 private:
  std::int64_t readCount(std::string_view token, const char* what) {
    const std::int64_t n = cursor_.toInteger(token, what);
    if (n < 0) cursor_.fail(std::string(what) + " " + std::to_string(n) + " is negative");
    if (n > kMaxCount) cursor_.fail(std::string(what) + " " + std::to_string(n) + " is too large");
    return n;
  }

  void readHeader() {
    std::string_view keyword;
    if (!cursor_.token(keyword)) cursor_.fail("file is empty");
    const OffHeader header = parseHeaderKeyword(keyword);
    if (!header.ok) cursor_.fail("not an OFF file: expected the header 'OFF', found " + quotedToken(keyword));
    if (header.higherDimension) cursor_.fail("header " + quotedToken(keyword) + ": only 3D OFF files are supported");
    std::string_view token;
    if (cursor_.tokenOnLine(token) && token == "BINARY") cursor_.fail("binary OFF files are not supported");
    // The counts may follow the keyword on the same line or start the next line.
    if (token.empty() && !cursor_.token(token)) cursor_.fail("file ends before the vertex, face and edge counts");
    const std::size_t countsLine = cursor_.line();
    vertexCount_ = readCount(token, "vertex count");
    if (!cursor_.tokenOnLine(token)) cursor_.fail("the counts line needs a face count after the vertex count");
    faceCount_ = readCount(token, "face count");
    if (cursor_.tokenOnLine(token)) readCount(token, "edge count");  // unused, optional in practice
    if (cursor_.tokenOnLine(token)) {
      cursor_.failAt(countsLine, "unexpected " + quotedToken(token) + " after the counts 'V F E'");
    }
    cursor_.skipLine();
  }

  /// Attribute values (normals, colours, texture coordinates) after the data on a line
  /// are skipped but must be numbers; returns how many there were.
  int skipExtras(const char* what) {
    std::string_view token;
    int n = 0;
    while (cursor_.tokenOnLine(token)) {
      cursor_.toDouble(token, what);
      ++n;
    }
    cursor_.skipLine();
    return n;
  }

  void readVertices() {
    // Each vertex needs at least "0 0 0\n": 6 bytes.
    coordinates_.reserve(3 * boundedReserve(vertexCount_, cursor_.remaining(), 6));
    std::string_view token;
    for (std::int64_t v = 0; v < vertexCount_; ++v) {
      for (int a = 0; a < 3; ++a) {
        if (!cursor_.token(token)) {
          cursor_.fail("file ends after " + std::to_string(v) + " of the " + std::to_string(vertexCount_) +
                       " vertices declared in the header (truncated file, or the header counts disagree with the "
                       "body)");
        }
        coordinates_.push_back(cursor_.toDouble(token, "vertex coordinate"));
      }
      skipExtras("vertex attribute");
    }
  }

  void readFaces() {
    // Each face needs at least "3 0 1 2\n": 8 bytes.
    faces_.reserve(boundedReserve(faceCount_, cursor_.remaining(), 8), 0);
    faceLines_.reserve(boundedReserve(faceCount_, cursor_.remaining(), 8));
    std::string_view token;
    for (std::int64_t f = 0; f < faceCount_; ++f) {
      if (!cursor_.token(token)) {
        cursor_.fail("file ends after " + std::to_string(f) + " of the " + std::to_string(faceCount_) +
                     " faces declared in the header (truncated file, or the header counts disagree with the body)");
      }
      const std::size_t line = cursor_.line();
      const std::int64_t n = cursor_.toInteger(token, "face size");
      const std::string name = "face " + std::to_string(f);
      if (n < 3) cursor_.fail(name + " has " + std::to_string(n) + " vertices (at least 3 needed)");
      if (n > kMaxCount - faces_.cornerCount()) cursor_.fail(name + ": face size " + std::to_string(n) + " too large");
      face_.clear();
      for (std::int64_t k = 0; k < n; ++k) {
        if (!cursor_.token(token)) {
          cursor_.fail("file ends inside " + name + " after " + std::to_string(k) + " of its " + std::to_string(n) +
                       " vertex indices (truncated file)");
        }
        const std::int64_t index = cursor_.toInteger(token, "vertex index");
        if (index < 0) cursor_.fail(name + ": negative vertex index " + std::to_string(index));
        if (index >= vertexCount_ && !outOfRange_) outOfRange_ = OutOfRange{f, index, cursor_.line()};
        sawZero_ = sawZero_ || index == 0;
        maxIndex_ = std::max(maxIndex_, index);
        face_.push_back(static_cast<Index>(std::min(index, kMaxCount)));
      }
      const int extras = skipExtras("face colour value");
      if (extras == 2 || extras > 4) {
        cursor_.failAt(line, name + ": " + std::to_string(extras) +
                                 " values after its vertex indices (a colour has 1, 3 or 4; is the face size " +
                                 std::to_string(n) + " right?)");
      }
      faces_.addFace(std::span<const Index>(face_));
      faceLines_.push_back(line);
    }
  }

  void checkIndices() const {
    if (!outOfRange_) return;
    const auto& bad = *outOfRange_;
    std::string message = "face " + std::to_string(bad.face) + ": vertex index " + std::to_string(bad.index) +
                          " out of range [0, " + std::to_string(vertexCount_) + ")";
    // A file written with 1-based indices: no index 0, and the vertex count itself used.
    if (!sawZero_ && maxIndex_ == vertexCount_) message += ": indices look 1-based (no index 0, and index V appears)";
    cursor_.failAt(bad.line, message);
  }

  struct OutOfRange {
    std::int64_t face;
    std::int64_t index;
    std::size_t line;
  };

  TextCursor cursor_;
  std::int64_t vertexCount_ = 0;
  std::int64_t faceCount_ = 0;
  std::vector<double> coordinates_;
  FaceList faces_;
  std::vector<std::size_t> faceLines_;
  std::vector<Index> face_;
  std::optional<OutOfRange> outOfRange_;
  bool sawZero_ = false;
  std::int64_t maxIndex_ = -1;
};

}  // namespace

PolygonMesh parseOff(std::string_view text, const std::string& source, std::vector<std::string>* warnings) {
  (void)warnings;  // the OFF reader has nothing to warn about yet: every defect is an error
  return OffParser(text, source).parse();
}

std::string formatOff(const PolygonMesh& mesh) {
  std::string out = "OFF\n";
  out.reserve(static_cast<std::size_t>(mesh.vertexCount()) * 60 + static_cast<std::size_t>(mesh.faces.cornerCount()) * 8);
  appendInteger(out, mesh.vertexCount());
  out += ' ';
  appendInteger(out, mesh.faceCount());
  out += " 0\n";
  appendVertexAndFaceLines(out, mesh);
  return out;
}

}  // namespace plano::io
