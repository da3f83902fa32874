// Shared declarations for Plano's compute shaders (included with #include "common.glsl").
#extension GL_ARB_gpu_shader_fp64 : require

// The default workgroup size of 1D kernels (vk::kWorkGroupSize on the host). Kernels
// loop grid-stride, because the workgroup count per dimension is capped (65535 on
// lavapipe) below the number of faces of a large mesh.
#define PLANO_GROUP_SIZE 64
#define GRID_STRIDE_LOOP(i, count) \
  for (uint i = gl_GlobalInvocationID.x; i < (count); i += gl_NumWorkGroups.x * gl_WorkGroupSize.x)

// Vector helpers written out so that the operation order matches the CPU reference
// (Eigen, compiled with -ffp-contract=off); `precise` forbids fused multiply-adds.
double dot3(dvec3 a, dvec3 b) {
  precise double r = a.x * b.x + a.y * b.y + a.z * b.z;
  return r;
}
double norm3(dvec3 a) { return sqrt(dot3(a, a)); }
dvec3 cross3(dvec3 a, dvec3 b) {
  precise dvec3 r = dvec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
  return r;
}
