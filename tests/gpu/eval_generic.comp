#version 450
// S of fibers at a batch of points from generic tables, through lib/shaders/hairlut_generic.glsl:
// the shader the generic GLSL runtime's test (tests/gpu/test_gpu_generic.cpp) runs. Point i is four
// vec4: (θo, θi, φ, 0) with mode 0, or wo with mode 1; wi (mode 1); (σa RGB, β_m); (β_n, tilt, 0, 0).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#define HAIRLUT_GENERIC_SET_BINDING 2   // the test harness's uniform buffer
#define HAIRLUT_GENERIC_DATA_BINDING 5  // and its third storage buffer
#include "hairlut_generic.glsl"

layout(set = 0, binding = 3, std430) readonly buffer Points { vec4 points[]; };
layout(set = 0, binding = 4, std430) writeonly buffer Values { vec4 values[]; };
layout(push_constant) uniform Push { uint count; uint mode; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  vec4 a = points[4 * i], b = points[4 * i + 1], c = points[4 * i + 2], d = points[4 * i + 3];
  HairlutFiber f = HairlutFiber(c.xyz, c.w, d.x, d.y);
  vec3 s = mode == 0u ? hairlut_generic_eval_angles(f, a.x, a.y, a.z) : hairlut_generic_eval(f, a.xyz, b.xyz);
  values[i] = vec4(s, 0.0);
}
