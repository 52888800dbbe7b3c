// hairlut cell Bernstein bounds: a certificate that a table's interpolant is ≥ 0 over a whole cell.
//
// Header-only and dependency-free (C++17 standard library and sampler.hpp only). Along one axis,
// inside the cell between nodes i and i + 1, the interpolant (linear, or Catmull–Rom with
// sampler.hpp's end rules) is a polynomial of degree 1 or 3 in the cell's own coordinate t ∈ [0, 1]
// (the mapped coordinate, in which the nodes are evenly spaced), whose coefficients are linear in
// the node values. Written in the Bernstein basis, its coefficients are linear combinations of at
// most four node values (cell_basis); over a cell of several axes the interpolant is the tensor
// product, whose Bernstein coefficients are the products of the axes' combinations applied to the
// node values (apply_along, one axis at a time). A polynomial lies in the convex hull of its
// Bernstein coefficients, so when all of them are ≥ 0 the interpolant is ≥ 0 over the whole cell:
// exact as a certificate (never wrong where it says yes), conservative (it may say no where the
// interpolant stays ≥ 0, near a steep fall).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <unordered_map>
#include <vector>

#include "hairlut/sampler/sampler.hpp"

namespace hairlut {
namespace sampler {

/// The number of cells of an axis: count − 1 between its nodes (count for a periodic axis, whose
/// last cell wraps to node 0; 1 for a single node).
inline int axis_cells(const Axis& a) {
  if (a.count <= 1) return 1;
  return a.wrap == Wrap::periodic ? a.count : a.count - 1;
}

/// The cell that a lookup at x interpolates in: locate()'s first node, the last cell beyond it.
inline int cell_of(const PreparedAxis& p, double x) {
  if (p.axis.count <= 1) return 0;
  const int i0 = p.locate(x).i0;
  const int cells = axis_cells(p.axis);
  return i0 < 0 ? 0 : (i0 >= cells ? cells - 1 : i0);
}

/// The taps of axis p at fraction t ∈ [0, 1] of cell i0: what taps() gives for an x that locate()
/// places there (the same weights and end rules, written for a given cell instead of a given x).
inline Taps cell_taps(const PreparedAxis& p, int i0, double t) {
  Taps r;
  const Axis& a = p.axis;
  r.i[0] = i0;
  if (a.count <= 1 || t == 0.0) return r;
  const int i1 = a.wrap == Wrap::periodic ? (i0 + 1) % a.count : i0 + 1;
  if (a.interpolation != Interpolation::cubic || a.count < 3) {
    r.n = 2;
    r.i[1] = i1;
    r.w[0] = 1.0 - t;
    r.w[1] = t;
    return r;
  }
  r.n = 4;
  double w[4];
  catmull_rom_weights(t, w);
  int idx[4] = {i0 - 1, i0, i0 + 1, i0 + 2};
  for (int k = 0; k < 4; ++k) idx[k] = wrapped_index(a, idx[k]);
  fold_clamped_ends(idx, w);
  for (int k = 0; k < 4; ++k) r.i[k] = idx[k], r.w[k] = w[k];
  return r;
}

/// The Bernstein coefficients of an axis's interpolant over one cell as combinations of node
/// values: coefficient m = Σ_j coef[m][j] v[node[j]], m < degree + 1 (1 for a single node, 2 for
/// linear, 4 for Catmull–Rom).
struct CellBasis {
  int nodes = 0;
  int node[4] = {0, 0, 0, 0};
  int terms = 1;  ///< degree + 1
  double coef[4][4] = {};
};

/// The cell's interpolant evaluated at t = 0, 1/3, 2/3, 1 (or 0, 1), turned into Bernstein form.
inline CellBasis cell_basis(const PreparedAxis& p, int cell) {
  CellBasis b;
  const Axis& a = p.axis;
  b.terms = a.count <= 1 ? 1 : (a.interpolation == Interpolation::cubic && a.count >= 3 ? 4 : 2);
  double value[4][4] = {};  // value[point][node slot]
  for (int q = 0; q < b.terms; ++q) {
    const double t = b.terms == 1 ? 0.0 : static_cast<double>(q) / (b.terms - 1);
    const Taps tp = cell_taps(p, cell, t);
    for (int k = 0; k < tp.n; ++k) {
      if (tp.w[k] == 0.0) continue;
      int slot = 0;
      while (slot < b.nodes && b.node[slot] != tp.i[k]) ++slot;
      if (slot == b.nodes) b.node[b.nodes++] = tp.i[k];
      value[q][slot] += tp.w[k];
    }
  }
  for (int j = 0; j < b.nodes; ++j) {
    if (b.terms < 4) {
      for (int m = 0; m < b.terms; ++m) b.coef[m][j] = value[m][j];
      continue;
    }
    // Values f0..f3 at t = 0, 1/3, 2/3, 1 of a cubic with Bernstein coefficients b0..b3:
    // f1 = (8 b0 + 12 b1 + 6 b2 + b3)/27, f2 = (b0 + 6 b1 + 12 b2 + 8 b3)/27.
    const double f0 = value[0][j], f1 = value[1][j], f2 = value[2][j], f3 = value[3][j];
    const double A = 27.0 * f1 - 8.0 * f0 - f3, B = 27.0 * f2 - f0 - 8.0 * f3;
    b.coef[0][j] = f0;
    b.coef[1][j] = (2.0 * A - B) / 18.0;
    b.coef[2][j] = (2.0 * B - A) / 18.0;
    b.coef[3][j] = f3;
  }
  return b;
}

/// Applies a cell basis along axis d of a row-major tensor of shape sh[0 … dims − 1] (the node
/// slots of the basis along d): out has sh[d] replaced by b.terms. in and out must differ.
inline void apply_along(const double* in, double* out, const int* sh, int dims, int d, const CellBasis& b) {
  std::size_t outer = 1, inner = 1;
  for (int e = 0; e < d; ++e) outer *= static_cast<std::size_t>(sh[e]);
  for (int e = d + 1; e < dims; ++e) inner *= static_cast<std::size_t>(sh[e]);
  const std::size_t n_in = static_cast<std::size_t>(sh[d]), n_out = static_cast<std::size_t>(b.terms);
  for (std::size_t o = 0; o < outer; ++o)
    for (std::size_t m = 0; m < n_out; ++m) {
      double* dst = out + (o * n_out + m) * inner;
      for (std::size_t i = 0; i < inner; ++i) dst[i] = 0.0;
      for (std::size_t j = 0; j < n_in; ++j) {
        const double c = b.coef[m][j];
        if (c == 0.0) continue;
        const double* src = in + (o * n_in + j) * inner;
        for (std::size_t i = 0; i < inner; ++i) dst[i] += c * src[i];
      }
    }
}

/// The Bernstein coefficients of a cubic c0 + c1 t + c2 t² + c3 t³ on [0, 1].
inline void bernstein_of_cubic(const double* c, double* b) {
  b[0] = c[0];
  b[1] = c[0] + c[1] / 3.0;
  b[2] = c[0] + (2.0 * c[1] + c[2]) / 3.0;
  b[3] = c[0] + c[1] + c[2] + c[3];
}

/// Runs body(i) for i in [0, n) in order, on the calling thread: the default way clamp_bounds and
/// AxisSampler::build_data run their independent blocks. A caller may pass any callable of the same
/// form that runs the blocks on several threads instead (each block writes only its own entries,
/// so the results do not depend on how the blocks are scheduled).
struct SerialBlocks {
  template <class Body>
  void operator()(std::size_t n, Body&& body) const {
    for (std::size_t i = 0; i < n; ++i) body(i);
  }
};

/// The clamp bounds (AxisData::clamp_bound) of a table of `dims` axes, the last sampled with n
/// nodes of spacing h: row_of(s, out) writes node slice s's sampled cells in Bernstein form (n − 1
/// cells of 4). For every cell of the other axes (at its first node's slice `first`) and every
/// sampled cell k, max(0, −least tensor Bernstein coefficient) · h rounded up to float, the n − 1
/// of them handed together to sink(first, bounds): the interpolant is ≥ that least coefficient
/// over the two cells, so max(0, ·) adds at most this to the sampled cell's integral anywhere in
/// the cell of the other axes (cos x ≤ 1 included). The slices that start no cell (an axis's last
/// node) get none. The cells of the other axes go in blocks through run_blocks(count, body)
/// (SerialBlocks: in order on this thread); each slice reaches the sink once, from one block.
/// Rows are made by the block whose cells gather them, not held for the whole table: a table's
/// Bernstein rows would take eight times its float values.
template <class RowOf, class Sink, class RunBlocks = SerialBlocks>
inline void clamp_bounds(RowOf&& row_of, const PreparedAxis* axes, const std::size_t* stride, int dims, int n_nodes, double h, Sink&& sink,
                         RunBlocks&& run_blocks = RunBlocks()) {
  const std::size_t n = static_cast<std::size_t>(n_nodes), cells = n - 1, row = cells * 4;
  const int od = dims - 1;
  std::vector<std::vector<CellBasis>> basis(static_cast<std::size_t>(od));
  std::size_t total = 1;  // cells of the other axes
  for (int d = 0; d < od; ++d) {
    for (int c = 0; c < axis_cells(axes[d].axis); ++c) basis[static_cast<std::size_t>(d)].push_back(cell_basis(axes[d], c));
    total *= basis[static_cast<std::size_t>(d)].size();
  }
  if (total == 0) return;
  // At most 64 blocks of consecutive cells, so that each block's scratch serves many cells; its
  // cache holds the rows its cells gather (neighbouring cells gather mostly the same slices: of a
  // cubic 3-axis box's 64 rows, the next cell along the last axis shares 48), emptied when full.
  const std::size_t blocks = std::min<std::size_t>(total, 64);
  constexpr std::size_t kCachedRows = 256;
  run_blocks(blocks, [&](std::size_t block) {
    std::vector<double> a, b;
    std::vector<float> out(cells);
    std::unordered_map<std::size_t, std::size_t> made;  // slice → offset in rows
    std::vector<double> rows;
    rows.reserve(kCachedRows * row);
    for (std::size_t cell = total * block / blocks; cell < total * (block + 1) / blocks; ++cell) {
      // The cell's multi-index over the other axes (row-major, the last fastest).
      int idx[8] = {0, 0, 0, 0, 0, 0, 0, 0};
      for (std::size_t rest = cell, d = static_cast<std::size_t>(od); d-- > 0;) {
        const std::size_t c = basis[d].size();
        idx[d] = static_cast<int>(rest % c);
        rest /= c;
      }
      int shape[9];
      std::size_t gathered = 1, first = 0;
      for (int d = 0; d < od; ++d) {
        const CellBasis& cb = basis[static_cast<std::size_t>(d)][static_cast<std::size_t>(idx[d])];
        shape[d] = cb.nodes;
        gathered *= static_cast<std::size_t>(cb.nodes);
        first += static_cast<std::size_t>(idx[d]) * (stride[d] / n);
      }
      // Gather the Bernstein rows of the slices the cell's bases combine, every sampled cell's
      // four coefficients together (the last dimension: cells × 4), then apply the bases along the
      // other axes for all sampled cells at once: each result is the same sum, in the same order,
      // as one sampled cell at a time would give.
      shape[od] = static_cast<int>(row);
      a.resize(gathered * row);
      if (made.size() + gathered > kCachedRows) made.clear(), rows.clear();
      int j[8] = {0, 0, 0, 0, 0, 0, 0, 0};
      for (std::size_t g = 0; g < gathered; ++g) {
        std::size_t s = 0;
        for (int d = 0; d < od; ++d)
          s += static_cast<std::size_t>(basis[static_cast<std::size_t>(d)][static_cast<std::size_t>(idx[d])].node[j[d]]) * (stride[d] / n);
        auto [it, fresh] = made.emplace(s, rows.size());
        if (fresh) {
          rows.resize(rows.size() + row);
          row_of(s, rows.data() + it->second);
        }
        std::copy(rows.begin() + static_cast<std::ptrdiff_t>(it->second), rows.begin() + static_cast<std::ptrdiff_t>(it->second + row),
                  a.begin() + static_cast<std::ptrdiff_t>(g * row));
        for (int d = od - 1; d >= 0; --d) {
          if (++j[d] < shape[d]) break;
          j[d] = 0;
        }
      }
      int sh[9];
      for (int d = 0; d <= od; ++d) sh[d] = shape[d];
      std::size_t terms = 1;
      for (int d = 0; d < od; ++d) {
        const CellBasis& cb = basis[static_cast<std::size_t>(d)][static_cast<std::size_t>(idx[d])];
        std::size_t size = 1;
        for (int e = 0; e <= od; ++e) size *= static_cast<std::size_t>(e == d ? cb.terms : sh[e]);
        b.resize(size);
        apply_along(a.data(), b.data(), sh, od + 1, d, cb);
        sh[d] = cb.terms;
        terms *= static_cast<std::size_t>(cb.terms);
        a.swap(b);
      }
      // Per sampled cell k: the interpolant is ≥ the least coefficient over the box, so the clamp
      // adds at most its negative part times the cell's width (cos x ≤ 1); rounded up to float.
      // Infinite when a coefficient is NaN.
      for (std::size_t k = 0; k < cells; ++k) {
        double least = 0.0;
        for (std::size_t o = 0; o < terms; ++o)
          for (std::size_t q = 0; q < 4; ++q) {
            const double v = a[o * row + k * 4 + q];
            least = v >= least ? least : (v == v ? v : -HUGE_VAL);
          }
        const double most = -least * h;
        float f = static_cast<float>(most);
        if (static_cast<double>(f) < most) f = std::nextafter(f, HUGE_VALF);
        out[k] = f;
      }
      sink(first, static_cast<const float*>(out.data()));
    }
  });
}

}  // namespace sampler
}  // namespace hairlut
