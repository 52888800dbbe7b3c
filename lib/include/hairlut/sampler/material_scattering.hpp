// hairlut::sampler::MaterialScattering — what HairScattering runs for the tables of one material
// (materials/<name>/np_<lobe>, mp_<lobe>, np_residual, mp_residual; docs/table-format.md): S, its
// importance sampling and pdf, at the cost of a few bilinear lookups.
//
// A material's tables fix σa (RGB) and each lobe's β, so N_p is RGB over (θd, φ) and M_p is over
// (θi, θr), both interpolated linearly. Linear interpolation has nonnegative weights, so every
// density below is a mixture of stored rows and is sampled exactly, with no per-call row building:
//   1. θi from q(θi) = [(1 − w) G_r(θi) + w G_{r+1}(θi)] / [(1 − w) ‖G_r‖ + w ‖G_{r+1}‖], where
//      r, w locate θo on M_p's θr axis and G_r is, on M_p's θi nodes and linear between them,
//      Σ_p M_p(θi, θr_r) Z_p(θd) cos θi with θd = (θr_r − θi)/2 and Z_p(θd) = ∫ N̄_p dφ (N̄: the
//      channels' mean). Between θi nodes M_p is linear, so q differs from the true marginal
//      Σ_p M_p Z_p cos θi only through Z_p cos θi's curvature and θd read at θr_r for θo;
//   2. the lobe q at θi in exact proportion to M_q(θi, θo) Z_q(θd);
//   3. φ from N̄_q(θd, ·): N_p is linear in t = t(θd) (the θd axis's spacing) between its θd rows
//      k, k + 1, so this density is the mixture of the two rows with weights (1 − w_t) Z_q[k] and
//      w_t Z_q[k+1], each row piecewise linear in φ (even: |φ| from the row, the sign by halves).
//      The residual is uniform in φ.
// Where the θd axis reaches 90° the tables store N_p divided by its grazing factor g_p(σa, cos θd)
// (grazing_factor.hpp: cos²θd for the lobes p ≥ 1, the residual's own form; docs/table-format.md),
// which every lookup multiplies back after interpolating: N_p(θd, φ) = g_p(cos θd) · Ñ_p(θd, φ).
// A factor common to the channels leaves step 3's rows as they are (it scales both rows of the
// mixture alike) and enters Z_p, and so steps 1 and 2, as g_p Z̃_p; the residual's factor differs
// by channel, so its Z is 2π times the channels' mean of g_c Ñ_c.
// The pdf per unit solid angle is then
//   pdf(θi, φ) = q(θi) / cos θi · S̄(θi, φ) / S̄_φ(θi),   S̄ = Σ_q M_q N̄_q, S̄_φ = Σ_q M_q Z_q,
// so that for a white fiber the weight S / pdf = S̄_φ cos θi / q(θi): the exact θi marginal over
// its piecewise-linear stand-in, ≈ the albedo at θo.
//
// Header-only, C++17, no dependencies beyond sampler.hpp's axis definitions. The tables are copied
// (values that are negative, NaN or infinite read as 0), so the object owns everything it reads.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "hairlut/sampler/grazing_factor.hpp"
#include "hairlut/sampler/linear_rows.hpp"
#include "hairlut/sampler/sampler.hpp"

namespace hairlut {
namespace sampler {

/// The tables of one material: per explicit lobe N_p over (channel, θd, φ) and M_p over (θi, θr);
/// the residual's N over (channel, θd) (uniform in φ) and its M over (θi, θr). Row-major, 3
/// channels. Pointers into the caller's arrays, read only while MaterialScattering is built.
template <class T>
struct MaterialTables {
  static constexpr int kMaxLobes = 7;
  int lobes = 0;                   ///< explicit lobes (R, TT, ...)
  const T* np[kMaxLobes] = {};     ///< [channel][θd][φ]
  const T* mp[kMaxLobes] = {};     ///< [θi][θr]
  const T* np_residual = nullptr;  ///< [channel][θd]; null: no residual
  const T* mp_residual = nullptr;  ///< [θi][θr]
  Axis theta_d, phi;               ///< N_p's axes after the channel
  Axis theta_i, theta_r;           ///< M_p's axes
  /// What np[p] and np_residual were divided by (Table::grazing_factor; none where the θd axis
  /// stops short of 90°). An explicit lobe's factor must be a power of cos θd alone.
  GrazingFactor grazing[kMaxLobes], residual_grazing;
  double sigma_a[3] = {0.0, 0.0, 0.0};  ///< the material's σa per channel, which the residual's factor reads
};

template <class T>
class MaterialScattering {
 public:
  using Incl = linear_rows::Incl;
  static Incl incl(double theta) { return linear_rows::incl(theta); }
  static Incl incl_of_sin(double s) { return linear_rows::incl_of_sin(s); }

  /// What at() holds for one wo: where θo falls on the θr axis and the mixture of step 1.
  struct Point {
    Incl o;
    int r = 0;                     // θr cell
    double w = 0.0;                // weight of node r + 1
    double a0 = 0.0, a1 = 0.0;     // (1 − w) ‖G_r‖, w ‖G_{r+1}‖
    bool ok = false;
  };
  using Draw = linear_rows::Draw;

  MaterialScattering() = default;
  explicit MaterialScattering(const MaterialTables<T>& t) {
    P_ = t.lobes;
    res_ = t.np_residual != nullptr && t.mp_residual != nullptr;
    L_ = P_ + (res_ ? 1 : 0);
    if (P_ < 1 || P_ > MaterialTables<T>::kMaxLobes || !supported(t)) return;
    for (int p = 0; p < P_; ++p)
      if (!t.np[p] || !t.mp[p] || t.grazing[p].x_scale != 0.0) return;
    for (int p = 0; p < P_; ++p) gpow_[p] = t.grazing[p].none() ? 0 : std::min(std::max(t.grazing[p].cos_power, 0), GrazingFactor::kMaxCosPower);
    if (res_) {
      gres_ = t.residual_grazing;
      for (int c = 0; c < 3; ++c) gx_[c] = gres_.x_of(std::max(0.0, t.sigma_a[c]));
    }
    graze_ = !gres_.none();
    for (int p = 0; p < P_; ++p) graze_ = graze_ || gpow_[p] > 0;
    nt_ = t.theta_d.count, nf_ = t.phi.count, ni_ = t.theta_i.count, nr_ = t.theta_r.count;
    td_ = Located(t.theta_d), ph_ = Located(t.phi), ti_ = Located(t.theta_i), tr_ = Located(t.theta_r);
    P4_ = (P_ + 3) / 4 * 4, SM_ = (L_ + 3) / 4 * 4, SN_ = 3 * P4_;
    const std::size_t nt = static_cast<std::size_t>(nt_), nf = static_cast<std::size_t>(nf_), ni = static_cast<std::size_t>(ni_),
                      nr = static_cast<std::size_t>(nr_);
    // M_p interleaved per node, θr outermost: [θr][θi][lobe].
    mp_.assign(nr * ni * static_cast<std::size_t>(SM_), 0.0f);
    for (int p = 0; p < L_; ++p) {
      const T* m = p < P_ ? t.mp[p] : t.mp_residual;
      for (std::size_t i = 0; i < ni; ++i)
        for (std::size_t r = 0; r < nr; ++r) mp_[(r * ni + i) * static_cast<std::size_t>(SM_) + static_cast<std::size_t>(p)] = clean(m[i * nr + r]);
    }
    // N_p interleaved per node: [θd][φ][channel][lobe]; the residual [θd][channel].
    np_.assign(nt * nf * static_cast<std::size_t>(SN_), 0.0f);
    for (int p = 0; p < P_; ++p)
      for (std::size_t c = 0; c < 3; ++c)
        for (std::size_t k = 0; k < nt; ++k)
          for (std::size_t j = 0; j < nf; ++j)
            np_[(k * nf + j) * static_cast<std::size_t>(SN_) + c * static_cast<std::size_t>(P4_) + static_cast<std::size_t>(p)] =
                clean(t.np[p][(c * nt + k) * nf + j]);
    nres_.assign(nt * 4, 0.0f);
    if (res_)
      for (std::size_t c = 0; c < 3; ++c)
        for (std::size_t k = 0; k < nt; ++k) nres_[k * 4 + c] = clean(t.np_residual[c * nt + k]);
    // Step 3's rows: N̄_p per θd node along φ ∈ [0, π], their prefix masses, and Z_p = ∫ over
    // [−π, π] (twice the half) per θd node; the residual's Z is 2π N̄.
    const double pi = 3.14159265358979323846, hf = pi / (nf_ - 1);
    nbar_.assign(static_cast<std::size_t>(P_) * nt * nf, 0.0);
    ncum_.assign(static_cast<std::size_t>(P_) * nt * nf, 0.0);
    z_.assign(nt * static_cast<std::size_t>(SM_), 0.0);
    for (int p = 0; p < L_; ++p)
      for (std::size_t k = 0; k < nt; ++k) {
        if (p == P_) {
          z_[k * static_cast<std::size_t>(SM_) + static_cast<std::size_t>(p)] = 2.0 * pi * (double(nres_[k * 4]) + nres_[k * 4 + 1] + nres_[k * 4 + 2]) / 3.0;
          continue;
        }
        double* row = &nbar_[(static_cast<std::size_t>(p) * nt + k) * nf];
        double* cum = &ncum_[(static_cast<std::size_t>(p) * nt + k) * nf];
        for (std::size_t j = 0; j < nf; ++j) {
          const float* v = &np_[(k * nf + j) * static_cast<std::size_t>(SN_) + static_cast<std::size_t>(p)];
          row[j] = (double(v[0]) + v[P4_] + v[2 * P4_]) / 3.0;
        }
        cum[0] = 0.0;
        for (std::size_t j = 1; j < nf; ++j) cum[j] = cum[j - 1] + 0.5 * hf * (row[j - 1] + row[j]);
        z_[k * static_cast<std::size_t>(SM_) + static_cast<std::size_t>(p)] = 2.0 * cum[nf - 1];
      }
    nguide_.assign(static_cast<std::size_t>(P_) * nt * kGuidePhi, 0);
    for (std::size_t row = 0; row < static_cast<std::size_t>(P_) * nt; ++row) build_guide(&ncum_[row * nf], nf_, &nguide_[row * kGuidePhi], kGuidePhi);
    // Step 1's rows G_r: on each θi cell, Σ_p M_p Z_p cos θi with M_p linear (as stored) and
    // Z_p cos θi linear between its values at the cell's nodes, a quadratic in the cell's own
    // coordinate s ∈ [0, 1], A + B s + C s² (≥ 0: a sum of products of nonnegative linears);
    // reading Z_p cos θi linearly, not M_p Z_p cos θi, keeps the steep M_p of a narrow lobe exact.
    // The θi cells are split in kSplit: M_p stays linear on each part, and Z_p cos θi, which
    // bends fastest where the θd nodes crowd towards 90° and cos θi falls to 0, is read on a finer
    // step.
    nq_ = (ni_ - 1) * static_cast<int>(kSplit) + 1, hq_ = ti_.h / static_cast<double>(kSplit);
    const std::size_t nq = static_cast<std::size_t>(nq_), nc = nq - 1;
    gq_.assign(nr * nc * 3, 0.0);
    gcum_.assign(nr * nq, 0.0);
    std::vector<double> mq(nq * static_cast<std::size_t>(SM_)), zc(nq * static_cast<std::size_t>(SM_));
    for (std::size_t r = 0; r < nr; ++r) {
      const double tr = node(t.theta_r, static_cast<int>(r));
      for (std::size_t i = 0; i < nq; ++i) {
        const double ti = i + 1 == nq ? t.theta_i.hi : t.theta_i.lo + static_cast<double>(i) * hq_;
        const double half = std::fabs(0.5 * (tr - ti));
        const Cell d = td_.at(half);
        Factors g;
        factors(std::cos(half), g);
        const std::size_t a = std::min(i / kSplit, ni - 2);
        const double f = static_cast<double>(i - a * kSplit) / static_cast<double>(kSplit), c = std::max(0.0, std::cos(ti));
        const float* m0 = &mp_[(r * ni + a) * static_cast<std::size_t>(SM_)];
        for (int p = 0; p < L_; ++p) {
          const std::size_t o = i * static_cast<std::size_t>(SM_) + static_cast<std::size_t>(p);
          mq[o] = (1.0 - f) * m0[p] + f * m0[SM_ + p];
          zc[o] = lobe_z(d, g, p) * c;
        }
      }
      double* cum = &gcum_[r * nq];
      cum[0] = 0.0;
      for (std::size_t i = 0; i < nc; ++i) {
        const double* m0 = &mq[i * static_cast<std::size_t>(SM_)];
        const double* m1 = m0 + SM_;
        const double* g0 = &zc[i * static_cast<std::size_t>(SM_)];
        const double* g1 = g0 + SM_;
        double A = 0.0, B = 0.0, C = 0.0;
        for (int p = 0; p < L_; ++p) {
          const double dm = m1[p] - m0[p], dg = g1[p] - g0[p];
          A += m0[p] * g0[p], B += m0[p] * dg + dm * g0[p], C += dm * dg;
        }
        double* q = &gq_[(r * nc + i) * 3];
        q[0] = A, q[1] = B, q[2] = C;
        cum[i + 1] = cum[i] + hq_ * std::max(0.0, A + 0.5 * B + C / 3.0);
      }
    }
    gguide_.assign(nr * kGuideTheta, 0);
    for (std::size_t r = 0; r < nr; ++r) build_guide(&gcum_[r * nq], nq_, &gguide_[r * kGuideTheta], kGuideTheta);
    valid_ = true;
  }

  bool valid() const { return valid_; }
  int lobes() const { return L_; }

  /// What sample() and pdf() read besides the tables, for a renderer that samples elsewhere (a GPU:
  /// gpu_textures.hpp). With nr θr nodes, nt θd nodes, nf φ nodes, P explicit
  /// lobes: step 1's rows, per θr node r, gq [r][cell][3] (A, B, C on each of nq − 1 cells of step
  /// hq from θi = −π/2) and gcum [r][nq] (prefix masses), gguide [r][64]; step 2's lobe energies
  /// z [θd node][lobes_padded], each over its lobe's grazing factor as the tables are (a reader
  /// multiplies it back; the residual's Z it takes from the residual's N, whose factor differs by
  /// channel); step 3's rows nbar, ncum [lobe][θd node][φ node], nguide [lobe][θd node][32]. Valid
  /// while this object lives.
  struct Rows {
    const double *gq = nullptr, *gcum = nullptr, *z = nullptr, *nbar = nullptr, *ncum = nullptr;
    const std::uint16_t *gguide = nullptr, *nguide = nullptr;
    int nq = 0, lobes_padded = 0, guide_theta = kGuideTheta, guide_phi = kGuidePhi;
    double hq = 0.0;
  };
  Rows rows() const {
    Rows r;
    r.gq = gq_.data(), r.gcum = gcum_.data(), r.z = z_.data(), r.nbar = nbar_.data(), r.ncum = ncum_.data();
    r.gguide = gguide_.data(), r.nguide = nguide_.data(), r.nq = nq_, r.lobes_padded = SM_, r.hq = hq_;
    return r;
  }

  /// S per channel at θo, θi and φ = φo − φi [rad] (finite arguments).
  void eval(const Incl& o, const Incl& i, double phi, double* rgb) const {
    Terms s;
    locate(o, i, phi, s);
    combine(s, false);
    rgb[0] = s.rgb[0], rgb[1] = s.rgb[1], rgb[2] = s.rgb[2];
  }
  /// Step 1's mixture at θo; not ok where no lobe has energy.
  Point at(const Incl& o) const {
    Point pt;
    pt.o = o;
    const Cell c = tr_.at(o.theta);
    pt.r = c.i, pt.w = c.w;
    const std::size_t n = static_cast<std::size_t>(nq_ - 1);
    pt.a0 = (1.0 - c.w) * gcum_[static_cast<std::size_t>(c.i) * static_cast<std::size_t>(nq_) + n];
    pt.a1 = c.w * gcum_[static_cast<std::size_t>(c.i + 1) * static_cast<std::size_t>(nq_) + n];
    const double total = pt.a0 + pt.a1;
    pt.ok = valid_ && total > 0.0 && total < HUGE_VAL;
    return pt;
  }
  /// ∫ S̄ dω at the point's θo as step 1 holds it: the mean weight of a white fiber.
  double albedo(const Point& pt) const { return pt.ok ? pt.a0 + pt.a1 : 0.0; }
  /// The pdf per unit solid angle of drawing (θi, φ) at the point.
  double pdf(const Point& pt, const Incl& i, double phi) const {
    if (!pt.ok) return 0.0;
    Terms s;
    terms(pt.o, i, phi, s);
    return density(pt, i, s);
  }
  /// Draws (θi, φ) from u ∈ [0, 1)³ (already kept off 0 and 1 by the caller).
  Draw sample(const Point& pt, const double* u) const {
    Draw d;
    if (!pt.ok) return d;
    // 1. The θr row by u0, then θi from that row by u1.
    double u0 = u[0] * (pt.a0 + pt.a1);
    int r = pt.r;
    if (u0 < pt.a0 || !(pt.a1 > 0.0)) {
      u0 = pt.a0 > 0.0 ? u0 / pt.a0 : 0.5;
    } else {
      u0 = (u0 - pt.a0) / pt.a1, ++r;
    }
    u0 = std::min(std::max(u0, 0.0), 1.0);
    const std::size_t rr = static_cast<std::size_t>(r);
    const Incl i = incl(invert_quadratic_row(&gq_[rr * static_cast<std::size_t>(nq_ - 1) * 3], &gcum_[rr * static_cast<std::size_t>(nq_)],
                                             &gguide_[rr * kGuideTheta], kGuideTheta, nq_, ti_.lo, hq_, u[1]));
    // 2. The lobe at θi in proportion to M_q Z_q.
    Terms s;
    locate(pt.o, i, 0.0, s);
    double share[8], norm = 0.0;
    for (int p = 0; p < L_; ++p) norm += share[p] = s.m[p] * lobe_z(s.cd, s.g, p);
    if (!(norm > 0.0) || !(norm < HUGE_VAL)) return d;
    u0 *= norm;
    int q = -1;
    for (int p = 0; p < L_; ++p) {
      if (!(share[p] > 0.0)) continue;
      q = p;
      if (u0 < share[p]) break;
      u0 -= share[p];
    }
    if (q < 0) return d;
    u0 = std::min(std::max(u0 / share[q], 0.0), 1.0);
    // 3. φ: the residual uniformly; a lobe from its θd row k or k + 1 by u0, |φ| by u2 folded.
    const double pi = 3.14159265358979323846;
    double phi;
    if (q == P_) {
      phi = (2.0 * u[2] - 1.0) * pi;
    } else {
      const Cell& cd = s.cd;
      const std::size_t nt = static_cast<std::size_t>(nt_), nf = static_cast<std::size_t>(nf_);
      const double b0 = (1.0 - cd.w) * z_[static_cast<std::size_t>(cd.i) * static_cast<std::size_t>(SM_) + static_cast<std::size_t>(q)];
      const double b1 = cd.w * z_[static_cast<std::size_t>(cd.i + 1) * static_cast<std::size_t>(SM_) + static_cast<std::size_t>(q)];
      const std::size_t k = static_cast<std::size_t>(cd.i) + (u0 * (b0 + b1) < b0 || !(b1 > 0.0) ? 0 : 1);
      const std::size_t row = static_cast<std::size_t>(q) * nt + k;
      const double v = std::fabs(2.0 * u[2] - 1.0);
      phi = invert_row(&nbar_[row * nf], &ncum_[row * nf], &nguide_[row * kGuidePhi], kGuidePhi, nf_, ph_.h, v);
      if (u[2] < 0.5) phi = -phi;
    }
    s.cf = ph_.at(std::fabs(phi));
    combine(s);
    return linear_rows::drawn(density(pt, i, s), i, phi, q, s.rgb);
  }

 private:
  using Cell = linear_rows::Cell;
  using Located = linear_rows::Located;
  // The grazing factors at one cos θd: each explicit lobe's (common to the channels) and the
  // residual's per channel; all 1 where the tables store N_p as is.
  struct Factors {
    double lobe[8] = {1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0};
    double res[3] = {1.0, 1.0, 1.0};
  };
  // One evaluation: the cells of θi, θo, θd and φ, the grazing factors, M_p of every lobe, then S
  // per channel and S̄_φ.
  struct Terms {
    Cell ci, co, cd, cf;
    Factors g;
    double m[8] = {};
    double rgb[3] = {0.0, 0.0, 0.0};
    double s_phi = 0.0;  // Σ_q M_q Z_q
  };

  // What the file must hold for the sampling above to be exact: linear, edge-placed, mapped axes
  // (no explicit nodes), φ over [0, π] even, θi over the whole [−π/2, π/2].
  static bool supported(const MaterialTables<T>& t) {
    const double pi = 3.14159265358979323846;
    auto plain = [](const Axis& a) {
      return a.count >= 2 && a.interpolation == Interpolation::linear && a.placement == Placement::edges && a.spacing != Spacing::explicit_values &&
             a.wrap != Wrap::periodic && a.lo < a.hi && std::isfinite(a.lo) && std::isfinite(a.hi) && a.count <= 16384;  // cells fit the 16-bit guides
    };
    return plain(t.theta_d) && plain(t.phi) && plain(t.theta_i) && plain(t.theta_r) && t.theta_d.lo >= 0.0 && t.theta_d.hi <= 0.5 * pi + 1e-12 &&
           (t.theta_d.spacing == Spacing::uniform || t.theta_d.spacing == Spacing::cos) && t.phi.spacing == Spacing::uniform &&
           t.phi.wrap == Wrap::even && t.phi.lo == 0.0 && std::fabs(t.phi.hi - pi) < 1e-12 && t.theta_i.spacing == Spacing::uniform &&
           t.theta_r.spacing == Spacing::uniform && std::fabs(t.theta_i.lo + 0.5 * pi) < 1e-12 && std::fabs(t.theta_i.hi - 0.5 * pi) < 1e-12 &&
           t.theta_r.lo >= -0.5 * pi - 1e-12 && t.theta_r.hi <= 0.5 * pi + 1e-12;
  }
  static float clean(T v) {
    const double x = static_cast<double>(v);
    return x > 0.0 && x < 3.0e38 ? static_cast<float>(x) : 0.0f;
  }
  double lerp(const std::vector<double>& a, const Cell& c, int p) const {
    const std::size_t o = static_cast<std::size_t>(c.i) * static_cast<std::size_t>(SM_) + static_cast<std::size_t>(p);
    return (1.0 - c.w) * a[o] + c.w * a[o + static_cast<std::size_t>(SM_)];
  }
  // The factors at u = cos θd.
  void factors(double u, Factors& g) const {
    if (!graze_) return;
    u = u > 0.0 ? u : 0.0;
    for (int p = 0; p < P_; ++p) g.lobe[p] = gpow_[p] == 0 ? 1.0 : gpow_[p] == 1 ? u : u * u;
    if (!gres_.none())
      for (int c = 0; c < 3; ++c) g.res[c] = gres_.of_cos_x(gx_[c], u);
  }
  // Z_p = ∫ N̄_p dφ in θd cell d with the factors there; the residual's from its channels.
  double lobe_z(const Cell& d, const Factors& g, int p) const {
    if (p < P_) return g.lobe[p] * lerp(z_, d, p);
    const float* r = &nres_[static_cast<std::size_t>(d.i) * 4];
    double z = 0.0;
    for (int c = 0; c < 3; ++c) z += g.res[c] * ((1.0 - d.w) * r[c] + d.w * r[4 + c]);
    return 2.0 * 3.14159265358979323846 * z / 3.0;
  }
  // M_p of every lobe at (θi cell, θr cell), bilinear, over the whole padded block (its padding
  // holds zeros).
  void mp_at(const Cell& ci, const Cell& co, double* m) const {
    const std::size_t S = static_cast<std::size_t>(SM_), ni = static_cast<std::size_t>(ni_);
    const float* a = &mp_[(static_cast<std::size_t>(co.i) * ni + static_cast<std::size_t>(ci.i)) * S];
    linear_rows::bilinear_block(a, a + ni * S, SM_, (1.0 - co.w) * (1.0 - ci.w), (1.0 - co.w) * ci.w, co.w * (1.0 - ci.w), co.w * ci.w, m);
  }
  // The cells of (θo, θi, |φ| folded into [0, π]) and M_p there. cos θd comes from the sines and
  // cosines, cos((θo − θi)/2) = √((1 + cos θo cos θi + sin θo sin θi)/2), for a cos-spaced θd axis.
  void locate(const Incl& o, const Incl& i, double phi, Terms& s) const {
    const double pi = 3.14159265358979323846;
    double f = std::fabs(phi);
    if (f > pi) f = std::fabs(f - 2.0 * pi * std::floor(f / (2.0 * pi) + 0.5));
    s.ci = ti_.at(i.theta), s.co = tr_.at(o.theta), s.cf = ph_.at(f);
    if (td_.spacing == Spacing::cos) {
      const double u = std::sqrt(std::max(0.0, 0.5 * (1.0 + o.cos * i.cos + o.sin * i.sin)));
      s.cd = td_.at_t(u);
      factors(u, s.g);
    } else {
      const double half = std::fabs(0.5 * (o.theta - i.theta));
      s.cd = td_.at(half);
      if (graze_) factors(std::cos(half), s.g);
    }
    mp_at(s.ci, s.co, s.m);
  }
  // S per channel and S̄_φ from the located cells (the lobe block's size fixed where it is 4).
  void combine(Terms& s, bool with_phi = true) const {
    if (P4_ == 4) combine_block<4>(s, with_phi);
    else combine_block<0>(s, with_phi);
  }
  template <int N>
  void combine_block(Terms& s, bool with_phi) const {
    const int n = N ? N : P4_;
    const Cell &cd = s.cd, &cf = s.cf;
    const std::size_t S = static_cast<std::size_t>(SN_), nf = static_cast<std::size_t>(nf_);
    const float* a = &np_[(static_cast<std::size_t>(cd.i) * nf + static_cast<std::size_t>(cf.i)) * S];
    const float* b = a + nf * S;
    const double w00 = (1.0 - cd.w) * (1.0 - cf.w), w01 = (1.0 - cd.w) * cf.w, w10 = cd.w * (1.0 - cf.w), w11 = cd.w * cf.w;
    double mg[8];
    for (int p = 0; p < 8; ++p) mg[p] = s.m[p] * s.g.lobe[p];
    for (int c = 0; c < 3; ++c) {
      double v = 0.0;
      for (int p = 0; p < n; ++p) {
        const int k = c * n + p;
        v += mg[p] * (w00 * a[k] + w01 * a[S + k] + w10 * b[k] + w11 * b[S + k]);
      }
      s.rgb[c] = v;
    }
    double res_phi = 0.0;
    if (res_) {
      const float* r = &nres_[static_cast<std::size_t>(cd.i) * 4];
      for (int c = 0; c < 3; ++c) {
        const double v = s.m[P_] * s.g.res[c] * ((1.0 - cd.w) * r[c] + cd.w * r[4 + c]);
        s.rgb[c] += v, res_phi += v;
      }
    }
    if (!with_phi) return;
    const double* z0 = &z_[static_cast<std::size_t>(cd.i) * static_cast<std::size_t>(SM_)];
    const double* z1 = z0 + SM_;
    double sp = 0.0;
    for (int p = 0; p < P_; ++p) sp += mg[p] * ((1.0 - cd.w) * z0[p] + cd.w * z1[p]);
    s.s_phi = sp + 2.0 * 3.14159265358979323846 * res_phi / 3.0;
  }
  void terms(const Incl& o, const Incl& i, double phi, Terms& s) const {
    locate(o, i, phi, s);
    combine(s);
  }
  // q(θi) / cos θi · S̄ / S̄_φ.
  double density(const Point& pt, const Incl& i, const Terms& s) const {
    const double sbar = (s.rgb[0] + s.rgb[1] + s.rgb[2]) / 3.0;
    if (!(i.cos > 0.0) || !(s.s_phi > 0.0) || !(sbar > 0.0)) return 0.0;
    const std::size_t nc = static_cast<std::size_t>(nq_ - 1);
    const double sq = std::min(std::max((i.theta - ti_.lo) / hq_, 0.0), static_cast<double>(nc));
    const std::size_t k = std::min(static_cast<std::size_t>(sq), nc - 1);
    const double* g0 = &gq_[(static_cast<std::size_t>(pt.r) * nc + k) * 3];
    const double* g1 = g0 + 3 * nc;
    const double x = sq - static_cast<double>(k);
    const double q = (1.0 - pt.w) * (g0[0] + x * (g0[1] + x * g0[2])) + pt.w * (g1[0] + x * (g1[1] + x * g1[2]));
    return q / (pt.a0 + pt.a1) / i.cos * sbar / s.s_phi;
  }
  static void build_guide(const double* cum, int n, std::uint16_t* guide, int g) { linear_rows::build_guide(cum, n, guide, g); }
  static double invert_row(const double* v, const double* cum, const std::uint16_t* guide, int g, int n, double h, double u) {
    return linear_rows::invert_row(v, cum, guide, g, n, h, u);
  }
  static double invert_quadratic_row(const double* q, const double* cum, const std::uint16_t* guide, int g, int n, double x0, double h, double u) {
    return linear_rows::invert_quadratic_row(q, cum, guide, g, n, x0, h, u);
  }

  static constexpr int kGuideTheta = 64, kGuidePhi = 32;
  static constexpr std::size_t kSplit = 4;

  bool valid_ = false, res_ = false;
  bool graze_ = false;                  // some lobe's tables are divided by a grazing factor
  int gpow_[8] = {};                    // the explicit lobes' factors: cos^n θd
  GrazingFactor gres_;                  // the residual's
  double gx_[3] = {0.0, 0.0, 0.0};      // and its x per channel (GrazingFactor::x_of)
  int nq_ = 0;       // θi nodes of step 1's rows
  double hq_ = 0.0;  // and their step
  int P_ = 0, L_ = 0, P4_ = 0, SM_ = 0, SN_ = 0;
  int nt_ = 0, nf_ = 0, ni_ = 0, nr_ = 0;
  Located td_, ph_, ti_, tr_;
  std::vector<float> mp_, np_, nres_;
  std::vector<double> z_, nbar_, ncum_, gq_, gcum_;
  std::vector<std::uint16_t> gguide_, nguide_;  // guides of step 1's and step 3's rows
};

}  // namespace sampler
}  // namespace hairlut
