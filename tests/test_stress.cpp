// Stress: no NaN, no Inf and no negative value in M_p, A and N_p over the extremes of the domain
// (β 0.1°–90°, θd 0–89.99°, σa 0–1e3, η 1.01–3, p up to 20, grazing angles).
#include <cmath>
#include <hairlut/hairlut.hpp>

#include "catch.hpp"

using namespace hairlut;

namespace {
bool ok(double x) { return std::isfinite(x) && x >= 0.0; }
const double kBetasDeg[] = {0.1, 0.25, 0.5, 2.0, 10.0, 45.0, 90.0};
const double kThetaDDeg[] = {0.0, 30.0, 60.0, 85.0, 89.0, 89.99};
const double kSigmas[] = {0.0, 1e-3, 0.5, 10.0, 1e3};
const double kEtas[] = {1.01, 1.1, 1.55, 3.0};
const int kLobes[] = {0, 1, 2, 3, 5, 10, 20};
}  // namespace

TEST_CASE("Stress: M_p is finite and non-negative everywhere", "[stress]") {
  long bad = 0, count = 0;
  for (double b : kBetasDeg)
    for (double v : {radians(b) * radians(b), 1e-12, 1e6})
      for (double alpha : {0.0, radians(-10.0), radians(10.0)})
        for (double ti = -kHalfPi; ti <= kHalfPi + 1e-12; ti += kPi / 36)
          for (double tr : {-kHalfPi, -1.5, -0.5, 0.0, 0.7, 1.5707, kHalfPi}) {
            const double t = std::min(ti, kHalfPi);
            const double m = longitudinal_deon_tilted(v, alpha, t, tr);
            const double g = longitudinal_gaussian(radians(b), 0.5 * alpha, t, tr, GaussianArgument::theta_h);
            ++count;
            if (!ok(m) || !ok(g)) ++bad;
          }
  INFO(bad << " bad of " << count);
  CHECK(bad == 0);
}

TEST_CASE("Stress: A and the residual are finite and in [0, 1]", "[stress]") {
  long bad = 0;
  for (double eta : kEtas)
    for (double td : kThetaDDeg)
      for (double s : kSigmas)
        for (auto path : {AbsorptionPath::chord, AbsorptionPath::papers}) {
          const AttenuationSlice slice(eta, radians(td), s, path);
          for (double h : {-1.0, -0.999999, -0.5, 0.0, 0.3, 0.9999, 1.0}) {
            const PathPoint q = slice.at_h(h);
            for (int p : kLobes) {
              const double a = q.attenuation(p);
              if (!ok(a) || a > 1.0) ++bad;
              if (p >= 1) {
                const double r = q.residual_attenuation(p);
                if (!ok(r) || r > 1.0) ++bad;
              }
            }
          }
        }
  CHECK(bad == 0);
}

TEST_CASE("Stress: N_p (quadrature, reference, smooth) is finite and non-negative", "[stress]") {
  const GaussLegendreRule rule(64);
  long bad = 0, unconverged = 0, count = 0;
  for (double eta : kEtas)
    for (double td : kThetaDDeg)
      for (double s : kSigmas) {
        const AttenuationSlice slice(eta, radians(td), s);
        for (double b : kBetasDeg)
          for (int p : kLobes)
            for (double phi : {0.0, 0.5, 1.5, 2.5, kPi}) {
              const double beta = radians(b);
              const double n1 = azimuthal_np(slice, p, beta, phi, rule, IntegrationVariable::gamma);
              const double n2 = azimuthal_np(slice, p, beta, phi, rule, IntegrationVariable::h);
              ++count;
              if (!ok(n1) || !ok(n2)) ++bad;
              if (p <= 3 && (s == 0.0 || s == 10.0) && (b == 0.1 || b == 2.0 || b == 90.0)) {
                const AdaptiveResult r = azimuthal_np_reference(slice, p, beta, phi);
                if (!ok(r.value[0]) || !ok(r.error[0])) ++bad;
                if (!r.converged) ++unconverged;
              }
            }
      }
  INFO(bad << " bad of " << count);
  CHECK(bad == 0);
  CHECK(unconverged == 0);
}

TEST_CASE("Stress: lobe energies stay in [0, 1] and sum to at most 1", "[stress]") {
  const GaussLegendreRule rule(128);
  for (double eta : kEtas)
    for (double td : kThetaDDeg)
      for (double s : kSigmas) {
        const auto e = lobe_energies(AttenuationSlice(eta, radians(td), s), {20, true}, rule);
        double sum = 0.0;
        for (double x : e) {
          CHECK(ok(x));
          sum += x;
        }
        CHECK(sum <= 1.0 + 1e-12);
      }
}
