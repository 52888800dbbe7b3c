#version 450
// pbrt-v4's HairBxDF::f in GLSL, operation for operation as tools/bench-hair-luts/pbrt_hair.cpp
// re-implements it (RGB instead of four spectral samples, pMax = 3): the baseline whose compiled
// SPIR-V docs/gpu.md counts against eval_material.comp's. Same point layout and outputs.
layout(local_size_x = 64) in;

layout(set = 0, binding = 2, std140) uniform Hair {
  vec4 sigma_a;  // RGB, h
  vec4 v;        // v[0..3]
  vec4 sin2k;    // sin 2^k α, k = 0..2; s
  vec4 cos2k;    // cos 2^k α, k = 0..2; η
};
layout(set = 0, binding = 3, std430) readonly buffer Points { vec4 points[]; };
layout(set = 0, binding = 4, std430) writeonly buffer Values { vec4 values[]; };
layout(push_constant) uniform Push { uint count; uint mode; };

const float PI = 3.14159265358979;

float sq(float x) { return x * x; }
float safe_sqrt(float x) { return sqrt(max(0.0, x)); }
float safe_asin(float x) { return asin(clamp(x, -1.0, 1.0)); }

float fast_exp(float x) {
  float xp = x * 1.442695041, fxp = floor(xp), f = xp - fxp;
  int i = int(fxp);
  float two_f = fma(f, fma(f, fma(f, 0.0781455737, 0.226173572), 0.695556856), 1.0);
  int exponent = int(floatBitsToUint(two_f) >> 23) - 127 + i;
  if (exponent < -126) return 0.0;
  if (exponent > 127) return 1.0 / 0.0;
  uint bits = floatBitsToUint(two_f) & 0x807fffffu;
  return uintBitsToFloat(bits | (uint(exponent + 127) << 23));
}

float bessel_i0(float x) {
  float val = 0.0, x2i = 1.0;
  int ifact = 1, i4 = 1;
  for (int i = 0; i < 10; ++i) {
    if (i > 1) ifact *= i;
    val += x2i / (float(i4) * float(ifact) * float(ifact));
    x2i *= x * x;
    i4 *= 4;
  }
  return val;
}

float log_bessel_i0(float x) {
  if (x > 12.0) return x + 0.5 * (-log(2.0 * PI) + log(1.0 / x) + 1.0 / (8.0 * x));
  return log(bessel_i0(x));
}

float longitudinal(float cos_i, float cos_o, float sin_i, float sin_o, float v) {
  float a = cos_i * cos_o / v, b = sin_i * sin_o / v;
  return v <= 0.1 ? fast_exp(log_bessel_i0(a) - b - 1.0 / v + 0.6931 + log(1.0 / (2.0 * v)))
                  : (fast_exp(-b) * bessel_i0(a)) / (sinh(1.0 / v) * 2.0 * v);
}

float fresnel_dielectric(float cos_i, float eta) {
  cos_i = clamp(cos_i, -1.0, 1.0);
  if (cos_i < 0.0) {
    eta = 1.0 / eta;
    cos_i = -cos_i;
  }
  float sin2_t = (1.0 - sq(cos_i)) / sq(eta);
  if (sin2_t >= 1.0) return 1.0;
  float cos_t = safe_sqrt(1.0 - sin2_t);
  float parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  float perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return (sq(parl) + sq(perp)) / 2.0;
}

float trimmed_logistic(float x, float s) {
  x = abs(x);
  float logistic = exp(-x / s) / (s * sq(1.0 + exp(-x / s)));
  return logistic / (1.0 / (1.0 + exp(-PI / s)) - 1.0 / (1.0 + exp(PI / s)));
}

float azimuthal(float phi, int p, float s, float gamma_o, float gamma_t) {
  float dphi = phi - (2.0 * float(p) * gamma_t - 2.0 * gamma_o + float(p) * PI);
  while (dphi > PI) dphi -= 2.0 * PI;
  while (dphi < -PI) dphi += 2.0 * PI;
  return trimmed_logistic(dphi, s);
}

vec3 pbrt_hair_f(vec3 wo, vec3 wi) {
  float h = sigma_a.w, s = sin2k.w, eta = cos2k.w;
  float sin_o = wo.x, cos_o = safe_sqrt(1.0 - sq(sin_o));
  float phi_o = atan(wo.z, wo.y);
  float gamma_o = safe_asin(h);
  float sin_i = wi.x, cos_i = safe_sqrt(1.0 - sq(sin_i));
  float phi_i = atan(wi.z, wi.y);
  float sin_t = sin_o / eta, cos_t = safe_sqrt(1.0 - sq(sin_t));
  float etap = safe_sqrt(sq(eta) - sq(sin_o)) / cos_o;
  float sin_gt = h / etap, cos_gt = safe_sqrt(1.0 - sq(sin_gt));
  float gamma_t = safe_asin(sin_gt);
  vec3 T = exp(-sigma_a.xyz * (2.0 * cos_gt / cos_t));
  float phi = phi_i - phi_o;

  vec3 ap[4];
  float fr = fresnel_dielectric(cos_o * safe_sqrt(1.0 - sq(h)), eta);
  ap[0] = vec3(fr);
  ap[1] = sq(1.0 - fr) * T;
  ap[2] = ap[1] * T * fr;
  ap[3] = ap[2] * fr * T / (1.0 - T * fr);

  vec3 sum = vec3(0.0);
  for (int p = 0; p < 3; ++p) {
    float sin_po, cos_po;
    if (p == 0) {
      sin_po = sin_o * cos2k[1] - cos_o * sin2k[1];
      cos_po = cos_o * cos2k[1] + sin_o * sin2k[1];
    } else if (p == 1) {
      sin_po = sin_o * cos2k[0] + cos_o * sin2k[0];
      cos_po = cos_o * cos2k[0] - sin_o * sin2k[0];
    } else {
      sin_po = sin_o * cos2k[2] + cos_o * sin2k[2];
      cos_po = cos_o * cos2k[2] - sin_o * sin2k[2];
    }
    cos_po = abs(cos_po);
    float mp = longitudinal(cos_i, cos_po, sin_i, sin_po, v[p]);
    float np = azimuthal(phi, p, s, gamma_o, gamma_t);
    sum += mp * ap[p] * np;
  }
  float mtail = longitudinal(cos_i, cos_o, sin_i, sin_o, v[3]);
  sum += mtail * ap[3] / (2.0 * PI);
  float abs_cos = abs(wi.z);
  if (abs_cos > 0.0) sum /= abs_cos;
  return sum;
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  values[i] = vec4(pbrt_hair_f(points[2 * i].xyz, points[2 * i + 1].xyz), 0.0);
}
