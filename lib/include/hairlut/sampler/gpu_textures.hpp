// Per-material hair tables laid out as GPU textures for lib/shaders/hairlut.glsl: two 2D array
// textures of RGBA texels (float32, or half after to_half) and one HairlutMaterial block per
// material. Header-only, C++17, on the header-only runtime's MaterialTables (an engine that reads
// the HDF5 file itself fills those; hairlut::TableSet users take them from the set, as
// tests/gpu/test_gpu_material.cpp does).
//
//   N_p texture: width = φ nodes, height = θd nodes; per material one layer per explicit lobe
//                (RGB = channels, A = 0) and one for the residual (its N repeated along φ).
//   M_p texture: width = θr nodes, height = θi nodes; per material ⌈lobes / 4⌉ layers, lobe p in
//                layer p / 4, component p % 4 (the residual is the last lobe).
//   rows:        float32 array (std430) of what sampling reads besides the tables
//                (MaterialScattering::Rows, guides as exact integers), at each material's offsets.
// Texel (x, y) of layer l is element ((l · height + y) · width + x) · 4 + component, the order
// vkCmdCopyBufferToImage and glTexSubImage3D read. Values that are negative, NaN or infinite are
// stored as 0, as the C++ runtime reads them.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "hairlut/sampler/material_scattering.hpp"

namespace hairlut::gpu {

/// The GLSL struct HairlutMaterial (std140 and std430: 176 bytes).
struct GpuMaterial {
  float theta_d[4], phi[4], theta_i[4], theta_r[4];  // a, b, last, 1 / count: s = clamp((x − a) b, 0, last)
  std::int32_t lobes[4];                             // explicit lobes, residual (0/1), first N_p layer, first M_p layer
  std::int32_t flags[4];                             // θd cos-spaced (1) or uniform (0); grazing factors: the explicit
                                                     // lobes' cos powers (2 bits per lobe), the residual's, its absorption term (1)
  std::int32_t rows0[4];                             // sampling rows' offsets: gq, gcum, gguide, z
  std::int32_t rows1[4];                             // nbar, ncum, nguide; nq (step 1's θi nodes)
  float rows2[4];                                    // hq (their step), θi of the first, 0, 0
  float grazing_x[4];                                // the residual's grazing factor: x per channel (held at 1e9), f
  float grazing_bcde[4];                             // and its b, c, d, e
};
static_assert(sizeof(GpuMaterial) == 176, "HairlutMaterial is 176 bytes in std140");

struct MaterialTextures {
  int np_width = 0, np_height = 0, np_layers = 0;  // φ, θd, layers
  int mp_width = 0, mp_height = 0, mp_layers = 0;  // θr, θi, layers
  std::vector<float> np, mp;                       // RGBA texels, layer by layer
  std::vector<float> rows;                         // the sampling rows of every material (a storage buffer)
  std::vector<GpuMaterial> materials;              // in the order added
  int explicit_lobes = 0;
  bool residual = false;

  /// Appends a material; every material must have the first one's axes and lobes. Throws
  /// std::invalid_argument naming what the shader cannot read.
  template <class T>
  void add(const hairlut::sampler::MaterialTables<T>& t);
};

/// IEEE 754 binary16 of a finite x ≥ 0, rounded to nearest even (65504 beyond the largest half).
inline std::uint16_t to_half(float x) {
  std::uint32_t b;
  std::memcpy(&b, &x, 4);
  const std::uint32_t sign = (b >> 16) & 0x8000u, abs = b & 0x7fffffffu;
  if (abs >= 0x477ff000u) return static_cast<std::uint16_t>(sign | 0x7bffu);  // ≥ 65520 rounds to inf: hold the largest
  if (abs < 0x38800000u) {                                                    // below 2⁻¹⁴: subnormal half (or 0)
    if (abs < 0x33000000u) return static_cast<std::uint16_t>(sign);           // below 2⁻²⁵: rounds to 0
    const std::uint32_t e = abs >> 23, m = (abs & 0x7fffffu) | 0x800000u, shift = 126u - e;
    std::uint32_t h = m >> shift;
    const std::uint32_t rest = m & ((1u << shift) - 1u), half_ulp = 1u << (shift - 1u);
    if (rest > half_ulp || (rest == half_ulp && (h & 1u))) ++h;
    return static_cast<std::uint16_t>(sign | h);
  }
  std::uint32_t h = ((abs >> 13) - (112u << 10));
  const std::uint32_t rest = abs & 0x1fffu;
  if (rest > 0x1000u || (rest == 0x1000u && (h & 1u))) ++h;
  return static_cast<std::uint16_t>(sign | h);
}
/// The float a binary16 holds (finite values; the sign kept).
inline float from_half(std::uint16_t h) {
  const int e = (h >> 10) & 0x1f, m = h & 0x3ff;
  const float v = e == 0 ? std::ldexp(static_cast<float>(m), -24) : std::ldexp(static_cast<float>(m | 0x400), e - 25);
  return (h & 0x8000u) ? -v : v;
}
inline std::vector<std::uint16_t> to_half(const std::vector<float>& v) {
  std::vector<std::uint16_t> h(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) h[i] = to_half(v[i]);
  return h;
}

namespace detail {
inline bool same_axis(const hairlut::sampler::Axis& a, const hairlut::sampler::Axis& b) {
  return a.count == b.count && a.lo == b.lo && a.hi == b.hi && a.spacing == b.spacing;
}
inline void check_axis(const hairlut::sampler::Axis& a, const char* name) {
  using namespace hairlut::sampler;
  if (a.count < 2 || a.interpolation != Interpolation::linear || a.placement != Placement::edges || !(a.lo < a.hi) ||
      (a.spacing != Spacing::uniform && !(a.spacing == Spacing::cos && std::string(name) == "theta_d")))
    throw std::invalid_argument(std::string("axis ") + name + ": the shader reads linear, edge-placed, uniform axes (theta_d: or cos-spaced) of 2 or more nodes");
}
// vec4(a, b, last, 1 / count) for x = the argument (uniform) or 1 − cos x (cos-spaced).
inline void locate(const hairlut::sampler::Axis& a, float* out) {
  const double last = a.count - 1;
  double lo = a.lo, span = a.hi - a.lo;
  if (a.spacing == hairlut::sampler::Spacing::cos) lo = 1.0 - std::cos(a.lo), span = std::cos(a.lo) - std::cos(a.hi);
  out[0] = static_cast<float>(lo), out[1] = static_cast<float>(last / span), out[2] = static_cast<float>(last);
  out[3] = static_cast<float>(1.0 / a.count);
}
template <class T>
float clean(T v) {
  const double x = static_cast<double>(v);
  return x > 0.0 && x < 3.0e38 ? static_cast<float>(x) : 0.0f;
}
}  // namespace detail

template <class T>
void MaterialTextures::add(const hairlut::sampler::MaterialTables<T>& t) {
  using namespace hairlut::sampler;
  const double pi = 3.14159265358979323846;
  detail::check_axis(t.theta_d, "theta_d"), detail::check_axis(t.phi, "phi");
  detail::check_axis(t.theta_i, "theta_i"), detail::check_axis(t.theta_r, "theta_r");
  if (t.phi.wrap != Wrap::even || t.phi.lo != 0.0 || std::fabs(t.phi.hi - pi) > 1e-12)
    throw std::invalid_argument("axis phi: the shader reads an even phi axis over [0, 180] deg");
  if (t.lobes < 1 || t.lobes > MaterialTables<T>::kMaxLobes) throw std::invalid_argument("lobes: 1 to 7 explicit lobes");
  for (int p = 0; p < t.lobes; ++p)
    if (!t.np[p] || !t.mp[p]) throw std::invalid_argument("lobe " + std::to_string(p) + ": N_p or M_p table missing");
  const bool res = t.np_residual && t.mp_residual;
  if (materials.empty()) {
    np_width = t.phi.count, np_height = t.theta_d.count, mp_width = t.theta_r.count, mp_height = t.theta_i.count;
    explicit_lobes = t.lobes, residual = res;
  } else if (t.lobes != explicit_lobes || res != residual || np_width != t.phi.count || np_height != t.theta_d.count ||
             mp_width != t.theta_r.count || mp_height != t.theta_i.count) {
    throw std::invalid_argument("material " + std::to_string(materials.size()) + ": lobes or axes differ from the first material's");
  }
  const int lobes = t.lobes + (res ? 1 : 0), mp_add = (lobes + 3) / 4;
  GpuMaterial g{};
  detail::locate(t.theta_d, g.theta_d), detail::locate(t.phi, g.phi), detail::locate(t.theta_i, g.theta_i), detail::locate(t.theta_r, g.theta_r);
  g.lobes[0] = t.lobes, g.lobes[1] = res ? 1 : 0, g.lobes[2] = np_layers, g.lobes[3] = mp_layers;
  g.flags[0] = t.theta_d.spacing == Spacing::cos ? 1 : 0;
  // The grazing factors the tables were divided by (material_scattering.hpp). x is held at 1e9 so
  // that x³ stays within float: there (σa ≳ 8) the residual's factor is below 1e-9 and its energy,
  // e^{−τσa(P−1)}, has long underflowed.
  for (int p = 0; p < t.lobes; ++p) {
    if (t.grazing[p].x_scale != 0.0) throw std::invalid_argument("lobe " + std::to_string(p) + ": an explicit lobe's grazing factor must be a power of cos theta_d");
    g.flags[1] |= std::min(std::max(t.grazing[p].cos_power, 0), 2) << (2 * p);
  }
  if (res) {
    const GrazingFactor& f = t.residual_grazing;
    g.flags[2] = std::min(std::max(f.cos_power, 0), 2), g.flags[3] = f.x_scale != 0.0 ? 1 : 0;
    for (int c = 0; c < 3; ++c) g.grazing_x[c] = static_cast<float>(std::min(f.x_of(std::max(0.0, t.sigma_a[c])), 1e9));
    g.grazing_x[3] = static_cast<float>(f.f);
    g.grazing_bcde[0] = static_cast<float>(f.b), g.grazing_bcde[1] = static_cast<float>(f.c), g.grazing_bcde[2] = static_cast<float>(f.d),
    g.grazing_bcde[3] = static_cast<float>(f.e);
  }
  // The sampling rows as the C++ runtime builds them.
  const MaterialScattering<T> ms(t);
  if (!ms.valid()) throw std::invalid_argument("material " + std::to_string(materials.size()) + ": the runtime cannot sample its tables");
  const typename MaterialScattering<T>::Rows rw = ms.rows();
  const std::size_t nr_ = static_cast<std::size_t>(t.theta_r.count), nt_ = static_cast<std::size_t>(t.theta_d.count),
                    nf_ = static_cast<std::size_t>(t.phi.count), nq = static_cast<std::size_t>(rw.nq), P = static_cast<std::size_t>(t.lobes);
  auto append = [&](const auto* v, std::size_t n) {
    const std::size_t at = rows.size();
    for (std::size_t i = 0; i < n; ++i) rows.push_back(static_cast<float>(v[i]));
    return static_cast<std::int32_t>(at);
  };
  g.rows0[0] = append(rw.gq, nr_ * (nq - 1) * 3), g.rows0[1] = append(rw.gcum, nr_ * nq);
  g.rows0[2] = append(rw.gguide, nr_ * static_cast<std::size_t>(rw.guide_theta));
  g.rows0[3] = append(rw.z, nt_ * static_cast<std::size_t>(rw.lobes_padded));
  g.rows1[0] = append(rw.nbar, P * nt_ * nf_), g.rows1[1] = append(rw.ncum, P * nt_ * nf_);
  g.rows1[2] = append(rw.nguide, P * nt_ * static_cast<std::size_t>(rw.guide_phi)), g.rows1[3] = rw.nq;
  g.rows2[0] = static_cast<float>(rw.hq), g.rows2[1] = static_cast<float>(t.theta_i.lo);
  materials.push_back(g);

  const std::size_t nf = static_cast<std::size_t>(np_width), nt = static_cast<std::size_t>(np_height);
  const std::size_t nr = static_cast<std::size_t>(mp_width), ni = static_cast<std::size_t>(mp_height);
  // N_p: source [channel][θd][φ]; the residual [channel][θd], repeated along φ.
  std::size_t base = np.size();
  np.resize(base + static_cast<std::size_t>(lobes) * nt * nf * 4, 0.0f);
  for (int p = 0; p < lobes; ++p)
    for (std::size_t k = 0; k < nt; ++k)
      for (std::size_t j = 0; j < nf; ++j)
        for (std::size_t c = 0; c < 3; ++c)
          np[base + ((static_cast<std::size_t>(p) * nt + k) * nf + j) * 4 + c] =
              p < t.lobes ? detail::clean(t.np[p][(c * nt + k) * nf + j]) : detail::clean(t.np_residual[c * nt + k]);
  np_layers += lobes;
  // M_p: source [θi][θr], four lobes to a layer.
  base = mp.size();
  mp.resize(base + static_cast<std::size_t>(mp_add) * ni * nr * 4, 0.0f);
  for (int p = 0; p < lobes; ++p) {
    const T* m = p < t.lobes ? t.mp[p] : t.mp_residual;
    for (std::size_t i = 0; i < ni; ++i)
      for (std::size_t r = 0; r < nr; ++r) mp[base + ((static_cast<std::size_t>(p / 4) * ni + i) * nr + r) * 4 + static_cast<std::size_t>(p % 4)] = detail::clean(m[i * nr + r]);
  }
  mp_layers += mp_add;
}

}  // namespace hairlut::gpu
