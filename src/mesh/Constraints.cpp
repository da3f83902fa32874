#include "mesh/Constraints.h"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unordered_map>

#include "core/Error.h"

namespace plano {
namespace {

/// A value for an error message: its JSON type, and for a number, string or literal its
/// text cut to a few dozen characters. Never the dump of an array or object: a file can
/// nest them deeper than the recursive dump's stack, or make the message as long as itself.
std::string describe(const nlohmann::json& value) {
  constexpr std::size_t kExcerpt = 40;
  if (value.is_array()) return "an array of size " + std::to_string(value.size());
  if (value.is_object()) return "an object of size " + std::to_string(value.size());
  std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (text.size() > kExcerpt) text = text.substr(0, kExcerpt) + "...";
  return std::string(value.type_name()) + " " + text;
}

Index parseVertex(const nlohmann::json& value, Index vertexCount, const std::string& where) {
  if (!value.is_number_integer()) throwBadInput(where + ": vertex index must be an integer, got " + describe(value));
  const auto outOfRange = [&](const std::string& index) {
    throwBadInput(where + ": vertex " + index + " is out of range (the mesh has " + std::to_string(vertexCount) +
                  " vertices, indices are 0-based)");
  };
  // Non-negative numbers are read as unsigned: one above INT64_MAX would wrap to a negative
  // long long, and the message would name a vertex the file does not.
  if (value.is_number_unsigned()) {
    const auto index = value.get<std::uint64_t>();
    if (index >= static_cast<std::uint64_t>(vertexCount)) outOfRange(std::to_string(index));
    return static_cast<Index>(index);
  }
  const auto index = value.get<long long>();
  if (index < 0 || index >= vertexCount) outOfRange(std::to_string(index));
  return static_cast<Index>(index);
}

}  // namespace

PositionalConstraints parseConstraints(const nlohmann::json& json, Index vertexCount, std::string* warnings,
                                       const std::string& source) {
  if (!json.is_object()) throwBadInput(source + ": expected a JSON object with \"fixed\" and/or \"handles\"");
  PositionalConstraints constraints;
  for (const auto& [key, value] : json.items()) {
    if (key != "fixed" && key != "handles" && warnings) {
      *warnings += "warning: " + source + ": unknown key \"" + key + "\" ignored\n";
    }
  }
  // Which entry claimed each vertex first, to name both sides of a conflict.
  std::unordered_map<Index, std::string> claimedBy;
  auto claim = [&](Index vertex, const std::string& where) {
    auto [it, inserted] = claimedBy.emplace(vertex, where);
    if (!inserted) {
      throwBadInput(source + ": vertex " + std::to_string(vertex) + " is constrained twice (" + it->second + " and " +
                    where + ")");
    }
  };
  if (json.contains("fixed")) {
    const auto& fixed = json["fixed"];
    if (!fixed.is_array()) throwBadInput(source + ": \"fixed\" must be an array of vertex indices");
    for (std::size_t i = 0; i < fixed.size(); ++i) {
      const std::string where = "fixed[" + std::to_string(i) + "]";
      const Index v = parseVertex(fixed[i], vertexCount, source + ": " + where);
      claim(v, where);
      constraints.fixed.push_back(v);
    }
  }
  if (json.contains("handles")) {
    const auto& handles = json["handles"];
    if (!handles.is_array()) throwBadInput(source + ": \"handles\" must be an array of {\"vertex\", \"position\"}");
    for (std::size_t i = 0; i < handles.size(); ++i) {
      const std::string where = "handles[" + std::to_string(i) + "]";
      const auto& h = handles[i];
      if (!h.is_object() || !h.contains("vertex") || !h.contains("position")) {
        throwBadInput(source + ": " + where + " must be an object with \"vertex\" and \"position\"");
      }
      Handle handle;
      handle.vertex = parseVertex(h["vertex"], vertexCount, source + ": " + where);
      const auto& p = h["position"];
      if (!p.is_array() || p.size() != 3) throwBadInput(source + ": " + where + ".position must be [x, y, z]");
      for (int c = 0; c < 3; ++c) {
        if (!p[c].is_number()) {
          throwBadInput(source + ": " + where + ".position[" + std::to_string(c) + "] must be a number, got " +
                        describe(p[c]));
        }
        handle.position[c] = p[c].get<double>();
        if (!std::isfinite(handle.position[c])) {
          throwBadInput(source + ": " + where + ".position is not finite");
        }
      }
      claim(handle.vertex, where);
      constraints.handles.push_back(handle);
    }
  }
  return constraints;
}

PositionalConstraints readConstraints(const std::filesystem::path& path, Index vertexCount, std::string* warnings) {
  // Checked first: a folder opens as a stream on Linux and fails only when read, with an
  // exception of the standard library's rather than a message naming the file.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throwBadInput(path.string() + ": is a folder, not a constraints file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throwBadInput(path.string() + ": cannot open constraints file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throwBadInput(path.string() + ": cannot read constraints file");
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::parse_error& e) {
    throwBadInput(path.string() + ": malformed JSON: " + e.what());
  } catch (const nlohmann::json::exception& e) {
    // out_of_range 406: a number too large for a double (1e400).
    throwBadInput(path.string() + ": invalid JSON: " + e.what());
  }
  return parseConstraints(json, vertexCount, warnings, path.string());
}

}  // namespace plano
