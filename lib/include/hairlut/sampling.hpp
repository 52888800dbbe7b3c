// hairlut sampling: importance sampling of the shading S = Σ_p M_p N_p from hairlut tables.
//
// Header-only and dependency-free (C++17 standard library and sampler.hpp only), like
// sampler.hpp: an engine may copy both files.
//
// What is sampled is the function the sampler evaluates, not the physics behind it:
//   - the lobe p with probability proportional to its energy E_p(σa, θd) at θd = θi (the mirror
//     direction θr = −θi has |θd| = |θi|), or to ∫N_p dφ there when no energy table is given;
//   - θr in proportion to max(0, M̃_p(θi, θr)) cos θr, where M̃_p is the M_p table interpolated
//     as it declares (linear or Catmull–Rom along θr, blended over β and θi);
//   - φ in proportion to max(0, Ñ_p(φ)), the N_p table (or its shape N_p / E_p) interpolated at
//     (β, σa or channel, θd) with θd = (θr − θi)/2. A lobe without a φ axis (the residual) is
//     uniform in φ.
// The interpolation over every axis but the sampled (last) one is a weighted sum of node rows,
// so the density along the sampled axis is, cell by cell, the polynomial that the same weights
// give to the blended row: linear, or the Catmull–Rom cubic (with the clamped-end extrapolation
// and the mirror nodes of an even axis, exactly as sampler.hpp's taps()). The sampler clamps a
// negative interpolated value (Catmull–Rom overshoot, negative tap weights) at 0, and so do
// eval() and pdf() here: the density is max(0, polynomial), cut at its roots.
//
// Exact and approximate: cell masses of a plain density are closed-form polynomial integrals;
// with the cos θr measure they use an 8-point Gauss–Legendre rule per cell, exact for the cubic
// times the degree-11 Taylor polynomial of cos over the cell (the remainder is below 1e-14 for a
// cell of 20°, far below for the shipped axes). Roots of the cubic are found by bisection on its
// monotone pieces; the inverse CDF within a cell by Newton's method safeguarded by bisection, to
// rounding. So pdf() equals eval()'s lobe value divided by the normalisation that the same
// interpolant integrates to, up to rounding; sample() draws exactly from pdf().
//
// Supported sampled axes: uniform spacing, edge placement, wrap clamp (θr) or even over [0, π]
// (φ). Axes before the sampled one may have any spacing, placement and wrap, and linear or cubic
// interpolation; a geometric axis there makes the density non-polynomial and is refused
// (supported() is false). hairlut's N_p tables (generic shape and per-material) and M_p tables
// satisfy this.
//
// Measures: pdf() is per unit solid angle, dω = cos θr dθr dφ (θ from the normal plane), the
// measure of the energy integral E(θi) = ∫ S dω; a renderer divides value by pdf directly.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "hairlut/sampler.hpp"

namespace hairlut {
namespace sampler {

/// The density along the sampled axis: the interpolated value (plain) or the value times cos x.
enum class Measure : int { plain = 0, cosine = 1 };

/// A piecewise-polynomial density along the last axis of a table, at fixed coordinates of the
/// other axes: its cells, their masses and their cumulative sums. Filled by AxisSampler::blend.
struct AxisRow {
  std::vector<double> coef;  ///< 4 coefficients per cell: p(t) = c0 + c1 t + c2 t² + c3 t³, t ∈ [0, 1]
  std::vector<double> cum;   ///< cells + 1 cumulative masses (cum[0] = 0) over the sampled half for even axes
  std::vector<double> nodes; ///< the blended node values
  double total = 0.0;        ///< ∫ density over the axis's whole domain ([−π, π] for even axes)
  bool ok = false;           ///< false: NaN coordinate or unsupported table
};

namespace detail {
inline double poly(const double* c, double t) { return c[0] + t * (c[1] + t * (c[2] + t * c[3])); }
inline double poly_integral(const double* c, double a, double b) {
  auto P = [c](double t) { return t * (c[0] + t * (c[1] / 2.0 + t * (c[2] / 3.0 + t * c[3] / 4.0))); };
  return P(b) - P(a);
}
// 8-point Gauss–Legendre on [0, 1].
inline const double* gl8_nodes() {
  static const double x[8] = {0.019855071751231856, 0.10166676129318664, 0.2372337950418355, 0.4082826787521751,
                              0.5917173212478249,   0.7627662049581645,  0.8983332387068134, 0.9801449282487681};
  return x;
}
inline const double* gl8_weights() {
  static const double w[8] = {0.05061426814518813, 0.11119051722668724, 0.15685332293894363, 0.18134189168918100,
                              0.18134189168918100, 0.15685332293894363, 0.11119051722668724, 0.05061426814518813};
  return w;
}
// The intervals of [0, 1] where the cubic is positive (at most 3 roots, so at most 4 pieces).
inline int positive_intervals(const double* c, double* lo, double* hi) {
  // Bernstein coefficients: the cubic lies in their convex hull on [0, 1], so when all are
  // positive (the common case) or none is, no root search is needed.
  const double b0 = c[0], b1 = c[0] + c[1] / 3.0, b2 = c[0] + (2.0 * c[1] + c[2]) / 3.0, b3 = c[0] + c[1] + c[2] + c[3];
  if (b0 > 0.0 && b1 > 0.0 && b2 > 0.0 && b3 > 0.0) {
    lo[0] = 0.0, hi[0] = 1.0;
    return 1;
  }
  if (b0 <= 0.0 && b1 <= 0.0 && b2 <= 0.0 && b3 <= 0.0) return 0;
  double b[5];
  int nb = 0;
  b[nb++] = 0.0;
  // Critical points: c1 + 2 c2 t + 3 c3 t² = 0.
  const double A = 3.0 * c[3], B = 2.0 * c[2], C = c[1];
  double r[2];
  int nr = 0;
  if (A != 0.0) {
    const double disc = B * B - 4.0 * A * C;
    if (disc > 0.0) {
      const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
      r[nr++] = q / A;
      if (q != 0.0) r[nr++] = C / q;
    }
  } else if (B != 0.0) {
    r[nr++] = -C / B;
  }
  if (nr == 2 && r[0] > r[1]) std::swap(r[0], r[1]);
  for (int k = 0; k < nr; ++k)
    if (r[k] > 0.0 && r[k] < 1.0) b[nb++] = r[k];
  b[nb++] = 1.0;
  // Split each monotone piece at its root (if the sign changes) and keep the positive parts.
  int n = 0;
  for (int k = 0; k + 1 < nb; ++k) {
    double a = b[k], e = b[k + 1];
    const double pa = poly(c, a), pe = poly(c, e);
    if (pa > 0.0 && pe > 0.0) {
      lo[n] = a, hi[n] = e, ++n;
      continue;
    }
    if (!(pa > 0.0) && !(pe > 0.0)) continue;
    // One sign change on a monotone piece: Newton's method kept inside the bracket [x0, x1]
    // (bisection when a step leaves it), to rounding.
    double x0 = a, x1 = e;
    const bool rising = pe > 0.0;
    double x = a + (e - a) * pa / (pa - pe);
    for (int it = 0; it < 100; ++it) {
      if (!(x > x0 && x < x1)) x = 0.5 * (x0 + x1);
      if (x <= x0 || x >= x1) break;
      const double px = poly(c, x);
      if ((px > 0.0) == rising) x1 = x;
      else x0 = x;
      const double d = c[1] + x * (2.0 * c[2] + 3.0 * x * c[3]);
      const double next = d != 0.0 ? x - px / d : 0.5 * (x0 + x1);
      if (next == x) break;
      x = next;
    }
    const double root = std::min(std::max(x, x0), x1);
    if (rising) lo[n] = root, hi[n] = e;
    else lo[n] = a, hi[n] = root;
    if (hi[n] > lo[n]) ++n;
  }
  // Merge touching intervals (a positive piece split at a critical point).
  int m = 0;
  for (int k = 0; k < n; ++k) {
    if (m > 0 && lo[k] == hi[m - 1]) hi[m - 1] = hi[k];
    else lo[m] = lo[k], hi[m] = hi[k], ++m;
  }
  return m;
}
}  // namespace detail

/// Sampling along the last axis of a table (φ of N_p, θr of M_p). Prepared once per table
/// (const afterwards, shareable between threads); per lookup, blend() fills an AxisRow.
template <class T>
class AxisSampler {
 public:
  AxisSampler() = default;
  AxisSampler(const T* data, const Axis* axes, int dims, Measure measure) : data_(data), dims_(dims), measure_(measure) {
    if (!data || dims < 1 || dims > 8) return;
    std::size_t s = 1;
    for (int d = dims - 1; d >= 0; --d) {
      axes_[d] = PreparedAxis(axes[d]);
      stride_[d] = s;
      s *= static_cast<std::size_t>(axes[d].count);
    }
    const Axis& a = axes[dims - 1];
    const double pi = 3.14159265358979323846;
    const bool even = a.wrap == Wrap::even && a.lo == 0.0 && a.hi == pi;
    supported_ = a.spacing == Spacing::uniform && a.placement == Placement::edges && a.count >= 2 && a.hi > a.lo &&
                 (a.wrap == Wrap::clamp || even);
    for (int d = 0; d + 1 < dims; ++d)
      if (axes[d].interpolation == Interpolation::geometric && axes[d].count > 1) supported_ = false;
    if (!supported_) return;
    even_ = even;
    n_ = a.count;
    h_ = (a.hi - a.lo) / (n_ - 1);
    lo_ = a.lo;
    // The outer nodes of each cell's Catmull–Rom piece after the wrap rule (−1: extrapolated).
    outer_.resize(static_cast<std::size_t>(2 * (n_ - 1)));
    for (int k = 0; k + 1 < n_; ++k) {
      outer_[static_cast<std::size_t>(2 * k)] = wrapped_index(a, k - 1);
      outer_[static_cast<std::size_t>(2 * k + 1)] = wrapped_index(a, k + 2);
    }
    if (measure_ == Measure::cosine) {
      // ∫_0^1 t^j cos(x_k + h t) dt of every cell, for the masses of whole cells.
      moments_.resize(static_cast<std::size_t>(n_ - 1) * 4);
      for (int k = 0; k + 1 < n_; ++k)
        for (int g = 0; g < 8; ++g) {
          const double t = detail::gl8_nodes()[g], w = detail::gl8_weights()[g] * std::cos(x_of(k, t));
          for (int j = 0; j < 4; ++j) moments_[static_cast<std::size_t>(k) * 4 + j] += w * std::pow(t, j);
        }
    }
  }

  bool supported() const { return supported_; }

  /// The density along the sampled axis at the other coordinates x[0 … dims − 2].
  void blend(const double* x, AxisRow& row) const {
    row.ok = false;
    row.total = 0.0;
    if (!supported_) return;
    Taps tp[8];
    for (int d = 0; d + 1 < dims_; ++d) {
      if (!(x[d] == x[d]) && axes_[d].axis.count > 1) return;
      tp[d] = taps(axes_[d], x[d]);
    }
    // The blended node row: Σ over the tensor product of the taps of the node rows.
    std::vector<double>& v = row.nodes;
    v.assign(static_cast<std::size_t>(n_), 0.0);
    int idx[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    for (;;) {
      double w = 1.0;
      std::size_t offset = 0;
      for (int d = 0; d + 1 < dims_; ++d) {
        w *= tp[d].w[idx[d]];
        offset += static_cast<std::size_t>(tp[d].i[idx[d]]) * stride_[d];
      }
      if (w != 0.0) {
        const T* src = data_ + offset;
        for (int j = 0; j < n_; ++j) v[static_cast<std::size_t>(j)] += w * static_cast<double>(src[j]);
      }
      int d = dims_ - 2;
      for (; d >= 0; --d) {
        if (++idx[d] < tp[d].n) break;
        idx[d] = 0;
      }
      if (d < 0) break;
    }
    // Cell polynomials, with sampler.hpp's end rules along the sampled axis.
    const Axis& a = axes_[dims_ - 1].axis;
    const bool cubic = a.interpolation == Interpolation::cubic && n_ >= 3;
    row.coef.resize(static_cast<std::size_t>(n_ - 1) * 4);
    row.cum.resize(static_cast<std::size_t>(n_));
    row.cum[0] = 0.0;
    for (int k = 0; k + 1 < n_; ++k) {
      double* c = &row.coef[static_cast<std::size_t>(k) * 4];
      const double p1 = v[static_cast<std::size_t>(k)], p2 = v[static_cast<std::size_t>(k + 1)];
      if (!cubic) {
        c[0] = p1, c[1] = p2 - p1, c[2] = 0.0, c[3] = 0.0;
      } else {
        const int i0 = outer_[static_cast<std::size_t>(2 * k)], i3 = outer_[static_cast<std::size_t>(2 * k + 1)];
        const double p0 = i0 >= 0 ? v[static_cast<std::size_t>(i0)] : 3.0 * p1 - 3.0 * p2 + v[static_cast<std::size_t>(k + 2)];
        const double p3 = i3 >= 0 ? v[static_cast<std::size_t>(i3)] : 3.0 * p2 - 3.0 * p1 + v[static_cast<std::size_t>(k - 1)];
        c[0] = p1;
        c[1] = 0.5 * (p2 - p0);
        c[2] = 0.5 * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3);
        c[3] = 0.5 * (-p0 + 3.0 * p1 - 3.0 * p2 + p3);
      }
      row.cum[static_cast<std::size_t>(k + 1)] = row.cum[static_cast<std::size_t>(k)] + whole_cell_mass(k, c);
    }
    row.total = row.cum.back() * (even_ ? 2.0 : 1.0);
    row.ok = true;
  }

  /// The density at x: max(0, interpolated value), times cos x for Measure::cosine; 0 outside
  /// the domain of a clamped axis.
  double density(const AxisRow& row, double x) const {
    const double p = value(row, x);
    return measure_ == Measure::cosine ? p * std::cos(x) : p;
  }
  /// max(0, interpolated value) at x, without the measure's cos x (0 outside a clamped axis).
  double value(const AxisRow& row, double x) const {
    if (!row.ok || !(x == x)) return 0.0;
    const Axis& a = axes_[dims_ - 1].axis;
    if (!even_ && (x < a.lo || x > a.hi)) return 0.0;
    const Lerp l = axes_[dims_ - 1].locate(x);
    return std::max(0.0, detail::poly(&row.coef[static_cast<std::size_t>(l.i0) * 4], l.w));
  }
  /// density / total: the probability density of sample() (0 where total is 0).
  double pdf(const AxisRow& row, double x) const { return row.total > 0.0 ? density(row, x) / row.total : 0.0; }

  /// Draws x in proportion to the density from u ∈ [0, 1); returns NaN when the row has no mass.
  double sample(const AxisRow& row, double u) const {
    if (!row.ok || !(row.total > 0.0)) return std::nan("");
    double sign = 1.0;
    if (even_) {
      // Even axis: x < 0 for u < ½, mapped so that x increases with u (the inverse CDF over
      // the whole domain, which keeps stratified u stratified).
      if (u < 0.5) sign = -1.0, u = 1.0 - 2.0 * u;
      else u = 2.0 * u - 1.0;
    }
    u = std::min(std::max(u, 0.0), 1.0);
    const double target = u * row.cum.back();
    // The cell k with cum[k] ≤ target < cum[k + 1] (cells without mass are never chosen).
    int k = static_cast<int>(std::upper_bound(row.cum.begin(), row.cum.end(), target) - row.cum.begin()) - 1;
    k = std::max(0, std::min(n_ - 2, k));
    while (k > 0 && !(row.cum[static_cast<std::size_t>(k + 1)] > row.cum[static_cast<std::size_t>(k)])) --k;
    const double* c = &row.coef[static_cast<std::size_t>(k) * 4];
    const double mass = row.cum[static_cast<std::size_t>(k + 1)] - row.cum[static_cast<std::size_t>(k)];
    const double m = std::min(std::max(target - row.cum[static_cast<std::size_t>(k)], 0.0), mass);
    // Invert F(t) = ∫_0^t density: Newton on [lo, hi], bisection when a step leaves the bracket.
    double lo = 0.0, hi = 1.0, t = mass > 0.0 ? m / mass : 0.5;
    for (int it = 0; it < 100; ++it) {
      const double f = cell_mass(k, c, t) - m;
      if (f > 0.0) hi = t;
      else lo = t;
      if (f == 0.0 || hi - lo <= 1e-15) break;
      const double dens = h_ * std::max(0.0, detail::poly(c, t)) * (measure_ == Measure::cosine ? std::cos(x_of(k, t)) : 1.0);
      double next = dens > 0.0 ? t - f / dens : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::fabs(next - t) <= 1e-16) {
        t = next;
        break;
      }
      t = next;
    }
    return sign * x_of(k, t);
  }

 private:
  double x_of(int k, double t) const { return lo_ + (k + t) * h_; }
  // cell_mass(k, c, 1) with the Bernstein test inline: a cell positive throughout (or nowhere)
  // needs no root search.
  double whole_cell_mass(int k, const double* c) const {
    const double b0 = c[0], b1 = c[0] + c[1] / 3.0, b2 = c[0] + (2.0 * c[1] + c[2]) / 3.0, b3 = c[0] + c[1] + c[2] + c[3];
    if (b0 > 0.0 && b1 > 0.0 && b2 > 0.0 && b3 > 0.0) {
      if (measure_ == Measure::plain) return (c[0] + c[1] / 2.0 + c[2] / 3.0 + c[3] / 4.0) * h_;
      const double* mo = &moments_[static_cast<std::size_t>(k) * 4];
      return std::max(0.0, c[0] * mo[0] + c[1] * mo[1] + c[2] * mo[2] + c[3] * mo[3]) * h_;
    }
    if (b0 <= 0.0 && b1 <= 0.0 && b2 <= 0.0 && b3 <= 0.0) return 0.0;
    return cell_mass(k, c, 1.0);
  }
  // ∫ over t' ∈ [0, t] of cell k of max(0, p) (times cos x), in units of x.
  double cell_mass(int k, const double* c, double t) const {
    double lo[4], hi[4];
    const int n = detail::positive_intervals(c, lo, hi);
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      const double a = lo[i], b = std::min(hi[i], t);
      if (!(b > a)) continue;
      if (measure_ == Measure::plain) {
        sum += detail::poly_integral(c, a, b);
      } else if (a == 0.0 && b == 1.0) {
        const double* mo = &moments_[static_cast<std::size_t>(k) * 4];
        sum += c[0] * mo[0] + c[1] * mo[1] + c[2] * mo[2] + c[3] * mo[3];
      } else {
        double s = 0.0;
        for (int g = 0; g < 8; ++g) {
          const double tt = a + (b - a) * detail::gl8_nodes()[g];
          s += detail::gl8_weights()[g] * detail::poly(c, tt) * std::cos(x_of(k, tt));
        }
        sum += s * (b - a);
      }
    }
    return std::max(0.0, sum) * h_;
  }
  const T* data_ = nullptr;
  int dims_ = 0;
  Measure measure_ = Measure::plain;
  PreparedAxis axes_[8];
  std::size_t stride_[8] = {};
  bool supported_ = false, even_ = false;
  int n_ = 0;
  double h_ = 0.0, lo_ = 0.0;
  std::vector<int> outer_;
  std::vector<double> moments_;
};

/// What a table axis stands for, so that the hair sampler can fill its coordinate.
enum class Coordinate : int { none = 0, beta, sigma_a, channel, theta_d, theta_i, theta_r, phi };

/// The coordinate of a hairlut axis name ("beta", "sigma_a", "channel", "theta_d", "theta_i",
/// "theta_r", "phi"); Coordinate::none for any other.
inline Coordinate coordinate_named(const std::string& name) {
  static const char* const names[] = {"beta", "sigma_a", "channel", "theta_d", "theta_i", "theta_r", "phi"};
  for (int k = 0; k < 7; ++k)
    if (name == names[k]) return static_cast<Coordinate>(k + 1);
  return Coordinate::none;
}

/// One table as the hair sampler reads it: values, axes and what each axis stands for.
template <class T>
struct TableRef {
  const T* data = nullptr;  ///< null: no table
  const Axis* axes = nullptr;
  int dims = 0;
  Coordinate coords[8] = {};
};

/// The tables of one lobe.
template <class T>
struct LobeTables {
  TableRef<T> np;      ///< N_p (or its shape, with `factor`); last axis φ, or no φ axis (uniform in φ)
  TableRef<T> factor;  ///< the table np is multiplied by (np/energy_<lobe> of a shape table); optional
  TableRef<T> energy;  ///< the lobe's energy for lobe selection (may equal factor); optional
  TableRef<T> mp;      ///< M_p; last axis θr
};

/// The non-angular coordinates of a fibre: the table axes beta, sigma_a and channel read these.
struct Fibre {
  double beta = 0.0;
  double sigma_a = 0.0;
  double channel = 0.0;
};

/// A sampled direction: θr, φ = φr − φi, S(θi, θr, φ) (all lobes) and the pdf per unit solid
/// angle of the whole mixture. pdf == 0 when nothing could be sampled.
struct HairSample {
  double theta_r = 0.0, phi = 0.0, value = 0.0, pdf = 0.0;
  int lobe = -1;
};

/// S = Σ_p M_p N_p from hairlut tables: eval as an engine evaluates it, and sampling of exactly
/// that function lobe by lobe (see the top of this file). Prepared once, const afterwards.
template <class T>
class HairSampler {
 public:
  static constexpr int max_lobes = 8;
  /// Scratch rows for one thread; reuse one across calls to avoid allocations.
  struct Workspace {
    AxisRow m, n;
  };

  HairSampler() = default;
  HairSampler(const LobeTables<T>* lobes, int count) : count_(std::min(count, max_lobes)) {
    supported_ = count > 0 && count <= max_lobes;
    for (int p = 0; p < count_; ++p) {
      Prepared& q = lobe_[p];
      q.t = lobes[p];
      const LobeTables<T>& l = lobes[p];
      if (!l.np.data || !l.mp.data || l.mp.coords[l.mp.dims - 1] != Coordinate::theta_r) supported_ = false;
      if (!l.np.data || !l.mp.data) continue;
      q.np = TableView<T>(l.np.data, l.np.axes, l.np.dims);
      q.mp = TableView<T>(l.mp.data, l.mp.axes, l.mp.dims);
      if (l.factor.data) q.factor = TableView<T>(l.factor.data, l.factor.axes, l.factor.dims);
      if (l.energy.data) q.energy = TableView<T>(l.energy.data, l.energy.axes, l.energy.dims);
      q.has_phi = l.np.coords[l.np.dims - 1] == Coordinate::phi;
      for (int d = 0; d + 1 < l.np.dims; ++d)
        if (l.np.coords[d] == Coordinate::phi) supported_ = false;
      q.mp_axis = AxisSampler<T>(l.mp.data, l.mp.axes, l.mp.dims, Measure::cosine);
      if (!q.mp_axis.supported()) supported_ = false;
      if (q.has_phi) {
        q.np_axis = AxisSampler<T>(l.np.data, l.np.axes, l.np.dims, Measure::plain);
        if (!q.np_axis.supported()) supported_ = false;
      }
    }
  }

  /// False when a table lacks, or its sampled axis is not supported (see the top of this file).
  bool supported() const { return supported_; }
  int lobes() const { return count_; }

  /// M_p N_p of lobe p as an engine evaluates it: each table interpolated by sampler.hpp and
  /// clamped at 0, θd = (θr − θi)/2.
  double eval_lobe(int p, const Fibre& f, double theta_i, double theta_r, double phi) const {
    const Prepared& q = lobe_[p];
    double x[8];
    const double theta_d = 0.5 * (theta_r - theta_i);
    fill(q.t.mp, f, theta_i, theta_r, theta_d, phi, x);
    const double m = std::max(0.0, q.mp(x));
    if (!(m > 0.0)) return m;
    fill(q.t.np, f, theta_i, theta_r, theta_d, phi, x);
    double n = std::max(0.0, q.np(x));
    if (q.t.factor.data && n > 0.0) {
      fill(q.t.factor, f, theta_i, theta_r, theta_d, phi, x);
      n *= std::max(0.0, q.factor(x));
    }
    return m * n;
  }
  /// S(θi, θr, φ) = Σ_p M_p N_p.
  double eval(const Fibre& f, double theta_i, double theta_r, double phi) const {
    double s = 0.0;
    for (int p = 0; p < count_; ++p) s += eval_lobe(p, f, theta_i, theta_r, phi);
    return s;
  }

  /// The probability of choosing each lobe at θi (they sum to 1, or are all 0).
  void lobe_probabilities(const Fibre& f, double theta_i, double* prob, Workspace& ws) const {
    double sum = 0.0;
    for (int p = 0; p < count_; ++p) {
      const Prepared& q = lobe_[p];
      double x[8], w;
      if (q.t.energy.data) {
        fill(q.t.energy, f, theta_i, 0.0, theta_i, 0.0, x);
        w = std::max(0.0, q.energy(x));
      } else {
        if (q.has_phi) {
          fill(q.t.np, f, theta_i, 0.0, theta_i, 0.0, x);
          q.np_axis.blend(x, ws.n);
          w = ws.n.total;
        } else {
          fill(q.t.np, f, theta_i, 0.0, theta_i, 0.0, x);
          w = 2.0 * 3.14159265358979323846 * std::max(0.0, q.np(x));
        }
        if (q.t.factor.data) {
          fill(q.t.factor, f, theta_i, 0.0, theta_i, 0.0, x);
          w *= std::max(0.0, q.factor(x));
        }
      }
      prob[p] = w == w ? w : 0.0;
      sum += prob[p];
    }
    for (int p = 0; p < count_; ++p) prob[p] = sum > 0.0 ? prob[p] / sum : 0.0;
  }

  /// The pdf per unit solid angle of drawing (θr, φ) from lobe p alone:
  /// max(0, M̃_p)/∫max(0, M̃_p) cos θr dθr · max(0, Ñ_p)/∫max(0, Ñ_p) dφ.
  double pdf_lobe(int p, const Fibre& f, double theta_i, double theta_r, double phi, Workspace& ws) const {
    const Prepared& q = lobe_[p];
    double x[8];
    const double theta_d = 0.5 * (theta_r - theta_i);
    fill(q.t.mp, f, theta_i, theta_r, theta_d, phi, x);
    q.mp_axis.blend(x, ws.m);
    if (!(ws.m.total > 0.0)) return 0.0;
    const double pm = q.mp_axis.value(ws.m, theta_r) / ws.m.total;
    if (!(pm > 0.0)) return 0.0;
    if (!q.has_phi) return pm / (2.0 * 3.14159265358979323846);
    fill(q.t.np, f, theta_i, theta_r, theta_d, phi, x);
    q.np_axis.blend(x, ws.n);
    return pm * q.np_axis.pdf(ws.n, phi);
  }

  /// The pdf per unit solid angle of sample(): Σ_p P_p pdf_lobe(p).
  double pdf(const Fibre& f, double theta_i, double theta_r, double phi, Workspace& ws) const {
    double prob[max_lobes];
    lobe_probabilities(f, theta_i, prob, ws);
    double s = 0.0;
    for (int p = 0; p < count_; ++p)
      if (prob[p] > 0.0) s += prob[p] * pdf_lobe(p, f, theta_i, theta_r, phi, ws);
    return s;
  }

  /// Draws a direction from three uniform numbers in [0, 1): u0 chooses the lobe, u1 θr, u2 φ.
  HairSample sample(const Fibre& f, double theta_i, double u0, double u1, double u2, Workspace& ws) const {
    HairSample r;
    double prob[max_lobes];
    lobe_probabilities(f, theta_i, prob, ws);
    int p = -1;
    double acc = 0.0;
    for (int k = 0; k < count_; ++k) {
      if (!(prob[k] > 0.0)) continue;
      p = k;
      acc += prob[k];
      if (u0 < acc) break;
    }
    if (p < 0) return r;
    const Prepared& q = lobe_[p];
    double x[8];
    fill(q.t.mp, f, theta_i, 0.0, 0.0, 0.0, x);
    q.mp_axis.blend(x, ws.m);
    const double theta_r = q.mp_axis.sample(ws.m, u1);
    if (!(theta_r == theta_r)) return r;
    double phi = -3.14159265358979323846 + 2.0 * 3.14159265358979323846 * u2;
    if (q.has_phi) {
      fill(q.t.np, f, theta_i, theta_r, 0.5 * (theta_r - theta_i), 0.0, x);
      q.np_axis.blend(x, ws.n);
      phi = q.np_axis.sample(ws.n, u2);
      if (!(phi == phi)) return r;
    }
    r.theta_r = theta_r;
    r.phi = phi;
    r.lobe = p;
    r.value = eval(f, theta_i, theta_r, phi);
    r.pdf = pdf(f, theta_i, theta_r, phi, ws);
    return r;
  }

 private:
  struct Prepared {
    LobeTables<T> t;
    TableView<T> np, factor, energy, mp;
    AxisSampler<T> np_axis, mp_axis;
    bool has_phi = false;
  };
  static void fill(const TableRef<T>& t, const Fibre& f, double theta_i, double theta_r, double theta_d, double phi, double* x) {
    for (int d = 0; d < t.dims; ++d) {
      switch (t.coords[d]) {
        case Coordinate::beta: x[d] = f.beta; break;
        case Coordinate::sigma_a: x[d] = f.sigma_a; break;
        case Coordinate::channel: x[d] = f.channel; break;
        case Coordinate::theta_d: x[d] = theta_d; break;
        case Coordinate::theta_i: x[d] = theta_i; break;
        case Coordinate::theta_r: x[d] = theta_r; break;
        case Coordinate::phi: x[d] = phi; break;
        default: x[d] = 0.0; break;
      }
    }
  }

  Prepared lobe_[max_lobes];
  int count_ = 0;
  bool supported_ = false;
};

/// A HairSampler for one fibre: its N_p and M_p tables blended over the fibre's own coordinates
/// (beta, sigma_a, channel) once, so that each lookup interpolates over the angles only (16×
/// fewer node rows per lookup for the generic tables). The values are those of the full tables
/// up to rounding: the same tensor product of the same taps, summed in another order. A table
/// whose fibre axes lead its angular ones and carry no geometric interpolation is reduced; any
/// other (the energies, geometric in σa) is kept whole, as a double copy. Build one per fibre
/// (strand, material), not per lookup; it owns its data.
template <class T>
class FibreSampler {
 public:
  FibreSampler(const LobeTables<T>* lobes, int count, const Fibre& fibre) : fibre_(fibre) {
    count = std::max(0, std::min(count, HairSampler<double>::max_lobes));
    for (int p = 0; p < count; ++p) {
      LobeTables<double>& l = lobes_[p];
      l.np = take(lobes[p].np);
      l.mp = take(lobes[p].mp);
      l.factor = take(lobes[p].factor);
      l.energy = take(lobes[p].energy);
    }
    sampler_ = HairSampler<double>(lobes_, count);
  }
  FibreSampler(const FibreSampler&) = delete;
  FibreSampler& operator=(const FibreSampler&) = delete;

  const HairSampler<double>& sampler() const { return sampler_; }
  /// The fibre it was built for: pass it to the sampler's calls.
  const Fibre& fibre() const { return fibre_; }

 private:
  static bool angular(Coordinate c) {
    return c == Coordinate::theta_d || c == Coordinate::theta_i || c == Coordinate::theta_r || c == Coordinate::phi;
  }
  TableRef<double> take(const TableRef<T>& t) {
    TableRef<double> r;
    if (!t.data || t.dims < 1 || t.dims > 8) return r;
    std::size_t total = 1;
    for (int d = 0; d < t.dims; ++d) total *= static_cast<std::size_t>(t.axes[d].count);
    int lead = 0;  // the leading fibre axes
    while (lead < t.dims && !angular(t.coords[lead])) ++lead;
    bool reducible = lead > 0 && lead < t.dims;
    for (int d = 0; d < t.dims; ++d) {
      if (d >= lead && !angular(t.coords[d])) reducible = false;
      if (d < lead && t.axes[d].interpolation == Interpolation::geometric && t.axes[d].count > 1) reducible = false;
    }
    std::vector<double>& out = data_[used_];
    std::vector<Axis>& axes = axes_[used_];
    ++used_;
    if (!reducible) {
      out.assign(t.data, t.data + total);
      axes.assign(t.axes, t.axes + t.dims);
      r.dims = t.dims;
      for (int d = 0; d < t.dims; ++d) r.coords[d] = t.coords[d];
    } else {
      std::size_t block = 1;
      for (int d = lead; d < t.dims; ++d) block *= static_cast<std::size_t>(t.axes[d].count);
      Taps tp[8];
      for (int d = 0; d < lead; ++d) {
        const Coordinate c = t.coords[d];
        const double x = c == Coordinate::beta ? fibre_.beta : c == Coordinate::sigma_a ? fibre_.sigma_a : c == Coordinate::channel ? fibre_.channel : 0.0;
        tp[d] = taps(PreparedAxis(t.axes[d]), x);
      }
      out.assign(block, 0.0);
      int idx[8] = {0, 0, 0, 0, 0, 0, 0, 0};
      for (;;) {
        double w = 1.0;
        std::size_t offset = 0;
        for (int d = 0; d < lead; ++d) {
          w *= tp[d].w[idx[d]];
          offset = offset * static_cast<std::size_t>(t.axes[d].count) + static_cast<std::size_t>(tp[d].i[idx[d]]);
        }
        if (w != 0.0) {
          const T* src = t.data + offset * block;
          for (std::size_t j = 0; j < block; ++j) out[j] += w * static_cast<double>(src[j]);
        }
        int d = lead - 1;
        for (; d >= 0; --d) {
          if (++idx[d] < tp[d].n) break;
          idx[d] = 0;
        }
        if (d < 0) break;
      }
      axes.assign(t.axes + lead, t.axes + t.dims);
      r.dims = t.dims - lead;
      for (int d = lead; d < t.dims; ++d) r.coords[d - lead] = t.coords[d];
    }
    r.data = out.data();
    r.axes = axes.data();
    return r;
  }

  Fibre fibre_;
  LobeTables<double> lobes_[HairSampler<double>::max_lobes];
  std::vector<double> data_[4 * HairSampler<double>::max_lobes];
  std::vector<Axis> axes_[4 * HairSampler<double>::max_lobes];
  int used_ = 0;
  HairSampler<double> sampler_;
};

}  // namespace sampler
}  // namespace hairlut
