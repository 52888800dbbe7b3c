// hairlut sampler: multilinear lookup in hairlut tables.
//
// Header-only and dependency-free (C++17 standard library only): an engine may copy this one
// file. It reproduces exactly how hairlut places table nodes, so sampling at a node returns the
// stored value and sampling between nodes interpolates linearly in each axis's mapped coordinate.
//
// Axis model (the same in the files' metadata, see schemas/hairlut-tables.schema.json):
//   - An axis covers [lo, hi] with `count` nodes.
//   - `spacing` names the mapping t(x) in which the nodes are evenly spaced:
//       uniform t = x,  cos t = cos x,  sin t = sin x,  log t = ln x,  sqrt t = √x,
//       explicit: the nodes are listed (strictly increasing) and interpolation is linear in x.
//   - `placement`: edges puts the first and last node on lo and hi, u_i = i/(count − 1);
//       centers puts node i at the centre of cell i, u_i = (i + ½)/count (texture convention);
//       node x_i = t⁻¹(t(lo) + u_i (t(hi) − t(lo))).
//   - `wrap`: clamp (x is clamped to the outermost nodes), periodic (period hi − lo; uniform
//       spacing; edges places count nodes at lo + i (hi − lo)/count), even (x is an azimuth of
//       an even function: it is wrapped to [−π, π], folded to |x|, then clamped), or reflect (x is
//       folded into [lo, hi] by reflection: the function is even about lo and periodic with
//       period 2 (hi − lo), e.g. the azimuthal half angle φh over [0, π/2] of a function of cos 2φh).
//   - `interpolation` along the axis, in the mapped coordinate t (in the node index for explicit
//       axes): linear (two nodes); cubic (Catmull–Rom through four nodes: exact at the nodes,
//       continuous slope, exact for quadratics; beyond a clamped end the missing node is the
//       quadratic extrapolation 3v₀ − 3v₁ + v₂, across an even or reflect end it is the mirror
//       node (but not on a cos-spaced axis: cos x is even about 0 and π, so there the end is a
//       clamped one), across a periodic end the wrapped one); or geometric (two nodes combined as
//       v₀^(1−w) v₁^w, i.e. linear in log v, for quantities that fall exponentially along the
//       axis such as N_p along σa; linear where either value is ≤ 0). A table has at most one
//       geometric axis; it is combined last, after the tensor product over the other axes.
//   - `lo_end` (absent: extrapolate): mirror makes the lower end a mirror end for cubic
//       interpolation, as across an even end: the missing node beyond lo is the mirror node
//       (about node 0 for edges, about lo for centers) instead of the quadratic extrapolation.
//       For a sqrt axis starting at 0, e.g. σa: f(σa) = f(t²) is even in t = √σa, so the mirror
//       node is exact, and a cubic reconstruction has slope 0 in t at σa = 0 as f has.
//   - Data are stored row-major: the last axis varies fastest.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace hairlut {
namespace sampler {

enum class Spacing : int { uniform = 0, cos = 1, sin = 2, log = 3, sqrt = 4, explicit_values = 5 };
enum class Placement : int { edges = 0, centers = 1 };
enum class Wrap : int { clamp = 0, periodic = 1, even = 2, reflect = 3 };
enum class Interpolation : int { linear = 0, cubic = 1, geometric = 2 };
/// The rule for a cubic tap beyond the lower end of a clamped axis.
enum class End : int { extrapolate = 0, mirror = 1 };

struct Axis {
  Spacing spacing = Spacing::uniform;
  Placement placement = Placement::edges;
  Wrap wrap = Wrap::clamp;
  double lo = 0.0;
  double hi = 1.0;
  int count = 1;
  const double* values = nullptr;  ///< the `count` nodes, for Spacing::explicit_values only
  Interpolation interpolation = Interpolation::linear;
  End lo_end = End::extrapolate;  ///< mirror: the node beyond lo is the mirror node (sqrt axes from 0)
};

/// Two neighbouring nodes and the weight of the second: value = (1 − w) v[i0] + w v[i1].
struct Lerp {
  int i0 = 0;
  int i1 = 0;
  double w = 0.0;
};

/// t(x), the coordinate in which the nodes are evenly spaced.
inline double mapped(Spacing s, double x) {
  switch (s) {
    case Spacing::cos: return std::cos(x);
    case Spacing::sin: return std::sin(x);
    case Spacing::log: return std::log(x);
    case Spacing::sqrt: return std::sqrt(x);
    default: return x;
  }
}

/// x = t⁻¹(t), the inverse of mapped() on the axis's range.
inline double unmapped(Spacing s, double t) {
  switch (s) {
    case Spacing::cos: return std::acos(std::max(-1.0, std::min(1.0, t)));
    case Spacing::sin: return std::asin(std::max(-1.0, std::min(1.0, t)));
    case Spacing::log: return std::exp(t);
    case Spacing::sqrt: return t * t;
    default: return t;
  }
}

/// Normalized position u in [0, 1] of node i (before mapping back to x).
inline double node_u(const Axis& a, int i) {
  if (a.wrap == Wrap::periodic)
    return (a.placement == Placement::centers ? i + 0.5 : static_cast<double>(i)) / a.count;
  if (a.placement == Placement::centers) return (i + 0.5) / a.count;
  return a.count > 1 ? static_cast<double>(i) / (a.count - 1) : 0.0;
}

/// Coordinate x of node i. End nodes of edge-placed axes are exactly lo and hi.
inline double node(const Axis& a, int i) {
  if (a.spacing == Spacing::explicit_values) return a.values[i];
  if (a.placement == Placement::edges && a.wrap != Wrap::periodic) {
    if (i == 0) return a.lo;
    if (i == a.count - 1) return a.hi;
  }
  const double t0 = mapped(a.spacing, a.lo), t1 = mapped(a.spacing, a.hi);
  const double u = node_u(a, i);
  return unmapped(a.spacing, t0 + u * (t1 - t0));
}

/// An axis prepared for repeated lookups: the mapped ends of its range and the scale from the
/// mapped coordinate to the node index are computed once, not per lookup.
struct PreparedAxis {
  Axis axis;
  double t0 = 0.0;      ///< t(lo) (periodic: lo)
  double scale = 0.0;   ///< node-index units per unit of t (periodic: count / period)
  double offset = 0.0;  ///< −½ for centre-placed nodes, 0 for edge-placed ones

  PreparedAxis() = default;
  explicit PreparedAxis(const Axis& a) : axis(a) {
    if (a.spacing == Spacing::explicit_values || a.count <= 1) return;
    offset = a.placement == Placement::centers ? -0.5 : 0.0;
    if (a.wrap == Wrap::periodic) {
      t0 = a.lo;
      scale = a.count / (a.hi - a.lo);
      return;
    }
    t0 = mapped(a.spacing, a.lo);
    scale = (a.placement == Placement::centers ? a.count : a.count - 1) / (mapped(a.spacing, a.hi) - t0);
  }

  /// The two nodes around x and the interpolation weight, with the axis's wrap rule.
  Lerp locate(double x) const {
    Lerp r;
    const Axis& a = axis;
    if (a.count <= 1 || !(x == x)) return r;  // a single node, or NaN (sample() returns NaN first)
    const int n = a.count;
    if (a.wrap == Wrap::periodic) {
      double u = (x - t0) * scale / n;
      u -= std::floor(u);  // [0, 1)
      double s = u * n + offset;
      const double nearest = std::floor(s + 0.5);
      if (std::fabs(s - nearest) < 1e-9) s = nearest;
      if (s < 0.0) s += n;
      if (s >= n) s -= n;
      const double fi = std::floor(s);
      r.w = s - fi;
      r.i0 = static_cast<int>(fi) % n;
      r.i1 = (r.i0 + 1) % n;
      return r;
    }
    const double pi = 3.14159265358979323846;
    if (a.wrap == Wrap::even) x = std::fabs(std::remainder(x, 2.0 * pi));
    if (a.wrap == Wrap::reflect && a.hi > a.lo) x = a.lo + std::fabs(std::remainder(x - a.lo, 2.0 * (a.hi - a.lo)));
    x = std::max(a.lo, std::min(a.hi, x));
    if (a.spacing == Spacing::explicit_values) {
      const double* v = a.values;
      if (x <= v[0]) return r;
      if (x >= v[n - 1]) {
        r.i0 = r.i1 = n - 1;
        return r;
      }
      const int hi = static_cast<int>(std::upper_bound(v, v + n, x) - v);
      r.i0 = hi - 1;
      r.i1 = hi;
      r.w = (x - v[r.i0]) / (v[r.i1] - v[r.i0]);
      return r;
    }
    double s = (mapped(a.spacing, x) - t0) * scale + offset;
    // Snap to a node when within rounding of it, so that sampling at a node returns its value.
    const double nearest = std::floor(s + 0.5);
    if (std::fabs(s - nearest) < 1e-9) s = nearest;
    s = std::max(0.0, std::min(static_cast<double>(n - 1), s));
    int i0 = static_cast<int>(s);
    if (i0 >= n - 1) i0 = n - 2;
    r.i0 = i0;
    r.i1 = i0 + 1;
    r.w = s - i0;
    return r;
  }
};

/// The two nodes around x and the interpolation weight, with the axis's wrap rule.
inline Lerp locate(const Axis& a, double x) { return PreparedAxis(a).locate(x); }

/// The nodes and weights that interpolate along one axis at x: one (at a clamped end or a
/// single-node axis), two (linear, geometric) or four (cubic) taps.
struct Taps {
  int n = 1;
  int i[4] = {0, 0, 0, 0};
  double w[4] = {1.0, 0.0, 0.0, 0.0};
};

/// Index of node i of an axis after its wrap rule (−1 → the mirror or wrapped node), or −1 when
/// i lies beyond a clamped end.
inline int wrapped_index(const Axis& a, int i) {
  const int n = a.count;
  if (i >= 0 && i < n) return i;
  if (a.wrap == Wrap::periodic) return ((i % n) + n) % n;
  // Even azimuths are symmetric about 0 and π, reflect axes about both ends of their range:
  // mirror about the end node (edges) or the end of the range (centers).
  const double pi = 3.14159265358979323846;
  // A mirror lower end (lo_end) is mirrored the same way. A cos-spaced even axis is not: its
  // mapped coordinate t = cos x is itself even about 0 and π, so an even function is a smooth
  // function of t there, and t has no node beyond its end (the clamped extrapolation applies).
  const bool even_end = a.wrap == Wrap::even && a.spacing != Spacing::cos && (i < 0 ? a.lo == 0.0 : a.hi == pi);
  const bool mirror = a.wrap == Wrap::reflect || even_end || (i < 0 && a.lo_end == End::mirror);
  if (!mirror) return -1;
  const bool centers = a.placement == Placement::centers;
  if (i < 0) i = centers ? -1 - i : -i;
  if (i > n - 1) i = centers ? 2 * n - 1 - i : 2 * (n - 1) - i;
  return std::max(0, std::min(n - 1, i));
}

/// Catmull–Rom weights of nodes i0 − 1 … i0 + 2 at fraction t of the cell [i0, i0 + 1].
inline void catmull_rom_weights(double t, double* w) {
  const double t2 = t * t, t3 = t2 * t;
  w[0] = 0.5 * (-t3 + 2.0 * t2 - t);
  w[1] = 0.5 * (3.0 * t3 - 5.0 * t2 + 2.0);
  w[2] = 0.5 * (-3.0 * t3 + 4.0 * t2 + t);
  w[3] = 0.5 * (t3 - t2);
}

/// Catmull–Rom taps idx[0..3] with weights w[0..3], where a tap past a clamped end (not a mirror
/// lo_end) is marked idx < 0: it becomes the quadratic extrapolation v₋₁ = 3v₀ − 3v₁ + v₂ (and its
/// mirror at the far end), folded into the other three weights.
inline void fold_clamped_ends(int idx[4], double w[4]) {
  if (idx[0] < 0) {
    idx[0] = idx[1];
    const double g = w[0];
    w[0] = 0.0, w[1] += 3.0 * g, w[2] -= 3.0 * g, w[3] += g;
  }
  if (idx[3] < 0) {
    idx[3] = idx[2];
    const double g = w[3];
    w[3] = 0.0, w[2] += 3.0 * g, w[1] -= 3.0 * g, w[0] += g;
  }
}

/// The taps of axis a at x, with its interpolation and wrap rules.
inline Taps taps(const PreparedAxis& p, double x) {
  Taps r;
  const Axis& a = p.axis;
  const Lerp l = p.locate(x);
  r.i[0] = l.i0;
  if (l.w == 0.0 || l.i0 == l.i1) return r;
  if (a.interpolation != Interpolation::cubic || a.count < 3) {
    r.n = 2;
    r.i[1] = l.i1;
    r.w[0] = 1.0 - l.w;
    r.w[1] = l.w;
    return r;
  }
  r.n = 4;
  double w[4];
  catmull_rom_weights(l.w, w);
  int idx[4] = {l.i0 - 1, l.i0, l.i1, l.i1 + 1};
  if (a.wrap == Wrap::periodic) idx[2] = l.i0 + 1;  // l.i1 may already be wrapped
  for (int k = 0; k < 4; ++k) idx[k] = wrapped_index(a, idx[k]);
  fold_clamped_ends(idx, w);
  for (int k = 0; k < 4; ++k) r.i[k] = idx[k], r.w[k] = w[k];
  return r;
}

/// A row-major table of up to 8 axes prepared for lookups: the axis mappings and strides are
/// computed once. view(x) interpolates at the point x[0 … dims−1] with each axis's
/// interpolation (multilinear when every axis is linear). T is float or double (or half, if it
/// converts to float). A NaN coordinate gives NaN. The view points into `data` (not a copy).
template <class T>
class TableView {
 public:
  TableView() = default;
  TableView(const T* data, const Axis* axes, int dims) : data_(data), dims_(dims) {
    std::size_t s = 1;
    for (int d = dims - 1; d >= 0; --d) {
      axes_[d] = PreparedAxis(axes[d]);
      stride_[d] = s;
      s *= static_cast<std::size_t>(axes[d].count);
    }
  }
  int dims() const { return dims_; }
  const PreparedAxis& axis(int d) const { return axes_[d]; }

  double operator()(const double* x) const {
    Taps tp[8];
    int geometric = -1;
    for (int d = 0; d < dims_; ++d) {
      if (!(x[d] == x[d]) && axes_[d].axis.count > 1) return x[d];
      tp[d] = taps(axes_[d], x[d]);
      if (axes_[d].axis.interpolation == Interpolation::geometric && tp[d].n == 2) geometric = d;
    }
    if (geometric < 0) return product(tp, -1, 0);
    const double v0 = product(tp, geometric, 0), v1 = product(tp, geometric, 1), w = tp[geometric].w[1];
    if (v0 > 0.0 && v1 > 0.0) return std::exp((1.0 - w) * std::log(v0) + w * std::log(v1));
    return (1.0 - w) * v0 + w * v1;
  }

 private:
  // Tensor product of the taps over every axis but the geometric one g (held at its tap k).
  double product(const Taps* tp, int g, int k) const {
    int idx[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    double sum = 0.0;
    for (;;) {
      double w = 1.0;
      std::size_t offset = 0;
      for (int d = 0; d < dims_; ++d) {
        const int kd = d == g ? k : idx[d];
        if (d != g) w *= tp[d].w[kd];
        offset += static_cast<std::size_t>(tp[d].i[kd]) * stride_[d];
      }
      if (w != 0.0) sum += w * static_cast<double>(data_[offset]);
      int d = dims_ - 1;
      for (; d >= 0; --d) {
        if (d == g) continue;
        if (++idx[d] < tp[d].n) break;
        idx[d] = 0;
      }
      if (d < 0) break;
    }
    return sum;
  }

  const T* data_ = nullptr;
  int dims_ = 0;
  PreparedAxis axes_[8];
  std::size_t stride_[8] = {};
};

/// view(x) of a TableView built for one lookup (prefer a TableView for repeated lookups).
template <class T>
double sample(const T* data, const Axis* axes, int dims, const double* x) {
  return TableView<T>(data, axes, dims)(x);
}

}  // namespace sampler
}  // namespace hairlut
