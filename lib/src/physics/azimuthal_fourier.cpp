#include "hairlut/physics/azimuthal_fourier.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/fresnel.hpp"

namespace hairlut {

int fourier_terms(double beta, double tolerance) {
  require_positive("beta", beta);
  if (!(tolerance > 0.0 && tolerance < 1.0)) throw_domain_error("tolerance", "must lie in (0, 1)", tolerance);
  const double b2 = 0.5 * beta * beta;
  // tail(N) = Σ_{n>N} e^{−n² b2} ≤ e^{−(N+1)² b2} / (1 − e^{−(2N+3) b2}) (the term ratios decrease).
  for (long n = 0; n <= 4'000'000; ++n) {
    const double next = std::exp(-static_cast<double>((n + 1) * (n + 1)) * b2);
    const double ratio = std::exp(-static_cast<double>(2 * n + 3) * b2);
    if (2.0 * next <= 0.5 * tolerance * (1.0 - ratio) || next == 0.0) return static_cast<int>(n);
  }
  throw_domain_error("beta", "is too small for the Fourier method (more than 4e6 terms)", beta);
}

int fourier_nodes(int terms, int p, const FiberGeometry& g, double tolerance) {
  // dΦ/dγ = 2p cos γ / (η' cos γt) − 2 decreases from 2p/η' − 2 at γ = 0 to −2 at γ = π/2.
  const double rate = std::max(std::abs(2.0 * p * g.inv_eta_prime - 2.0), 2.0);
  // Gauss–Legendre with m nodes integrates cos(kx) over [−1, 1] to ε once
  // m ≥ 0.5 k + (0.35 log10(1/ε) + 0.6) k^{1/3} + 4 (fitted to measurements for k = 20 … 1600,
  // ε = 1e−4 … 1e−14). C_n enters N_p weighted by g_n = e^{−n²β²/2} and the truncation makes
  // g_N ≈ tolerance, so C_n needs only ε_n = tolerance / (10 N g_n): the top terms need little.
  const double b2 = -std::log(std::max(tolerance, 1e-300)) / std::max<double>(static_cast<double>(terms) * terms, 1.0);  // β²/2 with g_N = tolerance
  double m = 8.0;
  for (int j = 1; j <= 32; ++j) {
    const double n = static_cast<double>(terms) * j / 32.0;
    const double k = n * rate * (kPi / 4.0);
    const double eps = std::min(1e-2, tolerance * std::exp(n * n * b2) / (10.0 * std::max(1, terms)));
    m = std::max(m, 0.5 * k + (0.35 * std::log10(1.0 / eps) + 0.6) * std::cbrt(k) + 4.0);
  }
  // The Fresnel factor of an index close to 1 rises from ~0 to 1 over a width ~ √(2(η − 1)) in γ.
  m += 16.0 / std::sqrt(std::max(g.eta - 1.0, 1e-4));
  return static_cast<int>(std::ceil(m / 16.0)) * 16;  // multiples of 16 let bakes share rules
}

FiberNodes FiberNodes::make(const FiberGeometry& g, AbsorptionPath path, const GaussLegendreRule& rule) {
  FiberNodes n;
  const auto x = rule.nodes();
  const auto wt = rule.weights();
  const double a = g.inv_eta_prime;
  n.weight.reserve(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    // The factors of PathPoint (attenuation.hpp), without its argument checks in this inner loop.
    const double gamma = 0.25 * kPi * (1.0 + x[i]);
    const double ci = std::cos(gamma), sg = std::sin(gamma);
    const double st = sg * a;
    const double ct = std::sqrt((1.0 - st) * (1.0 + st));
    const double c = g.cos_theta_d * ci;
    n.weight.push_back(wt[i] * 0.25 * kPi * ci);
    n.gamma_i.push_back(gamma);
    n.gamma_t.push_back(std::asin(st));
    n.f.push_back(detail::fresnel_reflectance_unchecked(g.eta, c));
    n.one_minus_f.push_back(detail::fresnel_transmittance_unchecked(g.eta, c));
    n.length.push_back(path == AbsorptionPath::chord ? 2.0 * ct : 4.0 * ct * ct);
  }
  return n;
}

namespace {

// A(p) without absorption: f for p = 0, (1 − f)² f^{p−1} otherwise.
double fresnel_factor(const FiberNodes& n, std::size_t i, int p) {
  if (p == 0) return n.f[i];
  double v = n.one_minus_f[i] * n.one_minus_f[i];
  for (int q = 1; q < p; ++q) v *= n.f[i];
  return v;
}

}  // namespace

void fourier_coefficients(const FiberNodes& nodes, const FiberGeometry& g, int p, std::span<const double> sigmas, int terms,
                          std::vector<double>& out, double length_offset) {
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  if (terms < 0) throw_domain_error("terms", "must be >= 0", static_cast<long long>(terms));
  const std::size_t K = sigmas.size();
  const auto N = static_cast<std::size_t>(terms);
  out.assign((N + 1) * K, 0.0);
  std::vector<double> sigma_prime(K);
  for (std::size_t k = 0; k < K; ++k) {
    require_non_negative("sigma_a", sigmas[k]);
    sigma_prime[k] = reduced_absorption(sigmas[k], g);
  }
  // Node data in structure-of-arrays form: the phase Φ_i and the weight of each σa; nodes whose
  // weights all vanish are dropped.
  std::vector<double> phase;
  std::vector<std::vector<double>> weight(K);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const double base = nodes.weight[i] * fresnel_factor(nodes, i, p);
    if (base == 0.0) continue;
    bool any = false;
    const double length = nodes.length[i] - length_offset;  // ℓ − ℓ_min for C_n / F
    for (std::size_t k = 0; k < K; ++k) any |= (p == 0 ? base : base * std::exp(-static_cast<double>(p) * sigma_prime[k] * length)) != 0.0;
    if (!any) continue;
    phase.push_back(exit_azimuth(p, nodes.gamma_i[i], nodes.gamma_t[i]));
    for (std::size_t k = 0; k < K; ++k)
      weight[k].push_back(p == 0 ? base : base * std::exp(-static_cast<double>(p) * sigma_prime[k] * length));
  }
  const std::size_t m = phase.size();
  if (m == 0) return;
  // cos(nΦ_i) by rotating z_i = e^{inΦ_i} for all nodes at once (vectorizable loops over i),
  // re-anchored with exact cos/sin every 32 steps so that rounding stays at a few ulp for any n.
  std::vector<double> zr(m), zi(m), sr(m), si(m);
  for (std::size_t i = 0; i < m; ++i) sr[i] = std::cos(phase[i]), si[i] = std::sin(phase[i]);
  for (std::size_t n = 0; n <= N; ++n) {
    if (n % 32 == 0)
      for (std::size_t i = 0; i < m; ++i) {
        const double arg = static_cast<double>(n) * phase[i];
        zr[i] = std::cos(arg), zi[i] = std::sin(arg);
      }
    double* row = out.data() + n * K;
    for (std::size_t k = 0; k < K; ++k) {
      const double* w = weight[k].data();
      double sum = 0.0;
      // A SIMD reduction: its (fixed) order of partial sums is the same in every run and thread.
#pragma omp simd reduction(+ : sum)
      for (std::size_t i = 0; i < m; ++i) sum += zr[i] * w[i];
      row[k] = sum;
    }
    for (std::size_t i = 0; i < m; ++i) {
      const double r = zr[i] * sr[i] - zi[i] * si[i];
      zi[i] = zr[i] * si[i] + zi[i] * sr[i];
      zr[i] = r;
    }
  }
}

void fourier_coefficients(const FiberGeometry& g, AbsorptionPath path, int p, std::span<const double> sigmas, int terms,
                          const GaussLegendreRule& rule, std::vector<double>& out) {
  fourier_coefficients(FiberNodes::make(g, path, rule), g, p, sigmas, terms, out);
}

int spread_nodes(double beta, int p, const FiberGeometry& g, double tolerance) {
  const double rate = std::max(std::abs(2.0 * p * g.inv_eta_prime - 2.0), 2.0);
  const double sigma = beta / rate;
  const double h = kPi * sigma * std::sqrt(2.0 / std::log(10.0 / tolerance));  // widest spacing allowed
  const double m = kPi * kPi / (4.0 * h) + 8.0 + 16.0 / std::sqrt(std::max(g.eta - 1.0, 1e-4));
  return static_cast<int>(std::ceil(m / 16.0)) * 16;
}

namespace {

// Step of a uniform grid (0 when not uniform to 1e−12) and its period 2π/step when that is an
// integer P with points ≤ P + 1 (the (P + 1)-th point, if present, repeats the first one 2π on),
// and when the grid is symmetric about φ = 0 on the circle (2φ_0 a multiple of the step).
struct GridShape {
  double step = 0.0;
  long period = 0;
  const char* why = nullptr;
};

GridShape grid_shape(std::span<const double> phis) {
  GridShape s;
  if (phis.size() < 2) {
    s.why = "a single phi node";
    return s;
  }
  const double step = phis[1] - phis[0];
  if (!(step > 0.0)) {
    s.why = "phi nodes are not increasing";
    return s;
  }
  for (std::size_t j = 0; j < phis.size(); ++j)
    if (std::abs(phis[j] - (phis[0] + static_cast<double>(j) * step)) > 1e-12) {
      s.why = "phi nodes are not uniformly spaced";
      return s;
    }
  const double P = kTwoPi / step;
  if (std::abs(P - std::round(P)) > 1e-9) {
    s.why = "the phi step does not divide 2 pi";
    return s;
  }
  if (std::round(P) + 1.0 < static_cast<double>(phis.size())) {
    s.why = "phi nodes span more than one period";
    return s;
  }
  const double mirror = -2.0 * phis[0] / step;
  if (std::abs(mirror - std::round(mirror)) > 1e-9) {
    s.why = "phi nodes are not symmetric about 0 (2 phi_0 is not a multiple of the step)";
    return s;
  }
  s.step = step;
  s.period = std::lround(P);
  return s;
}

}  // namespace

PeriodicGrid PeriodicGrid::of(std::span<const double> phis) {
  PeriodicGrid grid;
  const GridShape s = grid_shape(phis);
  if (s.period == 0) return grid;
  grid.phi0 = phis[0];
  grid.period = static_cast<int>(s.period);
  grid.points = static_cast<int>(phis.size());
  return grid;
}

std::string PeriodicGrid::why_not(std::span<const double> phis) {
  const GridShape s = grid_shape(phis);
  if (s.period > 0) return {};
  return std::string(s.why) + ": narrow detectors are evaluated from the Fourier series instead of by spreading (slower)";
}

void spread_np(const FiberNodes& nodes, const FiberGeometry& g, std::span<const SpreadLobe> lobes, std::span<const double> sigmas,
               const PeriodicGrid& grid, double tolerance, std::vector<std::vector<double>>& out) {
  if (grid.period <= 0) throw DomainError("spread_np needs a periodic phi grid");
  const std::size_t K = sigmas.size(), L = lobes.size();
  const auto P = static_cast<long>(grid.period);
  const double step = kTwoPi / static_cast<double>(P);
  // The grid is symmetric about φ = 0: point r mirrors to (shift − r) mod P.
  const long shift = std::lround(-2.0 * grid.phi0 / step);
  std::vector<std::vector<double>> circle(L, std::vector<double>(static_cast<std::size_t>(P) * K, 0.0));  // [k][r]
  std::vector<double> sigma_prime(K), T(K), a(K);
  for (std::size_t k = 0; k < K; ++k) sigma_prime[k] = reduced_absorption(sigmas[k], g);
  struct Width {
    long reach;
    double inv2var, q, norm;
  };
  std::vector<Width> width(L);
  for (std::size_t l = 0; l < L; ++l) {
    const double beta = lobes[l].beta;
    require_positive("beta", beta);
    const double radius = std::sqrt(2.0 * std::log(2.0 / tolerance)) * beta;  // Gaussian below ε·peak beyond
    width[l] = {static_cast<long>(std::ceil(radius / step)), 1.0 / (2.0 * beta * beta), std::exp(-step * step / (beta * beta)),
                1.0 / (std::sqrt(kTwoPi) * beta)};
  }
  long max_reach = 0;
  for (const Width& w : width) max_reach = std::max(max_reach, w.reach);
  std::vector<double> win_g(static_cast<std::size_t>(2 * max_reach + 1));
  std::vector<std::size_t> win_r(win_g.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    for (std::size_t k = 0; k < K; ++k) T[k] = std::exp(-sigma_prime[k] * nodes.length[i]);  // shared by the lobes
    for (std::size_t l = 0; l < L; ++l) {
      const int p = lobes[l].p;
      const Width& w = width[l];
      const double base = nodes.weight[i] * fresnel_factor(nodes, i, p) * w.norm;  // ½ from the mirror pair, × 2 at the end
      if (base == 0.0) continue;
      bool any = false;
      for (std::size_t k = 0; k < K; ++k) {
        double tp = 1.0;
        for (int q = 0; q < p; ++q) tp *= T[k];
        a[k] = base * tp;
        any |= a[k] != 0.0;
      }
      if (!any) continue;
      // Nearest circle point to Φ and its offset d0; g_j = exp(−(d0 + jΔ)²/2β²) by the recurrence
      // g_{j±1} = g_j ρ_j, ρ_{j+1} = ρ_j q (q = e^{−Δ²/β²}).
      const double centre = exit_azimuth(p, nodes.gamma_i[i], nodes.gamma_t[i]);
      const double u = (centre - grid.phi0) / step;
      const double j0 = std::floor(u + 0.5);
      const double d0 = (j0 - u) * step;
      long r0 = static_cast<long>(std::fmod(j0, static_cast<double>(P)));
      if (r0 < 0) r0 += P;
      // The window's Gaussian values and circle indices, then one pass per σa over them.
      const double g0 = std::exp(-d0 * d0 * w.inv2var);
      std::size_t used = 0;
      win_g[used] = g0, win_r[used] = static_cast<std::size_t>(r0), ++used;
      // Both ratios are ≤ 1 since |d0| ≤ Δ/2 and ρ_up ρ_down = q; on coarse grids they underflow
      // to 0 (nothing to spread), where ρ_down is computed on its own instead of as q/ρ_up.
      const double rho_up = std::exp(-(2.0 * d0 * step + step * step) * w.inv2var);
      const double rho_down = rho_up > 1e-150 ? w.q / rho_up : std::exp(-(-2.0 * d0 * step + step * step) * w.inv2var);
      for (const long dir : {1L, -1L}) {
        double gj = g0, rho = dir > 0 ? rho_up : rho_down;
        long r = r0;
        for (long j = 1; j <= w.reach; ++j) {
          gj *= rho;
          rho *= w.q;
          if (gj == 0.0) break;
          r += dir;
          if (r == P) r = 0;
          if (r < 0) r = P - 1;
          win_g[used] = gj, win_r[used] = static_cast<std::size_t>(r), ++used;
        }
      }
      for (std::size_t k = 0; k < K; ++k) {
        double* c = circle[l].data() + k * static_cast<std::size_t>(P);
        const double ak = a[k];
        for (std::size_t v = 0; v < used; ++v) c[win_r[v]] += ak * win_g[v];
      }
    }
  }
  // N(φ_j) = ½ Σ W A [g(φ_j − Φ) + g(φ_j + Φ)]: the second sum is the first at the mirror point.
  out.assign(L, std::vector<double>(K * static_cast<std::size_t>(grid.points), 0.0));
  for (std::size_t l = 0; l < L; ++l)
    for (std::size_t j = 0; j < static_cast<std::size_t>(grid.points); ++j) {
      long mirror = (shift - static_cast<long>(j)) % P;
      if (mirror < 0) mirror += P;
      const auto here = static_cast<std::size_t>(static_cast<long>(j) % P);  // the point after the last repeats the first
      for (std::size_t k = 0; k < K; ++k)
        out[l][k * static_cast<std::size_t>(grid.points) + j] =
            std::max(0.0, 0.5 * (circle[l][k * static_cast<std::size_t>(P) + here] + circle[l][k * static_cast<std::size_t>(P) + static_cast<std::size_t>(mirror)]));
    }
}

double fourier_cost(int terms, int nodes, std::size_t sigmas, std::size_t betas, std::size_t points) {
  const double N = terms + 1.0;
  return static_cast<double>(nodes) * N * (static_cast<double>(sigmas) + 3.0) + static_cast<double>(betas * sigmas) * (N + static_cast<double>(points) * std::min(N, 2.0 * static_cast<double>(points)));
}

double spread_cost(double beta, int nodes, std::size_t sigmas, const PeriodicGrid& grid, double tolerance) {
  if (grid.period <= 0) return INFINITY;
  const double width = 2.0 * std::sqrt(2.0 * std::log(2.0 / tolerance)) * beta / (kTwoPi / grid.period) + 1.0;
  return static_cast<double>(nodes) * (width * (static_cast<double>(sigmas) + 2.0) + 2.0 * static_cast<double>(sigmas));
}

CosineSeries::CosineSeries(std::span<const double> phis, int max_terms) : points_(phis.size()), max_terms_(max_terms) {
  if (max_terms < 0) throw_domain_error("max_terms", "must be >= 0", static_cast<long long>(max_terms));
  // A uniform grid φ_j = φ_0 + jΔ with Δ = 2π/P (P integer) folds exactly onto P terms.
  if (points_ >= 2) {
    const double step = phis[1] - phis[0];
    bool uniform = step > 0.0;
    for (std::size_t j = 0; j < points_ && uniform; ++j) uniform = std::abs(phis[j] - (phis[0] + static_cast<double>(j) * step)) < 1e-12;
    const double P = kTwoPi / step;
    if (uniform && std::abs(P - std::round(P)) < 1e-9 && std::round(P) >= 1.0) period_ = static_cast<int>(std::round(P));
  }
  phi0_ = points_ ? phis[0] : 0.0;
  const int n_table = period_ > 0 ? std::min(max_terms, period_ - 1) : max_terms;
  const auto cols = static_cast<std::size_t>(n_table + 1);
  cos_.resize(points_ * cols);
  if (period_ > 0) sin_.resize(points_ * cols);
  for (std::size_t j = 0; j < points_; ++j)
    for (std::size_t n = 0; n < cols; ++n) {
      cos_[j * cols + n] = std::cos(static_cast<double>(n) * phis[j]);
      if (period_ > 0) sin_[j * cols + n] = std::sin(static_cast<double>(n) * phis[j]);
    }
}

void CosineSeries::evaluate(std::span<const double> v, std::span<double> out) const {
  const std::size_t terms = v.size();
  if (terms > static_cast<std::size_t>(max_terms_) + 1) throw DomainError("cosine series has more terms than its table");
  const std::size_t cols = cos_.size() / std::max<std::size_t>(points_, 1);
  if (period_ == 0 || terms <= cols) {
    for (std::size_t j = 0; j < points_; ++j) {
      const double* c = cos_.data() + j * cols;
      double s = 0.0;
      for (std::size_t n = 0; n < terms; ++n) s += v[n] * c[n];
      out[j] = s;
    }
    return;
  }
  // Fold: n = r + qP gives cos(nφ_j) = cos(rφ_j + qPφ_0) since P·Δ = 2π.
  const auto P = static_cast<std::size_t>(period_);
  std::vector<double> a(P, 0.0), b(P, 0.0);
  for (std::size_t q = 0; q * P < terms; ++q) {
    const double psi = static_cast<double>(q) * static_cast<double>(P) * phi0_;
    const double cq = std::cos(psi), sq = std::sin(psi);
    for (std::size_t r = 0; r < P && q * P + r < terms; ++r) {
      a[r] += v[q * P + r] * cq;
      b[r] += v[q * P + r] * sq;
    }
  }
  for (std::size_t j = 0; j < points_; ++j) {
    const double* c = cos_.data() + j * cols;
    const double* s = sin_.data() + j * cols;
    double sum = 0.0;
    for (std::size_t r = 0; r < P; ++r) sum += a[r] * c[r] - b[r] * s[r];
    out[j] = sum;
  }
}

double fourier_np(std::span<const double> c, std::size_t stride, double beta, double phi, double tolerance) {
  const std::size_t available = stride ? c.size() / stride : 0;
  const std::size_t n_max = std::min<std::size_t>(available ? available - 1 : 0, static_cast<std::size_t>(fourier_terms(beta, tolerance)));
  double sum = c.empty() ? 0.0 : c[0];
  for (std::size_t n = 1; n <= n_max; ++n)
    sum += 2.0 * std::exp(-0.5 * static_cast<double>(n * n) * beta * beta) * c[n * stride] * std::cos(static_cast<double>(n) * phi);
  return std::max(0.0, sum / kTwoPi);
}

}  // namespace hairlut
