// Shared declarations for Plano's compute shaders (included with #include "common.glsl").
#extension GL_ARB_gpu_shader_fp64 : require
