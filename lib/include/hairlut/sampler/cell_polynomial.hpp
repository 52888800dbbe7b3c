// hairlut cell polynomials: one cubic p(t) = c0 + c1 t + c2 t² + c3 t³ over a table cell t ∈ [0, 1]
// (the form axis_sampling.hpp turns each cell of an interpolated row into) — its value, its exact
// integral, the 8-point Gauss–Legendre rule on [0, 1] that integrates it against cos x, and the
// intervals where it is positive (the pieces that survive the clamp max(0, p)).
//
// Header-only and dependency-free (C++17 standard library only).
#pragma once

#include <algorithm>
#include <cmath>

namespace hairlut {
namespace sampler {

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

}  // namespace sampler
}  // namespace hairlut
