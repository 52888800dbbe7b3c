#include "hairlut/azimuthal_fourier.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include "hairlut/angles.hpp"
#include "hairlut/error.hpp"

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

int fourier_nodes(int terms, int p, const FiberGeometry& g) {
  // dΦ/dγ = 2p cos γ / (η' cos γt) − 2 decreases from 2p/η' − 2 at γ = 0 to −2 at γ = π/2.
  const double rate = std::max(std::abs(2.0 * p * g.inv_eta_prime - 2.0), 2.0);
  const double k = static_cast<double>(terms) * rate * (kPi / 4.0);
  // The Fresnel factor of an index close to 1 rises from ~0 to 1 over a width ~ √(2(η − 1)) in γ.
  const double fresnel = 24.0 / std::sqrt(std::max(g.eta - 1.0, 1e-4));
  const double m = 0.52 * k + 6.0 * std::cbrt(k) + 20.0 + fresnel;
  return static_cast<int>(std::ceil(m / 16.0)) * 16;  // multiples of 16 let bakes share rules
}

void fourier_coefficients(const FiberGeometry& g, AbsorptionPath path, int p, std::span<const double> sigmas, int terms,
                          const GaussLegendreRule& rule, std::vector<double>& out) {
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  if (terms < 0) throw_domain_error("terms", "must be >= 0", static_cast<long long>(terms));
  const std::size_t K = sigmas.size();
  const auto N = static_cast<std::size_t>(terms);
  out.assign((N + 1) * K, 0.0);
  const AttenuationSlice clear(g.eta, g.theta_d, 0.0, path);
  std::vector<double> sigma_prime(K);
  for (std::size_t k = 0; k < K; ++k) {
    require_non_negative("sigma_a", sigmas[k]);
    sigma_prime[k] = reduced_absorption(sigmas[k], g);
  }
  std::vector<double> w(K);
  const auto x = rule.nodes();
  const auto wt = rule.weights();
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double gamma = 0.25 * kPi * (1.0 + x[i]);
    const PathPoint q = clear.at_gamma(gamma);
    // A(p) without absorption, times cos γ and the weight of the rule mapped to [0, π/2].
    const double fresnel = p == 0 ? q.f : q.one_minus_f * q.one_minus_f * std::pow(q.f, p - 1);
    const double base = wt[i] * 0.25 * kPi * q.cos_gamma_i * fresnel;
    if (base == 0.0) continue;
    const double length = path == AbsorptionPath::chord ? 2.0 * q.cos_gamma_t : 4.0 * q.cos_gamma_t * q.cos_gamma_t;
    bool any = false;
    for (std::size_t k = 0; k < K; ++k) {
      w[k] = p == 0 ? base : base * std::exp(-static_cast<double>(p) * sigma_prime[k] * length);
      any |= w[k] != 0.0;
    }
    if (!any) continue;
    // cos(nΦ) by rotating e^{inΦ}, re-anchored with exact cos/sin every 32 steps so that the
    // rounding error stays at a few ulp for any n.
    const double Phi = q.exit_azimuth(p);
    const std::complex<double> step(std::cos(Phi), std::sin(Phi));
    std::complex<double> z(1.0, 0.0);
    for (std::size_t n = 0; n <= N; ++n) {
      if (n % 32 == 0 && n > 0) z = std::complex<double>(std::cos(static_cast<double>(n) * Phi), std::sin(static_cast<double>(n) * Phi));
      const double c = z.real();
      double* row = out.data() + n * K;
      for (std::size_t k = 0; k < K; ++k) row[k] += c * w[k];
      z *= step;
    }
  }
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
