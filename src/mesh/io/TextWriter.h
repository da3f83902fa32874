#pragma once
// Number formatting for the text mesh writers. Doubles are written as the shortest
// decimal string that reads back to the identical double (std::to_chars), which never
// needs more than 17 significant digits: a write/read round trip is exact.
#include <charconv>
#include <string>

namespace plano::io {

inline void appendDouble(std::string& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

inline void appendInteger(std::string& out, long long value) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

}  // namespace plano::io
