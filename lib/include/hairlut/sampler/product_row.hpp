// A density along one uniform, clamped axis x ∈ [lo, lo + n h] that is, on cell k (x = lo + (k + t) h,
// t ∈ [0, 1]), max(0, c_k(t)) · (e_k + (e_{k+1} − e_k) t) · cos x: an interpolated row (the cubic or
// linear cell polynomials c_k that AxisSampler::blend gives) times a factor interpolated linearly
// between the nodes, with the cos x of the solid-angle measure. HairScattering samples θi from it:
// M̃_p(θi) times the lobe's energy along θd, so that the density follows the product M_p E_p of the
// tables across the lobe and not M_p alone.
//
// Cells where the row stays below 1e-12 of its largest value are cut: no mass and value 0 (the
// far tails of a narrow lobe, where a blended Catmull–Rom row rings about 0); S there is below
// 1e-12 of its peak, which sampling then never reaches.
// Exact for this density, to rounding: whole cells positive throughout by the moments
// ∫_0^1 t^j cos(x_k + h t) dt (j ≤ 4, Gauss–Legendre of order 8 per cell when prepared, exact for the
// degree-4 polynomial times the degree-11 Taylor polynomial of cos over a cell of up to 20°);
// cells where c_k dips below 0 on the positive pieces between its roots (detail::positive_intervals)
// by the same rule on each piece; the inverse CDF within a cell by Newton's method safeguarded by
// bisection.
//
// Header-only and dependency-free (C++17, with cell_polynomial.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "hairlut/sampler/cell_polynomial.hpp"

namespace hairlut {
namespace sampler {

/// The moments ∫_0^1 t^j cos(lo + (k + t) h) dt, j = 0 … 4, of the n cells of a uniform axis.
class CosineMoments {
 public:
  CosineMoments() = default;
  CosineMoments(double lo, double h, int cells) : lo_(lo), h_(h), cells_(cells), m_(static_cast<std::size_t>(std::max(cells, 0)) * 5, 0.0) {
    for (int k = 0; k < cells; ++k)
      for (int g = 0; g < 8; ++g) {
        const double t = detail::gl8_nodes()[g], w = detail::gl8_weights()[g] * std::cos(lo + (k + t) * h);
        double p = 1.0;
        for (int j = 0; j < 5; ++j, p *= t) m_[static_cast<std::size_t>(k) * 5 + static_cast<std::size_t>(j)] += w * p;
      }
  }
  double lo() const { return lo_; }
  double h() const { return h_; }
  int cells() const { return cells_; }
  const double* of(int k) const { return &m_[static_cast<std::size_t>(k) * 5]; }

 private:
  double lo_ = 0.0, h_ = 1.0;
  int cells_ = 0;
  std::vector<double> m_;
};

/// The density of the top of this file for one row: prepare with the cell polynomials (4 per cell)
/// and the n + 1 node factors e (≥ 0), then value, sample, total.
class ProductRow {
 public:
  /// Cells of the row below this fraction of its largest value are cut (see prepare()).
  static constexpr double kCut = 1e-12;
  /// coef: 4 coefficients per cell (c0 + c1 t + c2 t² + c3 t³), e: cells + 1 factors ≥ 0 (NaN or
  /// negative read as 0). The moments fix the axis.
  void prepare(const CosineMoments& mom, const double* coef, const double* e) {
    prepare(mom, coef, [e](int k) { return e[k]; });
  }
  /// The same with the node factors from e_of(k), called only for the nodes of cells that are not
  /// cut (see below).
  template <class EOf>
  void prepare(const CosineMoments& mom, const double* coef, EOf&& e_of) {
    mom_ = &mom;
    const int n = mom.cells();
    coef_.assign(coef, coef + static_cast<std::size_t>(n) * 4);
    e_.assign(static_cast<std::size_t>(n) + 1, 0.0);
    // Each cell's positive pieces, once: none, the whole cell, or those between its roots. A cell
    // whose Bernstein coefficients all lie below kCut of the row's largest is cut (no mass, value
    // 0): the far tails of a narrow blended lobe, where the interpolant only rings about 0.
    kind_.assign(static_cast<std::size_t>(n), 0);
    pieces_.clear();
    // The largest |b0|, |b1|, |b2| in three running maxima (one would make each comparison wait
    // on the last), and ⅓ multiplied rather than divided: this loop runs over every cell of every
    // lobe at each new θo.
    constexpr double third = 1.0 / 3.0;
    double top0 = 0.0, top1 = 0.0, top2 = 0.0;
    for (int k = 0; k < n; ++k) {
      const double* c = &coef_[static_cast<std::size_t>(k) * 4];
      const double a0 = std::fabs(c[0]), a1 = std::fabs(c[0] + c[1] * third), a2 = std::fabs(c[0] + (2.0 * c[1] + c[2]) * third);
      top0 = a0 > top0 ? a0 : top0;
      top1 = a1 > top1 ? a1 : top1;
      top2 = a2 > top2 ? a2 : top2;
    }
    const double cut = kCut * std::max({top0, top1, top2});
    for (int k = 0; k < n; ++k) {
      const double* c = &coef_[static_cast<std::size_t>(k) * 4];
      const double b0 = c[0], b1 = c[0] + c[1] * third, b2 = c[0] + (2.0 * c[1] + c[2]) * third, b3 = c[0] + c[1] + c[2] + c[3];
      if (std::max({b0, b1, b2, b3}) <= cut) continue;
      for (int j = k; j <= k + 1; ++j) {
        double& e = e_[static_cast<std::size_t>(j)];
        if (e == 0.0) {
          const double v = e_of(j);
          e = v > 0.0 && v < HUGE_VAL ? v : -1.0;  // −1: asked, no energy (read as 0 below)
        }
      }
      if (b0 > 0.0 && b1 > 0.0 && b2 > 0.0 && b3 > 0.0) {
        kind_[static_cast<std::size_t>(k)] = 1;
      } else if (b0 > 0.0 || b1 > 0.0 || b2 > 0.0 || b3 > 0.0) {
        Pieces pc;
        pc.n = detail::positive_intervals(c, pc.lo, pc.hi);
        if (pc.n > 0) {
          kind_[static_cast<std::size_t>(k)] = static_cast<int>(pieces_.size()) + 2;
          pieces_.push_back(pc);
        }
      }
    }
    for (double& e : e_) e = std::max(e, 0.0);
    cum_.resize(static_cast<std::size_t>(n) + 1);
    cum_[0] = 0.0;
    for (int k = 0; k < n; ++k) cum_[static_cast<std::size_t>(k) + 1] = cum_[static_cast<std::size_t>(k)] + cell_mass(k, 1.0);
    total_ = cum_.back() > 0.0 && cum_.back() < HUGE_VAL ? cum_.back() : 0.0;
  }
  /// ∫ density dx over the axis (0: nothing to sample).
  double total() const { return total_; }
  /// max(0, c_k(t)) · (linear factor) at x, without cos x; 0 outside the axis or for NaN.
  double value(double x) const {
    const int n = mom_ ? mom_->cells() : 0;
    const double s = (x - mom_->lo()) / mom_->h();
    if (!(s >= 0.0 && s <= n)) return 0.0;
    const int k = std::min(static_cast<int>(s), n - 1);
    if (kind_[static_cast<std::size_t>(k)] == 0) return 0.0;
    const double t = s - k;
    return std::max(0.0, detail::poly(&coef_[static_cast<std::size_t>(k) * 4], t)) * factor(k, t);
  }
  /// x from u ∈ [0, 1], increasing with u; NaN when the row has no mass.
  double sample(double u) const {
    if (!(total_ > 0.0)) return std::nan("");
    const double target = std::min(std::max(u, 0.0), 1.0) * total_;
    const int n = mom_->cells();
    int k = static_cast<int>(std::upper_bound(cum_.begin(), cum_.end(), target) - cum_.begin()) - 1;
    k = std::max(0, std::min(n - 1, k));
    while (k > 0 && !(cum_[static_cast<std::size_t>(k) + 1] > cum_[static_cast<std::size_t>(k)])) --k;
    const double mass = cum_[static_cast<std::size_t>(k) + 1] - cum_[static_cast<std::size_t>(k)];
    const double want = std::min(std::max(target - cum_[static_cast<std::size_t>(k)], 0.0), mass);
    // Newton on F(t) = want, kept inside the bracket [a, b] by bisection.
    double a = 0.0, b = 1.0, t = mass > 0.0 ? want / mass : 0.5;
    for (int it = 0; it < 60; ++it) {
      const double f = cell_mass(k, t) - want;
      if (f > 0.0) b = t;
      else a = t;
      const double d = std::max(0.0, detail::poly(&coef_[static_cast<std::size_t>(k) * 4], t)) * factor(k, t) * std::cos(x_of(k, t)) * mom_->h();
      double next = d > 0.0 ? t - f / d : 0.5 * (a + b);
      if (!(next > a && next < b)) next = 0.5 * (a + b);
      if (std::fabs(next - t) < 1e-15 || b - a < 1e-15) {
        t = next;
        break;
      }
      t = next;
    }
    return x_of(k, t);
  }

 private:
  double x_of(int k, double t) const { return mom_->lo() + (k + t) * mom_->h(); }
  double factor(int k, double t) const { return e_[static_cast<std::size_t>(k)] + (e_[static_cast<std::size_t>(k) + 1] - e_[static_cast<std::size_t>(k)]) * t; }
  // ∫_0^t density dx over cell k.
  double cell_mass(int k, double t) const {
    const double* c = &coef_[static_cast<std::size_t>(k) * 4];
    const double e0 = e_[static_cast<std::size_t>(k)], de = e_[static_cast<std::size_t>(k) + 1] - e0;
    const int kind = kind_[static_cast<std::size_t>(k)];
    if (kind == 0 || !(e0 > 0.0 || de > 0.0)) return 0.0;
    static const double whole_lo[1] = {0.0}, whole_hi[1] = {1.0};
    const double* lo = kind == 1 ? whole_lo : pieces_[static_cast<std::size_t>(kind - 2)].lo;
    const double* hi = kind == 1 ? whole_hi : pieces_[static_cast<std::size_t>(kind - 2)].hi;
    const int pieces = kind == 1 ? 1 : pieces_[static_cast<std::size_t>(kind - 2)].n;
    if (kind == 1 && t >= 1.0) {
      // The product polynomial's coefficients against the cell's moments.
      const double q[5] = {c[0] * e0, c[1] * e0 + c[0] * de, c[2] * e0 + c[1] * de, c[3] * e0 + c[2] * de, c[3] * de};
      const double* m = mom_->of(k);
      return std::max(0.0, (q[0] * m[0] + q[1] * m[1] + q[2] * m[2] + q[3] * m[3] + q[4] * m[4]) * mom_->h());
    }
    double sum = 0.0;
    for (int i = 0; i < pieces; ++i) {
      const double a = lo[i], b = std::min(hi[i], t);
      if (!(b > a)) continue;
      double s = 0.0;
      for (int g = 0; g < 8; ++g) {
        const double tt = a + (b - a) * detail::gl8_nodes()[g];
        s += detail::gl8_weights()[g] * std::max(0.0, detail::poly(c, tt)) * (e0 + de * tt) * std::cos(x_of(k, tt));
      }
      sum += s * (b - a);
    }
    return sum * mom_->h();
  }

  struct Pieces {
    int n = 0;
    double lo[4], hi[4];
  };
  const CosineMoments* mom_ = nullptr;
  std::vector<double> coef_, e_, cum_;
  std::vector<int> kind_;  // per cell: 0 no mass, 1 positive throughout, k + 2 pieces_[k]
  std::vector<Pieces> pieces_;
  double total_ = 0.0;
};

}  // namespace sampler
}  // namespace hairlut
