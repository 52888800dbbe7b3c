#include "representation_fourier.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <hairlut/physics/azimuthal_fourier.hpp>
#include <hairlut/physics/fiber_geometry.hpp>
#include <hairlut/util/angles.hpp>
#include <hairlut/util/error.hpp>
#include <hairlut/util/quadrature.hpp>

namespace bench {
namespace {

using namespace hairlut;

// Σ_{n=0}^{N} w_n a_n cos nφ / 2π (w_0 = 1, w_n = 2 e^{−n²β²/2}). The weights downwards from
// w_N by g_{n−1} = g_n e^{(2n−1)β²/2} (two exponentials per call), the cosines by Clenshaw:
// b_n = w_n a_n + 2 cos φ b_{n+1} − b_{n+2}, sum = a_0 + cos φ b_1 − b_2.
double series(const double* a, int N, double beta, double phi) {
  const double b2 = 0.5 * beta * beta, x = std::cos(phi);
  double g = std::exp(-static_cast<double>(N) * N * b2);
  double r = std::exp(static_cast<double>(2 * N - 1) * b2);
  const double q = std::exp(-2.0 * b2);
  double b1 = 0.0, bb = 0.0;
  for (int n = N; n >= 1; --n) {
    const double b0 = 2.0 * g * a[n] + 2.0 * x * b1 - bb;
    bb = b1, b1 = b0;
    g *= r, r *= q;
  }
  return (a[0] + x * b1 - bb) / kTwoPi;
}

// Interpolation taps along one axis of n nodes at fractional index u ∈ [0, n − 1]: weights of
// nodes base … base + count − 1. Catmull–Rom (n ≥ 4) with its missing neighbours beyond the ends
// taken as the mirror image across node 0 (an even function of the axis there) or by linear
// extrapolation, folded onto the nodes; otherwise linear.
struct Taps {
  int base = 0, count = 0;
  std::array<double, 4> w{};
};

Taps taps(double u, int n, bool cubic, bool lo_mirror) {
  Taps t;
  const int i = std::clamp(static_cast<int>(u), 0, n - 2);
  const double f = std::clamp(u - i, 0.0, 1.0);
  if (!cubic || n < 4) {
    t.base = i, t.count = 2;
    t.w[0] = 1.0 - f, t.w[1] = f;
    return t;
  }
  const double f2 = f * f, f3 = f2 * f;
  const std::array<double, 4> w = {0.5 * (-f3 + 2.0 * f2 - f), 0.5 * (3.0 * f3 - 5.0 * f2 + 2.0), 0.5 * (-3.0 * f3 + 4.0 * f2 + f),
                                   0.5 * (f3 - f2)};
  t.base = std::clamp(i - 1, 0, n - 4), t.count = 4;
  auto add = [&](int j, double v) { t.w[static_cast<std::size_t>(j - t.base)] += v; };
  for (int k = 0; k < 4; ++k) {
    const int j = i - 1 + k;
    const double v = w[static_cast<std::size_t>(k)];
    if (j < 0) {
      if (lo_mirror)
        add(1, v);
      else
        add(0, 2.0 * v), add(1, -v);
    } else if (j > n - 1) {
      add(n - 1, 2.0 * v), add(n - 2, -v);
    } else {
      add(j, v);
    }
  }
  return t;
}

}  // namespace

int fourier_series_terms(double beta, double tolerance, int max_terms) {
  // As fourier_terms: tail(N) ≤ e^{−(N+1)² b} / (1 − e^{−(2N+3) b}), b = β²/2, by recurrence.
  const double b = 0.5 * beta * beta;
  double next = std::exp(-b), ratio = std::exp(-3.0 * b);
  const double q = std::exp(-2.0 * b);
  for (int n = 0; n < max_terms; ++n) {
    if (2.0 * next <= 0.5 * tolerance * (1.0 - ratio) || next == 0.0) return n;
    next *= ratio, ratio *= q;
  }
  return max_terms;
}

double fourier_series(std::span<const double> a, double beta, double phi, double tolerance) {
  if (a.empty()) return 0.0;
  const int N = fourier_series_terms(beta, tolerance, static_cast<int>(a.size()) - 1);
  return series(a.data(), N, beta, phi);
}

template <class T>
FourierTable<T>::FourierTable(const FourierTableConfig& c) : config_(c) {
  if (c.lobes < 1 || c.lobes > 16) throw_domain_error("lobes", "must lie in [1, 16]", static_cast<long long>(c.lobes));
  require_positive("beta_min", c.beta_min);
  if (!(c.tolerance > 0.0 && c.tolerance < 1.0)) throw_domain_error("tolerance", "must lie in (0, 1)", c.tolerance);
  if (!(c.quadrature_tolerance > 0.0 && c.quadrature_tolerance < 1.0))
    throw_domain_error("quadrature_tolerance", "must lie in (0, 1)", c.quadrature_tolerance);
  if (c.theta_count < 2) throw_domain_error("theta_count", "must be >= 2", static_cast<long long>(c.theta_count));
  if (!(c.theta_max > 0.0 && c.theta_max < kHalfPi)) throw_domain_error("theta_max", "must lie in (0, pi/2)", c.theta_max);
  if (c.sigma_count < 2) throw_domain_error("sigma_count", "must be >= 2", static_cast<long long>(c.sigma_count));
  require_positive("sigma_max", c.sigma_max);
  const int N = fourier_terms(c.beta_min, c.tolerance);
  if (N + 1 > kMaxTerms) throw_domain_error("beta_min", "needs more terms than the table keeps (2048)", c.beta_min);
  terms_ = N + 1;
  const auto T_ = static_cast<std::size_t>(c.theta_count), S = static_cast<std::size_t>(c.sigma_count);
  const auto terms = static_cast<std::size_t>(terms_);
  data_.assign(static_cast<std::size_t>(c.lobes) * T_ * S * terms, T(0));
  std::vector<double> sigmas(S);
  for (std::size_t k = 0; k < S; ++k) sigmas[k] = sigma_node(static_cast<int>(k));
  GaussLegendreCache rules;
  std::vector<double> C;
  for (int p = 0; p < c.lobes; ++p)
    for (std::size_t t = 0; t < T_; ++t) {
      const double theta = theta_node(static_cast<int>(t));
      const FiberGeometry g = FiberGeometry::make(c.eta, theta);
      fourier_coefficients(g, c.path, p, sigmas, N, rules.get(fourier_nodes(N, p, g, c.quadrature_tolerance)), C);
      for (std::size_t k = 0; k < S; ++k) {
        const double F = c.store == FourierTableConfig::Store::raw ? 1.0 : absorption(p, sigmas[k], std::cos(theta));
        const double c0 = C[k];
        T* out = data_.data() + ((static_cast<std::size_t>(p) * T_ + t) * S + k) * terms;
        for (std::size_t n = 0; n < terms; ++n) {
          const double v = C[n * S + k];
          double stored = v;
          if (c.store == FourierTableConfig::Store::absorption || (c.store == FourierTableConfig::Store::ratio && n == 0))
            stored = F > 0.0 ? v / F : 0.0;
          else if (c.store == FourierTableConfig::Store::ratio)
            stored = c0 != 0.0 ? v / c0 : 0.0;
          out[n] = static_cast<T>(stored);
        }
      }
    }
}

template <class T>
double FourierTable<T>::theta_node(int i) const {
  const double s = static_cast<double>(i) / (config_.theta_count - 1);
  return config_.theta_cos ? std::acos(1.0 - s * (1.0 - std::cos(config_.theta_max))) : s * config_.theta_max;
}

template <class T>
double FourierTable<T>::sigma_node(int k) const {
  const double s = static_cast<double>(k) / (config_.sigma_count - 1);
  return config_.sigma_sqrt ? s * s * config_.sigma_max : s * config_.sigma_max;
}

// e^{−p σa' ℓ_min}: σa' = σa / cos θt = σa η / √(η² − sin²θd), ℓ_min the segment at the fibre's
// edge, where sin γt = 1/η' = cos θd / √(η² − sin²θd).
template <class T>
double FourierTable<T>::absorption(int p, double sigma_a, double cos_theta_d) const {
  if (p == 0 || sigma_a == 0.0) return 1.0;
  const double eta = config_.eta;
  const double q = std::sqrt(eta * eta - (1.0 - cos_theta_d * cos_theta_d));
  const double s = cos_theta_d / q;
  const double ct = std::sqrt(std::max(0.0, 1.0 - s * s));
  const double length = config_.path == AbsorptionPath::chord ? 2.0 * ct : 4.0 * ct * ct;
  return std::exp(-static_cast<double>(p) * sigma_a * eta / q * length);
}

template <class T>
double FourierTable<T>::value(int p, double beta, double sigma_a, double theta_d, double phi) const {
  const FourierTableConfig& c = config_;
  const double theta = std::min(std::abs(theta_d), c.theta_max);
  const double sigma = std::clamp(sigma_a, 0.0, c.sigma_max);
  const double ct = std::cos(theta);
  const double ut = (c.theta_cos ? (1.0 - ct) / (1.0 - std::cos(c.theta_max)) : theta / c.theta_max) * (c.theta_count - 1);
  const double us = (c.sigma_sqrt ? std::sqrt(sigma / c.sigma_max) : sigma / c.sigma_max) * (c.sigma_count - 1);
  const Taps tt = taps(ut, c.theta_count, c.cubic, !c.theta_cos);
  const Taps ts = taps(us, c.sigma_count, c.cubic, c.sigma_sqrt);
  const int N = fourier_series_terms(beta, c.tolerance, terms_ - 1);
  std::array<double, kMaxTerms> acc;
  std::fill(acc.begin(), acc.begin() + N + 1, 0.0);
  const auto S = static_cast<std::size_t>(c.sigma_count), terms = static_cast<std::size_t>(terms_);
  const T* lobe = data_.data() + static_cast<std::size_t>(p) * static_cast<std::size_t>(c.theta_count) * S * terms;
  for (int i = 0; i < tt.count; ++i)
    for (int k = 0; k < ts.count; ++k) {
      const double w = tt.w[static_cast<std::size_t>(i)] * ts.w[static_cast<std::size_t>(k)];
      if (w == 0.0) continue;
      const T* row = lobe + (static_cast<std::size_t>(tt.base + i) * S + static_cast<std::size_t>(ts.base + k)) * terms;
      for (int n = 0; n <= N; ++n) acc[static_cast<std::size_t>(n)] += w * static_cast<double>(row[n]);
    }
  if (c.store != FourierTableConfig::Store::raw) {
    const double F = absorption(p, sigma, ct);
    if (c.store == FourierTableConfig::Store::absorption) {
      for (int n = 0; n <= N; ++n) acc[static_cast<std::size_t>(n)] *= F;
    } else {
      acc[0] *= F;
      for (int n = 1; n <= N; ++n) acc[static_cast<std::size_t>(n)] *= acc[0];
    }
  }
  return std::max(0.0, series(acc.data(), N, beta, phi));
}

template class FourierTable<float>;
template class FourierTable<double>;

}  // namespace bench
