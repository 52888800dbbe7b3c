// hairlut sampler, N_p in its Fourier representation: the detector's cosine series with its
// coefficients tabulated over (θd, σa), β and φ exact (docs/table-format.md, "N_p as a Fourier
// series").
//
// Header-only and dependency-free (C++17, with sampler.hpp, sampler_fixed.hpp and sampler_simd.hpp).
// d'Eon's N_p with the wrapped-Gaussian detector of width β is exactly
//   N_p(φ; β, σa, θd) = (1/2π) [C_0 + 2 Σ_{n≥1} e^{−n²β²/2} C_n cos nφ],
//   C_n(θd, σa) = ½ ∫ A(p, h) cos(n Φ(p, h)) dh,
// so every β and φ share the C_n. A table stores c_n = C_n / F at (θd, σa) nodes, n = 0 … terms − 1
// the fastest axis, with the lobe's least absorption F = e^{−p σa′ ℓ_min} divided out (ℓ_min the
// shortest internal segment, at the fiber's edge h = ±1; σa′ = σa / cos θt): what is left varies
// slowly with σa. A table whose θd axis reaches 90° stores c_n / g instead, g the grazing factor of
// its lobe (grazing_factor.hpp: cos²θd for p ≥ 1, where every C_n vanishes as cos²θd; 1 for R; the
// residual's g_res), which has a finite limit there. A lookup interpolates the c_n along θd and σa
// (each axis's own interpolation, as FixedView reads it), multiplies F and g back exactly and sums
// the series to N(β) terms:
//   N(β) = the smallest N with 2 e^{−(N+1)²β²/2} / (1 − e^{−(2N+3)β²/2}) ≤ tolerance / 2,
// a bound on 2 Σ_{n>N} e^{−n²β²/2}, so the truncation is below tolerance × C_0 / 2π (the lobe's mean
// height, itself below its peak); a lookup sums whole groups of four terms (a few more than N(β)
// where the stored count allows, which only adds accuracy).
//
// Exact and approximate: β enters only through e^{−n²β²/2} and φ only through cos nφ, both
// evaluated exactly up to rounding (the weights by the recurrence e^{−(n+4)²b} = e^{−n²b} e^{−(8n+16)b},
// b = β²/2, the cosines by rotating e^{inφ} by e^{i4φ}, four terms per register, from a sine and
// cosine polynomial accurate to rounding on [−π/4, π/4]); F is exact (one exponential). The
// approximations are the interpolation of the c_n between nodes, the truncation above and the
// stored precision of the c_n.
//
// Domain and edges: θd is folded to |θd| (N_p depends on cos θd) and, like σa, clamped to its
// axis's range (the value held beyond it, as the tensor tables do; F is taken at the clamped
// point). β below beta_min reads beta_min (the terms stored are those β_min needs); above it,
// every β is exact (fewer terms). φ is any angle (the series is even and 2π-periodic). The result
// is clamped at 0 (interpolated coefficients can undershoot); a NaN argument gives NaN.
// Axes: θd spaced uniformly in θd or in cos θd, σa uniformly in σa or in √σa, each linear or cubic
// (Catmull–Rom, with the axis's end rules); other spacings make an invalid view (NaN).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "hairlut/sampler/grazing_factor.hpp"
#include "hairlut/sampler/sampler.hpp"
#include "hairlut/sampler/sampler_fixed.hpp"
#include "hairlut/sampler/sampler_simd.hpp"

namespace hairlut {
namespace sampler {

/// What a Fourier N_p table needs besides its axes (the file's attributes, docs/table-format.md).
struct FourierNpParams {
  int terms = 0;             ///< stored coefficients per node, n = 0 … terms − 1
  double beta_min = 0.0;     ///< the narrowest β the terms serve [rad]; a smaller β reads beta_min
  double tolerance = 1e-4;   ///< truncation bound of N(β)
  double eta = 1.55;         ///< refractive index of F
  int absorption_p = 0;      ///< p of F = e^{−p σa′ ℓ_min} (the lobe's p; the residual's first lobe)
  bool papers_path = false;  ///< segment length 4 cos²γt (the papers' form) instead of the chord 2 cos γt
  GrazingFactor grazing;     ///< g that the c_n of a θd axis reaching 90° are divided by (none otherwise)
};

/// Whether the tail bound holds for N terms beyond n = 0 at β: 2 e^{−(N+1)²b} ≤ ½ tolerance (1 − e^{−(2N+3)b}), b = β²/2.
inline bool fourier_tail_within(int N, double beta, double tolerance) {
  const double b = 0.5 * beta * beta, n1 = static_cast<double>(N) + 1.0;
  const double next = std::exp(-n1 * n1 * b);
  return next == 0.0 || 2.0 * next <= 0.5 * tolerance * (1.0 - std::exp(-(2.0 * n1 + 1.0) * b));
}

/// F = e^{−p σa′ ℓ_min}: the lobe's least absorption, along its shortest internal segment (at the
/// fiber's edge, sin γt = 1/η′). With q² = η² − sin²θd, σa′ = σa η / q and cos γt = √(η² − 1) / q
/// there, so the chord 2 cos γt gives F = exp(−2 p η √(η² − 1) σa / q²) and the papers' 4 cos²γt
/// F = exp(−4 p η (η² − 1) σa / q³). Exact; 1 for p = 0 or σa = 0. FourierAbsorption holds the
/// factors that do not depend on the point (η² − 1 and the constant k of x = k σa / q², or k σa / q³
/// on the papers' path, F = e^{−x}); fourier_absorption evaluates it once.
template <class R>
struct FourierAbsorption {
  R e2 = R(0), k = R(0);
  bool papers = false;
  explicit FourierAbsorption(const FourierNpParams& f) : papers(f.papers_path) {
    const R eta = static_cast<R>(f.eta), p = static_cast<R>(f.absorption_p);
    e2 = eta * eta - R(1);
    k = papers ? R(4) * p * eta * e2 : R(2) * p * eta * std::sqrt(e2);
  }
  FourierAbsorption() = default;
  /// F at σa and cos θd.
  R operator()(R sigma_a, R cos_theta_d) const {
    const R q2 = e2 + cos_theta_d * cos_theta_d;
    return std::exp(-(papers ? k * sigma_a / (q2 * std::sqrt(q2)) : k * sigma_a / q2));
  }
};

template <class R>
inline R fourier_absorption(const FourierNpParams& f, R sigma_a, R cos_theta_d) {
  return FourierAbsorption<R>(f)(sigma_a, cos_theta_d);
}

namespace detail {

/// (cos x, sin x) for two angles x ∈ [0, π]: a quadrant k = round(2x/π), r = x − kπ/2 ∈ [−π/4, π/4]
/// (π/2 in two parts, Cody–Waite), and the Taylor polynomials of sin r (to r¹⁷ in double, r¹³ in
/// float) and cos r (to r¹⁶, r¹²), whose remainders at π/4 (< 1e−17, < 1e−10) are below the rounding
/// of R, in one register: lanes (sin r₀, sin r₁, cos r₀, cos r₁), each lane Horner's scheme in r²
/// with its own coefficients; then the quadrant's rotation.
template <class R>
struct SinCosPolynomial {
  static constexpr bool wide = sizeof(R) >= sizeof(double);
  static constexpr int terms = wide ? 9 : 7;  // rows used, from the last: r^16 … r^0 in double, r^12 … r^0 in float
  // Per lane (sin, sin, cos, cos): the coefficients of r^(2j) in sin r / r = Σ (−1)^j r^(2j) / (2j + 1)!
  // and cos r = Σ (−1)^j r^(2j) / (2j)!, highest first.
  alignas(16) static constexpr R c[9][4] = {
      {R(1.0 / 355687428096000.0), R(1.0 / 355687428096000.0), R(1.0 / 20922789888000.0), R(1.0 / 20922789888000.0)},
      {R(-1.0 / 1307674368000.0), R(-1.0 / 1307674368000.0), R(-1.0 / 87178291200.0), R(-1.0 / 87178291200.0)},
      {R(1.0 / 6227020800.0), R(1.0 / 6227020800.0), R(1.0 / 479001600.0), R(1.0 / 479001600.0)},
      {R(-1.0 / 39916800.0), R(-1.0 / 39916800.0), R(-1.0 / 3628800.0), R(-1.0 / 3628800.0)},
      {R(1.0 / 362880.0), R(1.0 / 362880.0), R(1.0 / 40320.0), R(1.0 / 40320.0)},
      {R(-1.0 / 5040.0), R(-1.0 / 5040.0), R(-1.0 / 720.0), R(-1.0 / 720.0)},
      {R(1.0 / 120.0), R(1.0 / 120.0), R(1.0 / 24.0), R(1.0 / 24.0)},
      {R(-1.0 / 6.0), R(-1.0 / 6.0), R(-0.5), R(-0.5)},
      {R(1), R(1), R(1), R(1)}};
};

template <class R>
HAIRLUT_SAMPLER_INLINE void sincos_0_pi(R x0, R x1, R& c0, R& s0, R& c1, R& s1) {
  using V = Vec4<R>;
  using P = SinCosPolynomial<R>;
  const R two_over_pi = static_cast<R>(0.63661977236758134308);
  const int k0 = static_cast<int>(x0 * two_over_pi + R(0.5)), k1 = static_cast<int>(x1 * two_over_pi + R(0.5));
  const R hi = P::wide ? static_cast<R>(1.5707963267341256) : static_cast<R>(1.5707962513f);
  const R lo = P::wide ? static_cast<R>(6.077100506506192e-11) : static_cast<R>(7.5497894159e-08f);
  const R f0 = static_cast<R>(k0), f1 = static_cast<R>(k1);
  const R r0 = (x0 - f0 * hi) - f0 * lo, r1 = (x1 - f1 * hi) - f1 * lo;
  const V r = V::set(r0, r1, r0, r1), r2 = r * r;
  V v = V::load(P::c[9 - P::terms]);
  for (int j = 10 - P::terms; j < 9; ++j) v = v * r2 + V::load(P::c[j]);
  v = v * V::set(r0, r1, R(1), R(1));  // sin r = r · (its polynomial in r²)
  alignas(16) R out[4];
  v.store(out);
  // Quadrants 0, 1, 2: (c, s), (−s, c), (−c, −s).
  c0 = k0 == 0 ? out[2] : k0 == 1 ? -out[0] : -out[2];
  s0 = k0 == 0 ? out[0] : k0 == 1 ? out[2] : -out[0];
  c1 = k1 == 0 ? out[3] : k1 == 1 ? -out[1] : -out[3];
  s1 = k1 == 0 ? out[1] : k1 == 1 ? out[3] : -out[1];
}

}  // namespace detail

/// Σ_{n<count} a[n] cos nφ, by Clenshaw's recurrence (no clamp; NaN for a NaN φ).
inline double fourier_cosine_sum(const double* a, int count, double phi) {
  if (count < 1) return 0.0;
  const double c2 = 2.0 * std::cos(phi);
  double b1 = 0.0, b2 = 0.0;
  for (int n = count - 1; n >= 1; --n) {
    const double b = a[n] + c2 * b1 - b2;
    b2 = b1, b1 = b;
  }
  return a[0] + 0.5 * c2 * b1 - b2;
}

/// |φ| ∈ [0, π] drawn from the density ∝ Σ a[n] cos nφ on [0, π] at u ∈ [0, 1], by inverting its
/// CDF a_0 x + Σ_{n≥1} a_n sin(nx)/n (Clenshaw's recurrence for the sines) with Newton's method
/// kept inside a bisection bracket. The series should be ≥ 0: where truncation leaves it slightly
/// negative the CDF dips there, and the root found is one of the crossings (density off by that dip).
/// Needs a[0] > 0; NaN for a NaN u.
inline double fourier_sample_abs_phi(const double* a, int count, double u) {
  const double pi = 3.14159265358979323846;
  if (!(u == u) || count < 1 || !(a[0] > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double target = std::min(std::max(u, 0.0), 1.0) * a[0] * pi;
  auto cdf = [&](double x, double& density) {
    const double c2 = 2.0 * std::cos(x);
    double s1 = 0.0, s2 = 0.0, k1 = 0.0, k2 = 0.0;  // sine sum of a_n/n, cosine sum of a_n
    for (int n = count - 1; n >= 1; --n) {
      const double s = a[n] / n + c2 * s1 - s2, k = a[n] + c2 * k1 - k2;
      s2 = s1, s1 = s, k2 = k1, k1 = k;
    }
    density = a[0] + 0.5 * c2 * k1 - k2;
    return a[0] * x + s1 * std::sin(x) - target;
  };
  double lo = 0.0, hi = pi, x = u * pi, d = 0.0;
  for (int it = 0; it < 100; ++it) {
    const double g = cdf(x, d);
    if (g == 0.0) return x;
    (g < 0.0 ? lo : hi) = x;
    double next = d > 0.0 ? x - g / d : lo - 1.0;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::fabs(next - x) <= 1e-13 * pi || hi - lo <= 1e-13 * pi) return next;
    x = next;
  }
  return x;
}

/// N_p of one lobe (or the residual's C_0) from a Fourier table: values [θd][σa][n] of type T
/// (float as files store them, or double), arithmetic in R (double or float). The view points into
/// the values (no copy) and is immutable after construction: one view may serve many threads.
template <class T, class R = double>
class FourierNp {
 public:
  FourierNp() = default;
  /// values: c_n = C_n / F over the θd axis, the σa axis and n (fastest), terms per node.
  FourierNp(const T* values, const Axis& theta_d, const Axis& sigma_a, const FourierNpParams& params)
      : data_(values), params_(params), absorption_(params) {
    const bool theta_ok = theta_d.spacing == Spacing::uniform || theta_d.spacing == Spacing::cos;
    const bool sigma_ok = sigma_a.spacing == Spacing::uniform || sigma_a.spacing == Spacing::sqrt;
    if (!values || !theta_ok || !sigma_ok || params.terms < 1 || !(params.beta_min > 0.0) || !(params.tolerance > 0.0) || theta_d.count < 1 ||
        sigma_a.count < 1 || theta_d.lo < 0.0 || sigma_a.lo < 0.0)
      return;
    const std::size_t terms = static_cast<std::size_t>(params.terms);
    theta_lo_ = static_cast<R>(theta_d.lo), theta_hi_ = static_cast<R>(theta_d.hi);
    sigma_lo_ = static_cast<R>(sigma_a.lo), sigma_hi_ = static_cast<R>(sigma_a.hi);
    theta_cos_ = theta_d.spacing == Spacing::cos, sigma_sqrt_ = sigma_a.spacing == Spacing::sqrt;
    // Each axis as a uniform one in its mapped coordinate (−cos θd, √σa): the same nodes, weights
    // and end rules as the axis itself (an even end of a cos axis is a clamped one, sampler.hpp).
    Axis t = theta_d, s = sigma_a;
    if (theta_cos_) t.spacing = Spacing::uniform, t.lo = -std::cos(theta_d.lo), t.hi = -std::cos(theta_d.hi), t.wrap = Wrap::clamp;
    if (sigma_sqrt_) s.spacing = Spacing::uniform, s.lo = std::sqrt(sigma_a.lo), s.hi = std::sqrt(sigma_a.hi);
    s.wrap = Wrap::clamp;
    theta_ = FixedAxis<R>(t, static_cast<std::size_t>(sigma_a.count) * terms);
    sigma_ = FixedAxis<R>(s, terms);
    // N(β) as thresholds: N(β) ≤ n exactly where β ≥ threshold_[n] (the bound is monotonic in β).
    threshold_.assign(terms, 0.0);
    for (int n = 0; n < params.terms; ++n) {
      double lo = 1e-9, hi = 64.0;
      if (fourier_tail_within(n, lo, params.tolerance)) hi = lo;
      for (int it = 0; it < 80 && hi - lo > 1e-15 * hi; ++it) {
        const double mid = 0.5 * (lo + hi);
        (fourier_tail_within(n, mid, params.tolerance) ? hi : lo) = mid;
      }
      threshold_[static_cast<std::size_t>(n)] = hi;
    }
    guess_ = threshold_.back() * static_cast<double>(params.terms);  // threshold_[n] ≈ guess_ / (n + 1)
    beta_min_ = static_cast<R>(params.beta_min);
    bin_terms_.assign(static_cast<std::size_t>(kBins) + 1, 0);
    for (int k = 0; k <= kBins; ++k)
      bin_terms_[static_cast<std::size_t>(k)] = summed_terms(k < kBins ? static_cast<R>(params.beta_min * kBins / (k + 1.0)) : beta_min_);
    // Lanes 0 and 1 of the joint location: θd and σa (FixedAxis's constants).
    const FixedAxis<R>* ax[2] = {&theta_, &sigma_};
    R cst[7][4] = {};
    for (int k = 0; k < 2; ++k) {
      const FixedAxis<R>& a = *ax[k];
      cst[0][k] = a.t0(), cst[1][k] = a.scale(), cst[2][k] = a.offset(), cst[3][k] = a.top(), cst[4][k] = a.unsnapped();
      cst[5][k] = a.cubic() ? R(1) : R(0), cst[6][k] = static_cast<R>(a.count() - (a.cubic() ? 2 : 1));
    }
    for (int k = 2; k < 4; ++k) cst[3][k] = R(1), cst[6][k] = R(2);  // unused lanes: interior
    using V = detail::Vec4<R>;
    lane_t0_ = V::load(cst[0]), lane_scale_ = V::load(cst[1]), lane_offset_ = V::load(cst[2]), lane_top_ = V::load(cst[3]);
    lane_unsnapped_ = V::load(cst[4]), lane_first_ = V::load(cst[5]), lane_last_ = V::load(cst[6]);
    // A single node, or a linear axis of two nodes whose cell ends at both ends: the per-axis path.
    if (theta_d.count < 2 || sigma_a.count < 2) lane_unsnapped_ = V::all(R(-1));
    eval_ = pick(theta_.cubic(), sigma_.cubic());
  }

  bool valid() const { return eval_ != nullptr; }
  const FourierNpParams& params() const { return params_; }

  /// N(β): the last n of the series a lookup at β needs (β below beta_min counts as beta_min).
  int series_terms(R beta) const {
    const double b = static_cast<double>(beta < beta_min_ ? beta_min_ : beta);
    const int top = params_.terms - 1;
    int n = static_cast<int>(guess_ / b) - 1;
    n = n < 0 ? 0 : n > top ? top : n;
    while (n < top && b < threshold_[static_cast<std::size_t>(n)]) ++n;
    while (n > 0 && b >= threshold_[static_cast<std::size_t>(n - 1)]) --n;
    return n;
  }
  /// How many coefficients a lookup at β sums: N(β) + 1 rounded up to a multiple of 4, at most terms.
  int summed_terms(R beta) const {
    const int n = (series_terms(beta) + 4) / 4 * 4;
    return n < params_.terms ? n : params_.terms;
  }

  /// E = ∫N_p dφ = c_0 F at σa, θd (the series' mean times 2π; the residual's energy for its table),
  /// with the same folds and clamps as a lookup, not clamped at 0; NaN for a NaN argument.
  R energy(R sigma_a, R theta_d) const {
    if (!(sigma_a == sigma_a) || !(theta_d == theta_d) || !eval_) return std::numeric_limits<R>::quiet_NaN();
    const R pi = static_cast<R>(3.14159265358979323846);
    R th = std::fabs(theta_d);
    if (th > pi) th = std::fabs(std::remainder(th, R(2) * pi));
    if (!(th == th)) return th;
    th = th < theta_lo_ ? theta_lo_ : th > theta_hi_ ? theta_hi_ : th;
    const R sg = sigma_a < sigma_lo_ ? sigma_lo_ : sigma_a > sigma_hi_ ? sigma_hi_ : sigma_a;
    const R cos_t = std::cos(th);
    const FixedTaps<R> tt = theta_.taps(theta_cos_ ? -cos_t : th), ts = sigma_.taps(sigma_sqrt_ ? std::sqrt(sg) : sg);
    const int nt = theta_.cubic() ? 4 : 2, ns = sigma_.cubic() ? 4 : 2;
    R c0 = R(0);
    for (int i = 0; i < nt; ++i)
      for (int j = 0; j < ns; ++j) c0 += tt.w[i] * ts.w[j] * static_cast<R>(data_[tt.off[i] + ts.off[j]]);
    return c0 * absorption_(sg, cos_t) * params_.grazing.of_cos(sg, cos_t);
  }

  /// The series of N_p at β, σa, θd as cosine amplitudes: out[n] = (2 − δ_n0) e^{−n²β²/2} c_n F / 2π,
  /// so that N_p(φ) = max(0, Σ_n out[n] cos nφ) (operator() sums the same terms, and clamps).
  /// out must hold params().terms values; returns how many it wrote (as many as operator() sums
  /// at β: at least N(β) + 1, at most terms), 0 for a NaN argument or an invalid view. Folds and clamps as
  /// operator(); the scalar form of its sum, for samplers that need the amplitudes themselves.
  int series(R beta, R sigma_a, R theta_d, R* out) const {
    if (!(beta == beta) || !(sigma_a == sigma_a) || !(theta_d == theta_d) || !eval_) return 0;
    const R pi = static_cast<R>(3.14159265358979323846);
    R th = std::fabs(theta_d);
    if (th > pi) th = std::fabs(std::remainder(th, R(2) * pi));
    if (!(th == th)) return 0;
    th = th < theta_lo_ ? theta_lo_ : th > theta_hi_ ? theta_hi_ : th;
    const R sg = sigma_a < sigma_lo_ ? sigma_lo_ : sigma_a > sigma_hi_ ? sigma_hi_ : sigma_a;
    const R bt = beta < beta_min_ ? beta_min_ : beta;
    const R cos_t = std::cos(th);
    const FixedTaps<R> tt = theta_.taps(theta_cos_ ? -cos_t : th), ts = sigma_.taps(sigma_sqrt_ ? std::sqrt(sg) : sg);
    const int nt = theta_.cubic() ? 4 : 2, ns = sigma_.cubic() ? 4 : 2, count = lookup_terms(bt);
    const R scale = absorption_(sg, cos_t) * params_.grazing.of_cos(sg, cos_t) * static_cast<R>(0.15915494309189533577), b = R(0.5) * bt * bt;
    // e^{−n²b} by e^{−(n+1)²b} = e^{−n²b} e^{−(2n+1)b}, the step's factor itself times e^{−2b}.
    const R e2b = std::exp(R(-2) * b);
    R g = R(1), step = std::exp(-b);
    for (int n = 0; n < count; ++n) {
      R c = R(0);
      for (int i = 0; i < nt; ++i)
        for (int j = 0; j < ns; ++j) c += tt.w[i] * ts.w[j] * static_cast<R>(data_[tt.off[i] + ts.off[j] + static_cast<std::size_t>(n)]);
      out[n] = (n == 0 ? R(1) : R(2)) * g * c * scale;
      g *= step, step *= e2b;
    }
    return count;
  }

  /// N_p [1/rad] at β, σa, θd, φ (radians; any sign of θd and φ); the residual's uniform value for a
  /// one-term table.
  R operator()(R beta, R sigma_a, R theta_d, R phi) const {
    if (!(beta == beta) || !(sigma_a == sigma_a) || !(theta_d == theta_d) || !(phi == phi) || !eval_) return std::numeric_limits<R>::quiet_NaN();
    return (this->*eval_)(beta, sigma_a, theta_d, phi);
  }

 private:
  using Eval = R (FourierNp::*)(R, R, R, R) const;
  Eval pick(bool theta_cubic, bool sigma_cubic) const {
    if (theta_cubic) return sigma_cubic ? &FourierNp::eval<4, 4> : &FourierNp::eval<4, 2>;
    return sigma_cubic ? &FourierNp::eval<2, 4> : &FourierNp::eval<2, 2>;
  }

  // The lookup with KT taps along θd and KS along σa (2: linear, 4: Catmull–Rom).
  template <int KT, int KS>
  R eval(R beta, R sigma_a, R theta_d, R phi) const {
    using V = detail::Vec4<R>;
    const R pi = static_cast<R>(3.14159265358979323846);
    // Fold and clamp: θd → |θd| in [lo, hi], σa into [lo, hi], φ → |φ| in [0, π], β ≥ β_min.
    R th = std::fabs(theta_d);
    if (th > pi) th = std::fabs(std::remainder(th, R(2) * pi));
    th = th < theta_lo_ ? theta_lo_ : th > theta_hi_ ? theta_hi_ : th;
    const R sg = sigma_a < sigma_lo_ ? sigma_lo_ : sigma_a > sigma_hi_ ? sigma_hi_ : sigma_a;
    R ph = std::fabs(phi);
    if (ph > pi) ph = std::fabs(std::remainder(ph, R(2) * pi));
    if (!(th == th) || !(ph == ph)) return std::numeric_limits<R>::quiet_NaN();  // an infinite angle
    const R bt = beta < beta_min_ ? beta_min_ : beta;
    R cos_t, sin_t, cos_p, sin_p;
    detail::sincos_0_pi(th, ph, cos_t, sin_t, cos_p, sin_p);
    // The taps of both axes, each weight broadcast once.
    FixedTaps<R> tt, ts;
    V wt[KT], ws[KS];
    locate<KT, KS>(theta_cos_ ? -cos_t : th, sigma_sqrt_ ? std::sqrt(sg) : sg, tt, ts, wt, ws);
    // The KT × KS taps and their weights wt_i ws_j, multiplied once per lookup instead of once per
    // group of terms.
    constexpr int K = KT * KS;
    V w[K];
    const T* tap[K];
    for (int i = 0; i < KT; ++i)
      for (int j = 0; j < KS; ++j) w[i * KS + j] = wt[i] * ws[j], tap[i * KS + j] = data_ + tt.off[i] + ts.off[j];
    // Four terms per register: lanes n = 4g … 4g + 3. Weights (2 − δ_n0) e^{−n²b}, b = β²/2, by
    // the recurrence g ← g q, q ← q e^{−32b}; cosines as the real part of e^{inφ} rotated by e^{i4φ}.
    const R e1 = std::exp(R(-0.5) * bt * bt), e2 = e1 * e1, e4 = e2 * e2, e8 = e4 * e4, e16 = e8 * e8, e32 = e16 * e16;
    V g = V::set(R(1), R(2) * e1, R(2) * e4, R(2) * (e8 * e1));
    V q = V::set(e16, e16 * e8, e32, e32 * e8);
    const V r = V::all(e32);
    const R c2 = cos_p * cos_p - sin_p * sin_p, s2 = R(2) * sin_p * cos_p;
    V c = V::set(R(1), cos_p, c2, c2 * cos_p - s2 * sin_p), s = V::set(R(0), sin_p, s2, s2 * cos_p + c2 * sin_p);
    const V c4 = V::all(c2 * c2 - s2 * s2), s4 = V::all(R(2) * s2 * c2);
    const int count = lookup_terms(bt);
    const int full = count / 4;
    V acc = V::all(R(0));
    // Group k, then the recurrences to group k + 1 (forced inline: as a call, the state of the
    // recurrences goes through memory at every group, which doubled the cost in double). One loop
    // over both: blending a chunk of groups first and summing their series after spills less but
    // runs longer (the series' dependency chain has nothing to overlap with: 147 → 155 ns in double).
    auto step = [&](int k) HAIRLUT_SAMPLER_LAMBDA_INLINE {
      acc = acc + blend<K>(tap, w, static_cast<std::size_t>(4 * k)) * (g * c);
      const V cn = c * c4 - s * s4;
      s = c * s4 + s * c4, c = cn;
      g = g * q, q = q * r;
    };
    if (full > 0) {
      step(0);
      g = g * V::set(R(2), R(1), R(1), R(1));  // from n = 4 on, lane 0 carries the factor 2 too
    }
    for (int k = 1; k < full; ++k) step(k);
    if (count % 4) {  // a stored count that is not a multiple of 4: the last group in part
      T tail[K][4] = {};
      const T* ttap[K];
      for (int k = 0; k < K; ++k) {
        for (int l = 0; l < count % 4; ++l) tail[k][l] = tap[k][4 * full + l];
        ttap[k] = tail[k];
      }
      acc = acc + blend<K>(ttap, w, 0) * (g * c);
    }
    const R F = absorption_(sg, cos_t) * params_.grazing.of_cos(sg, cos_t);
    const R v = acc.sum() * F * static_cast<R>(0.15915494309189533577);  // 1/2π
    return v < R(0) ? R(0) : v;
  }

  // Σ_k w_k c(tap_k + n …): the K = KT × KS taps of one group of four terms, summed pairwise
  // (a tree of depth log₂ K).
  template <int K>
  static HAIRLUT_SAMPLER_INLINE detail::Vec4<R> blend(const T* const* tap, const detail::Vec4<R>* w, std::size_t n) {
    using V = detail::Vec4<R>;
    auto term = [&](int k) HAIRLUT_SAMPLER_LAMBDA_INLINE { return w[k] * V::load_from(tap[k] + n); };
    auto quad = [&](int k) HAIRLUT_SAMPLER_LAMBDA_INLINE { return (term(k) + term(k + 1)) + (term(k + 2) + term(k + 3)); };
    if constexpr (K == 4) return quad(0);
    else if constexpr (K == 8) return quad(0) + quad(4);
    else return (quad(0) + quad(4)) + (quad(8) + quad(12));
  }

  // The taps of θd (at its mapped coordinate xt) and σa (xs): both located in one register where
  // both cells are interior and no snap to a node applies (the same operations as
  // FixedAxis::locate per lane), else each by FixedAxis::taps (ends, snaps). Linear axes fill two.
  template <int KT, int KS>
  HAIRLUT_SAMPLER_INLINE void locate(R xt, R xs, FixedTaps<R>& tt, FixedTaps<R>& ts, detail::Vec4<R>* wt, detail::Vec4<R>* ws) const {
    using V = detail::Vec4<R>;
    V sv = (V::set(xt, xs, R(0), R(0)) - lane_t0_) * lane_scale_ + lane_offset_;
    sv = V::max(V::min(sv, lane_top_), V::all(R(0)));
    int i[4];
    const V f = sv.split(i);
    // Interior: first ≤ s < last (cubic: 1 ≤ i ≤ count − 3; linear: i ≤ count − 2); no snap.
    if (((V::greater(lane_first_, sv) | (V::greater(lane_last_, sv) ^ 15) | V::greater((f - V::all(R(0.5))).abs(), lane_unsnapped_)) & 3) != 0) {
      tt = theta_.taps(xt), ts = sigma_.taps(xs);
      for (int k = 0; k < KT; ++k) wt[k] = V::all(tt.w[k]);
      for (int k = 0; k < KS; ++k) ws[k] = V::all(ts.w[k]);
      return;
    }
    // Catmull–Rom (FixedAxis::catmull_rom) or linear weights, each lane's broadcast from its register.
    const V f2 = f * f, f3 = f2 * f, h = V::all(R(0.5));
    const V w[4] = {h * ((V::all(R(2)) * f2 - f3) - f), h * ((V::all(R(3)) * f3 - V::all(R(5)) * f2) + V::all(R(2))),
                    h * ((V::all(R(-3)) * f3 + V::all(R(4)) * f2) + f), h * (f3 - f2)};
    const V lin[2] = {V::all(R(1)) - f, f};
    for (int k = 0; k < KT; ++k) wt[k] = (KT == 4 ? w[k] : lin[k]).template lane<0>(), tt.off[k] = static_cast<std::size_t>(i[0] - (KT == 4) + k) * theta_.stride();
    for (int k = 0; k < KS; ++k) ws[k] = (KS == 4 ? w[k] : lin[k]).template lane<1>(), ts.off[k] = static_cast<std::size_t>(i[1] - (KS == 4) + k) * sigma_.stride();
  }

  // The terms a lookup at β sums (β ≥ β_min): from bins of u = β_min/β, each holding the count of
  // its smallest β (at least N(β) + 1, rounded up to a multiple of 4, at most terms).
  HAIRLUT_SAMPLER_INLINE int lookup_terms(R beta) const {
    const R u = beta_min_ / beta;
    const int k = static_cast<int>(u * static_cast<R>(kBins));
    return bin_terms_[static_cast<std::size_t>(k < kBins ? k : kBins)];
  }

  const T* data_ = nullptr;
  FourierNpParams params_;
  FourierAbsorption<R> absorption_;
  FixedAxis<R> theta_, sigma_;
  R theta_lo_ = R(0), theta_hi_ = R(0), sigma_lo_ = R(0), sigma_hi_ = R(0), beta_min_ = R(0);
  bool theta_cos_ = false, sigma_sqrt_ = false;
  std::vector<double> threshold_;
  double guess_ = 0.0;
  static constexpr int kBins = 512;
  std::vector<int> bin_terms_;
  detail::Vec4<R> lane_t0_{}, lane_scale_{}, lane_offset_{}, lane_top_{}, lane_unsnapped_{}, lane_first_{}, lane_last_{};
  Eval eval_ = nullptr;
};

}  // namespace sampler
}  // namespace hairlut
