// Convergence of the deterministic dual-scattering quantities against a Monte Carlo simulation of
// the same model written here from scratch: h uniform over the fiber, the path traced by Russian
// roulette on the exact dielectric Fresnel factor and the segment transmittance, Gaussian detector
// noise added to the exit azimuth, θr drawn from d'Eon's M_p by its von Mises–Fisher construction
// (d'Eon et al. 2013), and the energy counted in the forward and backward halves. The library is
// called only for the values under test; the agreement must hold within 4 standard errors.
#include <cmath>
#include <cstdint>
#include <hairlut/physics/dual_scattering.hpp>
#include <hairlut/bake/dual_scattering_grid.hpp>
#include <numbers>
#include <vector>

#include "catch.hpp"

using namespace hairlut;

namespace {

constexpr double pi = std::numbers::pi;

// splitmix64: a fixed, portable stream of uniform doubles in [0, 1).
struct Rng {
  std::uint64_t state;
  double uniform() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53;
  }
  double normal() {  // Box–Muller
    const double u = 1.0 - uniform(), v = uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * pi * v);
  }
};

// Unpolarized reflectance of a dielectric interface of relative index eta at incidence cos_i.
double fresnel(double eta, double cos_i) {
  const double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin2_t);
  const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t), rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

// θ with density M(v, θi, θ) cos θ: a von Mises–Fisher direction about the specular cone, whose
// inclination is d'Eon's M_p; 1 − cos Θ = −v ln(u + (1 − u) e^{−2/v}).
double sample_longitudinal(double v, double theta_i, Rng& rng) {
  const double u = 1.0 - rng.uniform();
  const double d = -v * std::log(u + (1.0 - u) * std::exp(-2.0 / v));
  const double cos_t = 1.0 - d, sin_t = std::sqrt(std::max(0.0, d * (2.0 - d)));
  const double s = -cos_t * std::sin(theta_i) + sin_t * std::cos(2.0 * pi * rng.uniform()) * std::cos(theta_i);
  return std::asin(std::clamp(s, -1.0, 1.0));
}

// The exit directions θr whose tilted lobe M(v, θi, fold(θr − α)) looks at θ*: θr − α = θ*, or
// folded over a pole (π − θ* above π/2, −π − θ* below −π/2), inside [−π/2, π/2].
std::vector<double> tilted_preimages(double theta_star, double alpha) {
  std::vector<double> out;
  for (double x : {theta_star, pi - theta_star, -pi - theta_star}) {
    const bool folded_ok = x == theta_star || (x > pi / 2) || (x < -pi / 2);
    const double tr = x + alpha;
    if (folded_ok && std::abs(tr) <= pi / 2) out.push_back(tr);
  }
  return out;
}

// One ray into the fiber cross-section at offset h, at longitudinal difference θd: the number of
// internal segments of the path that leaves the fiber (0: reflected), or −1 when absorbed; Φ its
// exit azimuth.
int trace(double eta, double theta_d, double sigma_a, double h, Rng& rng, double& Phi) {
  const double cd = std::cos(theta_d), sd = std::sin(theta_d);
  const double gamma_i = std::asin(h);
  const double eta_prime = std::sqrt(eta * eta - sd * sd) / cd;  // Bravais
  const double gamma_t = std::asin(h / eta_prime);
  const double f = fresnel(eta, cd * std::cos(gamma_i));
  const double cos_theta_t = std::sqrt(1.0 - (sd / eta) * (sd / eta));
  const double T = std::exp(-2.0 * sigma_a * std::cos(gamma_t) / cos_theta_t);
  if (rng.uniform() < f) {
    Phi = -2.0 * gamma_i;
    return 0;
  }
  for (int p = 1; p < 100000; ++p) {
    if (rng.uniform() >= T) return -1;             // absorbed on the segment
    if (rng.uniform() < 1.0 - f) {                 // transmitted out
      Phi = 2.0 * p * gamma_t - 2.0 * gamma_i + p * pi;
      return p;
    }
  }
  return -1;
}

struct Estimate {
  double mean = 0.0, stderr_ = 0.0;
};

struct McResult {
  Estimate energy, forward, backward;
};

// Monte Carlo of E, a_f and a_b of a model, `samples` paths per lobe.
McResult simulate(const HairModel& m, double theta_i, long samples, std::uint64_t seed) {
  std::vector<LobeParams> lobes = m.lobes;
  const int P = static_cast<int>(m.lobes.size());
  if (m.residual) lobes.push_back(*m.residual);
  Rng rng{seed};
  McResult total;
  double var_e = 0.0, var_f = 0.0, var_b = 0.0;
  for (std::size_t q = 0; q < lobes.size(); ++q) {
    const LobeParams& l = lobes[q];
    double se = 0, se2 = 0, sf = 0, sf2 = 0, sb = 0, sb2 = 0;
    for (long i = 0; i < samples; ++i) {
      const double theta_star = sample_longitudinal(l.beta_m * l.beta_m, theta_i, rng);
      double e = 0, fw = 0, bw = 0;
      for (double theta_r : tilted_preimages(theta_star, l.alpha)) {
        const double w = std::cos(theta_r) / std::cos(theta_star);
        double Phi = 0.0;
        const int p = trace(m.eta, 0.5 * (theta_r - theta_i), m.sigma_a, 2.0 * rng.uniform() - 1.0, rng, Phi);
        if (p < 0 || (static_cast<int>(q) < P && p != static_cast<int>(q)) || (static_cast<int>(q) == P && p < P)) continue;
        const double phi = static_cast<int>(q) < P ? Phi + l.beta_n * rng.normal() : pi * (2.0 * rng.uniform() - 1.0);
        e += w;
        (std::abs(std::remainder(phi, 2.0 * pi)) <= pi / 2 ? bw : fw) += w;
      }
      se += e, se2 += e * e, sf += fw, sf2 += fw * fw, sb += bw, sb2 += bw * bw;
    }
    const double n = static_cast<double>(samples);
    auto acc = [&](Estimate& est, double& var, double s, double s2) {
      est.mean += s / n;
      var += (s2 / n - (s / n) * (s / n)) / n;
    };
    acc(total.energy, var_e, se, se2);
    acc(total.forward, var_f, sf, sf2);
    acc(total.backward, var_b, sb, sb2);
  }
  total.energy.stderr_ = std::sqrt(var_e);
  total.forward.stderr_ = std::sqrt(var_f);
  total.backward.stderr_ = std::sqrt(var_b);
  return total;
}

}  // namespace

TEST_CASE("Dual scattering and mean energy converge to a Monte Carlo simulation of the model within 4 standard errors",
          "[dual_scattering][monte-carlo]") {
  struct Case {
    const char* name;
    HairModel model;
    double theta_i;
  };
  std::vector<Case> cases;
  {
    Case c{"white, uniform beta 0.3 rad, no tilt", HairModel::uniform(1.55, 0.0, 0.3, 3, true), 0.5};
    cases.push_back(c);
  }
  {
    // Unreal's lobes at roughness 0.5 and tilts, absorbing.
    HairModel m;
    m.sigma_a = 0.4;
    m.lobes = {{0.25, 0.25, -0.07}, {0.125, 0.125, 0.035}, {0.5, 0.5, 0.14}};
    m.residual = LobeParams{0.5, 0.5, 0.14};
    cases.push_back({"Unreal roughness 0.5, sigma_a 0.4", m, 0.9});
  }
  {
    // Narrow lobes (the baker's direct half ranges), a different index.
    HairModel m;
    m.eta = 1.4;
    m.sigma_a = 0.1;
    m.lobes = {{0.03, 0.02, -0.05}, {0.015, 0.01, 0.02}, {0.06, 0.04, 0.08}};
    m.residual = LobeParams{0.06, 0.06, 0.08};
    cases.push_back({"narrow lobes, eta 1.4, sigma_a 0.1", m, 0.15});
  }
  const long samples = 3'000'000;
  std::uint64_t seed = 20081;
  for (const Case& c : cases) {
    const McResult mc = simulate(c.model, c.theta_i, samples, seed++);
    const DualScatteringPoint ref = dual_scattering(c.model, c.theta_i);
    // The same cell through the baker's grid (interpolated θd curves, Fourier or direct halves).
    DualScatteringGridRequest rq;
    rq.eta = c.model.eta;
    rq.lobes = 3;
    rq.residual = true;
    rq.sigmas = {c.model.sigma_a};
    std::vector<LobeParams> lobes = c.model.lobes;
    lobes.push_back(*c.model.residual);
    rq.roughness = {lobes};
    rq.thetas = {c.theta_i};
    DualScatteringPoint grid;
    dual_scattering_grid(rq, BakeOptions{}, "", [&](std::size_t, std::size_t, std::size_t, const DualScatteringPoint& p) { grid = p; });
    INFO(c.name);
    REQUIRE(ref.converged);
    const std::pair<const char*, std::tuple<Estimate, double, double>> rows[] = {
        {"E", {mc.energy, ref.energy_total, grid.energy_total}},
        {"a_f", {mc.forward, ref.a_f, grid.a_f}},
        {"a_b", {mc.backward, ref.a_b, grid.a_b}}};
    for (const auto& [what, row] : rows) {
      const auto& [est, exact, table] = row;
      const double z = (exact - est.mean) / est.stderr_, zt = (table - est.mean) / est.stderr_;
      INFO(what << ": deterministic " << exact << ", grid " << table << ", Monte Carlo " << est.mean << " +- " << est.stderr_);
      CHECK(std::abs(exact - est.mean) <= 4.0 * est.stderr_);
      CHECK(std::abs(table - est.mean) <= 4.0 * est.stderr_);
      WARN("Monte Carlo (" << samples << " paths per lobe), " << c.name << ": " << what << " deterministic " << exact << ", grid " << table
                           << ", MC " << est.mean << " +- " << est.stderr_ << " (z = " << z << ", grid z = " << zt << ")");
    }
  }
}
