#pragma once
// SPIR-V of the compute shaders in shaders/, compiled and embedded at build time
// (cmake/EmbedShaders.cmake).
#include <cstdint>
#include <span>
#include <string_view>

namespace plano::vk {

/// The SPIR-V words of shaders/<name>.comp; empty when no such shader was built.
std::span<const std::uint32_t> embeddedShader(std::string_view name);

}  // namespace plano::vk
