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
/// The two arcsines are fast_acos's operations on two register lanes (the same bits).
template <class R>
HAIRLUT_SAMPLER_INLINE void fibre_angles(const R* wi, const R* wo, R& theta_i, R& theta_r, R& phi) {
  const R half_pi = static_cast<R>(1.57079632679489661923);
  {
    using V = detail::Vec4<R>;
    const V x = V::set(wi[0], wo[0], R(0), R(0));
    const V a = V::min(x.abs(), V::all(R(1))), a2 = a * a, a4 = a2 * a2;
    const V p01 = V::all(R(1.5707963050)) + a * V::all(R(-0.2145988016)), p23 = V::all(R(0.0889789874)) + a * V::all(R(-0.0501743046));
    const V p45 = V::all(R(0.0308918810)) + a * V::all(R(-0.0170881256)), p67 = V::all(R(0.0066700901)) + a * V::all(R(-0.0012624911));
    const V r = (V::all(R(1)) - a).sqrt() * ((p01 + a2 * p23) + a4 * (p45 + a2 * p67));
    const V t = V::all(half_pi) - V::if_negative(x, V::all(static_cast<R>(3.14159265358979323846)) - r, r);
    theta_i = t.lane0(), theta_r = t.template lane<1>().lane0();
  }
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
  const FixedView<T, 2, R>& table() const { return table_; }
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
  /// A cuticle scale angle α [rad] added to the tilts the M_p tables were baked with, in pbrt-v4's
  /// convention: R's lobe moves by 2α, TT's by −α and TRT's by −4α (hairlut's α_p; TRRT and the
  /// residual not at all, as in pbrt). Read by HairScattering only.
  double tilt = 0.0;
};

/// S(θi, θr, φ) per channel for one fibre, from the tables only.
///
/// Built once per fibre (like a renderer's per-material precompute): the tables are evaluated at
/// the fibre's β and σa on the nodes of their other axes, i.e. N_p per channel over the N_p
/// tables' (θd, φ) nodes, E_p and the residual per channel over the energy tables' θd nodes, M_p
/// over the (θi, θr) nodes. A lookup then interpolates these slices with the tables' own
/// interpolation on the remaining axes (2 or 4 taps each); the slices of all lobes and channels
/// are interleaved per node, so that one pass over the taps gives every lobe and channel: per
/// node, channel-major blocks of the lobes padded to a multiple of 4 (N_p, E_p: [channel][lobe],
/// then the residual's 3 channels; M_p: [lobe], then the residual's), so that each register of
/// four holds one channel of four lobes and S per channel is a sum over lanes.
/// Exactness: for axes interpolated linearly or cubically the tensor product does not depend on
/// the order of the axes, so the N_p and M_p slices give the tables' values (TableView's up to
/// rounding). Where a bound axis is geometric (σa of the default energy tables), the slice holds
/// the exact value at each θd node, and between nodes it interpolates those along θd instead of
/// combining the two σa rows geometrically after interpolating each: the difference is second
/// order in the θd step (the tests bound it against the typed views). The N_p slices use the
/// first lobe's θd and φ nodes, the energy rows the first lobe's energy θd nodes, the M_p slices
/// the first lobe's (θi, θr) nodes: exact when every lobe shares them (as baked tables do).
/// Memory, with P' = lobes rounded up to a multiple of 4: (3 P' · N_p θd × φ nodes + (3 P' + 4)
/// energy θd nodes + (P' + 4) θi × θr nodes) values of type R (without a residual, no + 4). Immutable after construction: one instance may serve many threads.
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
    eval_ = pick<1>(lobes_, residual_, true);
    eval_per_axis_ = pick<1>(lobes_, residual_, false);
    // Blocks per node (see the class comment); the padding holds zeros.
    const int lp = pad(lobes_), h = residual_ ? 4 : 0;
    const auto bn = static_cast<std::size_t>(3 * lp), be = static_cast<std::size_t>(3 * lp + h), bm = static_cast<std::size_t>(lp + h);
    // N_p: [θd node][φ node][channel][lobe].
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
            np_[static_cast<std::size_t>(k * nf + j) * bn + static_cast<std::size_t>(c * lp + p)] = np[p].table()(x);
          }
    // Energies: [θd node][channel][lobe], then the residual [channel] (1 for a lobe that stores
    // N_p itself).
    has_energy_ = np[0].has_energy();
    e_axis_ = has_energy_ ? np[0].energy().axis(1).axis() : np_axes_[0];
    const int ne = e_axis_.count;
    e_theta_ = FixedAxis<R>(e_axis_, be);
    e_.assign(static_cast<std::size_t>(ne) * be, R(0));
    for (int k = 0; k < ne; ++k) {
      const R th = static_cast<R>(node(e_axis_, k));
      for (int c = 0; c < 3; ++c) {
        const R sa = static_cast<R>(f.sigma_a[c]);
        for (int p = 0; p < lobes_; ++p) e_[static_cast<std::size_t>(k) * be + static_cast<std::size_t>(c * lp + p)] = np[p].energy(sa, th);
        if (residual_) e_[static_cast<std::size_t>(k) * be + static_cast<std::size_t>(3 * lp + c)] = t.np_residual(sa, th);
      }
    }
    // M_p: [θi node][θr node][lobe], then the residual.
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
          mp_[static_cast<std::size_t>(a * nr + b) * bm + static_cast<std::size_t>(p < lobes_ ? p : lp)] = (p < lobes_ ? t.mp[p] : t.mp_residual).table()(x);
        }
    // The four axes located together (θd and φ of N_p, θi and θr of M_p): uniform, cubic, at
    // least 4 nodes, θi and θr clamped (the default tables' axes).
    const FixedAxis<R>* lanes[4] = {&np_theta_, &np_phi_, &mp_theta_i_, &mp_theta_r_};
    R c[6][4];
    lanes_ = true;
    for (int k = 0; k < 4; ++k) {
      const FixedAxis<R>& a = *lanes[k];
      lanes_ = lanes_ && a.uniform_affine() && a.cubic() && a.count() >= 4 && (k < 2 || !a.even());
      c[0][k] = a.t0(), c[1][k] = a.scale(), c[2][k] = a.offset(), c[3][k] = a.top(), c[4][k] = a.unsnapped();
      c[5][k] = static_cast<R>(a.count() - 2);
    }
    using V = detail::Vec4<R>;
    lane_t0_ = V::load(c[0]), lane_scale_ = V::load(c[1]), lane_offset_ = V::load(c[2]), lane_top_ = V::load(c[3]);
    lane_unsnapped_ = V::load(c[4]), lane_last_ = V::load(c[5]);
  }

  /// S per channel at (θi, θr, φ) [1/sr], radians; NaN in every channel for a NaN argument.
  void operator()(R theta_i, R theta_r, R phi, R* rgb) const {
    if (!(theta_i == theta_i) || !(theta_r == theta_r) || !(phi == phi)) {
      rgb[0] = rgb[1] = rgb[2] = theta_i + theta_r + phi;
      return;
    }
    if (eval_) (this->*eval_)(theta_i, theta_r, phi, rgb);
    else rgb[0] = rgb[1] = rgb[2] = R(0);
  }

  /// S per channel for unit vectors wi, wo in the fibre frame (fibre_angles).
  void operator()(const R* wi, const R* wo, R* rgb) const {
    R ti, tr, phi;
    fibre_angles(wi, wo, ti, tr, phi);
    (*this)(ti, tr, phi, rgb);
  }

  /// S as operator() gives it, with each axis's taps computed one at a time (FixedAxis::taps)
  /// instead of the four axes located together in registers: the same values (for tests).
  void per_axis(R theta_i, R theta_r, R phi, R* rgb) const {
    if (!(theta_i == theta_i) || !(theta_r == theta_r) || !(phi == phi)) {
      rgb[0] = rgb[1] = rgb[2] = theta_i + theta_r + phi;
      return;
    }
    if (eval_per_axis_) (this->*eval_per_axis_)(theta_i, theta_r, phi, rgb);
    else rgb[0] = rgb[1] = rgb[2] = R(0);
  }

  /// Bytes of the per-fibre slices.
  std::size_t bytes() const { return (np_.size() + e_.size() + mp_.size()) * sizeof(R); }

 private:
  static constexpr int kMax = HairTables<T, R>::kMaxLobes;
  static constexpr int pad(int n) { return (n + 3) / 4 * 4; }
  using Eval = void (FibreScattering::*)(R, R, R, R*) const;

  // The lookup for P explicit lobes and H residual lobes (0 or 1): block sizes known at compile
  // time, so that the loops over lobes and channels unroll into whole registers (detail::Vec4).
  // Lanes: the four axes of N_p and M_p located together where they can be (interior).
  template <int P, int H, bool Lanes>
  void eval(R theta_i, R theta_r, R phi, R* rgb) const {
    using V = detail::Vec4<R>;
    constexpr int G = pad(P) / 4, M = G + H, N = 3 * G, E = 3 * G + H;  // registers per node
    const R theta_d = std::fabs(R(0.5) * (theta_r - theta_i)), phi_f = detail::fold_phi(phi, np_axes_[1]);
    V m[M], n[N], e[E];
    const FixedTaps<R> te = taps4(e_theta_, theta_d);
    accumulate1<E>(e_.data(), te, e);
    if (!(Lanes && lanes_ && interior<M, N>(theta_d, phi_f, theta_i, theta_r, m, n))) {
      const FixedTaps<R> tt = taps4(np_theta_, theta_d), tf = taps4(np_phi_, phi_f);
      const FixedTaps<R> ti = taps4(mp_theta_i_, theta_i), tr = taps4(mp_theta_r_, theta_r);
      accumulate2<M>(mp_.data(), ti, tr, m);
      accumulate2<N>(np_.data(), tt, tf, n);
    }
    // Per channel c and lane (lobe): M_p N_p E_p, summed over the lobes' registers, then over lanes.
    V sum[3];
    for (int c = 0; c < 3; ++c) {
      sum[c] = m[0].nonnegative() * n[c * G].nonnegative() * e[c * G].nonnegative();
      for (int g = 1; g < G; ++g) sum[c] = sum[c] + m[g].nonnegative() * n[c * G + g].nonnegative() * e[c * G + g].nonnegative();
    }
    V s = V::sums(sum[0], sum[1], sum[2]);
    if (H) s = s + V::all(detail::nonnegative(m[G].lane0())) * e[3 * G].nonnegative();
    s.store3(rgb);
  }
  // The taps of θd, φ (N_p) and θi, θr (M_p) as four lanes (FixedAxis::locate's operations, in
  // the same order, on each lane: uniform axes, θd ∈ [0, π] and φ folded), then the products
  // over M_p and N_p. Returns false, having done nothing, where a lane needs more than that: a
  // cell at an end (its taps wrap, mirror or extrapolate), a snap to a node, θd beyond π.
  template <int M, int N>
  HAIRLUT_SAMPLER_INLINE bool interior(R theta_d, R phi, R theta_i, R theta_r, detail::Vec4<R>* m, detail::Vec4<R>* n) const {
    using V = detail::Vec4<R>;
    if (!(theta_d <= static_cast<R>(3.14159265358979323846))) return false;
    V s = (V::set(theta_d, phi, theta_i, theta_r) - lane_t0_) * lane_scale_ + lane_offset_;
    s = V::max(V::min(s, lane_top_), V::all(R(0)));
    int i[4];
    const V f = s.split(i);
    // Interior: 1 ≤ i ≤ count − 3, i.e. 1 ≤ s < count − 2; no snap: |f − ½| ≤ unsnapped.
    if ((V::greater(V::all(R(1)), s) | (V::greater(lane_last_, s) ^ 15) | V::greater((f - V::all(R(0.5))).abs(), lane_unsnapped_)) != 0) return false;
    // Catmull–Rom weights (FixedAxis::catmull_rom), lane k the axis k; −t³ + 2t² is 2t² − t³.
    const V f2 = f * f, f3 = f2 * f, h = V::all(R(0.5));
    const V w[4] = {h * ((V::all(R(2)) * f2 - f3) - f), h * ((V::all(R(3)) * f3 - V::all(R(5)) * f2) + V::all(R(2))),
                    h * ((V::all(R(-3)) * f3 + V::all(R(4)) * f2) + f), h * (f3 - f2)};
    const std::size_t o[4] = {static_cast<std::size_t>(i[0] - 1) * np_theta_.stride(), static_cast<std::size_t>(i[1] - 1) * np_phi_.stride(),
                              static_cast<std::size_t>(i[2] - 1) * mp_theta_i_.stride(), static_cast<std::size_t>(i[3] - 1) * mp_theta_r_.stride()};
    accumulate2_interior<M, 2, 3>(mp_.data() + o[2] + o[3], mp_theta_i_.stride(), w, m);
    accumulate2_interior<N, 0, 1>(np_.data() + o[0] + o[1], np_theta_.stride(), w, n);
    return true;
  }
  template <int P>
  Eval pick(int lobes, bool residual, bool lanes) const {
    if constexpr (P > kMax) {
      return nullptr;
    } else if (lobes == P) {
      if (lanes) return residual ? &FibreScattering::eval<P, 1, true> : &FibreScattering::eval<P, 0, true>;
      return residual ? &FibreScattering::eval<P, 1, false> : &FibreScattering::eval<P, 0, false>;
    } else {
      return pick<P + 1>(lobes, residual, lanes);
    }
  }

  // Four taps on every axis (a linear axis's two, then two of weight 0 on its second node), so
  // that the loops below have fixed trip counts.
  static HAIRLUT_SAMPLER_INLINE FixedTaps<R> taps4(const FixedAxis<R>& a, R x) {
    FixedTaps<R> t = a.taps(x);
    if (!a.cubic()) t.off[2] = t.off[3] = t.off[1], t.w[2] = t.w[3] = R(0);
    return t;
  }
  // out[k] = Σ_i a.w[i] Σ_j b.w[j] p[a.off[i] + b.off[j] + 4k …], registers k < B, the four terms
  // of each sum added pairwise (a shorter dependency chain than a running sum).
  template <int B>
  static HAIRLUT_SAMPLER_INLINE void accumulate2(const R* p, const FixedTaps<R>& a, const FixedTaps<R>& b, detail::Vec4<R>* out) {
    using V = detail::Vec4<R>;
    const V b0 = V::all(b.w[0]), b1 = V::all(b.w[1]), b2 = V::all(b.w[2]), b3 = V::all(b.w[3]);
    // Row i of the taps of a: a.w[i] Σ_j b.w[j] v_ij; rows 0 + 1 and 2 + 3 first.
    auto row = [&](int i, int k) {
      const R* q = p + a.off[i] + 4 * k;
      return V::all(a.w[i]) * ((b0 * V::load(q + b.off[0]) + b1 * V::load(q + b.off[1])) + (b2 * V::load(q + b.off[2]) + b3 * V::load(q + b.off[3])));
    };
    for (int k = 0; k < B; ++k) out[k] = row(0, k) + row(1, k);
    for (int k = 0; k < B; ++k) out[k] = out[k] + (row(2, k) + row(3, k));
  }
  // accumulate2 for interior cells: the taps of a at p + i · sa, those of b (the inner axis, B
  // registers per node) at p + 4 B j, their weights lane La and Lb of w[i], w[j]. The same sums
  // in the same order.
  template <int B, int La, int Lb>
  static HAIRLUT_SAMPLER_INLINE void accumulate2_interior(const R* p, std::size_t sa, const detail::Vec4<R>* w, detail::Vec4<R>* out) {
    using V = detail::Vec4<R>;
    const V b0 = w[0].template lane<Lb>(), b1 = w[1].template lane<Lb>(), b2 = w[2].template lane<Lb>(), b3 = w[3].template lane<Lb>();
    auto row = [&](int i, int k) {
      const R* q = p + static_cast<std::size_t>(i) * sa + 4 * k;
      return w[i].template lane<La>() * ((b0 * V::load(q) + b1 * V::load(q + 4 * B)) + (b2 * V::load(q + 8 * B) + b3 * V::load(q + 12 * B)));
    };
    for (int k = 0; k < B; ++k) out[k] = row(0, k) + row(1, k);
    for (int k = 0; k < B; ++k) out[k] = out[k] + (row(2, k) + row(3, k));
  }
  template <int B>
  static HAIRLUT_SAMPLER_INLINE void accumulate1(const R* p, const FixedTaps<R>& a, detail::Vec4<R>* out) {
    using V = detail::Vec4<R>;
    const V a0 = V::all(a.w[0]), a1 = V::all(a.w[1]), a2 = V::all(a.w[2]), a3 = V::all(a.w[3]);
    const R* q0 = p + a.off[0];
    const R* q1 = p + a.off[1];
    const R* q2 = p + a.off[2];
    const R* q3 = p + a.off[3];
    for (int k = 0; k < B; ++k) out[k] = (a0 * V::load(q0 + 4 * k) + a1 * V::load(q1 + 4 * k)) + (a2 * V::load(q2 + 4 * k) + a3 * V::load(q3 + 4 * k));
  }

  Eval eval_ = nullptr, eval_per_axis_ = nullptr;
  int lobes_ = 0, L_ = 0;
  bool residual_ = false, has_energy_ = false, lanes_ = false;
  // Per lane (θd, φ of N_p; θi, θr of M_p): t0, scale, offset, top, unsnapped, count − 2.
  detail::Vec4<R> lane_t0_{}, lane_scale_{}, lane_offset_{}, lane_top_{}, lane_unsnapped_{}, lane_last_{};
  Axis np_axes_[2], mp_axes_[2], e_axis_;
  FixedAxis<R> np_theta_, np_phi_, e_theta_, mp_theta_i_, mp_theta_r_;
  std::vector<R> np_, e_, mp_;
};

}  // namespace sampler
}  // namespace hairlut
