#version 450
// S of hair materials at a batch of points, through lib/shaders/hairlut.glsl: the shader the GLSL
// runtime's test (tests/gpu/test_gpu_material.cpp) runs. Point i is two vec4: (wo, material) and
// (wi, 0), or with mode 1 (θo, θi, φ, material) and unused.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "hairlut.glsl"  // its textures at set 0, bindings 0 (N_p) and 1 (M_p)

layout(set = 0, binding = 2, std140) uniform Materials { HairlutMaterial materials[4]; };
layout(set = 0, binding = 3, std430) readonly buffer Points { vec4 points[]; };
layout(set = 0, binding = 4, std430) writeonly buffer Values { vec4 values[]; };
layout(push_constant) uniform Push { uint count; uint mode; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  vec4 a = points[2 * i], b = points[2 * i + 1];
  HairlutMaterial m = materials[int(a.w)];
  vec3 s = mode == 1u ? hairlut_eval_angles(m, a.x, a.y, a.z) : hairlut_eval(m, a.xyz, b.xyz);
  values[i] = vec4(s, 0.0);
}
