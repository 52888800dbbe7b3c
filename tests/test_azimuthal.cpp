// d'Eon's N_p: energy, symmetry, conservation, the smooth-fiber limit and quadrature convergence.
#include <algorithm>
#include <cmath>
#include <hairlut/hairlut.hpp>
#include <vector>

#include "catch.hpp"

using namespace hairlut;

namespace {
struct Case {
  double eta, theta_d, sigma_a, beta_deg;
  int p;
};
const Case kCases[] = {
    {1.55, 0.0, 0.0, 0.5, 0},  {1.55, 0.5, 0.3, 0.5, 1},  {1.55, 0.5, 0.3, 1.0, 2},   {1.55, 1.2, 0.0, 2.0, 3},
    {1.55, 0.3, 1.0, 10.0, 2}, {1.33, 0.9, 0.1, 25.0, 1}, {2.5, 1.4, 0.05, 60.0, 4}, {1.01, 0.2, 0.0, 5.0, 2},
    {1.55, 1.5, 0.0, 90.0, 8}, {3.0, 0.0, 5.0, 3.0, 1},
};
}  // namespace

TEST_CASE("N_p integrates over phi to the lobe energy within 1e-9", "[np]") {
  const GaussLegendreRule energy_rule(256);
  for (const Case& c : kCases) {
    const AttenuationSlice slice(c.eta, c.theta_d, c.sigma_a);
    const double beta = radians(c.beta_deg);
    const double energy = lobe_energies(slice, {c.p + 1, false}, energy_rule).back();
    // Integrate the reference over φ adaptively, split at the azimuths where N_p can have features
    // as narrow as β (caustics, the edges h = ±1, h = 0) and at geometric distances β·4^k around them.
    std::vector<double> bp = {-kPi, 0.0, kPi};
    const FiberGeometry& g = slice.geometry();
    std::vector<double> special_gammas = {0.0, kHalfPi};
    if (caustic_gamma(c.p, g) > 0.0) special_gammas.push_back(caustic_gamma(c.p, g));
    for (double gamma : special_gammas) {
      const double centre = std::abs(std::remainder(exit_azimuth(c.p, gamma, std::asin(std::sin(gamma) * g.inv_eta_prime)), kTwoPi));
      for (double s : {-1.0, 1.0}) {
        bp.push_back(s * centre);
        for (double w = beta; w < kPi; w *= 4.0) bp.push_back(s * (centre + w)), bp.push_back(s * (centre - w));
      }
    }
    std::erase_if(bp, [](double x) { return !(x >= -kPi && x <= kPi); });
    std::sort(bp.begin(), bp.end());
    bp.erase(std::unique(bp.begin(), bp.end()), bp.end());
    const AdaptiveResult r = integrate_adaptive(
        [&](double phi, std::span<double> out) { out[0] = azimuthal_np_reference(slice, c.p, beta, phi, 1e-13).value[0]; },
        1, bp, {1e-12, 1e-300, 8000});
    INFO("eta=" << c.eta << " theta_d=" << c.theta_d << " sigma_a=" << c.sigma_a << " beta=" << c.beta_deg << " p=" << c.p);
    CHECK(r.converged);
    CHECK(std::abs(r.value[0] - energy) <= 1e-9 * std::max(energy, 1e-3));
  }
}

TEST_CASE("N_p is even in phi", "[np]") {
  const GaussLegendreRule rule(64);
  for (const Case& c : kCases)
    for (double phi : {0.1, 0.7, 1.9, 3.0}) {
      const AttenuationSlice slice(c.eta, c.theta_d, c.sigma_a);
      const double beta = radians(c.beta_deg);
      for (auto var : {IntegrationVariable::gamma, IntegrationVariable::h})
        CHECK(azimuthal_np(slice, c.p, beta, phi, rule, var) == azimuthal_np(slice, c.p, beta, -phi, rule, var));
      const double a = azimuthal_np_reference(slice, c.p, beta, phi).value[0];
      const double b = azimuthal_np_reference(slice, c.p, beta, -phi).value[0];
      CHECK(a == Approx(b).epsilon(1e-12).margin(1e-300));
    }
}

TEST_CASE("White fibers: explicit lobes plus the residual carry all the energy at every theta_d", "[np]") {
  const GaussLegendreRule rule(128);
  for (double eta : {1.01, 1.2, 1.55, 3.0})
    for (double td_deg : {0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0, 89.99})
      for (int P : {1, 2, 3, 4, 8}) {
        const AttenuationSlice slice(eta, radians(td_deg), 0.0);
        const AdaptiveResult ref = lobe_energies_reference(slice, {P, true});
        const std::vector<double> e = lobe_energies(slice, {P, true}, rule);
        double sum = 0.0, sum_ref = 0.0;
        for (std::size_t i = 0; i < e.size(); ++i) {
          sum += e[i], sum_ref += ref.value[i];
          CHECK(e[i] == Approx(ref.value[i]).epsilon(1e-12).margin(1e-14));  // fixed rule vs adaptive
        }
        INFO("eta=" << eta << " theta_d=" << td_deg << " P=" << P);
        CHECK(ref.converged);
        CHECK(std::abs(sum - 1.0) <= 1e-9);
        CHECK(std::abs(sum_ref - 1.0) <= 1e-9);
      }
}

TEST_CASE("As beta -> 0, N_p approaches the smooth-fiber solution by root solving", "[np]") {
  const AttenuationSlice slice(1.55, radians(30.0), 0.2);
  struct Point { int p; double phi; };
  // Away from caustics: R everywhere, TT towards the back, TRT inside its caustic.
  for (const Point pt : {Point{0, 0.3}, Point{0, 2.0}, Point{0, 3.0}, Point{1, 2.0}, Point{1, 3.0}, Point{2, 0.3}, Point{2, 0.05}}) {
    const double smooth = azimuthal_np_smooth(slice, pt.p, pt.phi);
    REQUIRE(smooth > 0.0);
    double previous = INFINITY;
    for (double beta_deg : {1.0, 0.3, 0.1, 0.03}) {
      const AdaptiveResult r = azimuthal_np_reference(slice, pt.p, radians(beta_deg), pt.phi);
      REQUIRE(r.converged);
      const double err = std::abs(r.value[0] / smooth - 1.0);
      INFO("p=" << pt.p << " phi=" << pt.phi << " beta_deg=" << beta_deg << " rel err=" << err);
      CHECK(err < previous);  // monotone approach (the error falls like β²)
      previous = err;
    }
    CHECK(previous < 1e-5);
  }
}

TEST_CASE("Gauss-Legendre N_p approaches the adaptive reference as the order grows", "[np]") {
  for (double beta_deg : {2.0, 10.0, 30.0})
    for (int p : {0, 1, 2, 3}) {
      const AttenuationSlice slice(1.55, radians(20.0), 0.1);
      const double beta = radians(beta_deg);
      // Error relative to the lobe's peak over φ.
      double peak = 0.0;
      std::vector<double> phis, refs;
      for (double phi = 0.0; phi <= kPi; phi += kPi / 24) {
        const AdaptiveResult r = azimuthal_np_reference(slice, p, beta, phi);
        REQUIRE(r.converged);
        phis.push_back(phi), refs.push_back(r.value[0]);
        peak = std::max(peak, r.value[0]);
      }
      std::vector<double> errors;
      for (int order : {16, 32, 64, 128, 256, 512}) {
        const GaussLegendreRule rule(order);
        double err = 0.0;
        for (std::size_t i = 0; i < phis.size(); ++i)
          err = std::max(err, std::abs(azimuthal_np(slice, p, beta, phis[i], rule) - refs[i]) / peak);
        errors.push_back(err);
      }
      INFO("beta=" << beta_deg << " p=" << p << " errors 16..512: " << errors[0] << " " << errors[1] << " " << errors[2]
                   << " " << errors[3] << " " << errors[4] << " " << errors[5]);
      CHECK(errors.back() <= 1e-10);
      CHECK(errors.back() <= errors.front());
      for (std::size_t i = 1; i < errors.size(); ++i) CHECK(errors[i] <= std::max(errors[i - 1], 1e-12));
    }
}

TEST_CASE("d'Eon's order 35 in h is adequate for rough fibers and fails below 2 degrees", "[np][paper]") {
  const AttenuationSlice slice(1.55, radians(20.0), 0.1);
  const GaussLegendreRule rule(35);
  auto worst = [&](double beta_deg) {
    double peak = 0.0, err = 0.0;
    for (double phi = 0.0; phi <= kPi; phi += kPi / 48) {
      const double ref = azimuthal_np_reference(slice, 1, radians(beta_deg), phi).value[0];
      peak = std::max(peak, ref);
      err = std::max(err, std::abs(azimuthal_np(slice, 1, radians(beta_deg), phi, rule, IntegrationVariable::h) - ref));
    }
    return err / peak;
  };
  CHECK(worst(20.0) < 1e-2);
  CHECK(worst(1.0) > 0.1);
}

TEST_CASE("The residual lobe is uniform in phi and carries the residual energy", "[np]") {
  const AttenuationSlice slice(1.55, 0.4, 0.2);
  const GaussLegendreRule rule(128);
  const auto e = lobe_energies(slice, {3, true}, rule);
  CHECK(azimuthal_residual_np(slice, 3, rule) * kTwoPi == Approx(e[3]).epsilon(1e-15));
}
