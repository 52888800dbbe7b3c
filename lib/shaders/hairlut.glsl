// hairlut.glsl — S(wo, wi) of one hair material from its baked tables, in a shader: what
// hairlut::sampler::MaterialScattering::eval (material_scattering.hpp) computes, with the tables in
// textures. GLSL 4.50 for Vulkan; for OpenGL, declare the textures yourself (HAIRLUT_NP_TEXTURE,
// HAIRLUT_MP_TEXTURE and, to sample, HAIRLUT_ROWS below), since OpenGL's GLSL has no descriptor sets.
//
// The tables are those of a per-material bake (materials/<name>/np_<lobe>, mp_<lobe>, np_residual,
// mp_residual; docs/table-format.md): RGB N_p over (θd, φ) per lobe and M_p over (θi, θr), every
// axis linear in its mapped coordinate (θd uniform or cos-spaced), so each lookup is one bilinear
// filter and the sampler hardware can do it. S = Σ_p M_p(θi, θo) N_p(θd, |φ|) + M_res N_res(θd).
//
// With HAIRLUT_SAMPLING, hairlut_sampling.glsl adds hairlut_at, hairlut_sample and hairlut_pdf, as
// HairScattering's at, sample and pdf (the same density, drawn the same way).
//
// Textures (hairlut/sampler/gpu_textures.hpp lays them out; docs/gpu.md):
//   HAIRLUT_NP_TEXTURE  sampler2DArray; x = φ node, y = θd node, one layer per explicit lobe
//                       (RGB = the channels) and, when the material has one, one more layer for
//                       the residual (its N, uniform in φ, repeated along x).
//   HAIRLUT_MP_TEXTURE  sampler2DArray; x = θr node, y = θi node, each layer four lobes in RGBA
//                       (lobe p in layer p / 4, component p % 4; the residual is lobe P).
// Several materials on the same axes share the two textures; HairlutMaterial.lobes.zw say where
// a material's layers start. The sampler must clamp to the edge; for the hardware filter it must
// filter linearly (float32 textures need VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT, which
// not every GPU has; half-float textures are always filterable).
//
// Before including, a shader may define:
//   HAIRLUT_NP_TEXTURE, HAIRLUT_MP_TEXTURE  its own sampler2DArray names; otherwise this file
//       declares hairlut_np_texture and hairlut_mp_texture at (HAIRLUT_SET, HAIRLUT_BINDING) and
//       (HAIRLUT_SET, HAIRLUT_BINDING + 1), default set 0, bindings 0 and 1;
//   HAIRLUT_FILTER  HAIRLUT_FILTER_HARDWARE (default): textureLod with the sampler's bilinear
//       filter at texel centres, (s + ½) / count for node coordinate s; HAIRLUT_FILTER_EXPLICIT:
//       four texelFetch taps weighted in float arithmetic (the C++ runtime's reconstruction to
//       float rounding, on any GPU and for float32 textures that cannot be filtered);
//   HAIRLUT_WEIGHT_BITS  with the explicit filter, rounds the weights to this many fractional bits
//       (8 emulates the fixed-point weights of common GPU filter units); 0 (default) keeps them.
//   HAIRLUT_BUILTIN_INVERSE_TRIG  1: the direction interface takes θ and φ from GLSL's atan,
//       whose precision the specification leaves loose; 0 (default): from this file's own.
//   HAIRLUT_SAMPLING  1: also hairlut_at, hairlut_sample and hairlut_pdf (hairlut_sampling.glsl),
//       which read the material's sampling rows from the float array HAIRLUT_ROWS (declared at
//       (HAIRLUT_SET, HAIRLUT_BINDING + 2) unless the shader names its own).
//
// Directions are unit vectors in the fiber frame (x along the fiber, root to tip), wo the held one
// (towards the viewer), wi the sampled one (towards the light), as HairScattering::eval takes them;
// angles [rad] θ = asin(w.x) (read as atan2(w.x, |w.yz|)), φ = φo − φi. Arguments must be finite.
#ifndef HAIRLUT_GLSL
#define HAIRLUT_GLSL

#define HAIRLUT_FILTER_HARDWARE 0
#define HAIRLUT_FILTER_EXPLICIT 1
#ifndef HAIRLUT_FILTER
#define HAIRLUT_FILTER HAIRLUT_FILTER_HARDWARE
#endif
#ifndef HAIRLUT_WEIGHT_BITS
#define HAIRLUT_WEIGHT_BITS 0
#endif
#ifndef HAIRLUT_BUILTIN_INVERSE_TRIG
#define HAIRLUT_BUILTIN_INVERSE_TRIG 0
#endif
#ifndef HAIRLUT_SAMPLING
#define HAIRLUT_SAMPLING 0
#endif
#ifndef HAIRLUT_SET
#define HAIRLUT_SET 0
#endif
#ifndef HAIRLUT_BINDING
#define HAIRLUT_BINDING 0
#endif
#ifndef HAIRLUT_NP_TEXTURE
layout(set = HAIRLUT_SET, binding = HAIRLUT_BINDING) uniform sampler2DArray hairlut_np_texture;
#define HAIRLUT_NP_TEXTURE hairlut_np_texture
#endif
#ifndef HAIRLUT_MP_TEXTURE
layout(set = HAIRLUT_SET, binding = HAIRLUT_BINDING + 1) uniform sampler2DArray hairlut_mp_texture;
#define HAIRLUT_MP_TEXTURE hairlut_mp_texture
#endif

// One material (std140 and std430 alike: 176 bytes). Each axis maps its argument x to the node
// coordinate s = clamp((x − a) b, 0, last): vec4(a, b, last, 1 / count). x is θ for θi and θr, |φ|
// folded into [0, π] for φ, and |θd| (uniform θd axis) or 1 − cos θd (cos-spaced: the nodes are
// uniform in cos θd, and 1 − cos θd keeps its precision near θd = 0).
struct HairlutMaterial {
  vec4 theta_d;
  vec4 phi;
  vec4 theta_i;
  vec4 theta_r;
  ivec4 lobes;  // explicit lobes P, residual (1) or not (0), first N_p layer, first M_p layer
  ivec4 flags;  // x: θd axis cos-spaced (1) or uniform (0); the grazing factors (below): y the explicit
                // lobes' cos powers, 2 bits per lobe; z the residual's; w its absorption term (1) or not
  ivec4 rows0;  // sampling only: offsets in HAIRLUT_ROWS of gq, gcum, gguide, z
  ivec4 rows1;  // sampling only: offsets of nbar, ncum, nguide; nq (θi nodes of step 1's rows)
  vec4 rows2;   // sampling only: hq (their step), θi of the first, 0, 0
  vec4 grazing_x;     // the residual's grazing factor: x per channel, f
  vec4 grazing_bcde;  // and its b, c, d, e
};

const float HAIRLUT_PI = 3.14159265358979;

float hairlut_node(vec4 axis, float x) { return clamp((x - axis.x) * axis.y, 0.0, axis.z); }

// atan2 to a few float ulp: GLSL's built-in need not be close (the Vulkan environment allows atan
// 4096 ulp), and a direction's angles place it on the θ and φ axes. Cephes' single-precision
// polynomial.
// The angle of (x, y) for y ≥ 0, in [0, π]; 0 at the origin.
float hairlut_atan2_upper(float y, float x) {
  float ax = abs(x), hi = max(ax, y), lo = min(ax, y);
  if (hi == 0.0) return 0.0;
  float t = lo / hi, base = 0.0;  // t ∈ [0, 1]
  if (t > 0.41421356237) {
    base = 0.78539816339744831;
    t = (t - 1.0) / (t + 1.0);
  }
  float z = t * t;
  float r = base + (((8.05374449538e-2 * z - 1.38776856032e-1) * z + 1.99777106478e-1) * z - 3.33329491539e-1) * z * t + t;
  if (y > ax) r = 1.5707963267948966 - r;
  return x < 0.0 ? 3.14159265358979 - r : r;
}

// A direction's inclination: sin θ = w.x, cos θ = |w.yz| and θ = atan2(w.x, |w.yz|). Near a pole the
// normal-plane part keeps the precision that 1 − w.x² loses: a float w.x rounded to 1 would put
// a direction up to 3.5e-4 rad off the pole onto it, where S varies fastest (opposite grazing).
struct HairlutIncl {
  float theta, s, c;
};
HairlutIncl hairlut_inclination(vec3 w) {
  HairlutIncl r;
  r.s = clamp(w.x, -1.0, 1.0);
  r.c = length(w.yz);
#if HAIRLUT_BUILTIN_INVERSE_TRIG
  r.theta = r.s == 0.0 && r.c == 0.0 ? 0.0 : atan(r.s, r.c);
#else
  float a = hairlut_atan2_upper(abs(r.s), r.c);
  r.theta = r.s < 0.0 ? -a : a;
#endif
  return r;
}

// Where the θd axis reaches 90° the tables store N_p divided by its lobe's grazing factor g_p
// (hairlut::sampler::GrazingFactor; docs/table-format.md): cos^n θd for an explicit lobe, and for
// the residual u^n · u (u² + b x u + e x²) / (u³ + c x u² + d x² u + f x³) per channel, u = cos θd.
// A lookup multiplies it back after filtering; 1 where the tables store N_p as is.
// The factors at one lookup, computed once: u and u² for the explicit lobes' cos powers, and the
// residual's per channel.
struct HairlutGrazing {
  float u, u2;
  vec3 res;
};
HairlutGrazing hairlut_grazing_at(HairlutMaterial m, float u) {
  HairlutGrazing g;
  g.u = max(u, 0.0);
  g.u2 = g.u * g.u;
  g.res = vec3(m.flags.z == 0 ? 1.0 : m.flags.z == 1 ? g.u : g.u2);
  if (m.flags.w != 0) {
    vec3 x = m.grazing_x.xyz;
    float b = m.grazing_bcde.x, c = m.grazing_bcde.y, d = m.grazing_bcde.z, e = m.grazing_bcde.w, f = m.grazing_x.w;
    vec3 den = ((g.u + c * x) * g.u + d * x * x) * g.u + f * x * x * x;
    vec3 r = g.res * g.u * ((g.u + b * x) * g.u + e * x * x) / max(den, vec3(1e-37));
    g.res = mix(vec3(0.0), r, greaterThan(den, vec3(0.0)));
  }
  return g;
}
// Lobe p's factor (the residual is lobe lobes.x).
vec3 hairlut_grazing(HairlutMaterial m, HairlutGrazing g, int p) {
  if (p >= m.lobes.x) return g.res;
  int n = (m.flags.y >> (2 * p)) & 3;
  return vec3(n == 0 ? 1.0 : n == 1 ? g.u : g.u2);
}
// cos θd = cos((θo − θi)/2) from both inclinations' sines and cosines: half the length of the sum
// of (sin θ, cos θ), whose cosine part keeps its precision near grazing (1 − (1 − cos θd) would not).
float hairlut_cos_theta_d(float so, float co, float si, float ci) { return 0.5 * length(vec2(so + si, co + ci)); }
// 1 − cos θd, the cos-spaced θd axis's argument, from the same: up to 45° as sin²θd / (1 + cos θd)
// with sin θd from the chord between (sin θo, cos θo) and (sin θi, cos θi); beyond, as 1 − cos θd
// (each form keeps its precision where the other loses it: near 90° sin²θd ≈ 1 leaves cos θd only
// to the square root of float's rounding).
float hairlut_one_minus_cos_theta_d(float so, float co, float si, float ci) {
  float u = hairlut_cos_theta_d(so, co, si, ci);
  if (u < 0.70710678) return 1.0 - u;
  float ds = so - si, dc = co - ci;
  float s2 = 0.25 * (ds * ds + dc * dc);  // sin²θd
  return s2 / (1.0 + sqrt(max(0.0, 1.0 - s2)));
}

#if HAIRLUT_FILTER == HAIRLUT_FILTER_HARDWARE
// Node i is the centre of texel i; the sampler's clamp holds the last node beyond it.
#define HAIRLUT_DEFINE_BILINEAR(NAME, TEX)                                  \
  vec4 NAME(vec2 s, vec2 last, vec2 inv_count, int layer) {                 \
    return textureLod(TEX, vec3((s + 0.5) * inv_count, float(layer)), 0.0); \
  }
#else
// The C++ runtime's cell and weight; (1 − w) a + w b, not a + w (b − a), so that nonnegative
// values are combined without cancellation.
#define HAIRLUT_DEFINE_BILINEAR(NAME, TEX)                                                            \
  vec4 NAME(vec2 s, vec2 last, vec2 inv_count, int layer) {                                           \
    vec2 i = min(floor(s), max(last - 1.0, 0.0));                                                     \
    vec2 w = s - i;                                                                                   \
    if (HAIRLUT_WEIGHT_BITS > 0) {                                                                    \
      float q = float(1 << HAIRLUT_WEIGHT_BITS);                                                      \
      w = round(w * q) / q;                                                                           \
    }                                                                                                 \
    ivec2 i0 = ivec2(i), i1 = min(i0 + 1, ivec2(last));                                               \
    vec4 a = texelFetch(TEX, ivec3(i0.x, i0.y, layer), 0), b = texelFetch(TEX, ivec3(i1.x, i0.y, layer), 0); \
    vec4 c = texelFetch(TEX, ivec3(i0.x, i1.y, layer), 0), d = texelFetch(TEX, ivec3(i1.x, i1.y, layer), 0); \
    return (a * (1.0 - w.x) + b * w.x) * (1.0 - w.y) + (c * (1.0 - w.x) + d * w.x) * w.y;             \
  }
#endif
HAIRLUT_DEFINE_BILINEAR(hairlut_np_bilinear, HAIRLUT_NP_TEXTURE)
HAIRLUT_DEFINE_BILINEAR(hairlut_mp_bilinear, HAIRLUT_MP_TEXTURE)

// S from θo, θi, 1 − cos θd (the cos-spaced axis) or |θd| (the uniform one), cos θd and |φ| ∈ [0, π].
vec3 hairlut_eval_located(HairlutMaterial m, float theta_o, float theta_i, float theta_d_x, float u, float phi_abs) {
  vec2 sn = vec2(hairlut_node(m.phi, phi_abs), hairlut_node(m.theta_d, theta_d_x));
  vec2 sm = vec2(hairlut_node(m.theta_r, theta_o), hairlut_node(m.theta_i, theta_i));
  vec2 n_last = vec2(m.phi.z, m.theta_d.z), n_inv = vec2(m.phi.w, m.theta_d.w);
  vec2 m_last = vec2(m.theta_r.z, m.theta_i.z), m_inv = vec2(m.theta_r.w, m.theta_i.w);
  int lobes = m.lobes.x + m.lobes.y;
  HairlutGrazing g = hairlut_grazing_at(m, u);
  vec3 s = vec3(0.0);
  for (int k = 0; 4 * k < lobes; ++k) {
    vec4 mp = hairlut_mp_bilinear(sm, m_last, m_inv, m.lobes.w + k);
    for (int c = 0; c < 4 && 4 * k + c < lobes; ++c)
      s += mp[c] * hairlut_grazing(m, g, 4 * k + c) * hairlut_np_bilinear(sn, n_last, n_inv, m.lobes.z + 4 * k + c).rgb;
  }
  return s;
}

// S per channel [1/sr] at θo (held), θi (sampled) and φ = φo − φi [rad], as
// HairScattering::eval(fiber, theta_o, theta_i, phi, rgb).
vec3 hairlut_eval_angles(HairlutMaterial m, float theta_o, float theta_i, float phi) {
  float td = 0.5 * (theta_o - theta_i);
  float sd = sin(td);
  float x = m.flags.x != 0 ? sd * sd / (1.0 + cos(td)) : abs(td);
  float f = abs(phi);
  if (f > HAIRLUT_PI) f = abs(f - 2.0 * HAIRLUT_PI * floor(f / (2.0 * HAIRLUT_PI) + 0.5));
  return hairlut_eval_located(m, theta_o, theta_i, x, cos(td), f);
}

// S per channel [1/sr] for unit vectors wo, wi in the fiber frame, as HairScattering::eval(fiber,
// wo, wi, rgb): θ from hairlut_inclination, |φ| the angle between the projections on the normal
// plane, 1 − cos θd from the chord between (sin θo, cos θo) and (sin θi, cos θi).
vec3 hairlut_eval(HairlutMaterial m, vec3 wo, vec3 wi) {
  HairlutIncl o = hairlut_inclination(wo), i = hairlut_inclination(wi);
  float x = m.flags.x != 0 ? hairlut_one_minus_cos_theta_d(o.s, o.c, i.s, i.c) : abs(0.5 * (o.theta - i.theta));
  float cross_ = wo.y * wi.z - wo.z * wi.y, dot_ = wo.y * wi.y + wo.z * wi.z;
#if HAIRLUT_BUILTIN_INVERSE_TRIG
  float f = cross_ == 0.0 && dot_ == 0.0 ? 0.0 : atan(abs(cross_), dot_);
#else
  float f = hairlut_atan2_upper(abs(cross_), dot_);
#endif
  return hairlut_eval_located(m, o.theta, i.theta, x, hairlut_cos_theta_d(o.s, o.c, i.s, i.c), f);
}

#if HAIRLUT_SAMPLING
#include "hairlut_sampling.glsl"
#endif

#endif  // HAIRLUT_GLSL
