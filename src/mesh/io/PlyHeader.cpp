#include "mesh/io/PlyHeader.h"

#include <optional>

#include "mesh/io/TextCursor.h"

namespace plano::io {
namespace {

std::optional<PlyType> typeFromName(std::string_view name) {
  if (name == "char" || name == "int8") return PlyType::Int8;
  if (name == "uchar" || name == "uint8") return PlyType::UInt8;
  if (name == "short" || name == "int16") return PlyType::Int16;
  if (name == "ushort" || name == "uint16") return PlyType::UInt16;
  if (name == "int" || name == "int32") return PlyType::Int32;
  if (name == "uint" || name == "uint32") return PlyType::UInt32;
  if (name == "float" || name == "float32") return PlyType::Float32;
  if (name == "double" || name == "float64") return PlyType::Float64;
  return std::nullopt;
}

}  // namespace

std::size_t plySize(PlyType type) {
  switch (type) {
    case PlyType::Int8:
    case PlyType::UInt8: return 1;
    case PlyType::Int16:
    case PlyType::UInt16: return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 1;
}

bool plyIsInteger(PlyType type) { return type != PlyType::Float32 && type != PlyType::Float64; }

PlyHeader parsePlyHeader(std::string_view data, const std::string& source) {
  // No comment character: PLY comments are "comment ..." lines, and '#' is not special.
  TextCursor cursor(data, source, '\0');
  PlyHeader header;
  std::string_view token;
  if (!cursor.tokenOnLine(token) || token != "ply" || cursor.tokenOnLine(token)) {
    cursor.fail("not a PLY file: the first line must be 'ply'");
  }
  cursor.skipLine();
  bool sawFormat = false;
  auto required = [&](const char* what) {
    std::string_view t;
    if (!cursor.tokenOnLine(t)) cursor.fail(std::string("header line needs ") + what);
    return t;
  };
  auto type = [&](std::string_view name) {
    const auto t = typeFromName(name);
    if (!t) cursor.fail("unknown property type " + quotedToken(name));
    return *t;
  };
  while (true) {
    if (cursor.remaining() == 0) cursor.fail("file ends inside the header (no 'end_header' line)");
    std::string_view keyword;
    if (!cursor.tokenOnLine(keyword)) {  // blank line
      cursor.skipLine();
      continue;
    }
    if (keyword == "end_header") {
      if (cursor.tokenOnLine(token)) cursor.fail("unexpected " + quotedToken(token) + " after 'end_header'");
      cursor.skipLine();
      break;
    }
    if (keyword == "comment" || keyword == "obj_info") {
      cursor.skipLine();
      continue;
    }
    if (keyword == "format") {
      const std::string_view encoding = required("an encoding after 'format'");
      if (encoding == "ascii") {
        header.encoding = PlyEncoding::Ascii;
      } else if (encoding == "binary_little_endian") {
        header.encoding = PlyEncoding::BinaryLittleEndian;
      } else if (encoding == "binary_big_endian") {
        header.encoding = PlyEncoding::BinaryBigEndian;
      } else {
        cursor.fail("unknown PLY format " + quotedToken(encoding));
      }
      const std::string_view version = required("a version after the format");
      if (version != "1.0" && version != "1") cursor.fail("unsupported PLY version " + quotedToken(version));
      sawFormat = true;
    } else if (keyword == "element") {
      PlyElement element;
      element.name = std::string(required("an element name"));
      element.count = cursor.toInteger(required("an element count"), "element count");
      if (element.count < 0) cursor.fail("element " + quotedToken(element.name) + " has a negative count");
      element.line = cursor.line();
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) cursor.fail("'property' before any 'element'");
      PlyProperty property;
      property.line = cursor.line();
      const std::string_view first = required("a property type");
      if (first == "list") {
        property.isList = true;
        property.countType = type(required("a list count type"));
        property.type = type(required("a list item type"));
        if (!plyIsInteger(property.countType)) cursor.fail("list count type must be an integer type");
      } else {
        property.type = type(first);
      }
      property.name = std::string(required("a property name"));
      header.elements.back().properties.push_back(std::move(property));
    } else {
      cursor.fail("unknown header keyword " + quotedToken(keyword));
    }
    if (cursor.tokenOnLine(token)) cursor.fail("unexpected " + quotedToken(token) + " at the end of the header line");
    cursor.skipLine();
  }
  if (!sawFormat) cursor.fail("the header has no 'format' line");
  header.bodyOffset = cursor.position();
  header.bodyLine = cursor.line();
  return header;
}

}  // namespace plano::io
