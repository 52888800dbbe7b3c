// hairlut sampler, typed views of d'Eon 2011 tables: N_p, M_p and the residual looked up by their
// physical arguments, and S(θi, θr, φ) of one fibre from the tables.
//
// Header-only and dependency-free (C++17, with sampler.hpp and sampler_fixed.hpp). A loader fills
// the views from a file's metadata once (hairlut::hair_tables in hairlut/tables/hair_views.hpp does it
// from a loaded TableSet; an engine may fill the axes from the sidecar or the EXR header itself).
//
// Conventions (docs/conventions.md, docs/table-format.md): angles in radians, θd = (θr − θi)/2,
// φ = φr − φi, σa per unit fibre radius, β the standard deviation of the azimuthal (N_p) or
// longitudinal (M_p, v = β²) roughness. S = Σ_p M_p(θi, θr) N_p(φ; θd) with no 1/cos²θd factor
// (d'Eon's energy-conserving M_p contains it), the residual p ≥ P added as one more lobe.
//
// What the views fold (what the physics makes symmetric): N_p depends on θd through cos θd, so θd
// → |θd|; N_p is even and 2π-periodic in φ, so φ is wrapped to [−π, π] and folded to |φ| unless
// the φ axis is periodic. Every value is ≥ 0 (cubic interpolation can undershoot next to a steep
// fall; the negative part is cut, as Table::sample does). A NaN argument gives NaN, never a node.
// Where a table stores the shape N_p / E_p (its `factor` attribute), NpLobe multiplies by the
// energy table interpolated at (σa, θd).
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "hairlut/sampler/sampler_fixed.hpp"

namespace hairlut {
namespace sampler {

namespace detail {
template <class R>
R nonnegative(R v) {
  return v < R(0) ? R(0) : v;  // NaN stays NaN
}
template <class R>
R fold_phi(R phi, const Axis& a) {
  if (a.wrap == Wrap::periodic) return phi;
  const R pi = static_cast<R>(3.14159265358979323846);
  return std::fabs(phi) <= pi ? std::fabs(phi) : std::fabs(std::remainder(phi, R(2) * pi));
}
}  // namespace detail

/// acos x for x ∈ [−1, 1] (clamped) by Abramowitz & Stegun 4.4.46: √(1 − |x|) times a degree-7
/// polynomial, absolute error ≤ 2e-8 rad before rounding in R (the tests check 3e-7 in float and
/// 5e-8 in double against std::acos). A few multiplications and one square root, against the
/// tens of nanoseconds of std::acos/std::atan2; table lookups need no more than that accuracy.
template <class R>
HAIRLUT_SAMPLER_INLINE R fast_acos(R x) {
  const R a = std::fabs(x) < R(1) ? std::fabs(x) : R(1);
  // The polynomial by Estrin's scheme (pairs, then a², a⁴): a shorter dependency chain than
  // Horner's, the same terms.
  const R a2 = a * a, a4 = a2 * a2;
  const R p01 = R(1.5707963050) + a * R(-0.2145988016), p23 = R(0.0889789874) + a * R(-0.0501743046);
  const R p45 = R(0.0308918810) + a * R(-0.0170881256), p67 = R(0.0066700901) + a * R(-0.0012624911);
  const R p = (p01 + a2 * p23) + a4 * (p45 + a2 * p67);
  const R r = std::sqrt(R(1) - a) * p;
  return x < R(0) ? static_cast<R>(3.14159265358979323846) - r : r;
}

/// atan x for x ∈ [0, 1] by Abramowitz & Stegun 4.4.49: x times a degree-8 polynomial in x²,
/// absolute error ≤ 2e-8 rad before rounding in R; evaluated by Estrin's scheme.
template <class R>
HAIRLUT_SAMPLER_INLINE R fast_atan01(R x) {
  const R z = x * x, z2 = z * z, z4 = z2 * z2;
  const R q01 = R(1) + z * R(-0.3333314528), q23 = R(0.1999355085) + z * R(-0.1420889944);
  const R q45 = R(0.1065626393) + z * R(-0.0752896400), q67 = R(0.0429096138) + z * R(-0.0161657367);
  return x * (((q01 + z2 * q23) + z4 * (q45 + z2 * q67)) + (z4 * z4) * R(0.0028662257));
}

/// The arguments of S from unit vectors in the fibre frame (x along the fibre root to tip, y–z
/// the normal plane; pbrt's hair frame): θ = asin x = π/2 − acos x (fast_acos, ≤ 2e-8 rad), and
/// φ ∈ [0, π] the angle between the normal-plane projections, atan2(|cross|, dot) of the two
/// projections by fast_atan01 on the octant (≤ 2e-8 rad, and no loss of accuracy near 0 and π);
/// N_p is even in φ, so its sign is not needed. φ = 0 when a direction lies along the fibre.
template <class R>
HAIRLUT_SAMPLER_INLINE void fibre_angles(const R* wi, const R* wo, R& theta_i, R& theta_r, R& phi) {
  const R half_pi = static_cast<R>(1.57079632679489661923);
  theta_i = half_pi - fast_acos(wi[0]);
  theta_r = half_pi - fast_acos(wo[0]);
  const R y = std::fabs(wi[1] * wo[2] - wi[2] * wo[1]), x = wi[1] * wo[1] + wi[2] * wo[2], ax = std::fabs(x);
  const R lo = y < ax ? y : ax, hi = y < ax ? ax : y;
  R t = fast_atan01(hi > R(0) ? lo / hi : R(0));
  t = y > ax ? half_pi - t : t;
  phi = x < R(0) ? R(2) * half_pi - t : t;
  if (!(wi[0] == wi[0]) || !(wo[0] == wo[0])) phi = wi[0] + wo[0];  // NaN stays NaN
}

/// N_p of one lobe over (β, σa, θd, φ), stored in that axis order; optionally the shape N_p/E_p
/// times the energy table over (σa, θd).
template <class T, class R = double>
class NpLobe {
 public:
  NpLobe() = default;
  /// axes: beta, sigma_a, theta_d, phi; energy (nullable) and its axes: sigma_a, theta_d.
  NpLobe(const T* values, const Axis* axes, const T* energy = nullptr, const Axis* energy_axes = nullptr)
      : table_(values, axes), phi_axis_(axes[3]) {
    if (energy) energy_ = FixedView<T, 2, R>(energy, energy_axes), has_energy_ = true;
  }
  bool valid() const { return table_.data() != nullptr; }
  bool has_energy() const { return has_energy_; }
  const FixedView<T, 4, R>& table() const { return table_; }
  const FixedView<T, 2, R>& energy() const { return energy_; }

  /// N_p [1/rad] at β, σa, θd, φ (radians; any sign of θd and φ).
  R operator()(R beta, R sigma_a, R theta_d, R phi) const {
    const R x[4] = {beta, sigma_a, std::fabs(theta_d), detail::fold_phi(phi, phi_axis_)};
    R v = table_(x);
    if (has_energy_) v *= energy(sigma_a, theta_d);
    return detail::nonnegative(v);
  }
  /// E_p = ∫N_p dφ at σa, θd (1 when the table stores N_p itself).
  R energy(R sigma_a, R theta_d) const {
    if (!has_energy_) return R(1);
    const R y[2] = {sigma_a, std::fabs(theta_d)};
    return detail::nonnegative(energy_(y));
  }

 private:
  FixedView<T, 4, R> table_;
  FixedView<T, 2, R> energy_;
  Axis phi_axis_;
  bool has_energy_ = false;
};

/// M_p of one lobe over (β, θi, θr), the lobe's tilt included.
template <class T, class R = double>
class MpLobe {
 public:
  MpLobe() = default;
  /// axes: beta, theta_i, theta_r.
  MpLobe(const T* values, const Axis* axes) : table_(values, axes) {}
  bool valid() const { return table_.data() != nullptr; }
  const FixedView<T, 3, R>& table() const { return table_; }
  /// M_p [1/rad] at β (longitudinal roughness, v = β²), θi, θr (radians).
  R operator()(R beta, R theta_i, R theta_r) const {
    const R x[3] = {beta, theta_i, theta_r};
    return detail::nonnegative(table_(x));
  }

 private:
  FixedView<T, 3, R> table_;
};

/// N of the residual lobes p ≥ P over (σa, θd): their energy spread uniformly in φ and β.
template <class T, class R = double>
class NpResidual {
 public:
  NpResidual() = default;
  /// axes: sigma_a, theta_d; energy (nullable, a factor over the same axes).
  NpResidual(const T* values, const Axis* axes, const T* energy = nullptr, const Axis* energy_axes = nullptr) : table_(values, axes) {
    if (energy) energy_ = FixedView<T, 2, R>(energy, energy_axes), has_energy_ = true;
  }
  bool valid() const { return table_.data() != nullptr; }
  R operator()(R sigma_a, R theta_d) const {
    const R x[2] = {sigma_a, std::fabs(theta_d)};
    R v = table_(x);
    if (has_energy_) v *= energy_(x);
    return detail::nonnegative(v);
  }

 private:
  FixedView<T, 2, R> table_;
  FixedView<T, 2, R> energy_;
  bool has_energy_ = false;
};

/// The d'Eon 2011 tables of one set: N_p and M_p per explicit lobe, and the residual.
template <class T, class R = double>
struct HairTables {
  static constexpr int kMaxLobes = 8;
  static constexpr int kMaxBetaBands = 4;
  int lobes = 0;           ///< explicit lobes p = 0 … lobes − 1 (R, TT, TRT, ...)
  double eta = 0.0;        ///< the fibre's refractive index the tables were baked for
  NpLobe<T, R> np[kMaxLobes];  ///< N_p (β band 0 of a set baked in β bands)
  /// β bands (docs/table-format.md): band 0 is np, band k ≥ 1 np_band[k − 1]; band_hi[k] is the
  /// upper end of band k's β range. A set without bands has beta_bands = 1.
  int beta_bands = 1;
  double band_hi[kMaxBetaBands] = {};
  NpLobe<T, R> np_band[kMaxBetaBands - 1][kMaxLobes];
  MpLobe<T, R> mp[kMaxLobes];
  bool has_residual = false;
  NpResidual<T, R> np_residual;
  MpLobe<T, R> mp_residual;

  /// The band that serves β: the first whose upper end is ≥ β (a shared edge reads the lower
  /// band), the last band above the last end.
  int band_of(R beta) const {
    int k = 0;
    while (k + 1 < beta_bands && beta > static_cast<R>(band_hi[k])) ++k;
    return k;
  }
  /// The N_p views of every lobe in the band that serves β.
  const NpLobe<T, R>* np_at(R beta) const {
    const int k = band_of(beta);
    return k == 0 ? np : np_band[k - 1];
  }
  /// N_p of lobe p [1/rad] at β, σa, θd, φ, from the band that serves β.
  R np_value(int p, R beta, R sigma_a, R theta_d, R phi) const { return np_at(beta)[p](beta, sigma_a, theta_d, phi); }
};

/// One fibre: absorption per channel (per unit radius; e.g. from melanin), the longitudinal
/// roughness β_m of M_p and the azimuthal roughness β_n of N_p (radians, the tables' β axes).
struct Fibre {
  double sigma_a[3] = {0.0, 0.0, 0.0};
  double beta_m = 0.0;
  double beta_n = 0.0;
};

/// S(θi, θr, φ) per channel for one fibre, from the tables only.
///
/// Built once per fibre (like a renderer's per-material precompute): the tables are evaluated at
/// the fibre's β and σa on the nodes of their other axes, i.e. N_p per channel over the N_p
/// tables' (θd, φ) nodes, E_p and the residual per channel over the energy tables' θd nodes, M_p
/// over the (θi, θr) nodes. A lookup then interpolates these slices with the tables' own
/// interpolation on the remaining axes (2 or 4 taps each); the slices of all lobes and channels
/// are interleaved per node, so that one pass over the taps gives every lobe and channel.
/// Exactness: for axes interpolated linearly or cubically the tensor product does not depend on
/// the order of the axes, so the N_p and M_p slices give the tables' values (TableView's up to
/// rounding). Where a bound axis is geometric (σa of the default energy tables), the slice holds
/// the exact value at each θd node, and between nodes it interpolates those along θd instead of
/// combining the two σa rows geometrically after interpolating each: the difference is second
/// order in the θd step (the tests bound it against the typed views). The N_p slices use the
/// first lobe's θd and φ nodes, the energy rows the first lobe's energy θd nodes, the M_p slices
/// the first lobe's (θi, θr) nodes: exact when every lobe shares them (as baked tables do).
/// Memory: (3 lobes · N_p θd × φ nodes + 3 (lobes + 1) energy θd nodes + (lobes + 1) θi × θr
/// nodes) values of type R. Immutable after construction: one instance may serve many threads.
template <class T, class R = double>
class FibreScattering {
 public:
  FibreScattering() = default;
  FibreScattering(const HairTables<T, R>& t, const Fibre& f) {
    lobes_ = t.lobes;
    residual_ = t.has_residual;
    L_ = lobes_ + (residual_ ? 1 : 0);
    if (lobes_ <= 0 || lobes_ > HairTables<T, R>::kMaxLobes) {
      lobes_ = L_ = 0;
      return;
    }
    eval_ = pick<1>(lobes_, residual_);
    // Blocks padded to multiples of 4 values (whole SIMD registers; the padding holds zeros).
    const auto bn = static_cast<std::size_t>(pad(3 * lobes_)), be = static_cast<std::size_t>(pad(3 * L_)), bm = static_cast<std::size_t>(pad(L_));
    // N_p: [θd node][φ node][lobe][channel].
    const NpLobe<T, R>* np = t.np_at(static_cast<R>(f.beta_n));  // the β band of the fibre
    const auto& n0 = np[0].table();
    np_axes_[0] = n0.axis(2).axis(), np_axes_[1] = n0.axis(3).axis();
    const int nt = np_axes_[0].count, nf = np_axes_[1].count;
    np_theta_ = FixedAxis<R>(np_axes_[0], static_cast<std::size_t>(nf) * bn);
    np_phi_ = FixedAxis<R>(np_axes_[1], bn);
    np_.assign(static_cast<std::size_t>(nt * nf) * bn, R(0));
    for (int k = 0; k < nt; ++k)
      for (int j = 0; j < nf; ++j)
        for (int p = 0; p < lobes_; ++p)
          for (int c = 0; c < 3; ++c) {
            const R x[4] = {static_cast<R>(f.beta_n), static_cast<R>(f.sigma_a[c]), static_cast<R>(node(np_axes_[0], k)),
                            static_cast<R>(node(np_axes_[1], j))};
            np_[static_cast<std::size_t>(k * nf + j) * bn + static_cast<std::size_t>(3 * p + c)] = np[p].table()(x);
          }
    // Energies and the residual: [θd node][lobe][channel] (1 for a lobe that stores N_p itself).
    has_energy_ = np[0].has_energy();
    e_axis_ = has_energy_ ? np[0].energy().axis(1).axis() : np_axes_[0];
    const int ne = e_axis_.count;
    e_theta_ = FixedAxis<R>(e_axis_, be);
    e_.assign(static_cast<std::size_t>(ne) * be, R(0));
    for (int k = 0; k < ne; ++k) {
      const R th = static_cast<R>(node(e_axis_, k));
      for (int c = 0; c < 3; ++c) {
        const R sa = static_cast<R>(f.sigma_a[c]);
        for (int p = 0; p < lobes_; ++p) e_[static_cast<std::size_t>(k) * be + static_cast<std::size_t>(3 * p + c)] = np[p].energy(sa, th);
        if (residual_) e_[static_cast<std::size_t>(k) * be + static_cast<std::size_t>(3 * lobes_ + c)] = t.np_residual(sa, th);
      }
    }
    // M_p: [θi node][θr node][lobe].
    const auto& m0 = t.mp[0].table();
    mp_axes_[0] = m0.axis(1).axis(), mp_axes_[1] = m0.axis(2).axis();
    const int ni = mp_axes_[0].count, nr = mp_axes_[1].count;
    mp_theta_i_ = FixedAxis<R>(mp_axes_[0], static_cast<std::size_t>(nr) * bm);
    mp_theta_r_ = FixedAxis<R>(mp_axes_[1], bm);
    mp_.assign(static_cast<std::size_t>(ni * nr) * bm, R(0));
    for (int a = 0; a < ni; ++a)
      for (int b = 0; b < nr; ++b)
        for (int p = 0; p < L_; ++p) {
          const R x[3] = {static_cast<R>(f.beta_m), static_cast<R>(node(mp_axes_[0], a)), static_cast<R>(node(mp_axes_[1], b))};
          mp_[static_cast<std::size_t>(a * nr + b) * bm + static_cast<std::size_t>(p)] = (p < lobes_ ? t.mp[p] : t.mp_residual).table()(x);
        }
  }

  /// S per channel at (θi, θr, φ) [1/sr], radians; NaN in every channel for a NaN argument.
  void operator()(R theta_i, R theta_r, R phi, R* rgb) const {
    if (!(theta_i == theta_i) || !(theta_r == theta_r) || !(phi == phi)) {
      rgb[0] = rgb[1] = rgb[2] = theta_i + theta_r + phi;
      return;
    }
    rgb[0] = rgb[1] = rgb[2] = R(0);
    if (eval_) (this->*eval_)(theta_i, theta_r, phi, rgb);
  }

  /// S per channel for unit vectors wi, wo in the fibre frame (fibre_angles).
  void operator()(const R* wi, const R* wo, R* rgb) const {
    R ti, tr, phi;
    fibre_angles(wi, wo, ti, tr, phi);
    (*this)(ti, tr, phi, rgb);
  }

  /// Bytes of the per-fibre slices.
  std::size_t bytes() const { return (np_.size() + e_.size() + mp_.size()) * sizeof(R); }

 private:
  static constexpr int kMax = HairTables<T, R>::kMaxLobes;
  static constexpr int pad(int n) { return (n + 3) / 4 * 4; }
  using Eval = void (FibreScattering::*)(R, R, R, R*) const;

  // The lookup for P explicit lobes and H residual lobes (0 or 1): block sizes known at compile
  // time, so that the loops over lobes and channels unroll and vectorize.
  template <int P, int H>
  void eval(R theta_i, R theta_r, R phi, R* rgb) const {
    constexpr int M = pad(P + H), N = pad(3 * P), E = pad(3 * (P + H));
    const R theta_d = std::fabs(R(0.5) * (theta_r - theta_i));
    const FixedTaps<R> tt = taps4(np_theta_, theta_d), tf = taps4(np_phi_, detail::fold_phi(phi, np_axes_[1]));
    const FixedTaps<R> te = taps4(e_theta_, theta_d);
    const FixedTaps<R> ti = taps4(mp_theta_i_, theta_i), tr = taps4(mp_theta_r_, theta_r);
    R m[M], n[N], e[E];
    accumulate2<M>(mp_.data(), ti, tr, m);
    accumulate2<N>(np_.data(), tt, tf, n);
    accumulate1<E>(e_.data(), te, e);
    for (int p = 0; p < P; ++p) {
      const R mp = detail::nonnegative(m[p]);
      for (int c = 0; c < 3; ++c) rgb[c] += mp * detail::nonnegative(n[3 * p + c]) * detail::nonnegative(e[3 * p + c]);
    }
    if (H) {
      const R mp = detail::nonnegative(m[P]);
      for (int c = 0; c < 3; ++c) rgb[c] += mp * detail::nonnegative(e[3 * P + c]);
    }
  }
  template <int P>
  Eval pick(int lobes, bool residual) const {
    if constexpr (P > kMax) return nullptr;
    else if (lobes == P) return residual ? &FibreScattering::eval<P, 1> : &FibreScattering::eval<P, 0>;
    else return pick<P + 1>(lobes, residual);
  }

  // Four taps on every axis (a linear axis's two, then two of weight 0 on its second node), so
  // that the loops below have fixed trip counts.
  static HAIRLUT_SAMPLER_INLINE FixedTaps<R> taps4(const FixedAxis<R>& a, R x) {
    FixedTaps<R> t = a.taps(x);
    if (!a.cubic()) t.off[2] = t.off[3] = t.off[1], t.w[2] = t.w[3] = R(0);
    return t;
  }
  // out[0 … B) = Σ_i a.w[i] Σ_j b.w[j] p[a.off[i] + b.off[j] + k].
  // out[0 … B) = Σ_i a.w[i] Σ_j b.w[j] p[a.off[i] + b.off[j] + k], the four terms of each sum
  // added pairwise (a shorter dependency chain than a running sum).
  template <int B>
  static HAIRLUT_SAMPLER_INLINE void accumulate2(const R* p, const FixedTaps<R>& a, const FixedTaps<R>& b, R* out) {
    R row[4][B];
    for (int i = 0; i < 4; ++i) {
      const R* q = p + a.off[i];
      const R* v0 = q + b.off[0];
      const R* v1 = q + b.off[1];
      const R* v2 = q + b.off[2];
      const R* v3 = q + b.off[3];
      for (int k = 0; k < B; ++k) row[i][k] = a.w[i] * ((b.w[0] * v0[k] + b.w[1] * v1[k]) + (b.w[2] * v2[k] + b.w[3] * v3[k]));
    }
    for (int k = 0; k < B; ++k) out[k] = (row[0][k] + row[1][k]) + (row[2][k] + row[3][k]);
  }
  template <int B>
  static HAIRLUT_SAMPLER_INLINE void accumulate1(const R* p, const FixedTaps<R>& a, R* out) {
    const R* q0 = p + a.off[0];
    const R* q1 = p + a.off[1];
    const R* q2 = p + a.off[2];
    const R* q3 = p + a.off[3];
    for (int k = 0; k < B; ++k) out[k] = (a.w[0] * q0[k] + a.w[1] * q1[k]) + (a.w[2] * q2[k] + a.w[3] * q3[k]);
  }

  Eval eval_ = nullptr;
  int lobes_ = 0, L_ = 0;
  bool residual_ = false, has_energy_ = false;
  Axis np_axes_[2], mp_axes_[2], e_axis_;
  FixedAxis<R> np_theta_, np_phi_, e_theta_, mp_theta_i_, mp_theta_r_;
  std::vector<R> np_, e_, mp_;
};

}  // namespace sampler
}  // namespace hairlut
