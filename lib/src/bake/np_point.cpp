#include "hairlut/bake/np_point.hpp"

#include <cmath>
#include <cstdio>

#include "hairlut/util/angles.hpp"
#include "hairlut/physics/azimuthal_fourier.hpp"
#include "hairlut/physics/azimuthal_np.hpp"
#include "hairlut/bake/bake.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/fiber_geometry.hpp"

namespace hairlut {

namespace {

constexpr int kMaxRuleOrder = 32768;  // GaussLegendreRule's largest order

// n/d with d ≤ max_d and |x − n/d| ≤ 1e-13, by continued fractions; d = 0 when there is none.
void as_fraction(double x, long max_d, long& n, long& d) {
  long h0 = 0, h1 = 1, k0 = 1, k1 = 0;  // convergents h/k
  double r = x;
  n = d = 0;
  for (int i = 0; i < 40; ++i) {
    const double a = std::floor(r);
    const long h2 = static_cast<long>(a) * h1 + h0, k2 = static_cast<long>(a) * k1 + k0;
    if (k2 > max_d) return;
    h0 = h1, h1 = h2, k0 = k1, k1 = k2;
    if (std::abs(x - static_cast<double>(h1) / static_cast<double>(k1)) <= 1e-13) {
      n = h1, d = k1;
      return;
    }
    const double frac = r - a;
    if (frac < 1e-15) return;
    r = 1.0 / frac;
  }
}

}  // namespace

PointNp baker_np(double eta, AbsorptionPath path, double theta_d, double sigma_a, int p, double beta, double phi, double tolerance) {
  if (!(beta > 0.0) || !std::isfinite(beta)) throw_domain_error("beta", "must be a finite number > 0", beta);
  if (!(tolerance > 0.0 && tolerance < 1.0)) throw_domain_error("tolerance", "must lie in (0, 1)", tolerance);
  if (!std::isfinite(phi)) throw_domain_error("phi", "must be finite", phi);
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  const AttenuationSlice slice(eta, theta_d, sigma_a, path);  // checks η, θd, σa

  // N_p is even and 2π-periodic: fold φ into [0, π]. The baker's grids are periodic, symmetric
  // about 0 (spreading relies on it) and uniform; {φ, φ + 2π/P} is one when 2φP/2π is an integer.
  const double folded = std::abs(std::remainder(phi, kTwoPi));
  long n = 0, d = 0;
  as_fraction(folded / kPi, 1000000, n, d);
  std::vector<double> phis{folded};
  if (d > 0) {
    const long P = d < 2 ? 2 : d;
    phis.push_back(folded + kTwoPi / static_cast<double>(P));
  }

  // The baker plans with both forms; it cannot bake a β whose Fourier series is too long, nor one
  // for which neither form fits the largest Gauss–Legendre rule.
  const FiberGeometry g = FiberGeometry::make(eta, theta_d);
  const int spread_m = spread_nodes(beta, p, g, tolerance);
  std::string why;
  try {
    const int fourier_m = fourier_nodes(fourier_terms(beta, tolerance), p, g, tolerance);
    if (fourier_m > kMaxRuleOrder && (d == 0 || spread_m > kMaxRuleOrder))
      why = "its quadrature would need " + std::to_string(std::min(fourier_m, spread_m)) + " Gauss-Legendre nodes (at most " +
            std::to_string(kMaxRuleOrder) + ")";
  } catch (const DomainError& e) {
    why = e.what();
  }
  if (!why.empty()) {
    PointNp r;
    const AdaptiveResult a = azimuthal_np_reference(slice, p, beta, phi, tolerance);
    r.value = a.value[0];
    char buf[64];
    std::snprintf(buf, sizeof buf, "error estimate %.3g%s", a.error[0], a.converged ? "" : ", not converged");
    r.method = std::string("adaptive reference (") + buf + ")";
    r.note = "the baker cannot bake this beta (" + why + "); the value is the adaptive reference";
    return r;
  }
  NpGridRequest request;
  request.eta = eta;
  request.path = path;
  request.quadrature.method = NpQuadratureConfig::Method::fourier;
  request.quadrature.tolerance = tolerance;
  request.lobes = p + 1;
  request.sigmas = {sigma_a};
  request.thetas = {theta_d};
  request.phis = phis;
  request.betas_of = [&](int) { return std::vector<double>{beta}; };
  BakeOptions options;
  options.threads = 1;
  double value = 0.0;
  bake_np_grid(request, options, "", [&](int lobe, std::size_t, std::size_t, std::size_t, std::size_t j, double v) {
    if (lobe == p && j == 0) value = v;
  });
  PointNp r;
  r.value = value;
  char buf[200];
  std::snprintf(buf, sizeof buf, "the baker's: Fourier series or spreading of the detector, tolerance %.3g of the lobe peak", tolerance);
  r.method = buf;
  return r;
}

}  // namespace hairlut
