#pragma once
// The header of a PLY file: its encoding and its elements with their properties, as
// declared (internal to the PLY reader).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "mesh/io/PlyFormat.h"

namespace plano::io {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

std::size_t plySize(PlyType type);
bool plyIsInteger(PlyType type);

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;  ///< Scalar type, or the item type of a list.
  bool isList = false;
  PlyType countType = PlyType::UInt8;  ///< Lists only.
  std::size_t line = 0;                ///< Header line (for messages).
};

struct PlyElement {
  std::string name;
  std::int64_t count = 0;
  std::vector<PlyProperty> properties;
  std::size_t line = 0;
};

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::Ascii;
  std::vector<PlyElement> elements;
  std::size_t bodyOffset = 0;  ///< Byte offset of the first byte after "end_header\n".
  std::size_t bodyLine = 0;    ///< Line number of the first body line (ASCII).
};

/// Parse the header at the start of `data`. Throws Error(BadInput) "SOURCE:LINE: problem".
PlyHeader parsePlyHeader(std::string_view data, const std::string& source);

}  // namespace plano::io
