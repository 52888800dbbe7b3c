#include "hairlut/physics/material_np.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/util/vector_math.hpp"
#include "hairlut/physics/fiber_geometry.hpp"
#include "hairlut/physics/fresnel.hpp"

namespace hairlut {
namespace {

// max(x, 0) as std::max(0.0, x) gives it (NaN and −0 to +0), without a branch: maxsd returns its
// second operand unless the first is greater (GCC compiles the conditional to a compare and a
// jump, which mispredicts on values near 0).
inline double nonnegative(double x) {
#if defined(__SSE2__)
  return _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(x), _mm_setzero_pd()));
#else
  return x > 0.0 ? x : 0.0;
#endif
}

// sums[k] = Σ_{i < m} a[k · m + i] for k < n ≤ 4, each in increasing i from 0 (the order of a
// plain loop), the n sums advancing together.
void plane_sums(const double* a, std::size_t m, std::size_t n, double* sums) {
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  const double *a0 = a, *a1 = a + m, *a2 = a + 2 * m, *a3 = a + 3 * m;
  switch (n) {
    case 4: for (std::size_t i = 0; i < m; ++i) s0 += a0[i], s1 += a1[i], s2 += a2[i], s3 += a3[i]; break;
    case 3: for (std::size_t i = 0; i < m; ++i) s0 += a0[i], s1 += a1[i], s2 += a2[i]; break;
    case 2: for (std::size_t i = 0; i < m; ++i) s0 += a0[i], s1 += a1[i]; break;
    default: for (std::size_t i = 0; i < m; ++i) s0 += a0[i];
  }
  sums[0] = s0, sums[1] = s1, sums[2] = s2, sums[3] = s3;
}

// Points 2R + 1 of a detector window: the Gaussian is cut where it falls below tolerance/2 of its peak.
long window_radius(double beta, double step, double tolerance) {
  return static_cast<long>(std::ceil(std::sqrt(2.0 * std::log(2.0 / tolerance)) * beta / step));
}

// A window of 2R + 1 points runs over a multiple of 4 slots (at least 8), the extra ones zero
// (adding an exact 0 leaves every sum as it was): inner loops of a fixed length without remainder.
std::size_t window_run(long R) { return std::max<std::size_t>(8, (static_cast<std::size_t>(2 * R + 1) + 3) / 4 * 4); }

// b[j] += a · w[j] for j < Run (a compile-time length: unrolled, two lanes at a time).
template <std::size_t Run>
[[gnu::always_inline]] inline void add_window(double* b, double a, const double* w) {
#pragma omp simd
  for (std::size_t j = 0; j < Run; ++j) b[j] += a * w[j];
}
[[gnu::always_inline]] inline void add_window(double* b, double a, const double* w, std::size_t run) {
  switch (run) {
    case 8: return add_window<8>(b, a, w);
    case 12: return add_window<12>(b, a, w);
    case 16: return add_window<16>(b, a, w);
    case 20: return add_window<20>(b, a, w);
    case 24: return add_window<24>(b, a, w);
    case 28: return add_window<28>(b, a, w);
    case 32: return add_window<32>(b, a, w);
    default:
#pragma omp simd
      for (std::size_t j = 0; j < run; ++j) b[j] += a * w[j];
  }
}

// out[k · points + j] = Σ_{n ≤ N} v[n · vstride + k] cos nφ_j for k < Planes (cos_table as [n][j]),
// each sum taken in increasing n from 0 (CosineSeries's order), two points at a time with the
// planes in registers.
template <std::size_t Planes>
void cosine_sums(const double* cos_table, std::size_t points, const double* v, std::size_t vstride, std::size_t N, double* out) {
  std::size_t j = 0;
  for (; j + 2 <= points; j += 2) {
    double a[Planes][2] = {};
    for (std::size_t n = 0; n <= N; ++n) {
      const double c0 = cos_table[n * points + j], c1 = cos_table[n * points + j + 1];
      for (std::size_t k = 0; k < Planes; ++k) {
        a[k][0] += v[n * vstride + k] * c0;
        a[k][1] += v[n * vstride + k] * c1;
      }
    }
    for (std::size_t k = 0; k < Planes; ++k) out[k * points + j] = a[k][0], out[k * points + j + 1] = a[k][1];
  }
  for (; j < points; ++j)
    for (std::size_t k = 0; k < Planes; ++k) {
      double sum = 0.0;
      for (std::size_t n = 0; n <= N; ++n) sum += v[n * vstride + k] * cos_table[n * points + j];
      out[k * points + j] = sum;
    }
}

// The same for three planes sharing the window (the RGB channels of a lobe): each window value
// loaded once; every sum gets the same operations as three add_window calls.
template <std::size_t Run>
[[gnu::always_inline]] inline void add_window3(double* b0, double* b1, double* b2, const double* a, const double* w) {
  const double a0 = a[0], a1 = a[1], a2 = a[2];
#pragma omp simd
  for (std::size_t j = 0; j < Run; ++j) {
    b0[j] += a0 * w[j];
    b1[j] += a1 * w[j];
    b2[j] += a2 * w[j];
  }
}
[[gnu::always_inline]] inline void add_window3(double* b0, double* b1, double* b2, const double* a, const double* w, std::size_t run) {
  switch (run) {
    case 8: return add_window3<8>(b0, b1, b2, a, w);
    case 12: return add_window3<12>(b0, b1, b2, a, w);
    case 16: return add_window3<16>(b0, b1, b2, a, w);
    case 20: return add_window3<20>(b0, b1, b2, a, w);
    case 24: return add_window3<24>(b0, b1, b2, a, w);
    default:
      for (int k = 0; k < 3; ++k) add_window(k == 0 ? b0 : k == 1 ? b1 : b2, a[k], w, run);
  }
}

// Loops of element-wise arithmetic compiled for AVX2 as well as for the baseline ISA, the loader
// choosing by the CPU (GCC's target_clones): the AVX2 version does the same multiplies, adds,
// divisions and square roots four values at a time (AVX2 without FMA: no fused multiply–add, and
// no sums reordered), so the values are the same bits on every CPU.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define HAIRLUT_AVX2_CLONES [[gnu::target_clones("avx2", "default")]]
#else
#define HAIRLUT_AVX2_CLONES
#endif

// Every node's window added to every plane, a node at a time in increasing i: node i adds
// a[i · planes + k] · win[i · run + j] to slot j of plane k, b[start[i] + k · stride + j], three
// planes per window load when planes is a multiple of 3 (RGB, or several materials' RGB). One
// call per lobe, the window's length a constant of the loop.
template <std::size_t Run>
[[gnu::always_inline]] inline void spread_nodes_of(double* b, std::size_t stride, const double* a, std::size_t planes, const double* win,
                                                   const long* start, std::size_t m, std::size_t run) {
  for (std::size_t i = 0; i < m; ++i) {
    double* bi = b + start[i];
    const double* ai = a + i * planes;
    const double* wi = win + i * run;
    if (planes % 3 == 0) {
      for (std::size_t k = 0; k < planes; k += 3) {
        if constexpr (Run > 0) add_window3<Run>(bi + k * stride, bi + (k + 1) * stride, bi + (k + 2) * stride, ai + k, wi);
        else add_window3(bi + k * stride, bi + (k + 1) * stride, bi + (k + 2) * stride, ai + k, wi, run);
      }
    } else {
      for (std::size_t k = 0; k < planes; ++k) {
        if constexpr (Run > 0) add_window<Run>(bi + k * stride, ai[k], wi);
        else add_window(bi + k * stride, ai[k], wi, run);
      }
    }
  }
}
HAIRLUT_AVX2_CLONES
void spread_nodes(double* b, std::size_t stride, const double* a, std::size_t planes, const double* win, const long* start, std::size_t m,
                  std::size_t run) {
  switch (run) {
    case 8: return spread_nodes_of<8>(b, stride, a, planes, win, start, m, run);
    case 12: return spread_nodes_of<12>(b, stride, a, planes, win, start, m, run);
    case 16: return spread_nodes_of<16>(b, stride, a, planes, win, start, m, run);
    case 20: return spread_nodes_of<20>(b, stride, a, planes, win, start, m, run);
    case 24: return spread_nodes_of<24>(b, stride, a, planes, win, start, m, run);
    default: return spread_nodes_of<0>(b, stride, a, planes, win, start, m, run);
  }
}

// Per node i < m (st = sin γt, cg = cos γ): the path length len (2 cos γt, or 4 cos² γt), and the
// unpolarised Fresnel f at cos θd cos γ from outside (η > 1: never total reflection) and its
// complement omf = 1 − f in the cancellation-free form.
HAIRLUT_AVX2_CLONES
void path_and_fresnel(std::size_t m, const double* st, const double* cg, double cos_theta_d, double eta, bool chord, double* len, double* f,
                      double* omf) {
#pragma omp simd
  for (std::size_t i = 0; i < m; ++i) {
    const double s = st[i];
    const double ct = std::sqrt((1.0 - s) * (1.0 + s));
    len[i] = chord ? 2.0 * ct : 4.0 * ct * ct;
    const double c = cos_theta_d * cg[i];
    const double ctr = std::sqrt(1.0 - (1.0 - c) * (1.0 + c) / (eta * eta));
    const double ds = c + eta * ctr, dp = eta * c + ctr;
    const double rs = (c - eta * ctr) / ds, rp = (eta * c - ctr) / dp;
    const double num = 4.0 * eta * c * ctr;
    f[i] = std::min(1.0, 0.5 * (rs * rs + rp * rp));
    omf[i] = std::min(1.0, 0.5 * (num / (ds * ds) + num / (dp * dp)));
  }
}

// Above this many (terms + 1) × points the Fourier sums go through CosineSeries (which folds terms
// beyond a periodic grid's period) instead of a table of cos nφ_j of their own.
constexpr std::size_t kCosineTable = std::size_t{1} << 16;

// Work estimates (multiply–adds, an exponential counted as 8) of one (θd, lobe) on m nodes, with
// `planes` channels summed (1 for R, whose amplitude f does not depend on σa).
double spread_work(int m, long R, std::size_t planes, bool window_fixed) {
  const double W = 2.0 * static_cast<double>(R) + 1.0;
  return m * (W * static_cast<double>(planes) + (window_fixed ? 0.0 : 3.0 * W + 24.0));
}
double fourier_work(int m, int terms, std::size_t planes, std::size_t points) {
  const double N = terms + 1.0;
  return m * N * (static_cast<double>(planes) + 3.0) + static_cast<double>(planes) * static_cast<double>(points) * std::min(N, 2.0 * static_cast<double>(points));
}

}  // namespace

struct MaterialNp::Row {
  FiberGeometry g;
  std::size_t m = 0, K = 0;
  std::vector<double> st, gt, len, f, omf, T, fpow, tpow, amp;  // T, tpow, amp: [k · m + i]
  std::vector<double> centre, d0, g0, rr, win, buf, circle, scale;  // win: [i · run + j]; scale: [i · planes + k]
  std::vector<long> start;
  std::vector<double> vr, vi, phase, zr, zi, sr, si, C, v, series_row;  // the Fourier form
  bool rotations = false;  // vr, vi hold e^{2iγt} of this θd
};

MaterialNp::MaterialNp(MaterialNpRequest request) : r_(std::move(request)), grid_(PeriodicGrid::of(r_.phis)) {
  if (r_.betas.empty()) throw DomainError("a per-material N_p bake needs at least one lobe");
  for (double b : r_.betas) require_positive("beta", b);
  for (double s : r_.sigmas) require_non_negative("sigma_a", s);
  if (!(r_.tolerance > 0.0 && r_.tolerance < 1.0)) throw_domain_error("tolerance", "must lie in (0, 1)", r_.tolerance);
  if (grid_.period <= 0) note_ = PeriodicGrid::why_not(r_.phis);
  const std::size_t nt = r_.thetas.size(), L = r_.betas.size(), K = r_.sigmas.size(), nphi = r_.phis.size();
  const double tol = r_.tolerance;
  const double step = grid_.period > 0 ? kTwoPi / grid_.period : 0.0;
  spread_.assign(nt * L, 0);
  m_.assign(nt, 0);
  terms_.resize(L);
  window_.assign(L, 0);
  series_weight_.resize(L);
  int max_terms = 0;
  for (std::size_t p = 0; p < L; ++p) {
    const double beta = r_.betas[p];
    terms_[p] = fourier_terms(beta, tol);
    if (grid_.period > 0) {
      Window wp;
      wp.R = window_radius(beta, step, tol);
      wp.run = window_run(wp.R);
      wp.inv2var = 1.0 / (2.0 * beta * beta);
      wp.norm = 1.0 / (std::sqrt(kTwoPi) * beta);
      wp.recurrence = step / beta <= 20.0;
      for (long j = -wp.R; j <= wp.R; ++j) wp.c.push_back(std::exp(-static_cast<double>(j * j) * step * step * wp.inv2var));
      const long P = grid_.period;  // padded slot q holds circle point (q − R) mod P
      for (long q = 0; q < P + static_cast<long>(wp.run) - 1; ++q) wp.fold.push_back(static_cast<std::uint32_t>(((q - wp.R) % P + P) % P));
      window_[p] = static_cast<int>(2 * wp.R + 1);
      windows_.push_back(std::move(wp));
    }
    for (int n = 0; n <= terms_[p]; ++n)
      series_weight_[p].push_back((n ? 2.0 : 1.0) * std::exp(-0.5 * static_cast<double>(n) * n * beta * beta) / kTwoPi);
  }
  // The node counts depend on θd only through the phase rate max(|2p/η' − 2|, 2) (constant in θd
  // for p ≤ 2), so they are computed once per lobe and rate.
  std::map<std::pair<std::size_t, double>, int> counts;
  for (std::size_t t = 0; t < nt; ++t) {
    const FiberGeometry g = FiberGeometry::make(r_.eta, r_.thetas[t]);
    for (std::size_t p = 0; p < L; ++p) {
      const double rate = std::max(std::abs(2.0 * static_cast<double>(p) * g.inv_eta_prime - 2.0), 2.0);
      auto it = counts.find({p, rate});
      if (it == counts.end()) it = counts.emplace(std::pair{p, rate}, material_np_nodes(r_.betas[p], static_cast<int>(p), g, tol)).first;
      m_[t] = std::max(m_[t], it->second);
    }
    // The choice for one material's channels (MaterialNpRequest::channels), however many share the bake.
    const std::size_t per_material = r_.channels > 0 ? std::min(r_.channels, K) : K;
    for (std::size_t p = 0; p < L; ++p) {
      const std::size_t planes = p == 0 ? 1 : per_material;
      const bool spread = grid_.period > 0 &&
                          spread_work(m_[t], window_radius(r_.betas[p], step, tol), planes, p == 0) < fourier_work(m_[t], terms_[p], planes, nphi);
      spread_[t * L + p] = spread;
      if (!spread) max_terms = std::max(max_terms, terms_[p]);
    }
  }
  // The rules, with R's windows where R spreads (Φ = −2γ: the same at every θd).
  Row row;
  for (std::size_t t = 0; t < nt; ++t) {
    const int m = m_[t];
    if (nodes_.count(m)) continue;
    static_cast<TransplantedRule&>(nodes_[m]) = r_.rules ? r_.rules->get(m, tol) : transplanted_rule(m, tol);
  }
  for (std::size_t t = 0; t < nt; ++t) {
    RuleNodes& n = nodes_[m_[t]];
    if (!spread_[t * L] || !n.r_start.empty()) continue;
    const std::size_t m = n.gamma.size(), run = windows_[0].run;
    std::vector<double> centre(m);
    for (std::size_t i = 0; i < m; ++i) centre[i] = -2.0 * n.gamma[i];
    anchor_windows(0, centre.data(), m, row);
    n.r_start = row.start;
    n.r_window.assign(m * run, 0.0);
    for (std::size_t i = 0; i < m; ++i) window_values(0, i, row, n.r_window.data() + i * run);
  }
  if (grid_.period > 0) {  // φ_j and its mirror −φ_j as circle points
    const long P = grid_.period, shift = std::lround(-2.0 * grid_.phi0 / step);
    for (std::size_t j = 0; j < nphi; ++j) {
      here_.push_back(static_cast<std::uint32_t>(static_cast<long>(j) % P));
      mirror_.push_back(static_cast<std::uint32_t>(((shift - static_cast<long>(j)) % P + P) % P));
    }
  }
  if (max_terms > 0 && static_cast<std::size_t>(max_terms + 1) * nphi <= kCosineTable) {
    cos_terms_ = max_terms;
    for (int nn = 0; nn <= max_terms; ++nn)
      for (std::size_t j = 0; j < nphi; ++j) cos_table_.push_back(std::cos(static_cast<double>(nn) * r_.phis[j]));
  } else if (max_terms > 0) {
    series_ = std::make_unique<CosineSeries>(r_.phis, max_terms);
  }
}

// Anchors the windows of Gaussians centred at centre[0 … m): per node the padded-circle slot of
// its first point, d0, g0 = e^{−d0²/2β²} and r = e^{−d0Δ/β²} (two exponentials over arrays).
void MaterialNp::anchor_windows(std::size_t p, const double* centre, std::size_t m, Row& row) const {
  const Window& w = windows_[p];
  const auto P = static_cast<long>(grid_.period);
  const double step = kTwoPi / static_cast<double>(P);
  row.start.resize(m), row.d0.resize(m), row.g0.resize(m), row.rr.resize(m);
  for (std::size_t i = 0; i < m; ++i) {
    const double u = (centre[i] - grid_.phi0) / step;
    const double jr = (u + 0x1.8p52) - 0x1.8p52;  // nearest integer (|u| < 2^51)
    const double d0 = (jr - u) * step;
    row.d0[i] = d0;
    row.g0[i] = -d0 * d0 * w.inv2var;
    row.rr[i] = -2.0 * d0 * step * w.inv2var;
    long r0 = static_cast<long>(jr) % P;
    row.start[i] = r0 < 0 ? r0 + P : r0;  // slot q holds circle point (q − R) mod P
  }
  exp_in_place(std::span<double>(row.g0.data(), m));
  exp_in_place(std::span<double>(row.rr.data(), m));
}

// Node i's window: win[R + j] = g(d0 + jΔ) for |j| ≤ R (slots beyond 2R + 1 left as they are).
void MaterialNp::window_values(std::size_t p, std::size_t i, const Row& row, double* win) const {
  const Window& w = windows_[p];
  const long R = w.R;
  if (w.recurrence) {
    double up = row.g0[i], down = row.g0[i];
    const double r = row.rr[i], rinv = 1.0 / row.rr[i];
    win[R] = up;
    for (long j = 1; j <= R; ++j) {
      up *= r;
      down *= rinv;
      win[R + j] = up * w.c[static_cast<std::size_t>(R + j)];
      win[R - j] = down * w.c[static_cast<std::size_t>(R - j)];
    }
  } else {
    const double step = kTwoPi / static_cast<double>(grid_.period);
    for (long j = -R; j <= R; ++j) {
      const double d = row.d0[i] + static_cast<double>(j) * step;
      win[j + R] = std::exp(-d * d * w.inv2var);
    }
  }
}

// The factors of every node of θd node t that do not depend on the lobe: γt, the path length,
// f and 1 − f, and T = e^{−σa' ℓ} per channel.
void MaterialNp::node_factors(std::size_t t, Row& row) const {
  const FiberGeometry& g = row.g;
  const RuleNodes& n = nodes_.at(m_[t]);
  const std::size_t m = n.gamma.size(), K = r_.sigmas.size();
  row.m = m, row.K = K;
  row.st.resize(m), row.gt.resize(m), row.len.resize(m), row.f.resize(m), row.omf.resize(m), row.T.resize(K * m);
  const double a = g.inv_eta_prime, eta = g.eta;
  for (std::size_t i = 0; i < m; ++i) row.st[i] = n.sin_gamma[i] * a;
  for (std::size_t i = 0; i < m; ++i) row.gt[i] = std::asin(row.st[i]);
  path_and_fresnel(m, row.st.data(), n.cos_gamma.data(), g.cos_theta_d, eta, r_.path == AbsorptionPath::chord, row.len.data(), row.f.data(),
                   row.omf.data());
  for (std::size_t k = 0; k < K; ++k) {
    const double sp = reduced_absorption(r_.sigmas[k], g);
    double* T = row.T.data() + k * m;
    for (std::size_t i = 0; i < m; ++i) T[i] = -sp * row.len[i];
  }
  exp_in_place(std::span<double>(row.T.data(), K * m));
}

void MaterialNp::evaluate(std::size_t t, std::vector<double>& out, std::vector<double>* energies) const {
  const std::size_t L = r_.betas.size(), K = r_.sigmas.size(), nphi = r_.phis.size(), E = L;
  thread_local Row row;
  row.g = FiberGeometry::make(r_.eta, r_.thetas[t]);
  node_factors(t, row);
  row.rotations = false;
  const RuleNodes& n = nodes_.at(m_[t]);
  const std::size_t m = row.m;
  out.resize(L * K * nphi);  // every value written by its lobe's spread_lobe or fourier_lobe
  if (energies) energies->assign(K * E, 0.0);
  // A(p) = f for p = 0, (1 − f)² f^{p−1} T^p after: the powers of lobe p from those of lobe p − 1.
  // amp = W · A: [i] for R (the same for every σa), [i · K + k] after.
  row.fpow.resize(m);
  row.tpow.assign(K * m, 1.0);
  for (std::size_t p = 0; p < L; ++p) {
    if (p == 0) std::copy(row.f.begin(), row.f.end(), row.fpow.begin());
    else if (p == 1) for (std::size_t i = 0; i < m; ++i) row.fpow[i] = row.omf[i] * row.omf[i];
    else for (std::size_t i = 0; i < m; ++i) row.fpow[i] *= row.f[i];
    if (p > 0)
      for (std::size_t q = 0; q < K * m; ++q) row.tpow[q] *= row.T[q];
    const std::size_t planes = p == 0 ? 1 : K;
    row.amp.resize(m * planes);
    for (std::size_t i = 0; i < m; ++i) row.amp[i] = n.weight[i] * row.fpow[i];
    for (std::size_t k = planes; k-- > 0;)  // in place: plane 0 last
      for (std::size_t i = 0; i < m; ++i) row.amp[k * m + i] = row.amp[i] * row.tpow[k * m + i];
    if (energies) {  // ∫N_p dφ = Σ W A: the quadrature of N_p with D replaced by its integral 1
      // Each plane's sum in increasing i; four planes side by side (four independent chains of
      // additions instead of one), R's single plane once for every channel.
      double sums[4];
      for (std::size_t k0 = 0; k0 < planes; k0 += 4) {
        const std::size_t n4 = std::min<std::size_t>(4, planes - k0);
        plane_sums(row.amp.data() + k0 * m, m, n4, sums);
        for (std::size_t k = k0; k < k0 + n4; ++k) (*energies)[k * E + p] = sums[k - k0];
      }
      if (planes == 1)
        for (std::size_t k = 1; k < K; ++k) (*energies)[k * E + p] = sums[0];
    }
    if (spread_[t * L + p]) spread_lobe(p, n, row, out);
    else fourier_lobe(p, n, row, out);
  }
}

// Spreading: N(φ_j) = ½ Σ_i W_i A_i [g(φ_j − Φ_i) + g(φ_j + Φ_i)], each node's Gaussian added to
// the circle points of its window, on a circle padded by the window radius on both sides and
// folded at the end, so that the inner loop is a straight run of multiply–adds per channel.
void MaterialNp::spread_lobe(std::size_t p, const RuleNodes& n, Row& row, std::vector<double>& out) const {
  const std::size_t K = row.K, m = row.m, nphi = r_.phis.size();
  const Window& w = windows_[p];
  const std::size_t planes = p == 0 ? 1 : K, run = w.run;
  const auto P = static_cast<long>(grid_.period);
  const std::size_t stride = static_cast<std::size_t>(P) + run - 1;
  row.buf.assign(stride * planes, 0.0);
  const bool fixed = p == 0;  // R's windows were computed with the rule
  if (!fixed) {
    row.centre.resize(m);
    for (std::size_t i = 0; i < m; ++i) row.centre[i] = exit_azimuth(static_cast<int>(p), n.gamma[i], row.gt[i]);
    anchor_windows(p, row.centre.data(), m, row);
    row.win.assign(m * run, 0.0);  // the slots beyond 2R + 1 stay 0
    for (std::size_t i = 0; i < m; ++i) window_values(p, i, row, row.win.data() + i * run);
  }
  // Each node's amplitude times the detector's norm, node by node: scale[i · planes + k].
  const double* amp = row.amp.data();
  row.scale.resize(m * planes);
  for (std::size_t k = 0; k < planes; ++k)
    for (std::size_t i = 0; i < m; ++i) row.scale[i * planes + k] = amp[k * m + i] * w.norm;
  spread_nodes(row.buf.data(), stride, row.scale.data(), planes, fixed ? n.r_window.data() : row.win.data(), fixed ? n.r_start.data() : row.start.data(),
               m, run);
  // Fold the padding onto the circle, then N(φ_j) = ½ (circle(φ_j) + circle(−φ_j)). Circle point
  // j is slot R + j; when each circle point gets at most one wrapped slot, the padding is added
  // in place (the slots it adds to and the ones it reads are distinct); otherwise into a circle
  // of its own.
  const auto Pu = static_cast<std::size_t>(P);
  const auto R = static_cast<std::size_t>(w.R);
  const bool in_place = run - 1 <= Pu;
  if (!in_place) row.circle.assign(Pu * planes, 0.0);
  for (std::size_t k = 0; k < planes; ++k) {
    double* b = row.buf.data() + k * stride;
    if (in_place) {
      for (std::size_t q = 0; q < R; ++q) b[Pu + q] += b[q];
      for (std::size_t q = R + Pu; q < stride; ++q) b[q - Pu] += b[q];
    } else {
      double* c = row.circle.data() + k * Pu;
      for (std::size_t q = 0; q < stride; ++q) c[w.fold[q]] += b[q];
    }
  }
  for (std::size_t k = 0; k < K; ++k) {
    const std::size_t plane = planes == 1 ? 0 : k;
    const double* c = in_place ? row.buf.data() + plane * stride + R : row.circle.data() + plane * Pu;
    double* o = out.data() + (p * K + k) * nphi;
    for (std::size_t j = 0; j < nphi; ++j) o[j] = nonnegative(0.5 * (c[here_[j]] + c[mirror_[j]]));
  }
}

// The Fourier form (fourier_coefficients) with what the lobes and channels of a θd share: the
// node factors once, e^{iΦ_p} = (−1)^p e^{−2iγ} (e^{2iγt})^p from one sine and cosine per node
// (e^{−2iγ} once per rule), R's coefficients once for every channel. C_n by rotating z^n,
// re-anchored with exact cos and sin of nΦ every 32 steps.
void MaterialNp::fourier_lobe(std::size_t p, const RuleNodes& n, Row& row, std::vector<double>& out) const {
  const std::size_t K = row.K, m = row.m, nphi = r_.phis.size();
  const std::size_t planes = p == 0 ? 1 : K;
  const int pi = static_cast<int>(p);
  const auto N = static_cast<std::size_t>(terms_[p]);
  if (!row.rotations) {  // e^{2iγt}, once per θd
    row.vr.resize(m), row.vi.resize(m);
    for (std::size_t i = 0; i < m; ++i) row.vr[i] = std::cos(2.0 * row.gt[i]), row.vi[i] = std::sin(2.0 * row.gt[i]);
    row.rotations = true;
  }
  // e^{iΦ} of every node (nodes of zero amplitude add exact zeros).
  row.phase.resize(m), row.sr.resize(m), row.si.resize(m);
  const double sign = pi % 2 ? -1.0 : 1.0;
  for (std::size_t i = 0; i < m; ++i) {
    double er = sign * n.cos_2gamma[i], ei = -sign * n.sin_2gamma[i];  // (−1)^p e^{−2iγ}
    for (int q = 0; q < pi; ++q) {
      const double r = er * row.vr[i] - ei * row.vi[i];
      ei = er * row.vi[i] + ei * row.vr[i];
      er = r;
    }
    row.sr[i] = er, row.si[i] = ei;
    row.phase[i] = exit_azimuth(pi, n.gamma[i], row.gt[i]);
  }
  const double* amp = row.amp.data();  // [k · m + i]
  row.C.assign((N + 1) * planes, 0.0);
  row.zr.assign(m, 1.0), row.zi.assign(m, 0.0);
  double* zr = row.zr.data();
  double* zi = row.zi.data();
  const double* sr = row.sr.data();
  const double* si = row.si.data();
  const std::size_t m4 = m / 4 * 4;
  for (std::size_t nn = 0; nn <= N; ++nn) {
    if (nn % 32 == 0 && nn > 0)
      for (std::size_t i = 0; i < m; ++i) {
        const double arg = static_cast<double>(nn) * row.phase[i];
        zr[i] = std::cos(arg), zi[i] = std::sin(arg);
      }
    // C_n = Σ_i Re(z_i^n) amp_i in four interleaved partial sums (a fixed order: the same result
    // for any vector width).
    for (std::size_t k = 0; k < planes; ++k) {
      const double* a = amp + k * m;
      double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
      for (std::size_t i = 0; i < m4; i += 4) {
        s0 += zr[i] * a[i];
        s1 += zr[i + 1] * a[i + 1];
        s2 += zr[i + 2] * a[i + 2];
        s3 += zr[i + 3] * a[i + 3];
      }
      for (std::size_t i = m4; i < m; ++i) s0 += zr[i] * a[i];
      row.C[nn * planes + k] = (s0 + s1) + (s2 + s3);
    }
#pragma omp simd
    for (std::size_t i = 0; i < m; ++i) {
      const double r = zr[i] * sr[i] - zi[i] * si[i];
      zi[i] = zr[i] * si[i] + zi[i] * sr[i];
      zr[i] = r;
    }
  }
  const std::vector<double>& weight = series_weight_[p];
  row.v.resize((N + 1) * planes);
  for (std::size_t nn = 0; nn <= N; ++nn)
    for (std::size_t k = 0; k < planes; ++k) row.v[nn * planes + k] = weight[nn] * row.C[nn * planes + k];
  row.series_row.resize(planes * nphi);
  double* o = row.series_row.data();  // [k · nphi + j]
  if (series_) {
    std::vector<double> vk(N + 1);
    for (std::size_t k = 0; k < planes; ++k) {
      for (std::size_t nn = 0; nn <= N; ++nn) vk[nn] = row.v[nn * planes + k];
      series_->evaluate(vk, std::span<double>(o + k * nphi, nphi));
    }
  } else if (planes % 3 == 0) {  // RGB, or the RGB of several materials, three planes at a time
    for (std::size_t k = 0; k < planes; k += 3) cosine_sums<3>(cos_table_.data(), nphi, row.v.data() + k, planes, N, o + k * nphi);
  } else if (planes == 1) {
    cosine_sums<1>(cos_table_.data(), nphi, row.v.data(), 1, N, o);
  } else {
    for (std::size_t k = 0; k < planes; ++k)
      for (std::size_t j = 0; j < nphi; ++j) {
        double sum = 0.0;
        for (std::size_t nn = 0; nn <= N; ++nn) sum += row.v[nn * planes + k] * cos_table_[nn * nphi + j];
        o[k * nphi + j] = sum;
      }
  }
  for (std::size_t k = 0; k < K; ++k) {
    const double* src = o + (planes == 1 ? 0 : k) * nphi;
    double* dst = out.data() + (p * K + k) * nphi;
    for (std::size_t j = 0; j < nphi; ++j) dst[j] = nonnegative(src[j]);  // roundoff below 0 clamped
  }
}

void material_energies(double eta, double theta_d, AbsorptionPath path, std::span<const double> sigmas, LobeSet lobes,
                       const GaussLegendreRule& rule, std::vector<double>& out) {
  if (lobes.count < 1 || lobes.count > 1000) throw_domain_error("lobe count", "must lie in [1, 1000]", static_cast<long long>(lobes.count));
  const FiberGeometry g = FiberGeometry::make(eta, theta_d);
  const std::size_t K = sigmas.size(), E = static_cast<std::size_t>(lobes.size()), P = static_cast<std::size_t>(lobes.count);
  std::vector<double> sp(K);
  for (std::size_t k = 0; k < K; ++k) {
    require_non_negative("sigma_a", sigmas[k]);
    sp[k] = reduced_absorption(sigmas[k], g);
  }
  out.assign(K * E, 0.0);
  const auto x = rule.nodes();
  const auto w = rule.weights();
  const double half = 0.25 * kPi;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double gamma = half * (1.0 + x[i]);
    const double ci = std::cos(gamma), st = std::sin(gamma) * g.inv_eta_prime;
    const double ct = std::sqrt((1.0 - st) * (1.0 + st));
    const double c = g.cos_theta_d * ci;
    const double f = fresnel_reflectance(g.eta, c), omf = fresnel_transmittance(g.eta, c);
    const double len = path == AbsorptionPath::chord ? 2.0 * ct : 4.0 * ct * ct;
    for (std::size_t k = 0; k < K; ++k) {
      const double tau = sp[k] * len, T = std::exp(-tau);
      double* o = out.data() + k * E;
      // A(p) = f for p = 0, (1 − f)² f^{p−1} T^p after (PathPoint::attenuation), times cos γ.
      o[0] += w[i] * (f * ci);
      double fp = 1.0, tp = T;
      for (std::size_t p = 1; p < P; ++p, fp *= f, tp *= T) o[p] += w[i] * (omf * omf * fp * tp * ci);
      if (lobes.residual) {
        const double denom = omf + f * -std::expm1(-tau);  // 1 − fT without cancellation
        const double r = denom <= 0.0 ? 0.0 : std::min(1.0, omf * omf * std::pow(f, static_cast<double>(P) - 1.0) * std::pow(T, static_cast<double>(P)) / denom);
        o[P] += w[i] * (r * ci);
      }
    }
  }
  for (double& v : out) v *= half;
}

}  // namespace hairlut
