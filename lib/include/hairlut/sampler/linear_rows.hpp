// hairlut sampler, densities that are piecewise linear or quadratic on uniform nodes: locating an
// argument on a linear axis, guide tables, and the inverse CDFs that MaterialScattering and
// PreparedScattering draw their angles with.
//
// Header-only and dependency-free (C++17, with sampler.hpp's axis definitions).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "hairlut/sampler/sampler.hpp"

namespace hairlut {
namespace sampler {
namespace linear_rows {

/// An inclination with its sine and cosine (cos ≥ 0): the runtimes read both, and a caller that
/// holds a direction has the sine already.
struct Incl {
  double theta = 0.0, sin = 0.0, cos = 1.0;
};
inline Incl incl(double theta) { return {theta, std::sin(theta), std::cos(theta)}; }
/// From the sine (a direction's component along the fiber), clamped to [−1, 1].
inline Incl incl_of_sin(double s) {
  s = std::min(std::max(s, -1.0), 1.0);
  return {std::asin(s), s, std::sqrt(std::max(0.0, 1.0 - s * s))};
}

/// A direction drawn by the material and prepared runtimes, in angles (HairScattering turns it into
/// a vector): pdf 0 where nothing was drawn.
struct Draw {
  double theta_i = 0.0, sin_i = 0.0, cos_i = 1.0, phi = 0.0, pdf = 0.0, rgb[3] = {0.0, 0.0, 0.0};
  int lobe = -1;
};
/// A draw of inclination i, azimuth phi and lobe with its pdf and S per channel; an empty draw
/// where the pdf is not positive and finite.
inline Draw drawn(double pdf, const Incl& i, double phi, int lobe, const double* rgb) {
  Draw d;
  if (!(pdf > 0.0) || !(pdf < HUGE_VAL)) return d;
  d.pdf = pdf, d.theta_i = i.theta, d.sin_i = i.sin, d.cos_i = i.cos, d.phi = phi, d.lobe = lobe;
  d.rgb[0] = rgb[0], d.rgb[1] = rgb[1], d.rgb[2] = rgb[2];
  return d;
}

/// A cell of a linear axis and the weight of its upper node.
struct Cell {
  int i = 0;
  double w = 0.0;
};

/// An axis located in its mapped coordinate t (linear between nodes in t), its ends held.
struct Located {
  Spacing spacing = Spacing::uniform;
  double lo = 0.0, hi = 1.0, t0 = 0.0, scale = 0.0, h = 0.0;
  int last = 1;
  Located() = default;
  explicit Located(const Axis& a) : spacing(a.spacing), lo(a.lo), hi(a.hi), last(a.count - 1) {
    t0 = mapped(a.spacing, a.lo);
    scale = last / (mapped(a.spacing, a.hi) - t0);
    h = (a.hi - a.lo) / last;
  }
  Cell at(double x) const { return at_t(mapped(spacing, std::min(std::max(x, lo), hi))); }
  /// At the mapped coordinate t itself (cos θd for a cos-spaced θd axis).
  Cell at_t(double t) const {
    double s = (t - t0) * scale;
    s = std::min(std::max(s, 0.0), static_cast<double>(last));
    Cell c;
    c.i = std::min(static_cast<int>(s), last - 1);
    c.w = s - c.i;
    return c;
  }
};

/// A block of n values at the four corners of a cell blended bilinearly: a points to the block at
/// (i, j) and b to the block at (i + 1, j); each block's neighbour at j + 1 follows it n values on.
/// out[p] = w00 a[p] + w01 a[n + p] + w10 b[p] + w11 b[n + p] for p < n; N (4 or 8) fixes n at
/// compile time so that the loop becomes vector operations, 0 takes n at run time.
template <int N>
void bilinear_block(const float* a, const float* b, int n_runtime, double w00, double w01, double w10, double w11, double* out) {
  const int n = N ? N : n_runtime;
  for (int p = 0; p < n; ++p) out[p] = w00 * a[p] + w01 * a[n + p] + w10 * b[p] + w11 * b[n + p];
}
/// bilinear_block with n dispatched to a fixed size where it is 4 or 8.
inline void bilinear_block(const float* a, const float* b, int n, double w00, double w01, double w10, double w11, double* out) {
  if (n == 8) return bilinear_block<8>(a, b, n, w00, w01, w10, w11, out);
  if (n == 4) return bilinear_block<4>(a, b, n, w00, w01, w10, w11, out);
  bilinear_block<0>(a, b, n, w00, w01, w10, w11, out);
}

/// Guide tables: for each of g equal parts of a row's mass (prefix masses cum over n nodes), the
/// cell where that part begins, so that a search starts there and steps forward over a cell or two
/// instead of bisecting the row.
template <class C>
void build_guide(const C* cum, int n, std::uint16_t* guide, int g) {
  int k = 0;
  for (int b = 0; b < g; ++b) {
    const double target = static_cast<double>(b) / g * cum[n - 1];
    while (k < n - 2 && cum[k + 1] <= target) ++k;
    guide[b] = static_cast<std::uint16_t>(k);
  }
}
/// The cell holding `target` (= u · total): cum[k] ≤ target < cum[k + 1], cells of no mass skipped.
template <class C>
int find_cell(const C* cum, int n, const std::uint16_t* guide, int g, double u, double target) {
  int k = guide[std::min(static_cast<int>(u * g), g - 1)];
  while (k < n - 2 && cum[k + 1] <= target) ++k;
  return k;
}
/// The inverse CDF of a piecewise-linear density on n uniform nodes from 0 with step h (values
/// v[0], v[stride], …; prefix masses cum), at u ∈ [0, 1].
template <class V, class C>
double invert_row(const V* v, const C* cum, const std::uint16_t* guide, int g, int n, double h, double u, std::size_t stride = 1) {
  const double target = u * cum[n - 1];
  const int k = find_cell(cum, n, guide, g, u, target);
  const double m = std::max(0.0, target - cum[k]) / h, a = v[static_cast<std::size_t>(k) * stride], b = v[static_cast<std::size_t>(k + 1) * stride];
  // (b − a)/2 t² + a t = m, t ∈ [0, 1], in the form without cancellation.
  const double root = std::sqrt(std::max(0.0, a * a + 2.0 * (b - a) * m));
  double t = a + root > 0.0 ? 2.0 * m / (a + root) : 0.5;
  t = std::min(std::max(t, 0.0), 1.0);
  return (k + t) * h;
}
/// The inverse CDF of a density that is A + B s + C s² on cell k of n uniform nodes (s ∈ [0, 1]
/// the cell's coordinate, coefficients q[3k…3k+2]), prefix masses cum, at u ∈ [0, 1]: Newton on
/// the cell's cubic CDF from the root of its quadratic part, kept inside a shrinking bracket.
template <class Q, class Cum>
double invert_quadratic_row(const Q* q, const Cum* cum, const std::uint16_t* guide, int g, int n, double x0, double h, double u) {
  const double target = u * cum[n - 1];
  const int k = find_cell(cum, n, guide, g, u, target);
  const double A = q[3 * k], B = q[3 * k + 1], C = q[3 * k + 2];
  const double m = std::max(0.0, target - cum[k]) / h, total = A + 0.5 * B + C / 3.0;
  if (!(total > 0.0)) return x0 + (k + 0.5) * h;
  const double root = std::sqrt(std::max(0.0, A * A + 2.0 * B * m));
  double lo = 0.0, hi = 1.0, t = A + root > 0.0 ? std::min(1.0, 2.0 * m / (A + root)) : std::min(1.0, m / total);
  for (int it = 0; it < 12; ++it) {
    const double f = t * (A + t * (0.5 * B + t * C / 3.0)) - m, d = A + t * (B + t * C);
    if (f > 0.0) hi = t;
    else lo = t;
    double next = d > 0.0 ? t - f / d : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const bool done = std::fabs(next - t) < 1e-10;  // of the cell: far below any table's resolution
    t = next;
    if (done) break;
  }
  return x0 + (k + t) * h;
}

}  // namespace linear_rows
}  // namespace sampler
}  // namespace hairlut
