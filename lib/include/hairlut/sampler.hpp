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

struct Axis {
  Spacing spacing = Spacing::uniform;
  Placement placement = Placement::edges;
  Wrap wrap = Wrap::clamp;
  double lo = 0.0;
  double hi = 1.0;
  int count = 1;
  const double* values = nullptr;  ///< the `count` nodes, for Spacing::explicit_values only
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

/// The two nodes around x and the interpolation weight, with the axis's wrap rule.
inline Lerp locate(const Axis& a, double x) {
  Lerp r;
  if (a.count <= 1 || !(x == x)) return r;  // a single node, or NaN: the first node
  const double pi = 3.14159265358979323846;
  if (a.wrap == Wrap::periodic) {
    const double period = a.hi - a.lo;
    double u = (x - a.lo) / period;
    u -= std::floor(u);  // [0, 1)
    double s = u * a.count - (a.placement == Placement::centers ? 0.5 : 0.0);
    const double nearest = std::floor(s + 0.5);
    if (std::fabs(s - nearest) < 1e-9) s = nearest;
    if (s < 0.0) s += a.count;
    if (s >= a.count) s -= a.count;
    double fi = std::floor(s);
    r.w = s - fi;
    r.i0 = static_cast<int>(fi) % a.count;
    r.i1 = (r.i0 + 1) % a.count;
    return r;
  }
  if (a.wrap == Wrap::even) x = std::fabs(std::remainder(x, 2.0 * pi));
  if (a.wrap == Wrap::reflect && a.hi > a.lo) x = a.lo + std::fabs(std::remainder(x - a.lo, 2.0 * (a.hi - a.lo)));
  x = std::max(a.lo, std::min(a.hi, x));
  double s;
  if (a.spacing == Spacing::explicit_values) {
    const double* v = a.values;
    if (x <= v[0]) return r;
    if (x >= v[a.count - 1]) {
      r.i0 = r.i1 = a.count - 1;
      return r;
    }
    const int hi = static_cast<int>(std::upper_bound(v, v + a.count, x) - v);
    r.i0 = hi - 1;
    r.i1 = hi;
    r.w = (x - v[r.i0]) / (v[r.i1] - v[r.i0]);
    return r;
  }
  const double t0 = mapped(a.spacing, a.lo), t1 = mapped(a.spacing, a.hi);
  const double u = (mapped(a.spacing, x) - t0) / (t1 - t0);
  s = a.placement == Placement::centers ? u * a.count - 0.5 : u * (a.count - 1);
  // Snap to a node when within rounding of it, so that sampling at a node returns its value.
  const double nearest = std::floor(s + 0.5);
  if (std::fabs(s - nearest) < 1e-9) s = nearest;
  s = std::max(0.0, std::min(static_cast<double>(a.count - 1), s));
  int i0 = static_cast<int>(std::floor(s));
  if (i0 >= a.count - 1) i0 = a.count - 2;
  r.i0 = i0;
  r.i1 = i0 + 1;
  r.w = s - i0;
  return r;
}

/// Multilinear interpolation of a row-major table of `dims` axes at the point x[0 … dims−1].
/// T is float or double (or half, if it converts to float). dims ≤ 8.
template <class T>
double sample(const T* data, const Axis* axes, int dims, const double* x) {
  Lerp l[8];
  std::size_t stride[8];
  std::size_t s = 1;
  for (int d = dims - 1; d >= 0; --d) {
    l[d] = locate(axes[d], x[d]);
    stride[d] = s;
    s *= static_cast<std::size_t>(axes[d].count);
  }
  double sum = 0.0;
  for (int corner = 0; corner < (1 << dims); ++corner) {
    double w = 1.0;
    std::size_t offset = 0;
    for (int d = 0; d < dims; ++d) {
      const bool upper = (corner >> d) & 1;
      const double wd = upper ? l[d].w : 1.0 - l[d].w;
      if (wd == 0.0) { w = 0.0; break; }
      w *= wd;
      offset += static_cast<std::size_t>(upper ? l[d].i1 : l[d].i0) * stride[d];
    }
    if (w != 0.0) sum += w * static_cast<double>(data[offset]);
  }
  return sum;
}

}  // namespace sampler
}  // namespace hairlut
