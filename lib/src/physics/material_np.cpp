#include "hairlut/physics/material_np.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/fiber_geometry.hpp"
#include "hairlut/physics/fresnel.hpp"

namespace hairlut {
MaterialNp::MaterialNp(MaterialNpRequest request) : r_(std::move(request)), grid_(PeriodicGrid::of(r_.phis)) {
  if (r_.betas.empty()) throw DomainError("a per-material N_p bake needs at least one lobe");
  for (double b : r_.betas) require_positive("beta", b);
  for (double s : r_.sigmas) require_non_negative("sigma_a", s);
  if (grid_.period <= 0) note_ = PeriodicGrid::why_not(r_.phis);
  const std::size_t nt = r_.thetas.size(), L = r_.betas.size(), K = r_.sigmas.size(), nphi = r_.phis.size();
  const double tol = r_.tolerance;
  spread_.assign(nt * L, 0);
  spread_m_.assign(nt, 0);
  fourier_m_.assign(nt, 0);
  terms_.resize(L);
  for (std::size_t p = 0; p < L; ++p) terms_[p] = fourier_terms(r_.betas[p], tol);
  int max_terms = 0;
  // The node counts depend on θd only through the largest phase rate max(|2p/η' − 2|, 2) (constant
  // in θd for p ≤ 2), so they are computed once per lobe and rate.
  std::map<std::pair<std::size_t, double>, std::pair<int, int>> counts;
  for (std::size_t t = 0; t < nt; ++t) {
    const FiberGeometry g = FiberGeometry::make(r_.eta, r_.thetas[t]);
    for (std::size_t p = 0; p < L; ++p) {
      const int pi = static_cast<int>(p);
      const double beta = r_.betas[p];
      const double rate = std::max(std::abs(2.0 * pi * g.inv_eta_prime - 2.0), 2.0);
      auto it = counts.find({p, rate});
      if (it == counts.end()) it = counts.emplace(std::pair{p, rate}, std::pair{spread_nodes(beta, pi, g, tol), fourier_nodes(terms_[p], pi, g, tol)}).first;
      const int ms = it->second.first, mf = it->second.second;
      const bool spread = spread_cost(beta, ms, K, grid_, tol) < fourier_cost(terms_[p], mf, K, 1, nphi);
      spread_[t * L + p] = spread;
      if (spread) spread_m_[t] = std::max(spread_m_[t], ms);
      else fourier_m_[t] = std::max(fourier_m_[t], mf), max_terms = std::max(max_terms, terms_[p]);
    }
  }
  std::vector<double> x, w;
  for (std::size_t t = 0; t < nt; ++t)
    for (const int m : {spread_m_[t], fourier_m_[t]}) {
      if (m == 0 || nodes_.count(m)) continue;
      newton_gauss_legendre(m, x, w);
      RuleNodes& n = nodes_[m];
      for (std::size_t i = 0; i < x.size(); ++i) {
        const double gamma = 0.25 * kPi * (1.0 + x[i]);
        n.gamma.push_back(gamma);
        n.cos_gamma.push_back(std::cos(gamma));
        n.sin_gamma.push_back(std::sin(gamma));
        n.weight.push_back(w[i] * 0.25 * kPi * n.cos_gamma.back());
        n.cos_2gamma.push_back(std::cos(2.0 * gamma));
        n.sin_2gamma.push_back(std::sin(2.0 * gamma));
      }
    }
  if (max_terms > 0) series_ = std::make_unique<CosineSeries>(r_.phis, max_terms);
}

void MaterialNp::evaluate(std::size_t t, std::vector<double>& out) const {
  const std::size_t L = r_.betas.size(), K = r_.sigmas.size(), nphi = r_.phis.size();
  out.assign(L * K * nphi, 0.0);
  if (spread_m_[t] > 0) spread_at(t, out);
  if (fourier_m_[t] == 0) return;
  fourier_at(t, out);
}

// The Fourier form (fourier_coefficients) with what the lobes and channels of a θd share: the
// node factors once, T_k once per node for every lobe, and e^{iΦ_p} = (−1)^p e^{−2iγ} (e^{2iγt})^p
// from one sine and cosine per node (e^{−2iγ} once per rule). C_n by rotating z^n, re-anchored
// with exact cos and sin of nΦ every 32 steps as there.
void MaterialNp::fourier_at(std::size_t t, std::vector<double>& out) const {
  const std::size_t L = r_.betas.size(), K = r_.sigmas.size(), nphi = r_.phis.size();
  const FiberGeometry g = FiberGeometry::make(r_.eta, r_.thetas[t]);
  const RuleNodes& rn = nodes_.at(fourier_m_[t]);
  const std::size_t m = rn.gamma.size();
  const double a = g.inv_eta_prime;
  std::vector<double> gt(m), f(m), omf(m), vr(m), vi(m), T(K * m);
  for (std::size_t i = 0; i < m; ++i) {
    const double st = rn.sin_gamma[i] * a;
    const double ct = std::sqrt((1.0 - st) * (1.0 + st));
    gt[i] = std::asin(st);
    const double c = g.cos_theta_d * rn.cos_gamma[i];
    f[i] = detail::fresnel_reflectance_unchecked(g.eta, c);
    omf[i] = detail::fresnel_transmittance_unchecked(g.eta, c);
    const double len = r_.path == AbsorptionPath::chord ? 2.0 * ct : 4.0 * ct * ct;
    for (std::size_t k = 0; k < K; ++k) T[k * m + i] = std::exp(-reduced_absorption(r_.sigmas[k], g) * len);
    vr[i] = std::cos(2.0 * gt[i]), vi[i] = std::sin(2.0 * gt[i]);
  }
  std::vector<double> phase, zr, zi, sr, si, amp, C, v, row(nphi);
  for (std::size_t p = 0; p < L; ++p) {
    if (spread_[t * L + p]) continue;
    const int pi = static_cast<int>(p);
    const auto N = static_cast<std::size_t>(terms_[p]);
    // Nodes with a non-zero weight for some channel: e^{iΦ}, and the weights [k][i].
    phase.clear(), sr.clear(), si.clear(), amp.clear();
    std::vector<std::size_t> used;
    for (std::size_t i = 0; i < m; ++i) {
      double fp = pi == 0 ? f[i] : omf[i] * omf[i];
      for (int q = 1; q < pi; ++q) fp *= f[i];
      const double base = rn.weight[i] * fp;
      bool any = false;
      for (std::size_t k = 0; k < K; ++k) {
        double tp = 1.0;
        for (int q = 0; q < pi; ++q) tp *= T[k * m + i];
        any |= base * tp != 0.0;
      }
      if (!any) continue;
      used.push_back(i);
      double er = (pi % 2 ? -1.0 : 1.0) * rn.cos_2gamma[i], ei = (pi % 2 ? 1.0 : -1.0) * rn.sin_2gamma[i];  // (−1)^p e^{−2iγ}
      for (int q = 0; q < pi; ++q) {
        const double r = er * vr[i] - ei * vi[i];
        ei = er * vi[i] + ei * vr[i];
        er = r;
      }
      sr.push_back(er), si.push_back(ei);
      phase.push_back(exit_azimuth(pi, rn.gamma[i], gt[i]));
    }
    const std::size_t u = used.size();
    amp.assign(K * u, 0.0);
    for (std::size_t q = 0; q < u; ++q) {
      const std::size_t i = used[q];
      double fp = pi == 0 ? f[i] : omf[i] * omf[i];
      for (int e = 1; e < pi; ++e) fp *= f[i];
      for (std::size_t k = 0; k < K; ++k) {
        double tp = 1.0;
        for (int e = 0; e < pi; ++e) tp *= T[k * m + i];
        amp[k * u + q] = rn.weight[i] * fp * tp;
      }
    }
    C.assign((N + 1) * K, 0.0);
    zr.assign(u, 1.0), zi.assign(u, 0.0);
    for (std::size_t n = 0; n <= N; ++n) {
      if (n % 32 == 0 && n > 0)
        for (std::size_t q = 0; q < u; ++q) {
          const double arg = static_cast<double>(n) * phase[q];
          zr[q] = std::cos(arg), zi[q] = std::sin(arg);
        }
      for (std::size_t k = 0; k < K; ++k) {
        const double* w = amp.data() + k * u;
        double sum = 0.0;
#pragma omp simd reduction(+ : sum)
        for (std::size_t q = 0; q < u; ++q) sum += zr[q] * w[q];
        C[n * K + k] = sum;
      }
#pragma omp simd
      for (std::size_t q = 0; q < u; ++q) {
        const double r = zr[q] * sr[q] - zi[q] * si[q];
        zi[q] = zr[q] * si[q] + zi[q] * sr[q];
        zr[q] = r;
      }
    }
    const double beta = r_.betas[p];
    std::vector<double> weight(N + 1);
    for (std::size_t n = 0; n <= N; ++n) weight[n] = (n ? 2.0 : 1.0) * std::exp(-0.5 * static_cast<double>(n * n) * beta * beta) / kTwoPi;
    v.resize(N + 1);
    for (std::size_t k = 0; k < K; ++k) {
      for (std::size_t n = 0; n <= N; ++n) v[n] = weight[n] * C[n * K + k];
      series_->evaluate(v, row);
      for (std::size_t j = 0; j < nphi; ++j) out[(p * K + k) * nphi + j] = std::max(0.0, row[j]);  // roundoff below 0 clamped
    }
  }
}

// Spreading (the quadrature of spread_np): N(φ_j) = ½ Σ_i W_i A_i [g(φ_j − Φ_i) + g(φ_j + Φ_i)],
// each node's Gaussian added to the circle points within √(2 ln(2/ε)) β of Φ_i. The window
// values g(d0 + jΔ) = g0 r^j c_j with g0 = e^{−d0²/2β²}, r = e^{−d0Δ/β²}, c_j = e^{−j²Δ²/2β²}
// (c_j once per lobe), added to a circle padded by the window radius on both sides and folded
// at the end, so that the inner loop is a straight run of multiply–adds over the window × σa.
void MaterialNp::spread_at(std::size_t t, std::vector<double>& out) const {
  const std::size_t L = r_.betas.size(), K = r_.sigmas.size(), nphi = r_.phis.size();
  const FiberGeometry g = FiberGeometry::make(r_.eta, r_.thetas[t]);
  const RuleNodes& n = nodes_.at(spread_m_[t]);
  const std::size_t m = n.gamma.size();
  const double a = g.inv_eta_prime, eta = g.eta;
  std::vector<double> st(m), gt(m), f(m), one_minus_f(m), len(m);
  for (std::size_t i = 0; i < m; ++i) st[i] = n.sin_gamma[i] * a;
  for (std::size_t i = 0; i < m; ++i) gt[i] = std::asin(st[i]);
#pragma omp simd
  for (std::size_t i = 0; i < m; ++i) {
    const double ct = std::sqrt((1.0 - st[i]) * (1.0 + st[i]));
    len[i] = r_.path == AbsorptionPath::chord ? 2.0 * ct : 4.0 * ct * ct;
    // Unpolarised Fresnel at cos θd cos γ from outside (η > 1: never total reflection), and its
    // complement in the cancellation-free form.
    const double c = g.cos_theta_d * n.cos_gamma[i];
    const double ctr = std::sqrt(1.0 - (1.0 - c) * (1.0 + c) / (eta * eta));
    const double ds = c + eta * ctr, dp = eta * c + ctr;
    const double rs = (c - eta * ctr) / ds, rp = (eta * c - ctr) / dp;
    const double num = 4.0 * eta * c * ctr;
    f[i] = std::min(1.0, 0.5 * (rs * rs + rp * rp));
    one_minus_f[i] = std::min(1.0, 0.5 * (num / (ds * ds) + num / (dp * dp)));
  }
  std::vector<std::vector<double>> T(K, std::vector<double>(m));
  for (std::size_t k = 0; k < K; ++k) {
    const double sp = reduced_absorption(r_.sigmas[k], g);
    for (std::size_t i = 0; i < m; ++i) T[k][i] = std::exp(-sp * len[i]);
  }
  // A(p) = f for p = 0, (1 − f)² f^{p−1} T^p after: the powers of lobe p from those of lobe p − 1
  // (the same products in the same order as multiplying out each lobe's powers).
  std::vector<double> fpow(m), tpow(K * m, 1.0);
  const auto P = static_cast<long>(grid_.period);
  const double step = kTwoPi / static_cast<double>(P);
  const long shift = std::lround(-2.0 * grid_.phi0 / step);
  std::vector<double> amp(K * m), j0(m), dz(m), e1(m), e2(m), g0(m), rr(m), win, c, buf, circle(static_cast<std::size_t>(P) * K);
  std::vector<char> live(m);
  for (std::size_t p = 0; p < L; ++p) {
    if (p == 0) std::copy(f.begin(), f.end(), fpow.begin());
    else if (p == 1) std::transform(one_minus_f.begin(), one_minus_f.end(), fpow.begin(), [](double x) { return x * x; });
    else std::transform(fpow.begin(), fpow.end(), f.begin(), fpow.begin(), std::multiplies<>());
    if (p > 0)
      for (std::size_t k = 0; k < K; ++k) std::transform(tpow.begin() + static_cast<long>(k * m), tpow.begin() + static_cast<long>((k + 1) * m), T[k].begin(),
                                                         tpow.begin() + static_cast<long>(k * m), std::multiplies<>());
    if (!spread_[t * L + p]) continue;
    const int pi = static_cast<int>(p);
    const double beta = r_.betas[p];
    const long R = static_cast<long>(std::ceil(std::sqrt(2.0 * std::log(2.0 / r_.tolerance)) * beta / step));
    const std::size_t W = static_cast<std::size_t>(2 * R + 1);
    // Windows of up to kShortWindow points run over kShortWindow slots, the extra ones zero
    // (adding an exact 0 leaves every sum as it was): a fixed-length loop without remainder.
    constexpr std::size_t kShortWindow = 8;
    const std::size_t run = W <= kShortWindow ? kShortWindow : W;
    const double inv2var = 1.0 / (2.0 * beta * beta), norm = 1.0 / (std::sqrt(kTwoPi) * beta);
    const bool recurrence = step / beta <= 20.0;  // r^j c_j stays far from overflow
    c.resize(W);
    for (long j = -R; j <= R; ++j) c[static_cast<std::size_t>(j + R)] = std::exp(-static_cast<double>(j * j) * step * step * inv2var);
    for (std::size_t i = 0; i < m; ++i) {
      const double base = n.weight[i] * fpow[i] * norm;
      bool any = false;
      for (std::size_t k = 0; k < K; ++k) {
        amp[i * K + k] = base * tpow[k * m + i];
        any |= amp[i * K + k] != 0.0;
      }
      live[i] = any;
      const double centre = exit_azimuth(pi, n.gamma[i], gt[i]);
      const double u = (centre - grid_.phi0) / step;
      const double jr = (u + 0x1.8p52) - 0x1.8p52;  // nearest integer (|u| < 2^51)
      const double d0 = (jr - u) * step;
      j0[i] = jr;
      dz[i] = d0;
      e1[i] = -d0 * d0 * inv2var;
      e2[i] = -2.0 * d0 * step * inv2var;
    }
    for (std::size_t i = 0; i < m; ++i) g0[i] = std::exp(e1[i]), rr[i] = std::exp(e2[i]);
    const std::size_t stride = static_cast<std::size_t>(P) + run - 1;
    buf.assign(stride * K, 0.0);
    win.assign(run, 0.0);
    for (std::size_t i = 0; i < m; ++i) {
      const double* ai = amp.data() + i * K;
      if (!live[i] || g0[i] == 0.0) continue;
      if (recurrence) {
        double up = g0[i], down = g0[i];
        const double r = rr[i], rinv = 1.0 / rr[i];
        win[static_cast<std::size_t>(R)] = g0[i];
        for (long j = 1; j <= R; ++j) {
          up *= r;
          down *= rinv;
          win[static_cast<std::size_t>(R + j)] = up * c[static_cast<std::size_t>(R + j)];
          win[static_cast<std::size_t>(R - j)] = down * c[static_cast<std::size_t>(R - j)];
        }
      } else {
        for (long j = -R; j <= R; ++j) {
          const double d = dz[i] + static_cast<double>(j) * step;
          win[static_cast<std::size_t>(j + R)] = std::exp(-d * d * inv2var);
        }
      }
      long r0 = static_cast<long>(j0[i]) % P;
      if (r0 < 0) r0 += P;
      // One plane per σa: a straight, vectorizable run over the window.
      for (std::size_t k = 0; k < K; ++k) {
        double* b = buf.data() + k * stride + static_cast<std::size_t>(r0);
        const double ak = ai[k];
        if (run == kShortWindow) {
#pragma omp simd
          for (std::size_t j = 0; j < kShortWindow; ++j) b[j] += ak * win[j];
        } else {
#pragma omp simd
          for (std::size_t j = 0; j < run; ++j) b[j] += ak * win[j];
        }
      }
    }
    // Fold the padding onto the circle: buffer slot q holds circle point (q − R) mod P.
    std::fill(circle.begin(), circle.end(), 0.0);
    for (std::size_t q = 0; q < stride; ++q) {
      long rc = (static_cast<long>(q) - R) % P;
      if (rc < 0) rc += P;
      for (std::size_t k = 0; k < K; ++k) circle[static_cast<std::size_t>(rc) * K + k] += buf[k * stride + q];
    }
    for (std::size_t j = 0; j < nphi; ++j) {
      const auto here = static_cast<std::size_t>(static_cast<long>(j) % P);
      long mirror = (shift - static_cast<long>(j)) % P;
      if (mirror < 0) mirror += P;
      for (std::size_t k = 0; k < K; ++k)
        out[(p * K + k) * nphi + j] = std::max(0.0, 0.5 * (circle[here * K + k] + circle[static_cast<std::size_t>(mirror) * K + k]));
    }
  }
}

void newton_gauss_legendre(int m, std::vector<double>& nodes, std::vector<double>& weights) {
  if (m < 1 || m > 32768) throw_domain_error("quadrature order", "must lie in [1, 32768]", static_cast<long long>(m));
  const auto M = static_cast<std::size_t>(m), half = (M + 1) / 2;
  const double n = m;
  // P_k = a_k x P_{k−1} − b_k P_{k−2}, a_k = (2k − 1)/k, b_k = (k − 1)/k.
  std::vector<double> a(M + 1), b(M + 1);
  for (std::size_t k = 2; k <= M; ++k) a[k] = (2.0 * static_cast<double>(k) - 1.0) / static_cast<double>(k), b[k] = (static_cast<double>(k) - 1.0) / static_cast<double>(k);
  std::vector<double> x(half), value(half), deriv(half), p0(half), p1(half);
  for (std::size_t i = 0; i < half; ++i) x[i] = std::cos(kPi * (static_cast<double>(i) + 0.75) / (n + 0.5));
  // P_m and P_m' = m (x P_m − P_{m−1}) / (x² − 1) at every root estimate at once (a loop over the
  // roots inside the recurrence, which vectorizes).
  auto evaluate = [&] {
    for (std::size_t i = 0; i < half; ++i) p0[i] = 1.0, p1[i] = x[i];
    for (std::size_t k = 2; k <= M; ++k) {
      const double ak = a[k], bk = b[k];
#pragma omp simd
      for (std::size_t i = 0; i < half; ++i) {
        const double p2 = ak * x[i] * p1[i] - bk * p0[i];
        p0[i] = p1[i];
        p1[i] = p2;
      }
    }
    for (std::size_t i = 0; i < half; ++i) value[i] = p1[i], deriv[i] = n * (x[i] * p1[i] - p0[i]) / (x[i] * x[i] - 1.0);
  };
  // Newton until every step is below 1e−15, then one more (quadratic convergence).
  bool last = false;
  for (int it = 0; it < 100; ++it) {
    evaluate();
    double worst = 0.0;
    for (std::size_t i = 0; i < half; ++i) {
      const double dx = value[i] / deriv[i];
      x[i] -= dx;
      worst = std::max(worst, std::abs(dx));
    }
    if (last) break;
    last = worst <= 1e-15;
  }
  evaluate();  // P_m' at the converged roots
  nodes.assign(M, 0.0);
  weights.assign(M, 0.0);
  for (std::size_t i = 0; i < half; ++i) {
    nodes[M - 1 - i] = x[i];
    nodes[i] = -x[i];
    weights[M - 1 - i] = weights[i] = 2.0 / ((1.0 - x[i] * x[i]) * deriv[i] * deriv[i]);
  }
  if (M % 2 == 1) nodes[M / 2] = 0.0;
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
