// hairlut axis sampling: drawing a coordinate along the last axis of a table in proportion to the
// table's interpolant there (max(0, value), optionally times cos x), and its density.
//
// Header-only and dependency-free (C++17 standard library and sampler.hpp only). sampling.hpp
// builds the hair sampler on it; see there for what is exact. Per lookup, blend() forms the node
// row that the interpolation over the other axes gives (a weighted sum of node rows), turns it into
// one polynomial per cell with sampler.hpp's end rules (linear or Catmull–Rom), cuts each at its
// roots where the clamp at 0 applies, and sums the cells' masses; sample() inverts the cumulative
// exactly (binary search over cells, then safeguarded Newton within the cell to rounding). The
// mixture path (mix(), mix_value(), sample_mix()) is described and defined in axis_mixture.hpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>
#include <utility>

#include "hairlut/sampler/cell_bernstein.hpp"
#include "hairlut/sampler/cell_polynomial.hpp"
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

/// The sampling data of a table along its last axis (AxisSampler::build_data's layout; the
/// baked files store them, docs/table-format.md "Sampling data"): per node slice its n prefix
/// masses and its mass; per cell of the other axes and cell of the sampled axis, a bound of what
/// the clamp at 0 can add to that cell's mass (0: the interpolant is ≥ 0 there). Pointers into
/// the caller's arrays, which must outlive the sampler.
struct AxisData {
  const double* cdf = nullptr;
  const double* mass = nullptr;
  const float* clamp_bound = nullptr;
};

/// Sampling along the last axis of a table (φ of N_p, θr of M_p). Prepared once per table
/// (const afterwards, shareable between threads); per lookup, blend() fills an AxisRow.
template <class T>
class AxisSampler {
 public:
  AxisSampler() = default;
  /// With `stored` (all three arrays, as build_data() lays them out, e.g. read from a table file)
  /// the sampler points into them; without, it computes them (one pass over the table).
  AxisSampler(const T* data, const Axis* axes, int dims, Measure measure, const AxisData& stored = AxisData())
      : AxisSampler(data, axes, dims, measure, stored, SerialBlocks()) {}
  /// Without the mixture path's data (none computed, mix() always declines): for a caller that
  /// only blends rows, whose sampling data would cost a pass over the table and its size again.
  struct BlendOnly {};
  AxisSampler(const T* data, const Axis* axes, int dims, Measure measure, BlendOnly)
      : AxisSampler(data, axes, dims, measure, AxisData(), SerialBlocks(), false) {}
  /// The same, computing the data (when none are stored) with the clamp bounds' blocks run by
  /// run_blocks (build_data).
  template <class RunBlocks>
  AxisSampler(const T* data, const Axis* axes, int dims, Measure measure, const AxisData& stored, RunBlocks&& run_blocks, bool mixture = true)
      : data_(data), dims_(dims), measure_(measure) {
    if (!data || dims < 1 || dims > 8) return;
    std::size_t s = 1;
    for (int d = dims - 1; d >= 0; --d) {
      axes_[d] = PreparedAxis(axes[d]);
      stride_[d] = s;
      s *= static_cast<std::size_t>(axes[d].count);
    }
    const Axis& a = axes[dims - 1];
    supported_ = supports(axes, dims);
    if (!supported_) return;
    even_ = a.wrap == Wrap::even;
    n_ = a.count;
    cubic_ = a.interpolation == Interpolation::cubic && n_ >= 3;
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
    slices_ = stride_[0] * static_cast<std::size_t>(axes[0].count) / static_cast<std::size_t>(n_);
    if (!mixture) return;
    if (stored.cdf && stored.mass && stored.clamp_bound) {
      stored_ = stored;
    } else {
      build_data(cdf_, mass_, bound_, std::forward<RunBlocks>(run_blocks));
    }
    prepare_fixes();
    mixture_ = true;
  }

  bool supported() const { return supported_; }
  /// Whether a table with these axes can be sampled along its last one (see the top of sampling.hpp).
  static bool supports(const Axis* axes, int dims) {
    if (!axes || dims < 1 || dims > 8) return false;
    const Axis& a = axes[dims - 1];
    const bool even = a.wrap == Wrap::even && a.lo == 0.0 && a.hi == 3.14159265358979323846;
    if (!(a.spacing == Spacing::uniform && a.placement == Placement::edges && a.count >= 2 && a.hi > a.lo && (a.wrap == Wrap::clamp || even)))
      return false;
    for (int d = 0; d + 1 < dims; ++d)
      if (axes[d].interpolation == Interpolation::geometric && axes[d].count > 1) return false;
    return true;
  }

  /// The density along the sampled axis at the other coordinates x[0 … dims − 2]. Without
  /// with_masses only the blended nodes and cell polynomials are filled (cum and total stay
  /// unset: for a caller that integrates the row times something else).
  void blend(const double* x, AxisRow& row, bool with_masses = true) const {
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
    v.resize(static_cast<std::size_t>(n_));
    // Raw pointers: the vector's own members could alias the stores for all the compiler knows,
    // which keeps this loop (the runtime's largest per shading point) from vectorising.
    double* __restrict out = v.data();
    const int n = n_;
    bool first = true;
    each_corner(tp, [&](double w, std::size_t offset) {
      if (w != 0.0) {
        const T* __restrict src = data_ + offset;
        if (first) {
          for (int j = 0; j < n; ++j) out[j] = w * static_cast<double>(src[j]);
          first = false;
        } else {
          for (int j = 0; j < n; ++j) out[j] += w * static_cast<double>(src[j]);
        }
      }
      return true;
    });
    if (first) std::fill(v.begin(), v.end(), 0.0);
    // Cell polynomials, with sampler.hpp's end rules along the sampled axis.
    row.coef.resize(static_cast<std::size_t>(n_ - 1) * 4);
    if (!with_masses) {
      for (int k = 0; k + 1 < n_; ++k) cell_coef(v.data(), k, &row.coef[static_cast<std::size_t>(k) * 4]);
      row.ok = true;
      return;
    }
    row.cum.resize(static_cast<std::size_t>(n_));
    row.cum[0] = 0.0;
    for (int k = 0; k + 1 < n_; ++k) {
      double* c = &row.coef[static_cast<std::size_t>(k) * 4];
      cell_coef(v.data(), k, c);
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

  /// The mixture path at one lookup (see the top of this file): the node slices the other axes'
  /// taps touch and their weights (of either sign), the sampled cells whose clamp at 0 is
  /// accounted for (fix_cell, in increasing order, with what the clamp adds to their mass), and
  /// the normalisation Σ w_c E_c + Σ fixes.
  struct Mix {
    static constexpr int max_corners = 64, max_fixes = 48, max_nodes = 256;
    // Only the first `count` corners and `fixes` fixes are read, and mix() writes them: the arrays
    // are left uninitialised, since a Mix is made per lobe per sample.
    int count = 0, fixes = 0;
    double node[max_nodes];          // blended node values, where `blended` says so (mix()'s scratch)
    unsigned char blended[max_nodes];
    std::size_t row[max_corners];  // each slice's first entry in the table (and in the prefix masses): slice × n
    double w[max_corners];
    int fix_cell[max_fixes];
    double fix_add[max_fixes];
    double total = 0.0;
  };
  /// True when the mixture path is exact (to rounding) at the other coordinates x[0 … dims − 2]:
  /// the sampled cells whose clamp bound matters (those whose bounds, largest first, add up to
  /// more than 1e-15 of Σ w_c E_c) are at most max_fixes, and their clamped masses are computed
  /// here. False otherwise (then use blend()).
  bool mix(const double* x, Mix& m) const;
  /// The interpolated value at x along the sampled axis (without the measure's cos x; 0 outside
  /// a clamped axis): max(0, Σ w_c s_c(x)), eval's value.
  double mix_value(const Mix& m, double x) const;
  /// Draws x from the mixture with one u ∈ [0, 1): the cell whose cumulative Σ w_c F_c (plus the
  /// clamp additions of the fixed cells before it) brackets u, by binary search over the prefix
  /// masses, then Newton on that cell's blended polynomial (clamped at 0 in a fixed cell); NaN
  /// when the mixture has no mass. x increases with u.
  double sample_mix(const Mix& m, double u) const;
  /// Whether mix() can ever apply (the sampled axis is supported and the sampling data are there).
  bool has_mixture() const { return mixture_; }

  /// The node slices along the sampled axis (the product of the other axes' counts; a cell of the
  /// other axes is indexed by the slice of its first node).
  std::size_t slices() const { return slices_; }
  /// The sampling data in use: the stored ones, or those computed at construction (slices() × n
  /// prefix masses, slices() masses, slices() × n clamp bounds); null pointers when unsupported.
  AxisData sampling_data() const { return supported_ ? AxisData{cdfs(), masses(), bounds()} : AxisData(); }
  /// Moves out the sampling data computed at construction (build_data's arrays; empty when they
  /// were stored or the table is unsupported). The sampler is not to be used afterwards.
  void release_data(std::vector<double>& cdf, std::vector<double>& mass, std::vector<float>& bound) && {
    cdf = std::move(cdf_), mass = std::move(mass_), bound = std::move(bound_);
  }
  /// Computes the sampling data of the table (docs/table-format.md, "Sampling data"): per slice
  /// the prefix masses of its own interpolant along the sampled axis at the n nodes (unclamped;
  /// over [0, π] for an even axis; with the cos x weight for Measure::cosine) and its mass over the
  /// whole domain; per cell of the other axes (at its first node's slice) and cell k of the
  /// sampled axis (entry k of n; entry n − 1 and cells past an axis's end are 0), the clamp bound
  /// max(0, −least tensor Bernstein coefficient of the interpolant over the two cells) × the
  /// cell's width, rounded up to float: the most that max(0, ·) can add to that cell's mass
  /// anywhere in the cell of the other axes (0: the interpolant is ≥ 0 throughout).
  /// The clamp bounds' blocks go through run_blocks (clamp_bounds; SerialBlocks by default: on this
  /// thread, in order).
  template <class RunBlocks = SerialBlocks>
  void build_data(std::vector<double>& cdf, std::vector<double>& mass, std::vector<float>& bound, RunBlocks&& run_blocks = RunBlocks()) const {
    cdf.assign(slices_ * static_cast<std::size_t>(n_), 0.0);
    mass.assign(slices_, 0.0);
    bound.assign(slices_ * static_cast<std::size_t>(n_), 0.0f);
    if (!supported_) return;
    for (std::size_t s = 0; s < slices_; ++s) mass[s] = slice_prefix(s, &cdf[s * static_cast<std::size_t>(n_)]);
    const std::size_t n = static_cast<std::size_t>(n_);
    for_each_clamp_bound_row([&](std::size_t first, const float* b) { std::copy(b, b + (n - 1), bound.begin() + static_cast<std::ptrdiff_t>(first * n)); },
                             std::forward<RunBlocks>(run_blocks));
  }
  /// Slice s's prefix masses at the n nodes into cum (build_data's cdf row) and its mass (the
  /// returned value); s < slices(), the table supported.
  double slice_prefix(std::size_t s, double* cum) const {
    const T* v = data_ + s * static_cast<std::size_t>(n_);
    cum[0] = 0.0;
    for (int k = 0; k + 1 < n_; ++k) {
      double c[4];
      cell_coef(v, k, c);
      const double cell = measure_ == Measure::plain ? (c[0] + c[1] / 2.0 + c[2] / 3.0 + c[3] / 4.0) * h_ : unclamped_cosine_mass(k, c);
      cum[k + 1] = cum[k] + cell;
    }
    return cum[n_ - 1] * (even_ ? 2.0 : 1.0);
  }
  /// build_data's clamp bounds, handed row by row to sink(first, bounds) (cell_bernstein.hpp,
  /// clamp_bounds): the n − 1 bounds of the slice `first` that starts a cell of the other axes;
  /// the entries of other slices, and entry n − 1 of every slice, are 0. Memory: a few rows per
  /// block, whatever the table's size.
  template <class Sink, class RunBlocks = SerialBlocks>
  void for_each_clamp_bound_row(Sink&& sink, RunBlocks&& run_blocks = RunBlocks()) const {
    if (!supported_) return;
    const std::size_t n = static_cast<std::size_t>(n_);
    clamp_bounds(
        [&](std::size_t s, double* out) {
          const T* v = data_ + s * n;
          for (int k = 0; k + 1 < n_; ++k) {
            double c[4];
            cell_coef(v, k, c);
            bernstein_of_cubic(c, out + static_cast<std::size_t>(k) * 4);
          }
        },
        axes_, stride_, dims_, n_, h_, std::forward<Sink>(sink), std::forward<RunBlocks>(run_blocks));
  }
  /// Whether stored sampling data (slices() × n prefix masses, slices() masses, slices() × n clamp
  /// bounds) are those of this table: the prefix masses and masses recomputed as build_data does and
  /// equal to within 1e-12 of each slice's largest |prefix| (rounding where a compiler contracts or
  /// a libm's cos differs), and every clamp bound finite and ≥ 0 (they are not recomputed: that is
  /// most of build_data's cost). A file whose checksum was recomputed after an edit of its sampling
  /// data fails here; a NaN anywhere fails.
  bool matches(const AxisData& stored) const {
    if (!supported_ || !stored.cdf || !stored.mass || !stored.clamp_bound) return false;
    const std::size_t n = static_cast<std::size_t>(n_);
    std::vector<double> cdf(n);  // one slice at a time: a loader holds the table once, not twice
    for (std::size_t s = 0; s < slices_; ++s) {
      const double mass = slice_prefix(s, cdf.data());
      double scale = 0.0;
      for (std::size_t k = 0; k < n; ++k) scale = std::max(scale, std::fabs(cdf[k]));
      const double tol = 1e-12 * scale;
      for (std::size_t k = 0; k < n; ++k)
        if (!(std::fabs(cdf[k] - stored.cdf[s * n + k]) <= tol)) return false;
      if (!(std::fabs(mass - stored.mass[s]) <= 2.0 * tol)) return false;
    }
    for (std::size_t i = 0; i < slices_ * n; ++i)
      if (!(stored.clamp_bound[i] >= 0.0f) || !(stored.clamp_bound[i] < HUGE_VALF)) return false;
    return true;
  }

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
    return sign * x_of(k, invert_clamped(k, c, m, mass));
  }

 private:
  // The t ∈ [0, 1] of cell k (polynomial c, clamped at 0) where the mass from 0 reaches m:
  // F(t) = ∫_0^t density by cell_mass, Newton on [lo, hi], bisection when a step leaves the
  // bracket; to rounding.
  double invert_clamped(int k, const double* c, double m, double mass) const {
    return newton_in_bracket([&](double t) { return cell_mass(k, c, t); },
                             [&](double t) { return h_ * std::max(0.0, detail::poly(c, t)) * (measure_ == Measure::cosine ? std::cos(x_of(k, t)) : 1.0); },
                             m, mass > 0.0 ? m / mass : 0.5, 100);
  }
  // The t ∈ [0, 1] where the increasing F (derivative D ≥ 0) reaches m: Newton's method from t0,
  // a bisection step whenever Newton would leave the bracket [lo, hi] that the signs of F − m
  // keep; stops at rounding (the bracket or the step below 1e-15) or after `iterations`.
  template <class Fn, class Dn>
  static double newton_in_bracket(Fn&& F, Dn&& D, double m, double t0, int iterations) {
    double lo = 0.0, hi = 1.0, t = t0;
    for (int it = 0; it < iterations; ++it) {
      const double f = F(t) - m;
      if (f > 0.0) hi = t;
      else lo = t;
      if (f == 0.0 || hi - lo <= 1e-15) break;
      const double dens = D(t);
      double next = dens > 0.0 ? t - f / dens : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::fabs(next - t) <= 1e-16) {
        t = next;
        break;
      }
      t = next;
    }
    return t;
  }
  // Blends (once) the nodes that the polynomial of sampled cell k reads, into m.node.
  void blend_nodes_of_cell(Mix& m, int k) const;
  // Σ_c w_c base[row_c] over the mixture's slices, in four partial sums: the additions of one
  // chain would each wait for the last (the mixture path's inner loop, up to 64 slices).
  template <class V>
  static double gather(const Mix& m, const V* base);
  // The blended polynomial Σ w_c p_c of sampled cell k over the mixture's slices: the polynomial
  // of the blended nodes (cell_coef is linear in them).
  void blended_cell(const Mix& m, int k, double* c) const;
  // Per cell of the other axes, its sampled cells with a clamp bound > 0, largest bound first,
  // each with the sum of its own and the later bounds (what is left to account for).
  void prepare_fixes();
  // Visits the tensor product of the other axes' taps: f(weight, offset of the node slice) for
  // each corner in row-major order; stops and returns false as soon as f does.
  template <class F>
  bool each_corner(const Taps* tp, F&& f) const {
    int idx[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    for (;;) {
      double w = 1.0;
      std::size_t offset = 0;
      for (int d = 0; d + 1 < dims_; ++d) {
        w *= tp[d].w[idx[d]];
        offset += static_cast<std::size_t>(tp[d].i[idx[d]]) * stride_[d];
      }
      if (!f(w, offset)) return false;
      int d = dims_ - 2;
      for (; d >= 0; --d) {
        if (++idx[d] < tp[d].n) break;
        idx[d] = 0;
      }
      if (d < 0) return true;
    }
  }
  double x_of(int k, double t) const { return lo_ + (k + t) * h_; }
  // The polynomial of cell k of node row v along the sampled axis, with sampler.hpp's end rules
  // (linear, or Catmull–Rom with the clamped-end extrapolation and the mirror nodes of an even axis).
  template <class V>
  void cell_coef(const V* v, int k, double* c) const {
    const double p1 = static_cast<double>(v[k]), p2 = static_cast<double>(v[k + 1]);
    if (!cubic_) {
      c[0] = p1, c[1] = p2 - p1, c[2] = 0.0, c[3] = 0.0;
      return;
    }
    const int i0 = outer_[static_cast<std::size_t>(2 * k)], i3 = outer_[static_cast<std::size_t>(2 * k + 1)];
    const double p0 = i0 >= 0 ? static_cast<double>(v[i0]) : 3.0 * p1 - 3.0 * p2 + static_cast<double>(v[k + 2]);
    const double p3 = i3 >= 0 ? static_cast<double>(v[i3]) : 3.0 * p2 - 3.0 * p1 + static_cast<double>(v[k - 1]);
    catmull_rom(p0, p1, p2, p3, c);
  }
  static void catmull_rom(double p0, double p1, double p2, double p3, double* c) {
    c[0] = p1;
    c[1] = 0.5 * (p2 - p0);
    c[2] = 0.5 * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3);
    c[3] = 0.5 * (-p0 + 3.0 * p1 - 3.0 * p2 + p3);
  }
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
  // ∫ over the whole cell k of p(t) cos x, unclamped (the cosine moments), in units of x.
  double unclamped_cosine_mass(int k, const double* c) const {
    const double* mo = &moments_[static_cast<std::size_t>(k) * 4];
    return (c[0] * mo[0] + c[1] * mo[1] + c[2] * mo[2] + c[3] * mo[3]) * h_;
  }
  const double* cdfs() const { return stored_.cdf ? stored_.cdf : cdf_.data(); }
  const double* masses() const { return stored_.mass ? stored_.mass : mass_.data(); }
  const float* bounds() const { return stored_.clamp_bound ? stored_.clamp_bound : bound_.data(); }
  // The t ∈ [0, 1] of cell k (polynomial c, ≥ 0 on the cell, mass `mass`) where the mass from 0
  // reaches m: Newton's method kept in its bracket, to rounding. The cosine measure's integral
  // is that of c times the degree-11 Taylor polynomial of cos about the cell's start (remainder
  // below (h)¹²/12!, 6e-15 for a 20° cell), in closed form: no cos per step.
  double invert_cell(int k, const double* c, double m, double mass) const {
    if (!(mass > 0.0)) return 0.5;
    double q[16] = {};  // the density per unit t (times cos for the cosine measure), degree ≤ 14
    int deg = 3;
    if (measure_ == Measure::plain) {
      for (int j = 0; j < 4; ++j) q[j] = c[j] * h_;
    } else {
      const double x0 = lo_ + k * h_, cs = std::cos(x0), sn = std::sin(x0);
      double a[12];
      double f = 1.0;  // h^m / m!
      for (int j = 0; j < 12; ++j) {
        const double d = (j % 4 == 0) ? cs : (j % 4 == 1) ? -sn : (j % 4 == 2) ? -cs : sn;
        a[j] = d * f;
        f *= h_ / (j + 1);
      }
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 12; ++j) q[i + j] += c[i] * a[j] * h_;
      deg = 14;
    }
    double P[17];  // ∫_0^t q
    P[0] = 0.0;
    for (int j = 0; j <= deg; ++j) P[j + 1] = q[j] / (j + 1);
    auto F = [&](double t) {
      double r = P[deg + 1];
      for (int j = deg; j >= 0; --j) r = r * t + P[j];
      return r;
    };
    auto D = [&](double t) {
      double r = q[deg];
      for (int j = deg - 1; j >= 0; --j) r = r * t + q[j];
      return r;
    };
    return newton_in_bracket(F, D, m, m / mass, 60);
  }

  const T* data_ = nullptr;
  int dims_ = 0;
  Measure measure_ = Measure::plain;
  PreparedAxis axes_[8];
  std::size_t stride_[8] = {};
  bool supported_ = false, even_ = false, cubic_ = false;
  int n_ = 0;
  double h_ = 0.0, lo_ = 0.0;
  std::vector<int> outer_;
  std::vector<double> moments_;
  bool mixture_ = false;
  std::size_t slices_ = 0;
  AxisData stored_;                  // the caller's sampling data, when given
  std::vector<double> cdf_, mass_;   // else computed here
  std::vector<float> bound_;
  std::vector<std::size_t> fix_begin_;  // prepare_fixes(): per slice, its entries in fix_cell_ and fix_rest_
  std::vector<int> fix_cell_;
  std::vector<double> fix_rest_;
};

}  // namespace sampler
}  // namespace hairlut

// The mixture path's definitions.
#include "hairlut/sampler/axis_mixture.hpp"
