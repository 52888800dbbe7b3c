// hairlut sampler, fixed-dimension views: the lookups of sampler.hpp's TableView for tables of 1
// to 4 axes, compiled for their dimension and their axes' interpolations.
//
// Header-only and dependency-free (C++17 standard library only, with sampler.hpp,
// sampler_kernels.hpp and sampler_simd.hpp). Same axis model and the same reconstruction as
// TableView (see sampler.hpp): each axis's wrap, spacing and interpolation (linear, Catmull–Rom
// cubic, geometric combined last). What differs is cost:
//   - the axis mappings are prepared once (t(lo), the scale to node units, the strides); a lookup
//     evaluates one mapping per mapped axis (cos, sin, log or sqrt of the coordinate itself) and no
//     function of the range ends;
//   - the tensor product is a fixed loop nest chosen when the view is built (2 or 4 taps per axis),
//     reduced along the last (contiguous) axis first; no per-lookup loop over up to 8 axes;
//   - a table whose axes are all linear over mapped nodes (the common case) takes a shorter path,
//     inlined into the caller: per axis (unrolled) the fold and the mapping (scalar: log, sqrt,
//     cos or sin of the coordinate), then for all axes at once, in the lanes of one register
//     (detail::Vec4), the affine step to node units, the clamp to the nodes and the split into
//     cell and fraction, with one rarely taken branch for a snap to a node; then the 2^D values
//     combined as lerps (1 − w) a + w b, as pairs along the last axis that SSE2 combines in one
//     register (a scalar path does the same operations in the same order; the same value as the
//     weighted sum up to rounding). A periodic axis locates on its own (the step across its end);
//   - R is the arithmetic type: double (FixedView<T, D>) or float (FixedView<T, D, float>, which
//     maps, weights and sums in float).
// With R = double the result equals TableView's up to the order of the sums: a few ulps of
// Σ|weight · value| (tested on random points for every wrap, spacing and interpolation). With
// R = float the coordinates are mapped in float too: the position inside a cell carries a relative
// error of about count × 2⁻²⁴, so expect ~1e-6 of the values' scale, not double precision.
// A NaN coordinate gives NaN. The view points into the data (no copy); it is immutable after
// construction, so one view may serve any number of threads.
#pragma once

#include <cmath>
#include <cstddef>
#include <type_traits>
#include <utility>

#include "hairlut/sampler/sampler.hpp"
#include "hairlut/sampler/sampler_kernels.hpp"
#include "hairlut/sampler/sampler_simd.hpp"

namespace hairlut {
namespace sampler {

/// An axis prepared for FixedView: the constants of PreparedAxis in the arithmetic type R.
template <class R>
class FixedAxis {
 public:
  FixedAxis() = default;
  FixedAxis(const Axis& a, std::size_t stride) : stride_(stride), prepared_(a) {
    const PreparedAxis& p = prepared_;
    n_ = a.count;
    cubic_ = a.interpolation == Interpolation::cubic && a.count >= 3 && a.spacing != Spacing::explicit_values;
    t0_ = static_cast<R>(p.t0);
    scale_ = static_cast<R>(p.scale);
    offset_ = static_cast<R>(p.offset);
    lo_ = static_cast<R>(a.lo);
    hi_ = static_cast<R>(a.hi);
    span_ = static_cast<R>(2.0 * (a.hi - a.lo));
    simple_ = a.spacing != Spacing::explicit_values && n_ > 1;
    wrap_ = a.wrap;
    spacing_ = a.spacing;
    top_ = static_cast<R>(n_ > 1 ? n_ - 1 : 0);
    step_ = n_ > 1 ? static_cast<std::ptrdiff_t>(stride) : 0;
    snap_ = sizeof(R) >= sizeof(double) ? static_cast<R>(1e-9) : static_cast<R>(8.0 * 1.1920928955078125e-07 * (n_ > 1 ? n_ : 1));
    unsnapped_ = R(0.5) - snap_;
    const bool clamped = a.wrap == Wrap::clamp && n_ > 1 && simple_;
    map_ = !clamped                         ? Map::other
           : a.spacing == Spacing::uniform  ? Map::plain
           : a.spacing == Spacing::log      ? Map::log
           : a.spacing == Spacing::sqrt     ? Map::sqrt
                                            : Map::other;
    fold_ = n_ <= 1                      ? Fold::single
            : a.wrap == Wrap::periodic   ? Fold::periodic
            : a.wrap == Wrap::even       ? Fold::even
            : a.wrap == Wrap::reflect && hi_ > lo_ ? Fold::reflect
                                         : Fold::none;
  }
  bool cubic() const { return cubic_; }
  /// Whether cell(x) applies: a mapped axis (not explicit nodes), or a single node.
  bool direct() const { return simple_ || n_ <= 1; }

  /// The cell of x for two-tap (linear) interpolation, as offsets: the first node's (i0 · stride)
  /// and the step to the second (stride; across a periodic end, back to node 0; 0 for a single
  /// node), and the weight w of the second. For direct() axes; x not NaN.
  HAIRLUT_SAMPLER_INLINE void cell(R x, std::size_t& off, std::ptrdiff_t& step, R& w) const {
    int i0;
    const bool wrapped = locate(x, i0, w);
    off = static_cast<std::size_t>(i0) * stride_;
    step = wrapped ? -static_cast<std::ptrdiff_t>(i0) * static_cast<std::ptrdiff_t>(stride_) : step_;
  }
  bool geometric() const { return prepared_.axis.interpolation == Interpolation::geometric; }
  /// Whether locate(x) is s = (x − t0()) · scale() + offset() clamped to [0, top()], then the
  /// integer part and the fraction f, with snapping where |f − ½| > unsnapped(): a uniform axis
  /// of at least 2 nodes that clamps, or an even one for x ∈ [0, π] (what an evaluator that
  /// locates several axes at once in registers relies on, sampler_fiber.hpp).
  bool uniform_affine() const { return simple_ && spacing_ == Spacing::uniform && (fold_ == Fold::none || fold_ == Fold::even); }
  bool even() const { return fold_ == Fold::even; }
  R t0() const { return t0_; }
  R scale() const { return scale_; }
  R offset() const { return offset_; }
  R top() const { return top_; }
  R unsnapped() const { return unsnapped_; }
  std::size_t stride() const { return stride_; }
  int count() const { return n_; }
  const Axis& axis() const { return prepared_.axis; }

  /// The continuous node index s and the cell [i0, i0 + 1] that holds it, with the wrap rule
  /// (PreparedAxis::locate, in R). Not for explicit axes (locate_explicit) nor NaN. Returns
  /// whether the cell crosses a periodic end (i0 = count − 1, its second node 0).
  HAIRLUT_SAMPLER_INLINE bool locate(R x, int& i0, R& w) const {
    if (fold_ > Fold::reflect) {  // periodic, or a single node
      if (fold_ == Fold::single) {
        i0 = 0, w = R(0);
        return false;
      }
      locate_periodic(x, i0, w);
      return i0 == n_ - 1;
    }
    R s = (mapped(x) - t0_) * scale_ + offset_;
    // Clamp to the nodes, upper bound first: a NaN s (an infinite azimuth folded) goes to the
    // last node, as TableView's clamp of x sends it to hi.
    s = s < top_ ? s : top_;
    s = s > R(0) ? s : R(0);
    int i = static_cast<int>(s);
    R f = s - static_cast<R>(i);
    // Within snap of a node (|f − ½| > ½ − snap, i.e. f < snap or 1 − f < snap): snap to it, so
    // that sampling at a node returns its value; then the last node is the end of the last
    // cell. The same decisions as TableView's snap-then-clamp (the bounds are nodes; s − i is
    // exact). One branch, rarely taken and predicted.
    if (std::fabs(f - R(0.5)) > unsnapped_) snap(i, f);
    i0 = i;
    w = f;
    return false;
  }
  /// The snapping of locate for a cell [i, i + 1] and fraction f within snap of a node.
  HAIRLUT_SAMPLER_INLINE void snap(int& i, R& f) const {
    if (f > R(0.5)) ++i;
    f = R(0);
    if (i >= n_ - 1) i = n_ - 2, f = R(1);
  }
  /// Whether mapped() and the affine step locate x (every fold but periodic; not a single node).
  bool affine() const { return simple_ && fold_ != Fold::periodic && fold_ != Fold::single; }
  /// x folded (even, reflect), then on a mapped axis clamped to the range and mapped (log, sqrt,
  /// cos, sin): the coordinate t whose node index is s = (t − t0()) · scale() + offset(). For
  /// affine() axes.
  HAIRLUT_SAMPLER_INLINE R mapped(R x) const {
    // The commonest axes first, one test each: uniform and clamped; log or sqrt and clamped. log
    // and sqrt increase on (0, ∞): beyond hi, s lands beyond the last node and is clamped there as
    // clamping x first would put it (up to rounding, which the snap absorbs); below lo they need x
    // clamped (log, sqrt of 0 or less).
    if (map_ == Map::plain) return x;
    if (map_ == Map::log) return ln(x < lo_ ? lo_ : x);
    if (map_ == Map::sqrt) return std::sqrt(x < lo_ ? lo_ : x);
    if (fold_ != Fold::none) {
      if (fold_ == Fold::even) {
        // |x| ≤ π is what remainder(x, 2π) leaves unchanged (ties round to the even quotient 0).
        const R pi = static_cast<R>(3.14159265358979323846);
        x = std::fabs(x);
        if (x > pi) x = std::fabs(std::remainder(x, R(2) * pi));
      } else {  // reflect
        const R d = x - lo_;
        if (!(d >= R(0) && d <= hi_ - lo_)) x = lo_ + std::fabs(std::remainder(d, span_));
      }
    }
    // A uniform axis needs no clamp of x: s is clamped after the affine step, and s(lo) = 0,
    // s(hi) = top up to rounding, which the snapping and the end rule absorb. A mapped one
    // clamps x first (the mappings are monotonic only on the range; log and sqrt need it positive).
    if (spacing_ == Spacing::uniform) return x;
    x = x < lo_ ? lo_ : x;
    if (spacing_ == Spacing::log) return ln(x);
    if (spacing_ == Spacing::sqrt) return std::sqrt(x);
    x = x > hi_ ? hi_ : x;
    switch (spacing_) {
      case Spacing::cos: return std::cos(x);
      case Spacing::sin: return std::sin(x);
      default: return x;
    }
  }

  /// ln x as TableView locates log axes: ln_positive() in double (the same bits, so that the
  /// views agree to the ulp), std::log in float.
  static HAIRLUT_SAMPLER_INLINE R ln(R x) {
    if constexpr (std::is_same_v<R, double>) return ln_positive(x);
    else return std::log(x);
  }

  /// The taps at x (NaN excluded by the caller).
  HAIRLUT_SAMPLER_INLINE FixedTaps<R> taps(R x) const {
    FixedTaps<R> r;  // NOLINT: filled below (the taps the axis uses)
    if (!simple_) {
      const Lerp l = prepared_.locate(static_cast<double>(x));
      set_linear(r, l.i0, l.i1, static_cast<R>(l.w));
      return r;
    }
    int i0;
    R w;
    locate(x, i0, w);
    const bool periodic = wrap_ == Wrap::periodic;
    if (!cubic_) {
      set_linear(r, i0, periodic ? (i0 + 1) % n_ : i0 + 1, w);
      return r;
    }
    catmull_rom(w, r.w);
    if (i0 >= 1 && i0 + 2 <= n_ - 1) {
      for (int k = 0; k < 4; ++k) r.off[k] = static_cast<std::size_t>(i0 - 1 + k) * stride_;
      return r;
    }
    end_taps(i0, r);
    return r;
  }

  /// Catmull–Rom weights of nodes i0 − 1 … i0 + 2 at fraction t (sampler.hpp's, in R).
  static void catmull_rom(R t, R* w) {
    const R t2 = t * t, t3 = t2 * t, h = R(0.5);
    w[0] = h * (-t3 + R(2) * t2 - t);
    w[1] = h * (R(3) * t3 - R(5) * t2 + R(2));
    w[2] = h * (R(-3) * t3 + R(4) * t2 + t);
    w[3] = h * (t3 - t2);
  }

 private:
  // The cubic taps of the cell [i0, i0 + 1] next to an end, weights r.w already Catmull–Rom's.
  void end_taps(int i0, FixedTaps<R>& r) const {
    const Axis& a = prepared_.axis;
    // Next to an end: the wrapped or mirrored node (an even or reflect end, a mirror lo_end), or
    // the quadratic extrapolation beyond a clamped end (sampler.hpp's taps()).
    int idx[4] = {i0 - 1, i0, i0 + 1, i0 + 2};
    for (int k = 0; k < 4; ++k) idx[k] = wrapped_index(a, idx[k]);
    if (idx[0] < 0) {
      idx[0] = idx[1];
      const R g = r.w[0];
      r.w[0] = R(0), r.w[1] += R(3) * g, r.w[2] -= R(3) * g, r.w[3] += g;
    }
    if (idx[3] < 0) {
      idx[3] = idx[2];
      const R g = r.w[3];
      r.w[3] = R(0), r.w[2] += R(3) * g, r.w[1] -= R(3) * g, r.w[0] += g;
    }
    for (int k = 0; k < 4; ++k) r.off[k] = static_cast<std::size_t>(idx[k]) * stride_;
  }
  HAIRLUT_SAMPLER_INLINE void locate_periodic(R x, int& i0, R& w) const {
    const int n = n_;
    R u = (x - t0_) * scale_ / static_cast<R>(n);
    u -= std::floor(u);
    R s = u * static_cast<R>(n) + offset_;
    const R nearest = std::floor(s + R(0.5));
    if (std::fabs(s - nearest) < snap()) s = nearest;
    if (s < R(0)) s += static_cast<R>(n);
    if (s >= static_cast<R>(n)) s -= static_cast<R>(n);
    const R fi = std::floor(s);
    w = s - fi;
    i0 = static_cast<int>(fi) % n;
  }
  // Snapping distance in node units: TableView's 1e-9 in double; in float, a few ulps of the
  // largest index (the rounding of the mapped coordinate itself).
  R snap() const { return snap_; }
  void set_linear(FixedTaps<R>& r, int i0, int i1, R w) const {
    r.off[0] = static_cast<std::size_t>(i0) * stride_;
    r.off[1] = static_cast<std::size_t>(i1) * stride_;
    r.w[0] = R(1) - w;
    r.w[1] = w;
  }

  // The fields a lookup reads first, together; then the prepared axis for the rare paths.
  // What locate does before mapping: nothing (clamp), fold (even, reflect), or another path.
  enum class Fold : unsigned char { none, even, reflect, periodic, single };
  R t0_ = R(0), scale_ = R(0), offset_ = R(0), lo_ = R(0), hi_ = R(1), top_ = R(0), span_ = R(2), snap_ = R(1e-9), unsnapped_ = R(0.5);
  std::size_t stride_ = 1;
  std::ptrdiff_t step_ = 0;
  int n_ = 1;
  Fold fold_ = Fold::single;
  Wrap wrap_ = Wrap::clamp;
  Spacing spacing_ = Spacing::uniform;
  bool cubic_ = false;
  bool simple_ = false;  // mapped spacing and at least 2 nodes
  // mapped()'s commonest cases (clamped, at least 2 nodes): uniform (x itself), log, sqrt.
  enum class Map : unsigned char { plain, log, sqrt, other };
  Map map_ = Map::other;
  PreparedAxis prepared_;
};

/// A row-major table of D axes (1 ≤ D ≤ 4) prepared for fast lookups: view(x) equals
/// TableView<T>(data, axes, D)(x) up to the order of the sums (see the file comment). T is the
/// stored type (float, double, or a type that converts to R), R the arithmetic type.
template <class T, int D, class R = double>
class FixedView {
  static_assert(D >= 1 && D <= 4, "FixedView covers 1 to 4 axes; TableView any number up to 8");

 public:
  FixedView() = default;
  /// axes[0 … D−1] in storage order (the last fastest); data holds Π count values.
  FixedView(const T* data, const Axis* axes) : data_(data) {
    std::size_t stride = 1;
    int mask = 0;
    for (int d = D - 1; d >= 0; --d) {
      axes_[d] = FixedAxis<R>(axes[d], stride);
      stride *= static_cast<std::size_t>(axes[d].count);
      if (axes_[d].cubic()) mask |= 1 << (D - 1 - d);
      if (axes_[d].geometric() && axes[d].count > 1) geometric_ = d;
    }
    kernel_ = detail::pick_kernel<T, R, D>(mask, std::make_index_sequence<(1 << D)>{});
    linear_ = mask == 0 && geometric_ < 0;
    for (int d = 0; d < D; ++d) linear_ = linear_ && axes_[d].direct();
    // The lanes path: every axis linear and affine() (not periodic, at least two nodes). Unused
    // lanes (D < 4) locate 0 at node 0 with fraction 0 and never snap.
    lanes_ = linear_ && D >= 2;
    R c[5][4] = {{R(0), R(0), R(0), R(0)}, {R(0), R(0), R(0), R(0)}, {R(0), R(0), R(0), R(0)}, {R(0), R(0), R(0), R(0)}, {R(1), R(1), R(1), R(1)}};
    for (int d = 0; d < D; ++d) {
      const FixedAxis<R>& a = axes_[d];
      lanes_ = lanes_ && a.affine();
      c[0][d] = a.t0(), c[1][d] = a.scale(), c[2][d] = a.offset(), c[3][d] = a.top(), c[4][d] = a.unsnapped();
      steps_[d] = static_cast<std::ptrdiff_t>(a.stride());
    }
    using V = detail::Vec4<R>;
    lane_t0_ = V::load(c[0]), lane_scale_ = V::load(c[1]), lane_offset_ = V::load(c[2]), lane_top_ = V::load(c[3]), lane_unsnapped_ = V::load(c[4]);
    std::size_t m[4] = {0, 0, 0, 0};
    for (int d = 0; d < D; ++d) m[d] = axes_[d].stride();
    lanes_ = lanes_ && detail::Strides4::fits(m);  // the offset multiplied in 32 × 32 → 64 bits
    lane_strides_ = detail::Strides4(m);
  }
  const FixedAxis<R>& axis(int d) const { return axes_[d]; }
  const T* data() const { return data_; }

  /// The interpolated value at x[0 … D−1]; NaN when a coordinate of an axis of 2 or more nodes is NaN.
  /// Inline: the common path (every axis linear over mapped nodes, no NaN) is a few dozen
  /// instructions, the call would be a fair part of it; the other paths are one call away.
  HAIRLUT_SAMPLER_INLINE R operator()(const R* x) const {
    // The cell's corner and steps, then 2^D values combined as nested lerps. One NaN test for
    // all coordinates (a sum of infinities of both signs takes the general path, which tells
    // them apart). The lanes path is tested first: one flag on the commonest path.
    if (lanes_) {
      return lanes_path(x, std::make_index_sequence<D>{});
    } else if (linear_ && no_nan(x)) {
      return lerp_path(x, std::make_index_sequence<D>{});
    }
    return general(x);
  }
  /// The same with the taps already computed (FixedAxis::taps), e.g. shared by tables on one grid.
  R combine(FixedTaps<R>* tp) const {
    if (geometric_ < 0) return kernel_(data_, tp);
    // The geometric axis is combined last: the products at its two nodes, then v₀^(1−w) v₁^w.
    FixedTaps<R>& g = tp[geometric_];
    const R w = g.w[1];
    if (w == R(0)) return kernel_(data_, tp);
    const std::size_t o1 = g.off[1];
    g.w[0] = R(1), g.w[1] = R(0);
    const R v0 = kernel_(data_, tp);
    g.off[0] = o1;
    const R v1 = kernel_(data_, tp);
    if (v0 > R(0) && v1 > R(0)) return std::exp((R(1) - w) * std::log(v0) + w * std::log(v1));
    return (R(1) - w) * v0 + w * v1;
  }

 private:
  // Whether x[0] + … + x[D − 1] is a number (no NaN, and no infinities of both signs).
  static HAIRLUT_SAMPLER_INLINE bool no_nan(const R* x) {
    R sum = x[0];
    for (int d = 1; d < D; ++d) sum += x[d];
    return sum == sum;
  }
  // Any axes, or a NaN coordinate: the taps of every axis, then the kernel for their counts.
  HAIRLUT_SAMPLER_NOINLINE R general(const R* x) const {
    FixedTaps<R> tp[D];
    for (int d = 0; d < D; ++d) {
      if (!(x[d] == x[d]) && axes_[d].count() > 1) return x[d];
      tp[d] = axes_[d].taps(x[d]);
    }
    return combine(tp);
  }
  // The nested-lerp path: every axis's cell (unrolled, so that each axis's branches are
  // predicted on their own), then the 2^D values.
  template <std::size_t... I>
  HAIRLUT_SAMPLER_INLINE R lerp_path(const R* x, std::index_sequence<I...>) const {
    std::size_t o[D];
    std::ptrdiff_t step[D];
    R w[D];
    (axes_[I].cell(x[I], o[I], step[I], w[I]), ...);
    return detail::lerp_cell<T, R, D>(data_ + (o[I] + ...), step, w);
  }

  // The nested-lerp path with the axes located together: each axis's mapped coordinate (its fold,
  // clamp and mapping, scalar), then the affine step, the clamp to the nodes and the split into
  // cell and fraction for all axes in one register (detail::Vec4: FixedAxis::locate's operations
  // in the same order, so the same cells and weights), the snap in a rarely taken branch, then
  // the 2^D values as lerp_path combines them.
  template <std::size_t... I>
  HAIRLUT_SAMPLER_INLINE R lanes_path(const R* x, std::index_sequence<I...>) const {
    using V = detail::Vec4<R>;
    // The lanes set from registers (a load of values just stored one by one would stall).
    const R t[4] = {axes_[I].mapped(x[I])...};
    const V tv = V::set(t[0], t[1], t[2], t[3]);
    // A NaN coordinate maps to NaN (every fold and mapping keeps it): the general path then.
    // Infinities need no test: the clamp to the nodes below takes them to the end nodes.
    if (V::unordered(tv)) return general(x);
    V s = (tv - lane_t0_) * lane_scale_ + lane_offset_;
    s = V::max(V::min(s, lane_top_), V::all(R(0)));  // upper bound first: a NaN s goes to the last node
    int i[4];
    std::size_t o;  // Σ i_d · stride_d, multiplied in registers (not through i, stored and reloaded)
    const V f = s.split_offset(i, lane_strides_, o);
    const bool snapping = V::greater((f - V::all(R(0.5))).abs(), lane_unsnapped_) != 0;  // within snap of a node, or at the last
#if HAIRLUT_SAMPLER_SSE2
    // Double in SSE2: the weights go from f's registers to the lerps as broadcasts (a store and
    // reloads would put store forwarding on the path from the coordinates to the result).
    if constexpr (D >= 2 && std::is_same_v<R, double> && (std::is_same_v<T, float> || std::is_same_v<T, double>)) {
      if (!snapping && steps_[D - 1] == 1) {
        const __m128d wb[D] = {f.template lane<static_cast<int>(I)>().lo...};
        return detail::lerp_cell_pd<T, D>(data_ + o, steps_, wb, _mm_cvtsd_f64(wb[D - 1]));
      }
    }
#endif
    alignas(16) R w[4];
    f.store(w);
    if (snapping) {
      ((std::fabs(w[I] - R(0.5)) > axes_[I].unsnapped() ? axes_[I].snap(i[I], w[I]) : void()), ...);
      o = lane_strides_.dot(i);
    }
    return detail::lerp_cell<T, R, D>(data_ + o, steps_, w);
  }

  const T* data_ = nullptr;
  FixedAxis<R> axes_[D];
  int geometric_ = -1;
  bool linear_ = false;  // every axis linear and direct(): the nested-lerp path
  bool lanes_ = false;   // and every axis affine(): the axes located together (lanes_path)
  std::ptrdiff_t steps_[D] = {};  // each axis's stride, the step to a cell's second node
  // Per lane (axis d; unused lanes 0, 0, 0, 0, 1): t0, scale, offset, top, unsnapped.
  detail::Vec4<R> lane_t0_{}, lane_scale_{}, lane_offset_{}, lane_top_{}, lane_unsnapped_{};
  detail::Strides4 lane_strides_;  // the strides again, as the lanes multiply them
  detail::FixedKernel<T, R, D> kernel_ = nullptr;
};

}  // namespace sampler
}  // namespace hairlut
