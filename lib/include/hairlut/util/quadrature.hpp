// Quadrature rules: Gauss–Legendre of any order (nodes from Boost.Math) and a globally adaptive
// Gauss–Kronrod (10, 21) integrator for vector-valued integrands with error control.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

namespace hairlut {

/// Gauss–Legendre rule of order n on [−1, 1]: exact for polynomials of degree ≤ 2n − 1.
/// Nodes are Boost.Math's zeros of P_n; weights w_i = 2 / ((1 − x_i²) P_n'(x_i)²).
class GaussLegendreRule {
 public:
  /// Domain: 1 ≤ order ≤ 32768 (throws DomainError).
  explicit GaussLegendreRule(int order);

  int order() const { return static_cast<int>(nodes_.size()); }
  /// Nodes on [−1, 1] in ascending order; nodes()[i] = −nodes()[n − 1 − i] exactly.
  std::span<const double> nodes() const { return nodes_; }
  std::span<const double> weights() const { return weights_; }

  /// ∫_a^b f(x) dx ≈ (b − a)/2 Σ w_i f((a + b)/2 + (b − a)/2 x_i).
  template <class F>
  double integrate(F&& f, double a, double b) const {
    const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
    double sum = 0.0;
    for (std::size_t i = 0; i < nodes_.size(); ++i) sum += weights_[i] * f(mid + half * nodes_[i]);
    return half * sum;
  }

 private:
  std::vector<double> nodes_;
  std::vector<double> weights_;
};

/// Gauss–Legendre rules by order, built once and shared (rules of high order take O(n²) to
/// build). Owned by the caller; safe to use from several threads.
class GaussLegendreCache {
 public:
  /// The rule of this order (built on first use). The reference stays valid while the cache lives.
  const GaussLegendreRule& get(int order);

 private:
  std::mutex mutex_;
  std::map<int, std::unique_ptr<GaussLegendreRule>> rules_;
};

/// Settings of integrate_adaptive.
struct AdaptiveOptions {
  double rel_tol = 1e-12;    ///< requested |error| ≤ rel_tol · |integral| per component ...
  double abs_tol = 1e-300;   ///< ... or |error| ≤ abs_tol
  int max_intervals = 8000;  ///< give up (converged = false) past this many subintervals
};

/// Result of integrate_adaptive: one value and error estimate per component.
struct AdaptiveResult {
  std::vector<double> value;
  std::vector<double> error;  ///< Σ over subintervals of |K21 − G10| (conservative)
  bool converged = false;     ///< every component met its tolerance
  int intervals = 0;
  long evaluations = 0;
};

/// The 21-point Kronrod abscissae and weights with the embedded 10-point Gauss weights (Boost.Math
/// tables), laid out as Boost stores them: index 0 is the centre, odd indices are Gauss nodes.
struct KronrodTables {
  std::span<const double> abscissa;  // 11 non-negative nodes
  std::span<const double> kronrod;   // 11 Kronrod weights
  std::span<const double> gauss;     // 5 Gauss weights (for the odd indices, gauss[i / 2])
};
KronrodTables kronrod21_tables();

namespace detail {
// One (10, 21) Gauss–Kronrod panel on [a, b] of an m-component integrand: writes the Kronrod value
// and |K − G| per component. f(x, out) fills out[0..m).
template <class F>
void kronrod_panel(F& f, std::size_t m, double a, double b, std::vector<double>& val, std::vector<double>& err,
                   std::vector<double>& fp, std::vector<double>& fm) {
  static const KronrodTables t = kronrod21_tables();
  const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
  std::vector<double> gauss(m, 0.0);
  f(mid, std::span<double>(fp));
  for (std::size_t c = 0; c < m; ++c) val[c] = fp[c] * t.kronrod[0];
  for (std::size_t i = 1; i < t.abscissa.size(); ++i) {
    const double dx = half * t.abscissa[i];
    f(mid + dx, std::span<double>(fp));
    f(mid - dx, std::span<double>(fm));
    for (std::size_t c = 0; c < m; ++c) {
      const double s = fp[c] + fm[c];
      val[c] += s * t.kronrod[i];
      if (i & 1) gauss[c] += s * t.gauss[i / 2];
    }
  }
  for (std::size_t c = 0; c < m; ++c) {
    val[c] *= half;
    err[c] = std::abs(val[c] - half * gauss[c]);
  }
}
}  // namespace detail

/// Globally adaptive integration of an m-component integrand over the intervals between
/// consecutive breakpoints (sorted, at least two): repeatedly bisects the subinterval that
/// contributes most to the worst component's error relative to its tolerance, until every
/// component meets max(rel_tol·|I|, abs_tol) or the interval budget is spent. Boost.Math's
/// gauss_kronrod is scalar-only, which is why this loop is written here; its nodes are Boost's.
/// f(x, std::span<double> out) writes the m components at x.
template <class F>
AdaptiveResult integrate_adaptive(F&& f, std::size_t m, std::span<const double> breakpoints,
                                  const AdaptiveOptions& opt = {}) {
  struct Panel {
    double a, b;
    std::vector<double> val, err;
  };
  std::vector<Panel> panels;
  std::vector<double> fp(m), fm(m);
  AdaptiveResult r;
  auto make = [&](double a, double b) {
    Panel p{a, b, std::vector<double>(m), std::vector<double>(m)};
    detail::kronrod_panel(f, m, a, b, p.val, p.err, fp, fm);
    r.evaluations += 21;
    return p;
  };
  for (std::size_t i = 0; i + 1 < breakpoints.size(); ++i)
    if (breakpoints[i + 1] > breakpoints[i]) panels.push_back(make(breakpoints[i], breakpoints[i + 1]));

  std::vector<double> total(m), total_err(m);
  for (;;) {
    std::fill(total.begin(), total.end(), 0.0);
    std::fill(total_err.begin(), total_err.end(), 0.0);
    for (const Panel& p : panels)
      for (std::size_t c = 0; c < m; ++c) total[c] += p.val[c], total_err[c] += p.err[c];
    // Tolerance per component and whether all are met.
    std::vector<double> tol(m);
    bool done = true;
    for (std::size_t c = 0; c < m; ++c) {
      tol[c] = std::max(opt.rel_tol * std::abs(total[c]), opt.abs_tol);
      if (total_err[c] > tol[c]) done = false;
    }
    if (done) { r.converged = true; break; }
    if (static_cast<int>(panels.size()) >= opt.max_intervals) break;
    // The panel with the largest error relative to its component's tolerance.
    std::size_t worst = panels.size();
    double worst_ratio = 0.0;
    for (std::size_t i = 0; i < panels.size(); ++i) {
      const Panel& p = panels[i];
      const double mid = 0.5 * (p.a + p.b);
      if (!(mid > p.a && mid < p.b)) continue;  // cannot be split further in double precision
      for (std::size_t c = 0; c < m; ++c) {
        const double ratio = p.err[c] / tol[c];
        if (ratio > worst_ratio) worst_ratio = ratio, worst = i;
      }
    }
    if (worst == panels.size()) break;
    const Panel p = panels[worst];
    const double mid = 0.5 * (p.a + p.b);
    panels[worst] = make(p.a, mid);
    panels.push_back(make(mid, p.b));
  }
  r.value = total;
  r.error = total_err;
  r.intervals = static_cast<int>(panels.size());
  return r;
}

/// Scalar convenience form of integrate_adaptive over [a, b].
template <class F>
AdaptiveResult integrate_adaptive_scalar(F&& f, double a, double b, const AdaptiveOptions& opt = {}) {
  const double bp[2] = {a, b};
  return integrate_adaptive([&](double x, std::span<double> out) { out[0] = f(x); }, 1, bp, opt);
}

}  // namespace hairlut
