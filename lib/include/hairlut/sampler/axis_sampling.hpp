// hairlut axis sampling: drawing a coordinate along the last axis of a table in proportion to the
// table's interpolant there (max(0, value), optionally times cos x), and its density.
//
// Header-only and dependency-free (C++17 standard library and sampler.hpp only). sampling.hpp
// builds the hair sampler on it; see there for what is exact. Per lookup, blend() forms the node
// row that the interpolation over the other axes gives (a weighted sum of node rows), turns it into
// one polynomial per cell with sampler.hpp's end rules (linear or Catmull–Rom), cuts each at its
// roots where the clamp at 0 applies, and sums the cells' masses; sample() inverts the cumulative
// exactly (binary search over cells, then safeguarded Newton within the cell to rounding).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "hairlut/sampler/sampler.hpp"

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

}  // namespace sampler
}  // namespace hairlut
