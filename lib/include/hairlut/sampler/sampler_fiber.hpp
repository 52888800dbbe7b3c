// hairlut sampler, typed views of d'Eon 2011 tables: N_p, M_p and the residual looked up by their
// physical arguments (HairTables, which the renderer runtime HairScattering reads), one fiber's
// parameters (Fiber), and the angles of S from direction vectors (fiber_angles).
//
// Header-only and dependency-free (C++17, with sampler.hpp and sampler_fixed.hpp). A loader fills
// the views from a file's metadata once (hairlut::hair_tables in hairlut/tables/hair_views.hpp does it
// from a loaded TableSet; an engine may fill the axes from the sidecar or the EXR header itself).
//
// Conventions (docs/conventions.md, docs/table-format.md): angles in radians, θd = (θr − θi)/2,
// φ = φr − φi, σa per unit fiber radius, β the standard deviation of the azimuthal (N_p) or
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

#include "hairlut/sampler/grazing_factor.hpp"
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

/// The arguments of S from unit vectors in the fiber frame (x along the fiber root to tip, y–z
/// the normal plane; pbrt's hair frame): θ = asin x = π/2 − acos x (fast_acos, ≤ 2e-8 rad), and
/// φ ∈ [0, π] the angle between the normal-plane projections, atan2(|cross|, dot) of the two
/// projections by fast_atan01 on the octant (≤ 2e-8 rad, and no loss of accuracy near 0 and π);
/// N_p is even in φ, so its sign is not needed. φ = 0 when a direction lies along the fiber.
/// The two arcsines are fast_acos's operations on two register lanes (the same bits).
template <class R>
HAIRLUT_SAMPLER_INLINE void fiber_angles(const R* wi, const R* wo, R& theta_i, R& theta_r, R& phi) {
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
/// times the energy table over (σa, θd). An energy table that reaches θd = 90° stores E_p / g
/// (GrazingFactor: E_p of the lobes p ≥ 1 vanishes there as cos²θd); the view multiplies g back
/// after interpolating, so the energy has its limit at grazing.
template <class T, class R = double>
class NpLobe {
 public:
  NpLobe() = default;
  /// axes: beta, sigma_a, theta_d, phi; energy (nullable) and its axes: sigma_a, theta_d;
  /// energy_factor: the energy table's grazing factor (none when it has no such attributes).
  NpLobe(const T* values, const Axis* axes, const T* energy = nullptr, const Axis* energy_axes = nullptr, GrazingFactor energy_factor = {})
      : table_(values, axes), phi_axis_(axes[3]) {
    if (energy) energy_ = FixedView<T, 2, R>(energy, energy_axes), has_energy_ = true, factor_ = energy_factor;
  }
  bool valid() const { return table_.data() != nullptr; }
  bool has_energy() const { return has_energy_; }
  /// g of the energy table's values E_p / g.
  const GrazingFactor& energy_factor() const { return factor_; }
  const FixedView<T, 4, R>& table() const { return table_; }
  const FixedView<T, 2, R>& energy() const { return energy_; }

  /// N_p [1/rad] at β, σa, θd, φ (radians; any sign of θd and φ).
  R operator()(R beta, R sigma_a, R theta_d, R phi) const {
    const R x[4] = {beta, sigma_a, std::fabs(theta_d), detail::fold_phi(phi, phi_axis_)};
    R v = table_(x);
    if (has_energy_) v *= energy(sigma_a, theta_d);
    return detail::nonnegative(v);
  }
  /// N_p at three σa (one per channel) and one β, θd, φ: what the channels share (the taps of
  /// β, θd and φ, and of θd on the energy table) located once. Equal to three calls of
  /// operator() up to the order of the sums (the same taps and weights).
  void rgb(R beta, const R* sigma_a, R theta_d, R phi, R* out) const {
    const R td = std::fabs(theta_d), ph = detail::fold_phi(phi, phi_axis_);
    if (!(beta + td + ph + sigma_a[0] + sigma_a[1] + sigma_a[2] == beta + td + ph + sigma_a[0] + sigma_a[1] + sigma_a[2])) {
      for (int c = 0; c < 3; ++c) out[c] = (*this)(beta, sigma_a[c], theta_d, phi);  // NaN or infinities: the general rules
      return;
    }
    FixedTaps<R> tp[4];
    tp[0] = table_.axis(0).taps(beta), tp[2] = table_.axis(2).taps(td), tp[3] = table_.axis(3).taps(ph);
    FixedTaps<R> et[2];
    if (has_energy_) et[1] = energy_.axis(1).taps(td);
    // β, θd and φ cubic (the baked sets): the sum over them once per σa node that a channel's taps
    // touch (the channels' σa are near each other: about 6 nodes for 12 taps), then each channel's
    // σa taps over those partial sums; half the loads of three whole lookups.
    R value[3];
    const bool shared = table_.axis(0).cubic() && table_.axis(2).cubic() && table_.axis(3).cubic() && !table_.axis(1).geometric();
    if (shared) {
      const FixedTaps<R> rest[3] = {tp[0], tp[2], tp[3]};
      const int ns = table_.axis(1).cubic() ? 4 : 2;
      std::size_t node[12];
      R partial[12];
      int nodes = 0;
      for (int c = 0; c < 3; ++c) {
        const FixedTaps<R> ts = table_.axis(1).taps(sigma_a[c]);
        R v = R(0);
        for (int k = 0; k < ns; ++k) {
          int j = 0;
          while (j < nodes && node[j] != ts.off[k]) ++j;
          if (j == nodes) node[nodes] = ts.off[k], partial[nodes] = detail::fixed_product<T, R, 4, 4, 4>(table_.data() + ts.off[k], rest), ++nodes;
          v += ts.w[k] * partial[j];
        }
        value[c] = v;
      }
    } else {
      for (int c = 0; c < 3; ++c) {
        FixedTaps<R> t[4] = {tp[0], table_.axis(1).taps(sigma_a[c]), tp[2], tp[3]};  // combine() may change a geometric axis's taps
        value[c] = table_.combine(t);
      }
    }
    for (int c = 0; c < 3; ++c) {
      R v = value[c];
      if (has_energy_) {
        FixedTaps<R> e[2] = {energy_.axis(0).taps(sigma_a[c]), et[1]};
        v *= detail::nonnegative(energy_.combine(e)) * factor_(sigma_a[c], theta_d);
      }
      out[c] = detail::nonnegative(v);
    }
  }
  /// E_p = ∫N_p dφ at σa, θd (1 when the table stores N_p itself).
  R energy(R sigma_a, R theta_d) const {
    if (!has_energy_) return R(1);
    const R y[2] = {sigma_a, std::fabs(theta_d)};
    return detail::nonnegative(energy_(y)) * factor_(sigma_a, theta_d);
  }

 private:
  FixedView<T, 4, R> table_;
  FixedView<T, 2, R> energy_;
  Axis phi_axis_;
  bool has_energy_ = false;
  GrazingFactor factor_;
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

/// N of the residual lobes p ≥ P over (σa, θd): their energy spread uniformly in φ and β. A table
/// that reaches θd = 90° stores N / g (GrazingFactor: the residual of a white fiber vanishes as
/// cos θd, of an absorbing one as cos²θd); the view multiplies g back.
template <class T, class R = double>
class NpResidual {
 public:
  NpResidual() = default;
  /// axes: sigma_a, theta_d; energy (nullable, a factor over the same axes); factor and
  /// energy_factor: the two tables' grazing factors (none when they have no such attributes).
  NpResidual(const T* values, const Axis* axes, const T* energy = nullptr, const Axis* energy_axes = nullptr, GrazingFactor factor = {},
             GrazingFactor energy_factor = {})
      : table_(values, axes), factor_(factor), energy_factor_(energy_factor) {
    if (energy) energy_ = FixedView<T, 2, R>(energy, energy_axes), has_energy_ = true;
  }
  bool valid() const { return table_.data() != nullptr; }
  const FixedView<T, 2, R>& table() const { return table_; }
  bool has_energy() const { return has_energy_; }
  const FixedView<T, 2, R>& energy() const { return energy_; }
  /// The grazing factors of the table and of its energy factor.
  const GrazingFactor& factor() const { return factor_; }
  const GrazingFactor& energy_factor() const { return energy_factor_; }
  R operator()(R sigma_a, R theta_d) const {
    const R x[2] = {sigma_a, std::fabs(theta_d)};
    R v = table_(x);
    if (has_energy_) v *= energy_(x);
    return detail::nonnegative(v) * factor_(sigma_a, theta_d) * (has_energy_ ? energy_factor_(sigma_a, theta_d) : R(1));
  }

 private:
  FixedView<T, 2, R> table_;
  FixedView<T, 2, R> energy_;
  bool has_energy_ = false;
  GrazingFactor factor_, energy_factor_;
};

/// The d'Eon 2011 tables of one set: N_p and M_p per explicit lobe, and the residual.
template <class T, class R = double>
struct HairTables {
  static constexpr int kMaxLobes = 8;
  static constexpr int kMaxBetaBands = 4;
  int lobes = 0;           ///< explicit lobes p = 0 … lobes − 1 (R, TT, TRT, ...)
  double eta = 0.0;        ///< the fiber's refractive index the tables were baked for
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

/// One fiber: absorption per channel (per unit radius; e.g. from melanin), the longitudinal
/// roughness β_m of M_p and the azimuthal roughness β_n of N_p (radians, the tables' β axes).
struct Fiber {
  double sigma_a[3] = {0.0, 0.0, 0.0};
  double beta_m = 0.0;
  double beta_n = 0.0;
  /// A cuticle scale angle α [rad] added to the tilts the M_p tables were baked with, in pbrt-v4's
  /// convention: R's lobe moves by 2α, TT's by −α and TRT's by −4α (hairlut's α_p; TRRT and the
  /// residual not at all, as in pbrt). Read by HairScattering only.
  double tilt = 0.0;
};

}  // namespace sampler
}  // namespace hairlut
