// Strict PLY reader, ASCII and binary (why not OpenMesh: see PlyFormat.h).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "core/Error.h"
#include "mesh/io/MeshAssembly.h"
#include "mesh/io/PlyFormat.h"
#include "mesh/io/PlyHeader.h"
#include "mesh/io/TextCursor.h"

namespace plano::io {
namespace {

/// Values of the ASCII body, token by token (elements may span or share lines).
class AsciiBody {
 public:
  AsciiBody(std::string_view body, const std::string& source, std::size_t firstLine)
      : cursor_(body, source, '\0', firstLine) {}

  double value(PlyType type, const char* what) {
    const std::string_view token = next(what);
    if (plyIsInteger(type)) return static_cast<double>(cursor_.toInteger(token, what));
    return cursor_.toDouble(token, what, /*allowNonFinite=*/true);  // checked where it matters
  }
  std::int64_t integer(PlyType type, const char* what) {
    const std::string_view token = next(what);
    if (!plyIsInteger(type)) fail(std::string(what) + " has a floating-point type (an integer is needed)");
    return cursor_.toInteger(token, what);
  }
  std::size_t remaining() const { return cursor_.remaining(); }
  /// Bytes a value needs at least: one character and a separator.
  static std::size_t minimumSize(PlyType) { return 2; }
  bool atEnd() { return cursor_.atEnd(); }
  [[noreturn]] void fail(const std::string& message) const { cursor_.fail(message); }

 private:
  std::string_view next(const char* what) {
    std::string_view token;
    if (!cursor_.token(token)) {
      fail(std::string("file ends where a ") + what +
           " was expected (truncated file, or the header counts disagree with the body)");
    }
    return token;
  }

  TextCursor cursor_;
};

/// Values of a binary body, with the byte order of the file.
class BinaryBody {
 public:
  BinaryBody(std::string_view body, const std::string& source, bool bigEndian)
      : body_(body), source_(source), swap_(bigEndian != (std::endian::native == std::endian::big)) {}

  double value(PlyType type, const char* what) {
    switch (type) {
      case PlyType::Int8: return read<std::int8_t>(what);
      case PlyType::UInt8: return read<std::uint8_t>(what);
      case PlyType::Int16: return read<std::int16_t>(what);
      case PlyType::UInt16: return read<std::uint16_t>(what);
      case PlyType::Int32: return read<std::int32_t>(what);
      case PlyType::UInt32: return read<std::uint32_t>(what);
      case PlyType::Float32: return read<float>(what);
      case PlyType::Float64: return read<double>(what);
    }
    return 0.0;
  }
  std::int64_t integer(PlyType type, const char* what) {
    if (!plyIsInteger(type)) fail(std::string(what) + " has a floating-point type (an integer is needed)");
    return static_cast<std::int64_t>(value(type, what));
  }
  std::size_t remaining() const { return body_.size() - pos_; }
  static std::size_t minimumSize(PlyType type) { return plySize(type); }
  bool atEnd() const { return pos_ == body_.size(); }
  [[noreturn]] void fail(const std::string& message) const {
    throwBadInput(source_ + ": byte " + std::to_string(pos_) + " of the body: " + message);
  }

 private:
  template <class T>
  T read(const char* what) {
    if (remaining() < sizeof(T)) {
      fail(std::string("file ends where a ") + what + " was expected (truncated file)");
    }
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, body_.data() + pos_, sizeof(T));
    if (swap_) std::reverse(bytes, bytes + sizeof(T));
    pos_ += sizeof(T);
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }

  std::string_view body_;
  const std::string& source_;
  bool swap_;
  std::size_t pos_ = 0;
};

/// Where the mesh data sits in the declared elements.
struct MeshLayout {
  int vertexElement = -1;
  int faceElement = -1;
  int coordinate[3] = {-1, -1, -1};  ///< Property indices of x, y, z.
  int indices = -1;                  ///< Property index of the face's vertex list.
};

MeshLayout findLayout(const PlyHeader& header, const std::string& source) {
  auto fail = [&](std::size_t line, const std::string& message) {
    throwBadInput(source + ":" + std::to_string(line) + ": " + message);
  };
  MeshLayout layout;
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    const PlyElement& element = header.elements[e];
    if (element.name == "vertex") {
      if (layout.vertexElement >= 0) fail(element.line, "a second 'vertex' element");
      layout.vertexElement = static_cast<int>(e);
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        for (int a = 0; a < 3; ++a) {
          if (property.name != std::string(1, static_cast<char>('x' + a))) continue;
          if (property.isList) fail(property.line, "vertex property '" + property.name + "' is a list (a scalar is needed)");
          layout.coordinate[a] = static_cast<int>(p);
        }
      }
      for (int a = 0; a < 3; ++a) {
        if (layout.coordinate[a] < 0) {
          fail(element.line, std::string("the 'vertex' element has no '") + static_cast<char>('x' + a) + "' property");
        }
      }
    } else if (element.name == "face") {
      if (layout.faceElement >= 0) fail(element.line, "a second 'face' element");
      layout.faceElement = static_cast<int>(e);
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (property.name != "vertex_indices" && property.name != "vertex_index") continue;
        if (!property.isList) fail(property.line, "face property '" + property.name + "' must be a list");
        if (!plyIsInteger(property.type)) {
          fail(property.line, "face property '" + property.name +
                                  "' is a list of floating-point values: unsupported (vertex indices must be integers)");
        }
        layout.indices = static_cast<int>(p);
      }
      if (layout.indices < 0) fail(element.line, "the 'face' element has no 'vertex_indices' list property");
    }
  }
  if (layout.vertexElement < 0) throwBadInput(source + ": the header declares no 'vertex' element");
  return layout;
}

template <class Body>
PolygonMesh readBody(const PlyHeader& header, const MeshLayout& layout, Body& body) {
  std::vector<double> coordinates;
  FaceList faces;
  std::vector<Index> face;
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    const PlyElement& element = header.elements[e];
    // Refuse counts the remaining bytes cannot hold before reserving anything (one byte
    // of slack: the last ASCII value needs no separator).
    std::size_t minimum = 0;
    for (const auto& p : element.properties) minimum += Body::minimumSize(p.isList ? p.countType : p.type);
    if (minimum > 0 && static_cast<std::uint64_t>(element.count) > (body.remaining() + 1) / minimum) {
      body.fail("the header declares " + std::to_string(element.count) + " '" + element.name + "' elements of at least " +
                std::to_string(minimum) + " bytes each, but only " + std::to_string(body.remaining()) +
                " bytes follow (truncated file, or the header counts disagree with the body)");
    }
    // An element without properties occupies no bytes, whatever its count: nothing to
    // read (looping over a declared count of billions would hang; found by fuzzing).
    if (element.properties.empty()) continue;
    const bool isVertex = static_cast<int>(e) == layout.vertexElement;
    const bool isFace = static_cast<int>(e) == layout.faceElement;
    if ((isVertex || isFace) && element.count > kMaxCount) {
      body.fail("too many '" + element.name + "' elements (" + std::to_string(element.count) + ")");
    }
    if (isVertex) coordinates.reserve(3 * static_cast<std::size_t>(element.count));
    if (isFace) faces.reserve(static_cast<std::size_t>(element.count), 0);
    for (std::int64_t i = 0; i < element.count; ++i) {
      double point[3] = {0.0, 0.0, 0.0};
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (!property.isList) {
          const double x = body.value(property.type, "property value");
          for (int a = 0; a < 3; ++a) {
            if (isVertex && static_cast<int>(p) == layout.coordinate[a]) point[a] = x;
          }
          continue;
        }
        const std::int64_t n = body.integer(property.countType, "list count");
        const bool isIndices = isFace && static_cast<int>(p) == layout.indices;
        const std::string name = "face " + std::to_string(i);
        if (n < 0) body.fail("list " + quotedToken(property.name) + " has a negative count");
        if (isIndices && n < 3) body.fail(name + " has " + std::to_string(n) + " vertices (at least 3 needed)");
        if (static_cast<std::uint64_t>(n) > (body.remaining() + 1) / Body::minimumSize(property.type)) {
          body.fail("list " + quotedToken(property.name) + " of " + std::to_string(n) +
                    " items runs past the end of the file (truncated file)");
        }
        if (isIndices) {
          if (n > kMaxCount - faces.cornerCount()) body.fail("too many face corners");
          face.clear();
          for (std::int64_t k = 0; k < n; ++k) {
            const std::int64_t v = body.integer(property.type, "vertex index");
            const std::int64_t vertexCount = header.elements[layout.vertexElement].count;
            if (v < 0 || v >= vertexCount) {
              body.fail(name + ": vertex index " + std::to_string(v) + " out of range [0, " +
                        std::to_string(vertexCount) + ")");
            }
            face.push_back(static_cast<Index>(v));
          }
          faces.addFace(std::span<const Index>(face));
        } else {
          for (std::int64_t k = 0; k < n; ++k) body.value(property.type, "list item");
        }
      }
      if (isVertex) {
        // Only coordinates must be finite: a NaN in a property the mesh does not use is not an error.
        for (int a = 0; a < 3; ++a) {
          if (!std::isfinite(point[a])) {
            body.fail("vertex " + std::to_string(i) + ": coordinate " + static_cast<char>('x' + a) + " is not finite");
          }
        }
        coordinates.insert(coordinates.end(), point, point + 3);
      }
    }
  }
  if (!body.atEnd()) {
    body.fail("unexpected data after the last element declared in the header (the header counts disagree with the "
              "body)");
  }
  return assembleMesh(coordinates, std::move(faces));
}

}  // namespace

PolygonMesh parsePly(std::string_view data, const std::string& source, std::vector<std::string>* warnings) {
  (void)warnings;
  const PlyHeader header = parsePlyHeader(data, source);
  const MeshLayout layout = findLayout(header, source);
  const std::string_view body = data.substr(header.bodyOffset);
  if (header.encoding == PlyEncoding::Ascii) {
    AsciiBody ascii(body, source, header.bodyLine);
    return readBody(header, layout, ascii);
  }
  BinaryBody binary(body, source, header.encoding == PlyEncoding::BinaryBigEndian);
  return readBody(header, layout, binary);
}

}  // namespace plano::io
