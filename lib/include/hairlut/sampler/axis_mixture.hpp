// hairlut axis sampling, the mixture path: AxisSampler's mix(), mix_value() and sample_mix() and
// what they share, defined apart from the class (axis_sampling.hpp, which includes this file).
//
// The mixture path (mix(), mix_value(), sample_mix()): the density is max(0, Σ w_c s_c) over the
// node slices s_c the other axes' taps touch, with weights of either sign. Integrals are linear,
// so the integral of Σ w_c s_c over cells 0 … k − 1 is Σ w_c F_c(k), F_c the slice's own prefix
// integrals (AxisData, computed once per table or stored with it), and its total Σ w_c E_c. The
// clamp at 0 adds ∫ max(0, −Σ w_c s_c) to a cell; the clamp bounds (per cell of the other axes and
// cell of the sampled axis, from the tensor Bernstein coefficients: cell_bernstein.hpp) bound
// that addition anywhere in the cell. mix() integrates the cells whose bounds matter under the
// clamp (largest first, until the rest is below 1e-15 of the total) and adds the differences;
// sample_mix() searches the cumulative so corrected, then inverts the chosen cell's blended
// polynomial (under the clamp in a corrected cell). Exact to rounding, like the general path;
// mix() declines (then use blend()) when more than Mix::max_fixes cells would need the clamp, a
// lookup touches more than Mix::max_corners slices, or a coordinate is NaN.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "hairlut/sampler/axis_sampling.hpp"

namespace hairlut {
namespace sampler {

template <class T>
bool AxisSampler<T>::mix(const double* x, Mix& m) const {
  m.count = 0;
  m.fixes = 0;
  m.total = 0.0;
  if (!mixture_) return false;
  Taps tp[8];
  std::size_t cell = 0;
  for (int d = 0; d + 1 < dims_; ++d) {
    if (!(x[d] == x[d]) && axes_[d].axis.count > 1) return false;
    tp[d] = taps(axes_[d], x[d]);
    cell += static_cast<std::size_t>(cell_of(axes_[d], x[d])) * (stride_[d] / static_cast<std::size_t>(n_));
  }
  const double* mass = masses();
  const bool fits = each_corner(tp, [&](double w, std::size_t offset) {
    if (w == 0.0) return true;
    if (m.count == Mix::max_corners) return false;
    const std::size_t s = offset / static_cast<std::size_t>(n_);
    m.row[m.count] = offset;
    m.w[m.count] = w;
    ++m.count;
    m.total += w * mass[s];
    return true;
  });
  if (!fits || m.count == 0 || !(m.total > 0.0)) return false;
  // The cells that may be clamped, largest bound first, until what is left is below rounding:
  // those whose blended polynomial here has a Bernstein coefficient < 0 are integrated under the
  // clamp. The blended nodes they need are formed once each (at most the general path's blend).
  const double negligible = 1e-15 * m.total;
  double add = 0.0;
  const std::size_t begin = fix_begin_[cell], end = fix_begin_[cell + 1];
  if (begin < end && fix_rest_[begin] > negligible) {
    if (n_ > Mix::max_nodes) return false;
    std::fill(m.blended, m.blended + n_, static_cast<unsigned char>(0));
  }
  for (std::size_t e = begin; e < end && fix_rest_[e] > negligible; ++e) {
    if (!(fix_rest_[e] < HUGE_VAL)) return false;  // a NaN node
    const int k = fix_cell_[e];
    double c[4], b[4];
    blend_nodes_of_cell(m, k);
    cell_coef(m.node, k, c);
    bernstein_of_cubic(c, b);
    if (b[0] >= 0.0 && b[1] >= 0.0 && b[2] >= 0.0 && b[3] >= 0.0) continue;  // not clamped at this lookup
    if (m.fixes == Mix::max_fixes) return false;
    const double unclamped = measure_ == Measure::plain ? (c[0] + c[1] / 2.0 + c[2] / 3.0 + c[3] / 4.0) * h_ : unclamped_cosine_mass(k, c);
    int j = m.fixes++;
    for (; j > 0 && m.fix_cell[j - 1] > k; --j) m.fix_cell[j] = m.fix_cell[j - 1], m.fix_add[j] = m.fix_add[j - 1];
    m.fix_cell[j] = k;
    m.fix_add[j] = cell_mass(k, c, 1.0) - unclamped;
    add += m.fix_add[j];
  }
  m.total += add * (even_ ? 2.0 : 1.0);
  return m.total > 0.0;
}

template <class T>
double AxisSampler<T>::mix_value(const Mix& m, double x) const {
  if (!(x == x)) return 0.0;
  const Axis& a = axes_[dims_ - 1].axis;
  if (!even_ && (x < a.lo || x > a.hi)) return 0.0;
  const Lerp l = axes_[dims_ - 1].locate(x);
  double c[4];
  blended_cell(m, l.i0, c);
  return std::max(0.0, detail::poly(c, l.w));
}

template <class T>
double AxisSampler<T>::sample_mix(const Mix& m, double u) const {
  if (!(m.total > 0.0)) return std::nan("");
  double sign = 1.0;
  if (even_) {
    if (u < 0.5) sign = -1.0, u = 1.0 - 2.0 * u;
    else u = 2.0 * u - 1.0;
  }
  u = std::min(std::max(u, 0.0), 1.0);
  const double* cdf = cdfs();
  auto F = [&](int k) {
    double s = gather(m, cdf + k);
    for (int j = 0; j < m.fixes && m.fix_cell[j] < k; ++j) s += m.fix_add[j];
    return s;
  };
  // The cell k with F(k) ≤ target < F(k + 1).
  const double top = F(n_ - 1), target = u * top;
  int lo = 0, hi = n_ - 1;
  double f_lo = 0.0, f_hi = top;
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    const double f = F(mid);
    if (f <= target) lo = mid, f_lo = f;
    else hi = mid, f_hi = f;
  }
  double c[4];
  blended_cell(m, lo, c);
  const double mass = std::max(0.0, f_hi - f_lo), want = std::min(std::max(target - f_lo, 0.0), mass);
  bool fixed = false;
  for (int j = 0; j < m.fixes; ++j) fixed = fixed || m.fix_cell[j] == lo;
  return sign * x_of(lo, fixed ? invert_clamped(lo, c, want, mass) : invert_cell(lo, c, want, mass));
}

template <class T>
void AxisSampler<T>::blend_nodes_of_cell(Mix& m, int k) const {
  int need[4] = {k, k + 1, -1, -1};
  if (cubic_) {
    const int i0 = outer_[static_cast<std::size_t>(2 * k)], i3 = outer_[static_cast<std::size_t>(2 * k + 1)];
    need[2] = i0 >= 0 ? i0 : k + 2;
    need[3] = i3 >= 0 ? i3 : k - 1;
  }
  for (int j : need) {
    if (j < 0 || j >= n_ || m.blended[j]) continue;
    m.node[j] = gather(m, data_ + j);
    m.blended[j] = 1;
  }
}

template <class T>
template <class V>
double AxisSampler<T>::gather(const Mix& m, const V* base) {
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  int c = 0;
  for (; c + 4 <= m.count; c += 4) {
    s0 += m.w[c] * static_cast<double>(base[m.row[c]]);
    s1 += m.w[c + 1] * static_cast<double>(base[m.row[c + 1]]);
    s2 += m.w[c + 2] * static_cast<double>(base[m.row[c + 2]]);
    s3 += m.w[c + 3] * static_cast<double>(base[m.row[c + 3]]);
  }
  for (; c < m.count; ++c) s0 += m.w[c] * static_cast<double>(base[m.row[c]]);
  return (s0 + s1) + (s2 + s3);
}

template <class T>
void AxisSampler<T>::blended_cell(const Mix& m, int k, double* c) const {
  const double p1 = gather(m, data_ + k), p2 = gather(m, data_ + k + 1);
  if (!cubic_) {
    c[0] = p1, c[1] = p2 - p1, c[2] = 0.0, c[3] = 0.0;
    return;
  }
  const int i0 = outer_[static_cast<std::size_t>(2 * k)], i3 = outer_[static_cast<std::size_t>(2 * k + 1)];
  const double p0 = i0 >= 0 ? gather(m, data_ + i0) : 3.0 * p1 - 3.0 * p2 + gather(m, data_ + k + 2);
  const double p3 = i3 >= 0 ? gather(m, data_ + i3) : 3.0 * p2 - 3.0 * p1 + gather(m, data_ + k - 1);
  catmull_rom(p0, p1, p2, p3, c);
}

template <class T>
void AxisSampler<T>::prepare_fixes() {
  const float* b = bounds();
  const std::size_t n = static_cast<std::size_t>(n_);
  fix_begin_.assign(slices_ + 1, 0);
  fix_cell_.clear();
  fix_rest_.clear();
  std::vector<std::pair<float, int>> list;
  for (std::size_t s = 0; s < slices_; ++s) {
    list.clear();
    for (std::size_t k = 0; k + 1 < n; ++k)
      if (b[s * n + k] > 0.0f || !(b[s * n + k] == b[s * n + k])) list.emplace_back(b[s * n + k] == b[s * n + k] ? b[s * n + k] : HUGE_VALF, static_cast<int>(k));
    std::sort(list.begin(), list.end(), [](const std::pair<float, int>& x, const std::pair<float, int>& y) { return x.first > y.first; });
    const std::size_t at = fix_cell_.size();
    fix_cell_.resize(at + list.size());
    fix_rest_.resize(at + list.size());
    double rest = 0.0;
    for (std::size_t e = list.size(); e-- > 0;) {
      rest += static_cast<double>(list[e].first);
      fix_cell_[at + e] = list[e].second;
      fix_rest_[at + e] = rest;
    }
    fix_begin_[s + 1] = fix_cell_.size();
  }
}

}  // namespace sampler
}  // namespace hairlut
