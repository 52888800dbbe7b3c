// hairlut_generic.glsl — S(wo, wi) of any fiber from hairlut's generic d'Eon tables, in a shader:
// what hairlut::sampler::HairScattering::eval (hair_scattering.hpp) computes for a set read with
// hairlut::hair_scattering<float>(set), per fiber (RGB σa, β_m, β_n, a cuticle tilt), with the
// tables in two buffers. GLSL 4.50 for Vulkan; for OpenGL, declare the buffers yourself.
//
// The generic tables interpolate Catmull–Rom over up to four axes (β, σa, θd, φ), with mirror and
// extrapolated ends, geometrically along σa where a table says so, and multiply shape × energy ×
// grazing factor: no texture type holds a 4D table and no filter unit does that reconstruction, so
// every lookup reads its taps explicitly (sampler.hpp's axis model, FixedView's reconstruction,
// in float). A cubic N_p lookup reads 256 values per lobe and channel.
//
// Buffers (hairlut/sampler/gpu_buffers.hpp fills them from a loaded table set; docs/gpu.md):
//   HAIRLUT_GENERIC_SET   a HairlutGenericSet (below): which tables serve each lobe, and each
//                         table's axes; std140 or std430 (every member is 16-byte aligned).
//   HAIRLUT_GENERIC_DATA  the float values of every table, row-major, last axis fastest.
// This file declares the set as a uniform block at (HAIRLUT_GENERIC_DESCRIPTOR_SET,
// HAIRLUT_GENERIC_SET_BINDING), default set 0, binding 0, and the values as a readonly storage
// buffer at HAIRLUT_GENERIC_DATA_BINDING (default: the next binding), unless the shader defines
// HAIRLUT_GENERIC_DATA as its own float array before including.
//
// Directions are unit vectors in the fiber frame (x along the fiber, root to tip), wo towards the
// viewer (held), wi towards the light (sampled), as HairScattering::eval takes them; angles [rad]
// θ = atan2(w.x, |w.yz|), φ = φo − φi. Arguments must be finite.
#ifndef HAIRLUT_GENERIC_GLSL
#define HAIRLUT_GENERIC_GLSL

#ifndef HAIRLUT_GENERIC_SET_BINDING
#define HAIRLUT_GENERIC_SET_BINDING 0
#endif
#ifndef HAIRLUT_GENERIC_DATA_BINDING
#define HAIRLUT_GENERIC_DATA_BINDING (HAIRLUT_GENERIC_SET_BINDING + 1)
#endif
#ifndef HAIRLUT_GENERIC_DESCRIPTOR_SET
#define HAIRLUT_GENERIC_DESCRIPTOR_SET 0
#endif
#define HAIRLUT_GENERIC_MAX_TABLES 24
#define HAIRLUT_GENERIC_MAX_AXES 80

// One axis (48 bytes). map: t0, scale, offset and top of sampler.hpp's PreparedAxis (the node
// coordinate s = clamp((t(x) − t0) scale + offset, 0, top)); range: lo, hi, the snapping distance,
// 0; mode: count, spacing (0 uniform, 1 cos, 2 sin, 3 log, 4 sqrt), flags (1 cubic, 2 geometric,
// 4 even azimuth: |x| folded into [0, π], 8 mirror node beyond the first node, 16 beyond the last,
// 32 centre-placed nodes), stride (values between neighbouring nodes).
struct HairlutAxis {
  vec4 map;
  vec4 range;
  ivec4 mode;
};
// One table (48 bytes). head: first value in HAIRLUT_GENERIC_DATA, first axis, axis count (1 to 4),
// the cos power n of its grazing factor (hairlut::sampler::GrazingFactor; 0 and x_scale = 0: none);
// grazing: x_scale, τ, b, c; grazing2: d, e, f, 0.
struct HairlutTable {
  ivec4 head;
  vec4 grazing;
  vec4 grazing2;
};
// The set: lobes.x explicit lobes P (at most 8), lobes.y 1 with a residual; per explicit lobe p
// the table indices np (N_p or its shape over β, σa, θd, φ), energy (its energy over σa, θd; −1
// when N_p is stored as is) and mp (M_p over β, θi, θr); residual: N over (σa, θd), its energy
// factor (−1: none), M_p. A table index is −1 where there is none.
struct HairlutGenericSet {
  ivec4 lobes;
  ivec4 np[2];
  ivec4 energy[2];
  ivec4 mp[2];
  ivec4 residual;
  HairlutTable tables[HAIRLUT_GENERIC_MAX_TABLES];
  HairlutAxis axes[HAIRLUT_GENERIC_MAX_AXES];
};

layout(std140, set = HAIRLUT_GENERIC_DESCRIPTOR_SET, binding = HAIRLUT_GENERIC_SET_BINDING) uniform HairlutGenericSetBlock {
  HairlutGenericSet hairlut_generic_set;
};
#define HAIRLUT_GENERIC_SET hairlut_generic_set
#ifndef HAIRLUT_GENERIC_DATA
layout(std430, set = HAIRLUT_GENERIC_DESCRIPTOR_SET, binding = HAIRLUT_GENERIC_DATA_BINDING) readonly buffer HairlutGenericDataBlock {
  float hairlut_generic_data[];
};
#define HAIRLUT_GENERIC_DATA hairlut_generic_data
#endif

// One fiber: absorption per channel per unit radius, β_m of M_p and β_n of N_p [rad], and a
// cuticle scale angle added to the tilts the tables were baked with (pbrt-v4's α: R moves by 2α,
// TT by −α, TRT by −4α), as hairlut::sampler::Fiber.
struct HairlutFiber {
  vec3 sigma_a;
  float beta_m;
  float beta_n;
  float tilt;
};

const float HAIRLUT_GENERIC_PI = 3.14159265358979;

// The taps of one axis at x: up to four values at offsets off (in values) with weights w.
struct HairlutTaps {
  ivec4 off;
  vec4 w;
  int n;
};

// x remainder 2π, folded to [0, π] (|x| ≤ π is kept as it is), as the C++ views fold an azimuth.
float hairlut_fold_azimuth(float x) {
  x = abs(x);
  return x <= HAIRLUT_GENERIC_PI ? x : abs(x - 2.0 * HAIRLUT_GENERIC_PI * roundEven(x / (2.0 * HAIRLUT_GENERIC_PI)));
}

// The node beyond an end (i < 0 or i ≥ count), or −1 where the end has none (the quadratic
// extrapolation then): sampler.hpp's wrapped_index for clamped and even axes.
int hairlut_wrapped_index(HairlutAxis a, int i) {
  int n = a.mode.x, flags = a.mode.z;
  if (i >= 0 && i < n) return i;
  if ((flags & (i < 0 ? 8 : 16)) == 0) return -1;
  bool centers = (flags & 32) != 0;
  if (i < 0) i = centers ? -1 - i : -i;
  if (i > n - 1) i = centers ? 2 * n - 1 - i : 2 * (n - 1) - i;
  return clamp(i, 0, n - 1);
}

// FixedAxis::taps in float: fold, map, locate (with the snap to a node), then two linear taps or
// four Catmull–Rom taps with the end rules.
HairlutTaps hairlut_axis_taps(HairlutAxis a, float x) {
  HairlutTaps r;
  r.off = ivec4(0);
  r.w = vec4(1.0, 0.0, 0.0, 0.0);
  r.n = 1;
  int n = a.mode.x, spacing = a.mode.y, flags = a.mode.z, stride = a.mode.w;
  if (n <= 1) return r;
  if ((flags & 4) != 0) x = hairlut_fold_azimuth(x);
  float t = x;
  if (spacing != 0) {
    x = max(x, a.range.x);
    if (spacing == 3) t = log(x);
    else if (spacing == 4) t = sqrt(x);
    else t = spacing == 1 ? cos(min(x, a.range.y)) : sin(min(x, a.range.y));
  }
  float s = clamp((t - a.map.x) * a.map.y + a.map.z, 0.0, a.map.w);
  int i = int(s);
  float f = s - float(i);
  if (abs(f - 0.5) > 0.5 - a.range.z) {  // within snap of a node: on it
    if (f > 0.5) ++i;
    f = 0.0;
    if (i >= n - 1) {
      i = n - 2;
      f = 1.0;
    }
  }
  if ((flags & 1) == 0 || n < 3) {
    r.off = ivec4(i, i + 1, 0, 0) * stride;
    r.w = vec4(1.0 - f, f, 0.0, 0.0);
    r.n = 2;
    return r;
  }
  float f2 = f * f, f3 = f2 * f;
  vec4 w = 0.5 * vec4(-f3 + 2.0 * f2 - f, 3.0 * f3 - 5.0 * f2 + 2.0, -3.0 * f3 + 4.0 * f2 + f, f3 - f2);
  ivec4 idx = ivec4(i - 1, i, i + 1, i + 2);
  if (i < 1 || i + 2 > n - 1) {
    idx = ivec4(hairlut_wrapped_index(a, idx.x), hairlut_wrapped_index(a, idx.y), hairlut_wrapped_index(a, idx.z), hairlut_wrapped_index(a, idx.w));
    if (idx.x < 0) {  // beyond a clamped end: the quadratic extrapolation 3v₀ − 3v₁ + v₂
      idx.x = idx.y;
      float g = w.x;
      w = vec4(0.0, w.y + 3.0 * g, w.z - 3.0 * g, w.w + g);
    }
    if (idx.w < 0) {
      idx.w = idx.z;
      float g = w.w;
      w = vec4(w.x + g, w.y - 3.0 * g, w.z + 3.0 * g, 0.0);
    }
  }
  r.off = idx * stride;
  r.w = w;
  r.n = 4;
  return r;
}

// Σ over the taps of every axis (unused axes: one tap of weight 1 at offset 0) of the weights'
// product times the value.
float hairlut_tensor(int base, HairlutTaps t0, HairlutTaps t1, HairlutTaps t2, HairlutTaps t3) {
  float v = 0.0;
  for (int a = 0; a < t0.n; ++a) {
    float va = 0.0;
    for (int b = 0; b < t1.n; ++b) {
      float vb = 0.0;
      for (int c = 0; c < t2.n; ++c) {
        int o = base + t0.off[a] + t1.off[b] + t2.off[c];
        float vc = 0.0;
        for (int d = 0; d < t3.n; ++d) vc += t3.w[d] * HAIRLUT_GENERIC_DATA[o + t3.off[d]];
        vb += t2.w[c] * vc;
      }
      va += t1.w[b] * vb;
    }
    v += t0.w[a] * va;
  }
  return v;
}

// Table ti at x (its axes' coordinates, unused ones ignored): FixedView's value, with a geometric
// axis combined last as v₀^(1−w) v₁^w (linear where either is ≤ 0).
float hairlut_table(int ti, vec4 x) {
  HairlutTable tb = HAIRLUT_GENERIC_SET.tables[ti];
  HairlutTaps t[4];
  int geometric = -1;
  for (int k = 0; k < 4; ++k) {
    t[k].off = ivec4(0);
    t[k].w = vec4(1.0, 0.0, 0.0, 0.0);
    t[k].n = 1;
    if (k < tb.head.z) {
      HairlutAxis a = HAIRLUT_GENERIC_SET.axes[tb.head.y + k];
      t[k] = hairlut_axis_taps(a, x[k]);
      if ((a.mode.z & 2) != 0 && a.mode.x > 1) geometric = k;
    }
  }
  if (geometric < 0 || t[geometric].w.y == 0.0) return hairlut_tensor(tb.head.x, t[0], t[1], t[2], t[3]);
  HairlutTaps g = t[geometric];
  float w = g.w.y;
  t[geometric].n = 1;
  t[geometric].w = vec4(1.0, 0.0, 0.0, 0.0);
  float v0 = hairlut_tensor(tb.head.x, t[0], t[1], t[2], t[3]);
  t[geometric].off.x = g.off.y;
  float v1 = hairlut_tensor(tb.head.x, t[0], t[1], t[2], t[3]);
  return v0 > 0.0 && v1 > 0.0 ? exp((1.0 - w) * log(v0) + w * log(v1)) : (1.0 - w) * v0 + w * v1;
}

// The grazing factor of table ti at σa and u = cos θd (GrazingFactor::of_cos_x): u^n, times
// u (u² + b x u + e x²) / (u³ + c x u² + d x² u + f x³) with x = x_scale (e^{τ σa} − 1) where the
// table has an absorption term. 1 for a table without one.
float hairlut_grazing(int ti, float sigma_a, float u) {
  HairlutTable tb = HAIRLUT_GENERIC_SET.tables[ti];
  u = max(u, 0.0);
  float g = 1.0;
  for (int k = 0; k < tb.head.w; ++k) g *= u;
  if (tb.grazing.x != 0.0) {
    float ts = tb.grazing.y * sigma_a;
    float x = tb.grazing.x * (abs(ts) < 1e-3 ? ts * (1.0 + 0.5 * ts) : exp(ts) - 1.0);
    float den = ((u + tb.grazing.w * x) * u + tb.grazing2.x * x * x) * u + tb.grazing2.z * x * x * x;
    g = den > 0.0 && !isinf(den) ? g * u * ((u + tb.grazing.z * x) * u + tb.grazing2.y * x * x) / den : 0.0;
  }
  return g;
}

// θo as lobe p's M_p reads it: moved by the fiber's extra tilt (R 2α, TT −α, TRT −4α) and folded
// back across a pole (HairScattering::held).
float hairlut_held(HairlutFiber f, int p, float theta_o) {
  if (f.tilt == 0.0 || p > 2) return theta_o;
  float shift = p == 0 ? 2.0 * f.tilt : p == 1 ? -f.tilt : -4.0 * f.tilt, h = 0.5 * HAIRLUT_GENERIC_PI;
  float t = theta_o - shift;
  return t > h ? 2.0 * h - t : t < -h ? -2.0 * h - t : t;
}

// S per channel [1/sr] at θo (held), θi (sampled), φ = φo − φi [rad], as HairScattering::eval(fiber,
// theta_o, theta_i, phi, rgb).
vec3 hairlut_generic_eval_angles(HairlutFiber f, float theta_o, float theta_i, float phi) {
  vec3 rgb = vec3(0.0);
  float td = 0.5 * (theta_o - theta_i), atd = abs(td), u = cos(td), fp = hairlut_fold_azimuth(phi);
  int lobes = HAIRLUT_GENERIC_SET.lobes.x;
  bool residual = HAIRLUT_GENERIC_SET.lobes.y != 0;
  for (int p = 0; p <= lobes; ++p) {
    if (p == lobes && !residual) break;
    bool explicit_lobe = p < lobes;
    int mp = explicit_lobe ? HAIRLUT_GENERIC_SET.mp[p / 4][p % 4] : HAIRLUT_GENERIC_SET.residual.z;
    float m = max(hairlut_table(mp, vec4(f.beta_m, theta_i, explicit_lobe ? hairlut_held(f, p, theta_o) : theta_o, 0.0)), 0.0);
    if (!(m > 0.0)) continue;
    vec3 n;
    for (int c = 0; c < 3; ++c) {
      float s = f.sigma_a[c], v;
      if (explicit_lobe) {
        v = hairlut_table(HAIRLUT_GENERIC_SET.np[p / 4][p % 4], vec4(f.beta_n, s, atd, fp));
        int e = HAIRLUT_GENERIC_SET.energy[p / 4][p % 4];
        if (e >= 0) v *= max(hairlut_table(e, vec4(s, atd, 0.0, 0.0)), 0.0) * hairlut_grazing(e, s, u);
        v = max(v, 0.0);
      } else {
        int nr = HAIRLUT_GENERIC_SET.residual.x, e = HAIRLUT_GENERIC_SET.residual.y;
        v = hairlut_table(nr, vec4(s, atd, 0.0, 0.0));
        if (e >= 0) v *= hairlut_table(e, vec4(s, atd, 0.0, 0.0));
        v = max(v, 0.0) * hairlut_grazing(nr, s, u) * (e >= 0 ? hairlut_grazing(e, s, u) : 1.0);
      }
      n[c] = v;
    }
    rgb += m * n;
  }
  return rgb;
}

// atan2 for y ≥ 0 to a few float ulp, in [0, π] (0 at the origin): GLSL's built-in need not be
// close (Vulkan allows atan 4096 ulp), and the angles place a direction on the tables' axes.
// Cephes' single-precision polynomial, as hairlut.glsl's hairlut_atan2_upper (this file is
// included on its own, so it carries its own copy).
float hairlut_generic_atan2_upper(float y, float x) {
  float ax = abs(x), hi = max(ax, y), lo = min(ax, y);
  if (hi == 0.0) return 0.0;
  float t = lo / hi, base = 0.0;
  if (t > 0.41421356237) {
    base = 0.78539816339744831;
    t = (t - 1.0) / (t + 1.0);
  }
  float z = t * t;
  float r = base + (((8.05374449538e-2 * z - 1.38776856032e-1) * z + 1.99777106478e-1) * z - 3.33329491539e-1) * z * t + t;
  if (y > ax) r = 1.5707963267948966 - r;
  return x < 0.0 ? 3.14159265358979 - r : r;
}

// S per channel [1/sr] for unit vectors wo, wi in the fiber frame, as HairScattering::eval(fiber,
// wo, wi, rgb): θ = atan2(w.x, |w.yz|) (near a pole |w.yz| keeps the precision that 1 − w.x²
// loses), |φ| the angle between the projections on the normal plane.
vec3 hairlut_generic_eval(HairlutFiber f, vec3 wo, vec3 wi) {
  float so = clamp(wo.x, -1.0, 1.0), si = clamp(wi.x, -1.0, 1.0);
  float to = hairlut_generic_atan2_upper(abs(so), length(wo.yz)), ti = hairlut_generic_atan2_upper(abs(si), length(wi.yz));
  float cross_ = wo.y * wi.z - wo.z * wi.y, dot_ = wo.y * wi.y + wo.z * wi.z;
  return hairlut_generic_eval_angles(f, so < 0.0 ? -to : to, si < 0.0 ? -ti : ti, hairlut_generic_atan2_upper(abs(cross_), dot_));
}

#endif  // HAIRLUT_GENERIC_GLSL
