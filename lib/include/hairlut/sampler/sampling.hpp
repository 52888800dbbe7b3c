// hairlut sampling: importance sampling of the shading S = Σ_p M_p N_p from hairlut tables.
//
// Header-only and dependency-free (C++17 standard library, sampler.hpp and axis_sampling.hpp), like
// sampler.hpp: an engine may copy the three files.
//
// What is sampled is the function the sampler evaluates, not the physics behind it:
//   - the lobe p with probability proportional to its energy E_p(σa, θd) at θd = θi (the mirror
//     direction θr = −θi has |θd| = |θi|), or to ∫N_p dφ there when no energy table is given;
//   - θr in proportion to max(0, M̃_p(θi, θr)) cos θr, where M̃_p is the M_p table interpolated
//     as it declares (linear or Catmull–Rom along θr, blended over β and θi);
//   - φ in proportion to max(0, Ñ_p(φ)), the N_p table (or its shape N_p / E_p) interpolated at
//     (β, σa or channel, θd) with θd = (θr − θi)/2. A lobe without a φ axis (the residual) is
//     uniform in φ.
// The interpolation over every axis but the sampled (last) one is a weighted sum of node rows,
// so the density along the sampled axis is, cell by cell, the polynomial that the same weights
// give to the blended row: linear, or the Catmull–Rom cubic (with the clamped-end extrapolation
// and the mirror nodes of an even axis, exactly as sampler.hpp's taps()). The sampler clamps a
// negative interpolated value (Catmull–Rom overshoot, negative tap weights) at 0, and so do
// eval() and pdf() here: the density is max(0, polynomial), cut at its roots.
//
// Exact and approximate: cell masses of a plain density are closed-form polynomial integrals;
// with the cos θr measure they use an 8-point Gauss–Legendre rule per cell, exact for the cubic
// times the degree-11 Taylor polynomial of cos over the cell (the remainder is below 1e-14 for a
// cell of 20°, far below for the shipped axes). Roots of the cubic are found by bisection on its
// monotone pieces; the inverse CDF within a cell by Newton's method safeguarded by bisection, to
// rounding. So pdf() equals eval()'s lobe value divided by the normalisation that the same
// interpolant integrates to, up to rounding; sample() draws exactly from pdf().
//
// Two paths, both exact for the same density (axis_sampling.hpp): the mixture path reads the
// node slices' prefix integrals along the sampled axis (stored next to the tables, or computed when
// the sampler is prepared) and sums the 4–64 slices a lookup touches with their weights (of either
// sign): exact wherever the clamp at 0 does not act, which the stored clamp bounds tell per cell;
// the few cells where it may act are integrated under the clamp per lookup. Where too many would
// need that, the general path builds the blended row and cuts it per lookup as above. Which path a
// lookup takes changes which u gives which direction, never the density.
//
// Supported sampled axes: uniform spacing, edge placement, wrap clamp (θr) or even over [0, π]
// (φ). Axes before the sampled one may have any spacing, placement and wrap, and linear or cubic
// interpolation; a geometric axis there makes the density non-polynomial and is refused
// (supported() is false). hairlut's N_p tables (generic shape and per-material) and M_p tables
// satisfy this.
//
// Measures: pdf() is per unit solid angle, dω = cos θr dθr dφ (θ from the normal plane), the
// measure of the energy integral E(θi) = ∫ S dω; a renderer divides value by pdf directly.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "hairlut/sampler/axis_sampling.hpp"
#include "hairlut/sampler/sampler.hpp"

namespace hairlut {
namespace sampler {

/// What a table axis stands for, so that the hair sampler can fill its coordinate.
enum class Coordinate : int { none = 0, beta, sigma_a, channel, theta_d, theta_i, theta_r, phi };

/// The coordinate of a hairlut axis name ("beta", "sigma_a", "channel", "theta_d", "theta_i",
/// "theta_r", "phi"); Coordinate::none for any other.
inline Coordinate coordinate_named(const std::string& name) {
  static const char* const names[] = {"beta", "sigma_a", "channel", "theta_d", "theta_i", "theta_r", "phi"};
  for (int k = 0; k < 7; ++k)
    if (name == names[k]) return static_cast<Coordinate>(k + 1);
  return Coordinate::none;
}

/// One table as the hair sampler reads it: values, axes and what each axis stands for.
template <class T>
struct TableRef {
  const T* data = nullptr;  ///< null: no table
  const Axis* axes = nullptr;
  int dims = 0;
  Coordinate coords[8] = {};
};

/// The tables of one lobe.
template <class T>
struct LobeTables {
  TableRef<T> np;      ///< N_p (or its shape, with `factor`); last axis φ, or no φ axis (uniform in φ)
  TableRef<T> factor;  ///< the table np is multiplied by (np/energy_<lobe> of a shape table); optional
  TableRef<T> energy;  ///< the lobe's energy for lobe selection (may equal factor); optional
  TableRef<T> mp;      ///< M_p; last axis θr
  AxisData np_data;    ///< np's stored sampling data along φ (optional: computed when absent)
  AxisData mp_data;    ///< mp's stored sampling data along θr (optional)
};

/// The non-angular coordinates of a fibre: the table axes beta, sigma_a and channel read these.
struct FibreCoordinates {
  double beta = 0.0;
  double sigma_a = 0.0;
  double channel = 0.0;
};

/// A sampled direction: θr, φ = φr − φi, S(θi, θr, φ) (all lobes) and the pdf per unit solid
/// angle of the whole mixture. pdf == 0 when nothing could be sampled.
struct HairSample {
  double theta_r = 0.0, phi = 0.0, value = 0.0, pdf = 0.0;
  int lobe = -1;
};

/// S = Σ_p M_p N_p from hairlut tables: eval as an engine evaluates it, and sampling of exactly
/// that function lobe by lobe (see the top of this file). Prepared once, const afterwards.
template <class T>
class HairSampler {
 public:
  static constexpr int max_lobes = 8;
  /// Scratch rows for one thread; reuse one across calls to avoid allocations. It also keeps what
  /// depends only on the shading point (the fibre and θi): the lobe probabilities and each lobe's
  /// θr density (its mixture or blended row), reused while sample() and pdf() are called with the
  /// same fibre and θi on the same sampler, as a renderer does at one shading point.
  struct Workspace {
    AxisRow m, n;
    const void* owner = nullptr;  ///< the sampler the point below belongs to
    double key[4] = {0.0, 0.0, 0.0, 0.0};
    double prob[max_lobes] = {};
    bool mp_mixed[max_lobes] = {};
    typename AxisSampler<T>::Mix mp_mix[max_lobes];
    AxisRow mp_row[max_lobes];
  };

  HairSampler() = default;
  HairSampler(const LobeTables<T>* lobes, int count) : count_(std::min(count, max_lobes)) {
    supported_ = count > 0 && count <= max_lobes;
    for (int p = 0; p < count_; ++p) {
      Prepared& q = lobe_[p];
      q.t = lobes[p];
      const LobeTables<T>& l = lobes[p];
      if (!l.np.data || !l.mp.data || l.mp.coords[l.mp.dims - 1] != Coordinate::theta_r) supported_ = false;
      if (!l.np.data || !l.mp.data) continue;
      for (int d = 0; d + 1 < l.mp.dims; ++d)  // the θr density must depend on the shading point only
        if (l.mp.coords[d] == Coordinate::theta_d || l.mp.coords[d] == Coordinate::theta_r || l.mp.coords[d] == Coordinate::phi) supported_ = false;
      q.np = TableView<T>(l.np.data, l.np.axes, l.np.dims);
      q.mp = TableView<T>(l.mp.data, l.mp.axes, l.mp.dims);
      if (l.factor.data) q.factor = TableView<T>(l.factor.data, l.factor.axes, l.factor.dims);
      if (l.energy.data) q.energy = TableView<T>(l.energy.data, l.energy.axes, l.energy.dims);
      q.has_phi = l.np.coords[l.np.dims - 1] == Coordinate::phi;
      for (int d = 0; d + 1 < l.np.dims; ++d)
        if (l.np.coords[d] == Coordinate::phi) supported_ = false;
      q.mp_axis = AxisSampler<T>(l.mp.data, l.mp.axes, l.mp.dims, Measure::cosine, l.mp_data);
      if (!q.mp_axis.supported()) supported_ = false;
      if (q.has_phi) {
        q.np_axis = AxisSampler<T>(l.np.data, l.np.axes, l.np.dims, Measure::plain, l.np_data);
        if (!q.np_axis.supported()) supported_ = false;
      }
    }
  }

  /// False when a table lacks, or its sampled axis is not supported (see the top of this file).
  bool supported() const { return supported_; }
  int lobes() const { return count_; }

  /// M_p N_p of lobe p as an engine evaluates it: each table interpolated by sampler.hpp and
  /// clamped at 0, θd = (θr − θi)/2.
  double eval_lobe(int p, const FibreCoordinates& f, double theta_i, double theta_r, double phi) const {
    const Prepared& q = lobe_[p];
    double x[8];
    const double theta_d = 0.5 * (theta_r - theta_i);
    fill(q.t.mp, f, theta_i, theta_r, theta_d, phi, x);
    const double m = std::max(0.0, q.mp(x));
    if (!(m > 0.0)) return m;
    fill(q.t.np, f, theta_i, theta_r, theta_d, phi, x);
    double n = std::max(0.0, q.np(x));
    if (q.t.factor.data && n > 0.0) {
      fill(q.t.factor, f, theta_i, theta_r, theta_d, phi, x);
      n *= std::max(0.0, q.factor(x));
    }
    return m * n;
  }
  /// S(θi, θr, φ) = Σ_p M_p N_p.
  double eval(const FibreCoordinates& f, double theta_i, double theta_r, double phi) const {
    double s = 0.0;
    for (int p = 0; p < count_; ++p) s += eval_lobe(p, f, theta_i, theta_r, phi);
    return s;
  }

  /// The probability of choosing each lobe at θi (they sum to 1, or are all 0).
  void lobe_probabilities(const FibreCoordinates& f, double theta_i, double* prob, Workspace& ws) const {
    double sum = 0.0;
    for (int p = 0; p < count_; ++p) {
      const Prepared& q = lobe_[p];
      double x[8], w;
      if (q.t.energy.data) {
        fill(q.t.energy, f, theta_i, 0.0, theta_i, 0.0, x);
        w = std::max(0.0, q.energy(x));
      } else {
        if (q.has_phi) {
          fill(q.t.np, f, theta_i, 0.0, theta_i, 0.0, x);
          typename AxisSampler<T>::Mix mx;
          if (q.np_axis.mix(x, mx)) {
            w = mx.total;
          } else {
            q.np_axis.blend(x, ws.n);
            w = ws.n.total;
          }
        } else {
          fill(q.t.np, f, theta_i, 0.0, theta_i, 0.0, x);
          w = 2.0 * 3.14159265358979323846 * std::max(0.0, q.np(x));
        }
        if (q.t.factor.data) {
          fill(q.t.factor, f, theta_i, 0.0, theta_i, 0.0, x);
          w *= std::max(0.0, q.factor(x));
        }
      }
      prob[p] = w == w ? w : 0.0;
      sum += prob[p];
    }
    for (int p = 0; p < count_; ++p) prob[p] = sum > 0.0 ? prob[p] / sum : 0.0;
  }

  /// The pdf per unit solid angle of drawing (θr, φ) from lobe p alone:
  /// max(0, M̃_p)/∫max(0, M̃_p) cos θr dθr · max(0, Ñ_p)/∫max(0, Ñ_p) dφ.
  double pdf_lobe(int p, const FibreCoordinates& f, double theta_i, double theta_r, double phi, Workspace& ws) const {
    at_point(f, theta_i, ws);
    const double pm = mp_pdf(p, theta_r, ws);
    if (!(pm > 0.0)) return 0.0;
    const Prepared& q = lobe_[p];
    if (!q.has_phi) return pm / (2.0 * 3.14159265358979323846);
    double x[8];
    fill(q.t.np, f, theta_i, theta_r, 0.5 * (theta_r - theta_i), phi, x);
    typename AxisSampler<T>::Mix mx;
    if (q.np_axis.mix(x, mx)) return pm * q.np_axis.mix_value(mx, phi) / mx.total;
    q.np_axis.blend(x, ws.n);
    return pm * q.np_axis.pdf(ws.n, phi);
  }

  /// The pdf per unit solid angle of sample(): Σ_p P_p pdf_lobe(p).
  double pdf(const FibreCoordinates& f, double theta_i, double theta_r, double phi, Workspace& ws) const {
    at_point(f, theta_i, ws);
    double s = 0.0;
    for (int p = 0; p < count_; ++p)
      if (ws.prob[p] > 0.0) s += ws.prob[p] * pdf_lobe(p, f, theta_i, theta_r, phi, ws);
    return s;
  }

  /// Draws a direction from three uniform numbers in [0, 1): u0 chooses the lobe, u1 θr, u2 φ.
  HairSample sample(const FibreCoordinates& f, double theta_i, double u0, double u1, double u2, Workspace& ws) const {
    HairSample r;
    at_point(f, theta_i, ws);
    const double* prob = ws.prob;
    int p = -1;
    double acc = 0.0;
    for (int k = 0; k < count_; ++k) {
      if (!(prob[k] > 0.0)) continue;
      p = k;
      acc += prob[k];
      if (u0 < acc) break;
    }
    if (p < 0) return r;
    const Prepared& q = lobe_[p];
    double x[8];
    typename AxisSampler<T>::Mix mx;
    const double theta_r = ws.mp_mixed[p] ? q.mp_axis.sample_mix(ws.mp_mix[p], u1) : q.mp_axis.sample(ws.mp_row[p], u1);
    if (!(theta_r == theta_r)) return r;
    double phi = -3.14159265358979323846 + 2.0 * 3.14159265358979323846 * u2;
    if (q.has_phi) {
      fill(q.t.np, f, theta_i, theta_r, 0.5 * (theta_r - theta_i), 0.0, x);
      if (q.np_axis.mix(x, mx)) {
        phi = q.np_axis.sample_mix(mx, u2);
      } else {
        q.np_axis.blend(x, ws.n);
        phi = q.np_axis.sample(ws.n, u2);
      }
      if (!(phi == phi)) return r;
    }
    r.theta_r = theta_r;
    r.phi = phi;
    r.lobe = p;
    // Value and mixture pdf in one pass over the lobes (the lobe probabilities are those above).
    double value = 0.0, pdf_sum = 0.0;
    for (int k = 0; k < count_; ++k) {
      double v, pd;
      value_pdf_lobe(k, f, theta_i, theta_r, phi, prob[k] > 0.0, ws, v, pd);
      value += v;
      if (prob[k] > 0.0) pdf_sum += prob[k] * pd;
    }
    r.value = value;
    r.pdf = pdf_sum;
    return r;
  }

 private:
  // eval_lobe and (when with_pdf) pdf_lobe of lobe p at once: where the mixture fast path holds
  // the lookups that give M̃ and Ñ also give their normalisations; else as the two calls do.
  void value_pdf_lobe(int p, const FibreCoordinates& f, double theta_i, double theta_r, double phi, bool with_pdf, Workspace& ws, double& value,
                      double& pdf) const {
    const Prepared& q = lobe_[p];
    value = 0.0, pdf = 0.0;
    double x[8];
    const double theta_d = 0.5 * (theta_r - theta_i);
    typename AxisSampler<T>::Mix mx;
    // M̃_p and its normalisation from the shading point's θr density (at_point()).
    const double m = ws.mp_mixed[p] ? q.mp_axis.mix_value(ws.mp_mix[p], theta_r) : q.mp_axis.value(ws.mp_row[p], theta_r);
    const double pm = with_pdf ? mp_pdf(p, theta_r, ws) : 0.0;
    if (!(m > 0.0)) return;
    fill(q.t.np, f, theta_i, theta_r, theta_d, phi, x);
    double n, pn = 0.0;
    if (!q.has_phi) {
      n = std::max(0.0, q.np(x));
      pn = 1.0 / (2.0 * 3.14159265358979323846);
    } else if (q.np_axis.mix(x, mx)) {
      n = q.np_axis.mix_value(mx, phi);
      if (mx.total > 0.0) pn = n / mx.total;
    } else {
      n = std::max(0.0, q.np(x));
      if (with_pdf && pm > 0.0) {
        q.np_axis.blend(x, ws.n);
        pn = q.np_axis.pdf(ws.n, phi);
      }
    }
    pdf = pm * pn;
    if (q.t.factor.data && n > 0.0) {
      fill(q.t.factor, f, theta_i, theta_r, theta_d, phi, x);
      n *= std::max(0.0, q.factor(x));
    }
    value = m * n;
  }

  // Fills the workspace's shading-point part for (f, θi) unless it holds it already.
  void at_point(const FibreCoordinates& f, double theta_i, Workspace& ws) const {
    if (ws.owner == this && ws.key[0] == f.beta && ws.key[1] == f.sigma_a && ws.key[2] == f.channel && ws.key[3] == theta_i) return;
    ws.owner = nullptr;
    lobe_probabilities(f, theta_i, ws.prob, ws);
    for (int p = 0; p < count_; ++p) {
      const Prepared& q = lobe_[p];
      double x[8];
      fill(q.t.mp, f, theta_i, 0.0, 0.0, 0.0, x);
      ws.mp_mixed[p] = q.mp_axis.mix(x, ws.mp_mix[p]);
      if (!ws.mp_mixed[p]) q.mp_axis.blend(x, ws.mp_row[p]);
    }
    ws.owner = this;
    ws.key[0] = f.beta, ws.key[1] = f.sigma_a, ws.key[2] = f.channel, ws.key[3] = theta_i;
  }
  // max(0, M̃_p(θr)) / ∫ max(0, M̃_p) cos θr dθr at the workspace's shading point.
  double mp_pdf(int p, double theta_r, const Workspace& ws) const {
    const Prepared& q = lobe_[p];
    if (ws.mp_mixed[p]) return ws.mp_mix[p].total > 0.0 ? q.mp_axis.mix_value(ws.mp_mix[p], theta_r) / ws.mp_mix[p].total : 0.0;
    return ws.mp_row[p].total > 0.0 ? q.mp_axis.value(ws.mp_row[p], theta_r) / ws.mp_row[p].total : 0.0;
  }

  struct Prepared {
    LobeTables<T> t;
    TableView<T> np, factor, energy, mp;
    AxisSampler<T> np_axis, mp_axis;
    bool has_phi = false;
  };
  static void fill(const TableRef<T>& t, const FibreCoordinates& f, double theta_i, double theta_r, double theta_d, double phi, double* x) {
    for (int d = 0; d < t.dims; ++d) {
      switch (t.coords[d]) {
        case Coordinate::beta: x[d] = f.beta; break;
        case Coordinate::sigma_a: x[d] = f.sigma_a; break;
        case Coordinate::channel: x[d] = f.channel; break;
        case Coordinate::theta_d: x[d] = theta_d; break;
        case Coordinate::theta_i: x[d] = theta_i; break;
        case Coordinate::theta_r: x[d] = theta_r; break;
        case Coordinate::phi: x[d] = phi; break;
        default: x[d] = 0.0; break;
      }
    }
  }

  Prepared lobe_[max_lobes];
  int count_ = 0;
  bool supported_ = false;
};

/// A HairSampler for one fibre: its N_p and M_p tables blended over the fibre's own coordinates
/// (beta, sigma_a, channel) once, so that each lookup interpolates over the angles only (16×
/// fewer node rows per lookup for the generic tables). The values are those of the full tables
/// up to rounding: the same tensor product of the same taps, summed in another order. A table
/// whose fibre axes lead its angular ones and carry no geometric interpolation is reduced; any
/// other (the energies, geometric in σa) is kept whole, as a double copy. Build one per fibre
/// (strand, material), not per lookup; it owns its data.
template <class T>
class FibreSampler {
 public:
  FibreSampler(const LobeTables<T>* lobes, int count, const FibreCoordinates& fibre) : fibre_(fibre) {
    count = std::max(0, std::min(count, HairSampler<double>::max_lobes));
    for (int p = 0; p < count; ++p) {
      LobeTables<double>& l = lobes_[p];
      l.np = take(lobes[p].np);
      l.mp = take(lobes[p].mp);
      l.factor = take(lobes[p].factor);
      l.energy = take(lobes[p].energy);
    }
    sampler_ = HairSampler<double>(lobes_, count);
  }
  FibreSampler(const FibreSampler&) = delete;
  FibreSampler& operator=(const FibreSampler&) = delete;

  const HairSampler<double>& sampler() const { return sampler_; }
  /// The fibre it was built for: pass it to the sampler's calls.
  const FibreCoordinates& fibre() const { return fibre_; }

 private:
  static bool angular(Coordinate c) {
    return c == Coordinate::theta_d || c == Coordinate::theta_i || c == Coordinate::theta_r || c == Coordinate::phi;
  }
  TableRef<double> take(const TableRef<T>& t) {
    TableRef<double> r;
    if (!t.data || t.dims < 1 || t.dims > 8) return r;
    std::size_t total = 1;
    for (int d = 0; d < t.dims; ++d) total *= static_cast<std::size_t>(t.axes[d].count);
    int lead = 0;  // the leading fibre axes
    while (lead < t.dims && !angular(t.coords[lead])) ++lead;
    bool reducible = lead > 0 && lead < t.dims;
    for (int d = 0; d < t.dims; ++d) {
      if (d >= lead && !angular(t.coords[d])) reducible = false;
      if (d < lead && t.axes[d].interpolation == Interpolation::geometric && t.axes[d].count > 1) reducible = false;
    }
    std::vector<double>& out = data_[used_];
    std::vector<Axis>& axes = axes_[used_];
    ++used_;
    if (!reducible) {
      out.assign(t.data, t.data + total);
      axes.assign(t.axes, t.axes + t.dims);
      r.dims = t.dims;
      for (int d = 0; d < t.dims; ++d) r.coords[d] = t.coords[d];
    } else {
      std::size_t block = 1;
      for (int d = lead; d < t.dims; ++d) block *= static_cast<std::size_t>(t.axes[d].count);
      Taps tp[8];
      for (int d = 0; d < lead; ++d) {
        const Coordinate c = t.coords[d];
        const double x = c == Coordinate::beta ? fibre_.beta : c == Coordinate::sigma_a ? fibre_.sigma_a : c == Coordinate::channel ? fibre_.channel : 0.0;
        tp[d] = taps(PreparedAxis(t.axes[d]), x);
      }
      out.assign(block, 0.0);
      int idx[8] = {0, 0, 0, 0, 0, 0, 0, 0};
      for (;;) {
        double w = 1.0;
        std::size_t offset = 0;
        for (int d = 0; d < lead; ++d) {
          w *= tp[d].w[idx[d]];
          offset = offset * static_cast<std::size_t>(t.axes[d].count) + static_cast<std::size_t>(tp[d].i[idx[d]]);
        }
        if (w != 0.0) {
          const T* src = t.data + offset * block;
          for (std::size_t j = 0; j < block; ++j) out[j] += w * static_cast<double>(src[j]);
        }
        int d = lead - 1;
        for (; d >= 0; --d) {
          if (++idx[d] < tp[d].n) break;
          idx[d] = 0;
        }
        if (d < 0) break;
      }
      axes.assign(t.axes + lead, t.axes + t.dims);
      r.dims = t.dims - lead;
      for (int d = lead; d < t.dims; ++d) r.coords[d - lead] = t.coords[d];
    }
    r.data = out.data();
    r.axes = axes.data();
    return r;
  }

  FibreCoordinates fibre_;
  LobeTables<double> lobes_[HairSampler<double>::max_lobes];
  std::vector<double> data_[4 * HairSampler<double>::max_lobes];
  std::vector<Axis> axes_[4 * HairSampler<double>::max_lobes];
  int used_ = 0;
  HairSampler<double> sampler_;
};

}  // namespace sampler
}  // namespace hairlut
