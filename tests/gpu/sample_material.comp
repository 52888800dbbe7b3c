#version 450
// hairlut_sample and hairlut_pdf of hair materials at a batch of points (tests/gpu/test_gpu_material.cpp).
// Point i is two vec4: (wo, material) and (wi, 0) for mode 0, which writes (pdf, 0, 0, 0) to
// values[2i]; or (u, 0) for mode 1, which writes (wi, pdf) and (weight, lobe).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

layout(set = 0, binding = 5, std430) readonly buffer Rows { float rows[]; };
#define HAIRLUT_ROWS rows
#define HAIRLUT_SAMPLING 1
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
  HairlutPoint pt = hairlut_at(m, a.xyz);
  if (mode == 0u) {
    values[2 * i] = vec4(hairlut_pdf(m, pt, b.xyz), 0.0, 0.0, 0.0);
    values[2 * i + 1] = vec4(0.0);
  } else {
    HairlutSample s = hairlut_sample(m, pt, b.xyz);
    values[2 * i] = vec4(s.wi, s.pdf);
    values[2 * i + 1] = vec4(s.weight, float(s.lobe));
  }
}
