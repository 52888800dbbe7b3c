// hairlut::sampler::PreparedScattering — what HairScattering runs for a set of any representation
// (tensor, β bands, Fourier) prepared at load for one roughness (β_m, β_n and a tilt), with σa
// free per fiber: S, its importance sampling and pdf at the cost of a few bilinear lookups, as
// MaterialScattering's for the tables of one material.
//
// Prepared once per roughness from the set's own lookups there (HairScattering::prepared):
//   - M_p(β_m; θi, θo) with the lobes' tilts, on uniform (θi, θr) nodes, linear;
//   - each explicit lobe's shape Ñ_p = N_p / E_p on (√σa, θd, φ) nodes (θd cos-spaced), linear in
//     all three, each (σa, θd) row scaled so that its linear interpolant has ∫ Ñ_p dφ = 1 over
//     [−π, π] (E_p = ∫ N_p dφ, the lobe's energy);
//   - ln E_p on (√σa, θd) nodes of a dense σa axis (the residual's E = 2π N_res), so that a
//     fiber's energies are geometric in σa between nodes, as the tables' energy axes are;
//   - step 1's rows (below) at a few σa, its row groups.
// Node counts follow from the roughness: a Gaussian of standard deviation s read linearly on
// step h errs at its peak by h²/(8s²) of it. Every N_p is its azimuthal detector, a Gaussian of
// standard deviation β_n, convolved with the rest, and every M_p is about as wide as β_m, so φ
// takes h = β_n √(8ε) and θi, θr take h = β_m √(8ε) (ε = PreparedGrid::error), within the
// grid's node bounds. θd is cos-spaced: N_p depends on θd through cos θd.
//
// Per fiber (PreparedFiber, built by fiber() in a few µs): each channel's E_p on the θd nodes and
// its σa's weights on the shape nodes and on the row groups. Per channel c
//   S_c = Σ_p M_p(θi, θo) E_p(σa_c, θd) Ñ_p(σa_c; θd, φ) + M_res(θi, θo) E_res(σa_c, θd) / 2π,
// E_p linear in θd between its nodes. Sampling follows MaterialScattering with the channels' mean
// Ē_p = (1/3) Σ_c E_p(σa_c, θd) in the place of its Z_p:
//   1. θi from q(θi) ∝ Σ_g a_g [(1 − w) G_{g,r}(θi) + w G_{g,r+1}(θi)], where r, w locate θo on
//      the θr nodes, G_{g,r} = Σ_p M_p(θi, θr_r) E_p(σ_g, θd) cos θi is row group g's density at
//      θr node r (quadratic on each θi cell or half cell, as MaterialScattering's rows), and the
//      a_g ≥ 0 are fitted per fiber so that Σ_g a_g E_p(σ_g, θd) is nearest its Ē_p(θd) in least
//      squares (fit_groups). Group 0 is σa = 0, so a white fiber reads its own energies; a
//      coloured fiber's q is the nearest mixture of the groups' densities, and pdf() is that
//      mixture's density;
//   2. the lobe q at θi in proportion to M_q(θi, θo) Ē_q(θd);
//   3. φ from Σ_c E_q(σa_c, θd) Ñ_q(σa_c; θd, φ), a mixture of stored rows (shape node, θd node)
//      with nonnegative weights, each row normalised; the residual uniformly.
// Every stage is exact for its density, so
//   pdf(θi, φ) = q(θi) / cos θi · S̄(θi, φ) / S̄_φ(θi),   S̄ = (1/3) Σ_c S_c,   S̄_φ = Σ_q M_q Ē_q,
// and a white fiber's weight S / pdf = S̄_φ cos θi / q(θi), the albedo at θo up to q's piecewise
// form.
//
// Header-only, C++17, no dependencies beyond sampler.hpp's axis definitions. The object owns
// everything it reads; a value that is negative, NaN or infinite reads as 0.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "hairlut/sampler/linear_rows.hpp"
#include "hairlut/sampler/sampler.hpp"

namespace hairlut {
namespace sampler {

/// How finely PreparedScattering resamples a set (see the top of this file).
struct PreparedGrid {
  double error = 5e-4;      ///< the peak error of a Gaussian of the lobes' width read linearly
  int min_nodes = 65;       ///< bounds on the φ, θi and θr node counts that `error` sets
  int max_nodes = 721;
  int theta_d = 65;         ///< θd nodes, cos-spaced over [0°, 90°]
  int shape_sigma_a = 17;   ///< shape nodes, uniform in √σa over [0, σa_max]
  int energy_sigma_a = 129; ///< energy nodes, uniform in √σa (ln E linear between them)
  int row_groups = 5;       ///< step 1's groups, uniform in √σa from 0
};

/// A fiber's σa read by PreparedScattering: per channel its energies on the θd nodes and its
/// weights on the shape nodes; the row groups' weights fitted to its energies. Built by
/// PreparedScattering::fiber().
struct PreparedFiber {
  std::vector<float> e;           // [θd node][channel 0..2, then their mean][lobe, padded]
  int node[3] = {0, 0, 0};        // shape node j of each channel (with j + 1)
  double w[3] = {0.0, 0.0, 0.0};  // and the weight of j + 1
  int groups = 0;                 // row groups with weight
  int group[6] = {};
  double gw[6] = {};              // their weights
  bool ok = false;
};

template <class T>
class PreparedScattering {
 public:
  static constexpr int kMaxLobes = 8;  ///< explicit lobes plus the residual
  using Incl = linear_rows::Incl;
  using Cell = linear_rows::Cell;

  /// What at() holds for one fiber and wo: where θo falls on the θr nodes and step 1's mixture.
  struct Point {
    Incl o;
    Cell co;
    double a[12] = {};  // the masses of (group m, θr node r + k), index 2m + k
    double total = 0.0;
    bool ok = false;
  };
  using Draw = linear_rows::Draw;

  PreparedScattering() = default;
  /// From a source at one roughness: `src` has lobes() (explicit), residual(), sigma_max() (the
  /// set's σa range, σa beyond it reads as σa_max), mp(p, θi, θo) for every lobe (the residual
  /// p = lobes()), np(p, σa, θd, φ) and has_energy(p) for the explicit lobes, energy(p, σa, θd)
  /// for every lobe that has one (the residual always: 2π N_res), and the roughness beta_m(),
  /// beta_n() that sets the node counts. A lobe without an energy takes ∫ N_p dφ on the φ nodes.
  template <class Source>
  PreparedScattering(const Source& src, const PreparedGrid& grid) {
    const double pi = 3.14159265358979323846, half_pi = 0.5 * pi;
    P_ = src.lobes(), res_ = src.residual(), L_ = P_ + (res_ ? 1 : 0);
    if (P_ < 1 || L_ > kMaxLobes || !(src.sigma_max() >= 0.0) || !(src.beta_m() > 0.0) || !(src.beta_n() > 0.0)) return;
    if (grid.min_nodes < 2 || grid.max_nodes < grid.min_nodes || grid.max_nodes > 16384 || grid.theta_d < 2 || grid.theta_d > 16384 ||
        grid.shape_sigma_a < 2 || grid.energy_sigma_a < 2 || grid.row_groups < 2 || grid.row_groups > 6 || !(grid.error > 0.0))
      return;
    P4_ = (P_ + 3) / 4 * 4, SM_ = (L_ + 3) / 4 * 4;
    auto count = [&](double width, double span) {
      const double h = width * std::sqrt(8.0 * grid.error), n = std::ceil(span / h) + 1.0;
      return static_cast<int>(std::min(std::max(n, static_cast<double>(grid.min_nodes)), static_cast<double>(grid.max_nodes)));
    };
    nf_ = count(src.beta_n(), pi), ni_ = nr_ = count(src.beta_m(), pi), nt_ = grid.theta_d;
    K_ = grid.shape_sigma_a, KE_ = grid.energy_sigma_a, G_ = grid.row_groups;
    smax_ = std::sqrt(std::max(0.0, src.sigma_max()));
    Axis ti{Spacing::uniform, Placement::edges, Wrap::clamp, -half_pi, half_pi, ni_};
    Axis tr{Spacing::uniform, Placement::edges, Wrap::clamp, -half_pi, half_pi, nr_};
    Axis td{Spacing::cos, Placement::edges, Wrap::clamp, 0.0, half_pi, nt_};
    Axis ph{Spacing::uniform, Placement::edges, Wrap::clamp, 0.0, pi, nf_};
    ti_ = linear_rows::Located(ti), tr_ = linear_rows::Located(tr), td_ = linear_rows::Located(td), ph_ = linear_rows::Located(ph);
    const std::size_t nt = static_cast<std::size_t>(nt_), nf = static_cast<std::size_t>(nf_), ni = static_cast<std::size_t>(ni_),
                      nr = static_cast<std::size_t>(nr_), K = static_cast<std::size_t>(K_), KE = static_cast<std::size_t>(KE_),
                      SM = static_cast<std::size_t>(SM_), P4 = static_cast<std::size_t>(P4_);
    // θd nodes: cos θd = 1 − k/(nt − 1). The shapes are read a hair short of 90°, where N_p and
    // E_p of the lobes p ≥ 1 both vanish and their ratio has its limit.
    std::vector<double> theta_d(nt), theta_d_shape(nt);
    for (std::size_t k = 0; k < nt; ++k) {
      const double u = 1.0 - static_cast<double>(k) / static_cast<double>(nt - 1);
      theta_d[k] = k + 1 == nt ? half_pi : std::acos(u);
      theta_d_shape[k] = std::acos(std::max(u, 1e-6));
    }
    const double hf = pi / static_cast<double>(nf - 1);
    // M_p interleaved per node, θr outermost: [θr][θi][lobe].
    mp_.assign(nr * ni * SM, 0.0f);
    for (std::size_t r = 0; r < nr; ++r)
      for (std::size_t i = 0; i < ni; ++i)
        for (int p = 0; p < L_; ++p)
          mp_[(r * ni + i) * SM + static_cast<std::size_t>(p)] = clean(src.mp(p, node(ti, static_cast<int>(i)), node(tr, static_cast<int>(r))));
    // A lobe's energy at (σa, θd): its own, or ∫ N_p dφ on the φ nodes (trapezoids, twice [0, π]).
    auto energy = [&](int p, double sa, double t) {
      if (p >= P_ || src.has_energy(p)) return std::max(0.0, finite(src.energy(p, sa, t)));
      double s = 0.0;
      for (std::size_t f = 0; f < nf; ++f) s += (f == 0 || f + 1 == nf ? 0.5 : 1.0) * std::max(0.0, finite(src.np(p, sa, t, static_cast<double>(f) * hf)));
      return 2.0 * hf * s;
    };
    // ln E on the dense σa nodes: [σa node][θd node][lobe]; 0 reads as ln of the least normal.
    le_.assign(KE * nt * SM, 0.0);
    for (std::size_t j = 0; j < KE; ++j) {
      const double s = smax_ * static_cast<double>(j) / static_cast<double>(KE - 1);
      for (std::size_t k = 0; k < nt; ++k)
        for (int p = 0; p < L_; ++p) le_[(j * nt + k) * SM + static_cast<std::size_t>(p)] = std::log(std::max(energy(p, s * s, theta_d[k]), 2.2250738585072014e-308));
    }
    // The shapes, [θd][φ][σa node][lobe], each (lobe, σa node, θd) row over φ ∈ [0, π] scaled to
    // ∫ over [−π, π] = 1, and step 3's prefix masses of the rows, [lobe][σa node][θd][φ]. A row
    // with no energy (σa so large that N_p underflowed) is uniform.
    sh_.assign(nt * nf * K * P4, 0.0f);
    cum_.assign(static_cast<std::size_t>(P_) * K * nt * nf, 0.0f);
    std::vector<double> v(nf);
    for (int p = 0; p < P_; ++p)
      for (std::size_t j = 0; j < K; ++j) {
        const double s = smax_ * static_cast<double>(j) / static_cast<double>(K - 1), sa = s * s;
        for (std::size_t k = 0; k < nt; ++k) {
          double mass = 0.0;
          for (std::size_t f = 0; f < nf; ++f) {
            v[f] = std::max(0.0, finite(src.np(p, sa, theta_d_shape[k], static_cast<double>(f) * hf)));
            if (f > 0) mass += hf * (v[f - 1] + v[f]);  // twice the trapezoid: [−π, π]
          }
          const double scale = mass > 0.0 && mass < HUGE_VAL ? 1.0 / mass : 0.0;
          const std::size_t row = ((static_cast<std::size_t>(p) * K + j) * nt + k) * nf;
          double c = 0.0, last = 0.0;
          for (std::size_t f = 0; f < nf; ++f) {
            const float x = static_cast<float>(scale > 0.0 ? v[f] * scale : 0.5 / pi);
            if (f > 0) c += 0.5 * hf * (last + static_cast<double>(x));
            last = x, cum_[row + f] = static_cast<float>(c);
            sh_[((k * nf + f) * K + j) * P4 + static_cast<std::size_t>(p)] = x;
          }
        }
      }
    guide_.assign(cum_.size() / nf * kGuidePhi, 0);
    for (std::size_t r = 0; r < cum_.size() / nf; ++r) linear_rows::build_guide(&cum_[r * nf], nf_, &guide_[r * kGuidePhi], kGuidePhi);
    // Step 1's rows per group: E_p(σ_g, θd) on the θd nodes, then on each half θi cell
    // Σ_p M_p Z_p cos θi with M_p linear (as stored) and Z_p cos θi = E_p cos θi linear between the
    // half cell's ends, A + B s + C s² in the cell's own coordinate (≥ 0: a sum of products of
    // nonnegative linears).
    eg_.assign(static_cast<std::size_t>(G_) * nt * SM, 0.0);
    for (int g = 0; g < G_; ++g) {
      const double s = smax_ * g / (G_ - 1.0);
      for (std::size_t k = 0; k < nt; ++k)
        for (int p = 0; p < L_; ++p) eg_[(static_cast<std::size_t>(g) * nt + k) * SM + static_cast<std::size_t>(p)] = energy(p, s * s, theta_d[k]);
    }
    // Z_p cos θi is read on half θi cells where the cells are coarse (it bends fastest where cos θi
    // falls to 0 and the θd nodes crowd towards 90°), on the cells themselves where they are fine.
    split_ = ni_ < 128 ? 2 : 1;
    const std::size_t kSplit = static_cast<std::size_t>(split_);
    nq_ = (ni_ - 1) * split_ + 1, hq_ = ti_.h / static_cast<double>(kSplit);
    gram_.assign(static_cast<std::size_t>(G_ * G_), 0.0);
    for (std::size_t g = 0; g < static_cast<std::size_t>(G_); ++g)
      for (std::size_t h = 0; h < static_cast<std::size_t>(G_); ++h)
        for (std::size_t k = 0; k < nt * SM; ++k) gram_[g * static_cast<std::size_t>(G_) + h] += eg_[g * nt * SM + k] * eg_[h * nt * SM + k];
    const std::size_t nq = static_cast<std::size_t>(nq_), nc = nq - 1, G = static_cast<std::size_t>(G_);
    gq_.assign(G * nr * nc * 3, 0.0f);
    gcum_.assign(G * nr * nq, 0.0);
    std::vector<double> mq(nq * SM), zc(nq * SM);
    for (std::size_t g = 0; g < G; ++g)
      for (std::size_t r = 0; r < nr; ++r) {
        const double thr = node(tr, static_cast<int>(r));
        for (std::size_t i = 0; i < nq; ++i) {
          const double thi = i + 1 == nq ? half_pi : -half_pi + static_cast<double>(i) * hq_;
          const Cell d = td_.at_t(std::cos(0.5 * (thr - thi)));
          const std::size_t a = std::min(i / kSplit, ni - 2);
          const double f = static_cast<double>(i - a * kSplit) / static_cast<double>(kSplit), c = std::max(0.0, std::cos(thi));
          const float* m0 = &mp_[(r * ni + a) * SM];
          const double* e0 = &eg_[(g * nt + static_cast<std::size_t>(d.i)) * SM];
          for (int p = 0; p < L_; ++p) {
            const std::size_t o = i * SM + static_cast<std::size_t>(p);
            mq[o] = (1.0 - f) * m0[p] + f * m0[SM + static_cast<std::size_t>(p)];
            zc[o] = ((1.0 - d.w) * e0[p] + d.w * e0[SM + static_cast<std::size_t>(p)]) * c;
          }
        }
        double* cum = &gcum_[(g * nr + r) * nq];
        cum[0] = 0.0;
        for (std::size_t i = 0; i < nc; ++i) {
          const double *m0 = &mq[i * SM], *m1 = m0 + SM, *g0 = &zc[i * SM], *g1 = g0 + SM;
          double A = 0.0, B = 0.0, C = 0.0;
          for (int p = 0; p < L_; ++p) {
            const double dm = m1[p] - m0[p], dg = g1[p] - g0[p];
            A += m0[p] * g0[p], B += m0[p] * dg + dm * g0[p], C += dm * dg;
          }
          float* q = &gq_[((g * nr + r) * nc + i) * 3];
          q[0] = static_cast<float>(A), q[1] = static_cast<float>(B), q[2] = static_cast<float>(C);
          cum[i + 1] = cum[i] + hq_ * std::max(0.0, static_cast<double>(q[0]) + 0.5 * static_cast<double>(q[1]) + static_cast<double>(q[2]) / 3.0);
        }
      }
    gguide_.assign(G * nr * kGuideTheta, 0);
    for (std::size_t r = 0; r < G * nr; ++r) linear_rows::build_guide(&gcum_[r * nq], nq_, &gguide_[r * kGuideTheta], kGuideTheta);
    valid_ = true;
  }

  bool valid() const { return valid_; }
  int lobes() const { return L_; }
  /// Node counts (φ, θi = θr, θd) and the bytes held: what the roughness asked for.
  int phi_nodes() const { return nf_; }
  int theta_nodes() const { return ni_; }
  int theta_d_nodes() const { return nt_; }
  std::size_t bytes() const {
    return mp_.size() * 4 + sh_.size() * 4 + cum_.size() * 4 + guide_.size() * 2 + le_.size() * 8 + eg_.size() * 8 + gq_.size() * 4 +
           gcum_.size() * 8 + gguide_.size() * 2;
  }

  /// The state of a fiber with absorption σa per channel (per unit radius; NaN or negative reads
  /// as 0, beyond the set's range as its end): each channel's energies on the θd nodes, ln E read
  /// linearly in √σa between the dense nodes, and its weights on the shape nodes and row groups.
  PreparedFiber fiber(const double* sigma_a) const {
    PreparedFiber f;
    if (!valid_) return f;
    const std::size_t nt = static_cast<std::size_t>(nt_), SM = static_cast<std::size_t>(SM_);
    f.e.assign(nt * 4 * SM, 0.0f);
    double x[3];
    for (int c = 0; c < 3; ++c) {
      const double sa = sigma_a[c] > 0.0 ? sigma_a[c] : 0.0;  // NaN reads as 0
      x[c] = smax_ > 0.0 ? std::min(std::sqrt(sa) / smax_, 1.0) : 0.0;
      const Cell e = cell(x[c], KE_);
      const double* l0 = &le_[static_cast<std::size_t>(e.i) * nt * SM];
      const double* l1 = l0 + nt * SM;
      for (std::size_t k = 0; k < nt; ++k) {
        float* out = &f.e[(k * 4 + static_cast<std::size_t>(c)) * SM];
        for (int p = 0; p < L_; ++p) {
          const std::size_t o = k * SM + static_cast<std::size_t>(p);
          out[p] = static_cast<float>(std::exp((1.0 - e.w) * l0[o] + e.w * l1[o]));
        }
      }
      const Cell s = cell(x[c], K_);
      f.node[c] = s.i, f.w[c] = s.w;
      const Cell g = cell(x[c], G_);
      add_group(f, g.i, (1.0 - g.w) / 3.0);
      add_group(f, g.i + 1, g.w / 3.0);
    }
    for (std::size_t k = 0; k < nt; ++k) {
      float* e = &f.e[k * 4 * SM];
      for (int p = 0; p < L_; ++p) e[3 * SM + static_cast<std::size_t>(p)] = (e[p] + e[SM + static_cast<std::size_t>(p)] + e[2 * SM + static_cast<std::size_t>(p)]) / 3.0f;
    }
    if (!(f.groups == 1 && f.gw[0] == 1.0)) fit_groups(f);
    f.ok = true;
    return f;
  }

  /// S per channel at θo, θi and φ = φo − φi [rad] for fiber f (finite arguments).
  void eval(const PreparedFiber& f, const Incl& o, const Incl& i, double phi, double* rgb) const {
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    if (!valid_ || !f.ok) return;
    Terms s;
    locate(o, i, phi, s);
    combine(f, s, false);
    rgb[0] = s.rgb[0], rgb[1] = s.rgb[1], rgb[2] = s.rgb[2];
  }
  /// Step 1's mixture at θo for fiber f; not ok where no lobe has energy. pdf() and sample() take
  /// the same fiber.
  Point at(const PreparedFiber& f, const Incl& o) const {
    Point pt;
    pt.o = o;
    if (!valid_ || !f.ok) return pt;
    pt.co = tr_.at(o.theta);
    const std::size_t nq = static_cast<std::size_t>(nq_), nr = static_cast<std::size_t>(nr_), r = static_cast<std::size_t>(pt.co.i);
    double total = 0.0;
    for (int m = 0; m < f.groups; ++m) {
      const double* cum = &gcum_[(static_cast<std::size_t>(f.group[m]) * nr + r) * nq];
      pt.a[2 * m] = f.gw[m] * (1.0 - pt.co.w) * cum[nq - 1];
      pt.a[2 * m + 1] = f.gw[m] * pt.co.w * cum[2 * nq - 1];
      total += pt.a[2 * m] + pt.a[2 * m + 1];
    }
    pt.total = total;
    pt.ok = total > 0.0 && total < HUGE_VAL;
    return pt;
  }
  /// The normalisation of step 1's density at the point's θo: ∫ S̄ dω for a white fiber (the mean
  /// of its weights); for a coloured fiber that of its fitted groups' mixture, near its own ∫ S̄ dω
  /// (the weights' mean) as the fit is near its energies.
  double albedo(const Point& pt) const { return pt.ok ? pt.total : 0.0; }
  /// The pdf per unit solid angle of drawing (θi, φ) at the point.
  double pdf(const Point& pt, const PreparedFiber& f, const Incl& i, double phi) const {
    if (!pt.ok) return 0.0;
    Terms s;
    locate(pt.o, i, phi, s);
    combine(f, s, true);
    return density(pt, f, i, s);
  }
  /// Draws (θi, φ) from u ∈ [0, 1)³ (already kept off 0 and 1 by the caller).
  Draw sample(const Point& pt, const PreparedFiber& f, const double* u) const {
    Draw d;
    if (!pt.ok) return d;
    // 1. The (group, θr node) component by u0, then θi from its row by u1.
    double u0 = u[0] * pt.total;
    int comp = -1;
    for (int k = 0; k < 2 * f.groups; ++k) {
      if (!(pt.a[k] > 0.0)) continue;
      comp = k;
      if (u0 < pt.a[k]) break;
      u0 -= pt.a[k];
    }
    if (comp < 0) return d;
    u0 = std::min(std::max(u0 / pt.a[comp], 0.0), 1.0);
    const std::size_t nq = static_cast<std::size_t>(nq_), nr = static_cast<std::size_t>(nr_);
    const std::size_t row = static_cast<std::size_t>(f.group[comp / 2]) * nr + static_cast<std::size_t>(pt.co.i + comp % 2);
    const Incl i = linear_rows::incl(linear_rows::invert_quadratic_row(&gq_[row * (nq - 1) * 3], &gcum_[row * nq], &gguide_[row * kGuideTheta],
                                                                     kGuideTheta, nq_, ti_.lo, hq_, u[1]));
    // 2. The lobe at θi in proportion to M_q Ē_q.
    Terms s;
    locate(pt.o, i, 0.0, s);
    energies(f, s);
    double norm = 0.0;
    for (int p = 0; p < L_; ++p) norm += s.m[p] * s.ebar[p];
    if (!(norm > 0.0) || !(norm < HUGE_VAL)) return d;
    u0 *= norm;
    int q = -1;
    for (int p = 0; p < L_; ++p) {
      const double share = s.m[p] * s.ebar[p];
      if (!(share > 0.0)) continue;
      q = p;
      if (u0 < share) break;
      u0 -= share;
    }
    if (q < 0) return d;
    // 3. φ: the residual uniformly; a lobe from a (channel's shape node, θd node) row chosen by
    // the rest of u0 in proportion to (1/3) E_qc (θd) times the two linear weights, |φ| by u2 folded.
    const double pi = 3.14159265358979323846;
    double phi;
    if (q == P_) {
      phi = (2.0 * u[2] - 1.0) * pi;
    } else {
      const std::size_t SM = static_cast<std::size_t>(SM_), nt = static_cast<std::size_t>(nt_), nf = static_cast<std::size_t>(nf_);
      const float* e0 = &f.e[static_cast<std::size_t>(s.cd.i) * 4 * SM + static_cast<std::size_t>(q)];
      const float* e1 = e0 + 4 * SM;
      double t = std::min(std::max(u0 / (s.m[q] * s.ebar[q]), 0.0), 1.0) * 3.0 * s.ebar[q];
      std::size_t pick = 0, j = 0, k = 0;
      bool found = false;
      for (int c = 0; c < 3 && !found; ++c) {
        const double ec = (1.0 - s.cd.w) * e0[static_cast<std::size_t>(c) * SM] + s.cd.w * e1[static_cast<std::size_t>(c) * SM];
        for (int b = 0; b < 4; ++b) {
          const double wn = (b & 1) ? f.w[c] : 1.0 - f.w[c], wd = (b & 2) ? s.cd.w : 1.0 - s.cd.w, a = ec * wn * wd;
          if (!(a > 0.0)) continue;
          j = static_cast<std::size_t>(f.node[c] + (b & 1)), k = static_cast<std::size_t>(s.cd.i + (b >> 1));
          pick = ((static_cast<std::size_t>(q) * static_cast<std::size_t>(K_) + j) * nt + k) * nf;
          found = t < a;
          if (found) break;
          t -= a;
        }
      }
      const double v = std::fabs(2.0 * u[2] - 1.0);
      const std::size_t SK = static_cast<std::size_t>(K_) * static_cast<std::size_t>(P4_);
      phi = linear_rows::invert_row(&sh_[k * nf * SK + j * static_cast<std::size_t>(P4_) + static_cast<std::size_t>(q)], &cum_[pick],
                                    &guide_[pick / nf * kGuidePhi], kGuidePhi, nf_, ph_.h, v, SK);
      if (u[2] < 0.5) phi = -phi;
    }
    s.cf = ph_.at(std::fabs(phi));
    combine(f, s, true, true);
    return linear_rows::drawn(density(pt, f, i, s), i, phi, q, s.rgb);
  }

 private:
  struct Terms {
    Cell ci, co, cd, cf;
    double m[kMaxLobes] = {};
    double ebar[kMaxLobes] = {};  // Ē_p at θd
    double rgb[3] = {0.0, 0.0, 0.0};
    double s_phi = 0.0;  // Σ_q M_q Ē_q
  };

  static double finite(double x) { return x == x && std::fabs(x) < HUGE_VAL ? x : 0.0; }
  static float clean(double x) { return x > 0.0 && x < 3.0e38 ? static_cast<float>(x) : 0.0f; }
  // x ∈ [0, 1] on n uniform nodes.
  static Cell cell(double x, int n) {
    const double s = std::min(std::max(x, 0.0), 1.0) * (n - 1);
    Cell c;
    c.i = std::min(static_cast<int>(s), n - 2);
    c.w = s - c.i;
    return c;
  }
  // The row groups' weights a_g ≥ 0 that bring Σ_g a_g E_p(σ_g, θd) closest to the fiber's mean
  // energies Ē_p(θd) in least squares over the lobes and θd nodes: step 1's density is then the
  // mixture nearest the fiber's own θi marginal that the rows allow, and its normalisation near
  // the fiber's ∫ S̄ dω. Over the G ≤ 6 groups every subset is solved in turn (its normal
  // equations by Cholesky) and the best one whose weights are all ≥ 0 kept: the exact
  // nonnegative least-squares solution, at G ≤ 6 cheaper than an active-set iteration. Kept as
  // they are (√σa-linear) where no subset fits.
  void fit_groups(PreparedFiber& f) const {
    const std::size_t nt = static_cast<std::size_t>(nt_), SM = static_cast<std::size_t>(SM_);
    double b[6] = {};
    for (int g = 0; g < G_; ++g) {
      const double* eg = &eg_[static_cast<std::size_t>(g) * nt * SM];
      double v = 0.0;
      for (std::size_t k = 0; k < nt; ++k)
        for (int p = 0; p < L_; ++p) v += eg[k * SM + static_cast<std::size_t>(p)] * f.e[(k * 4 + 3) * SM + static_cast<std::size_t>(p)];
      b[g] = v;
    }
    double best = HUGE_VAL, best_a[6] = {};
    for (unsigned mask = 1; mask < (1u << G_); ++mask) {
      int idx[6], n = 0;
      for (int g = 0; g < G_; ++g)
        if (mask & (1u << g)) idx[n++] = g;
      // Cholesky of the subset's Gram matrix, then the two triangular solves.
      double L[6][6] = {}, y[6], a[6];
      bool ok = true;
      for (int i = 0; i < n && ok; ++i)
        for (int j = 0; j <= i; ++j) {
          double v = gram_[static_cast<std::size_t>(idx[i] * G_ + idx[j])];
          for (int k = 0; k < j; ++k) v -= L[i][k] * L[j][k];
          if (i == j) {
            ok = v > 1e-12 * gram_[static_cast<std::size_t>(idx[i] * G_ + idx[i])];
            L[i][i] = ok ? std::sqrt(v) : 0.0;
          } else {
            L[i][j] = v / L[j][j];
          }
        }
      if (!ok) continue;
      for (int i = 0; i < n; ++i) {
        double v = b[idx[i]];
        for (int k = 0; k < i; ++k) v -= L[i][k] * y[k];
        y[i] = v / L[i][i];
      }
      for (int i = n - 1; i >= 0; --i) {
        double v = y[i];
        for (int k = i + 1; k < n; ++k) v -= L[k][i] * a[k];
        a[i] = v / L[i][i];
        ok = ok && a[i] >= 0.0;
      }
      if (!ok) continue;
      // The residual up to its constant: aᵀQa − 2aᵀb = −aᵀb at the subset's solution.
      double r = 0.0;
      for (int i = 0; i < n; ++i) r -= a[i] * b[idx[i]];
      if (r < best) {
        best = r;
        for (int g = 0; g < 6; ++g) best_a[g] = 0.0;
        for (int i = 0; i < n; ++i) best_a[idx[i]] = a[i];
      }
    }
    if (!(best < HUGE_VAL)) return;
    f.groups = 0;
    for (int g = 0; g < G_; ++g)
      if (best_a[g] > 0.0) f.group[f.groups] = g, f.gw[f.groups] = best_a[g], ++f.groups;
  }
  static void add_group(PreparedFiber& f, int g, double w) {
    if (!(w > 0.0)) return;
    for (int m = 0; m < f.groups; ++m)
      if (f.group[m] == g) {
        f.gw[m] += w;
        return;
      }
    f.group[f.groups] = g, f.gw[f.groups] = w, ++f.groups;
  }
  // (θo, θi, |φ| folded into [0, π]) located, M_p there; cos θd from the sines and cosines.
  void locate(const Incl& o, const Incl& i, double phi, Terms& s) const {
    const double pi = 3.14159265358979323846;
    double f = std::fabs(phi);
    if (f > pi) f = std::fabs(f - 2.0 * pi * std::floor(f / (2.0 * pi) + 0.5));
    s.ci = ti_.at(i.theta), s.co = tr_.at(o.theta), s.cf = ph_.at(f);
    s.cd = td_.at_t(std::sqrt(std::max(0.0, 0.5 * (1.0 + o.cos * i.cos + o.sin * i.sin))));
    // M_p of every lobe, bilinear over the padded block (its padding holds zeros).
    const std::size_t S = static_cast<std::size_t>(SM_), ni = static_cast<std::size_t>(ni_);
    const float* a = &mp_[(static_cast<std::size_t>(s.co.i) * ni + static_cast<std::size_t>(s.ci.i)) * S];
    linear_rows::bilinear_block(a, a + ni * S, SM_, (1.0 - s.co.w) * (1.0 - s.ci.w), (1.0 - s.co.w) * s.ci.w, s.co.w * (1.0 - s.ci.w), s.co.w * s.ci.w, s.m);
  }
  // Ē_p at the located θd.
  void energies(const PreparedFiber& f, Terms& s) const {
    const std::size_t SM = static_cast<std::size_t>(SM_);
    const float* e0 = &f.e[(static_cast<std::size_t>(s.cd.i) * 4 + 3) * SM];
    const float* e1 = e0 + 4 * SM;
    for (int p = 0; p < L_; ++p) s.ebar[p] = (1.0 - s.cd.w) * e0[p] + s.cd.w * e1[p];
  }
  // S per channel (and S̄_φ) from the located cells.
  void combine(const PreparedFiber& f, Terms& s, bool with_phi, bool have_energies = false) const {
    if (P4_ == 4) combine_block<4>(f, s);
    else combine_block<0>(f, s);
    if (!with_phi) return;
    if (!have_energies) energies(f, s);
    double sp = 0.0;
    for (int p = 0; p < L_; ++p) sp += s.m[p] * s.ebar[p];
    s.s_phi = sp;
  }
  // The explicit lobes over a block of N (4: the loops become vector operations) and the residual:
  // per channel, M_p E_pc(θd) times the shape read at the channel's two σa nodes and the four
  // (θd, φ) corners.
  template <int N>
  void combine_block(const PreparedFiber& f, Terms& s) const {
    const int n = N ? N : P4_;
    const std::size_t SM = static_cast<std::size_t>(SM_), P4 = static_cast<std::size_t>(n), SK = static_cast<std::size_t>(K_) * P4,
                      nf = static_cast<std::size_t>(nf_);
    const Cell &cd = s.cd, &cf = s.cf;
    const float* A = &sh_[(static_cast<std::size_t>(cd.i) * nf + static_cast<std::size_t>(cf.i)) * SK];
    const float* B = A + nf * SK;
    const float* e0 = &f.e[static_cast<std::size_t>(cd.i) * 4 * SM];
    const float* e1 = e0 + 4 * SM;
    // In float: the shapes and energies are floats, and their eight-tap blends lose nothing that a
    // float table holds; the sum over lobes is in double.
    const float wd = static_cast<float>(cd.w), wf = static_cast<float>(cf.w);
    const float w00 = (1.0f - wd) * (1.0f - wf), w01 = (1.0f - wd) * wf, w10 = wd * (1.0f - wf), w11 = wd * wf;
    const double inv_2pi = 0.15915494309189533577;
    float m[8];
    for (int p = 0; p < n; ++p) m[p] = static_cast<float>(s.m[p]);
    for (int c = 0; c < 3; ++c) {
      const std::size_t j = static_cast<std::size_t>(f.node[c]) * P4, ec = static_cast<std::size_t>(c) * SM;
      const float wj = static_cast<float>(f.w[c]), wa = 1.0f - wj;
      const float *a = A + j, *b = B + j;
      float t[8];
      for (int p = 0; p < n; ++p) {
        const std::size_t q = static_cast<std::size_t>(p), r = q + P4;
        const float e = (1.0f - wd) * e0[ec + q] + wd * e1[ec + q];
        const float shape = wa * (w00 * a[q] + w01 * a[SK + q] + w10 * b[q] + w11 * b[SK + q]) + wj * (w00 * a[r] + w01 * a[SK + r] + w10 * b[r] + w11 * b[SK + r]);
        t[p] = m[p] * e * shape;
      }
      double v = 0.0;
      for (int p = 0; p < n; ++p) v += static_cast<double>(t[p]);
      if (res_) v += s.m[P_] * ((1.0 - cd.w) * e0[ec + static_cast<std::size_t>(P_)] + cd.w * e1[ec + static_cast<std::size_t>(P_)]) * inv_2pi;
      s.rgb[c] = v;
    }
  }
  // q(θi) / cos θi · S̄ / S̄_φ.
  double density(const Point& pt, const PreparedFiber& f, const Incl& i, const Terms& s) const {
    const double sbar = (s.rgb[0] + s.rgb[1] + s.rgb[2]) / 3.0;
    if (!(i.cos > 0.0) || !(s.s_phi > 0.0) || !(sbar > 0.0)) return 0.0;
    const std::size_t nc = static_cast<std::size_t>(nq_ - 1), nr = static_cast<std::size_t>(nr_);
    const double sq = std::min(std::max((i.theta - ti_.lo) / hq_, 0.0), static_cast<double>(nc));
    const std::size_t k = std::min(static_cast<std::size_t>(sq), nc - 1);
    const double x = sq - static_cast<double>(k);
    double q = 0.0;
    for (int m = 0; m < f.groups; ++m) {
      const float* g0 = &gq_[((static_cast<std::size_t>(f.group[m]) * nr + static_cast<std::size_t>(pt.co.i)) * nc + k) * 3];
      const float* g1 = g0 + 3 * nc;
      q += f.gw[m] * ((1.0 - pt.co.w) * (g0[0] + x * (g0[1] + x * static_cast<double>(g0[2]))) + pt.co.w * (g1[0] + x * (g1[1] + x * static_cast<double>(g1[2]))));
    }
    return q / pt.total / i.cos * sbar / s.s_phi;
  }

  static constexpr int kGuideTheta = 256, kGuidePhi = 128;  // about one guide per cell

  bool valid_ = false, res_ = false;
  int P_ = 0, L_ = 0, P4_ = 0, SM_ = 0;
  int nt_ = 0, nf_ = 0, ni_ = 0, nr_ = 0, K_ = 0, KE_ = 0, G_ = 0, nq_ = 0, split_ = 2;
  double smax_ = 0.0, hq_ = 0.0;
  linear_rows::Located td_, ph_, ti_, tr_;
  std::vector<float> mp_, sh_, cum_, gq_;
  std::vector<double> le_, eg_, gcum_, gram_;  // gram_: Σ E_p(σ_g) E_p(σ_h) over lobes and θd nodes
  std::vector<std::uint16_t> guide_, gguide_;
};

}  // namespace sampler
}  // namespace hairlut
