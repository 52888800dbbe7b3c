// The shipped default tables at grazing θd (89.5°, 89.9°, 89.99°, 90°), where the energies of the
// lobes p ≥ 1 vanish as cos²θd and the residual's as cos θd: the runtime's N_p, lobe energies and S
// against direct evaluation of the model, within the config's accuracy threshold, and nothing NaN
// or negative at exactly 90°.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <hairlut/io/table_io.hpp>
#include <hairlut/physics/azimuthal_np.hpp>
#include <hairlut/physics/lobe_energy.hpp>
#include <hairlut/physics/longitudinal_mp.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <hairlut/util/angles.hpp>
#include <nlohmann/json.hpp>

#include "catch.hpp"

using namespace hairlut;

namespace {

const TableSet& default_tables() {
  static const TableSet set = load_tables(std::string(HAIRLUT_SOURCE_DIR) + "/tables/default/hairlut-default.h5");
  return set;
}

// The default config's threshold on N_p (the worst error relative to the local peak).
double config_threshold() {
  std::ifstream in(std::string(HAIRLUT_SOURCE_DIR) + "/tables/configs/default.json");
  return nlohmann::json::parse(in).at("validate").at("thresholds").at("accuracy_max_rel").get<double>();
}

const double kThetaDeg[] = {89.5, 89.9, 89.99, 90.0};
const double kSigma[] = {0.0, 0.02, 0.3, 2.0, 8.0};

// Direct N_p over the φ grid of one slice, and its peak.
std::vector<double> direct_np(double eta, double theta_d, double sigma_a, int p, double beta, const std::vector<double>& phis,
                              const GaussLegendreRule& rule) {
  const NpQuadratureSlab slab(AttenuationSlice(eta, theta_d, sigma_a), p, rule);
  std::vector<double> out;
  for (double phi : phis) out.push_back(slab(beta, phi));
  return out;
}

double peak(const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); }

}  // namespace

TEST_CASE("grazing: N_p and lobe energies of the default tables at theta_d up to 90 deg match the model", "[grazing]") {
  const TableSet& set = default_tables();
  REQUIRE(set.metadata.value("absorption_path", std::string("chord")) == "chord");
  const auto h = hair_tables<float, double>(set);
  const double threshold = config_threshold();
  const GaussLegendreRule rule(1024), energy_rule(256);
  std::vector<double> phis;
  for (int j = 0; j <= 90; ++j) phis.push_back(kPi * j / 90.0);
  const double betas[] = {radians(5.0), radians(12.0), radians(40.0)};
  double worst_np = 0.0, worst_energy = 0.0;
  for (double deg : kThetaDeg) {
    const double td = radians(deg);
    const std::vector<double> white = lobe_energies(AttenuationSlice(h.eta, td, 0.0), LobeSet{h.lobes, true}, energy_rule);
    for (double sa : kSigma) {
      const std::vector<double> e = lobe_energies(AttenuationSlice(h.eta, td, sa), LobeSet{h.lobes, true}, energy_rule);
      for (int p = 0; p <= h.lobes; ++p) {
        const bool res = p == h.lobes;
        const double got = res ? 2.0 * kPi * h.np_residual(sa, td) : h.np[p].energy(sa, td);
        const double want = e[static_cast<std::size_t>(p)], den = std::max(want, 1e-3 * white[static_cast<std::size_t>(p)]);
        INFO("energy of lobe " << p << " at theta_d " << deg << " deg, sigma_a " << sa << ": table " << got << ", model " << want);
        REQUIRE(std::isfinite(got));
        CHECK(got >= 0.0);
        CHECK(std::fabs(got - want) <= threshold * den);
        worst_energy = std::max(worst_energy, std::fabs(got - want) / den);
      }
      for (int p = 0; p < h.lobes; ++p)
        for (double beta : betas) {
          const std::vector<double> want = direct_np(h.eta, td, sa, p, beta, phis, rule);
          const double den = std::max(peak(want), 1e-3 * peak(direct_np(h.eta, td, 0.0, p, beta, phis, rule)));
          for (std::size_t j = 0; j < phis.size(); ++j) {
            const double got = h.np_value(p, beta, sa, td, phis[j]);
            INFO("N_p of lobe " << p << " at theta_d " << deg << " deg, sigma_a " << sa << ", beta " << degrees(beta) << " deg, phi "
                                << degrees(phis[j]) << " deg: table " << got << ", model " << want[j] << ", peak " << den);
            REQUIRE(std::isfinite(got));
            CHECK(got >= 0.0);
            CHECK(std::fabs(got - want[j]) <= threshold * den);
            worst_np = std::max(worst_np, std::fabs(got - want[j]) / den);
          }
        }
    }
  }
  WARN("grazing theta_d 89.5 .. 90 deg: worst N_p error " << worst_np << " of the slice peak, worst energy error " << worst_energy
                                                          << " relative (threshold " << threshold << ")");
}

TEST_CASE("grazing: S of the runtime at theta_d up to 90 deg matches the model", "[grazing]") {
  const TableSet& set = default_tables();
  const sampler::HairScattering<float> rt = hair_scattering<float>(set);
  const auto& h = rt.tables();
  REQUIRE(rt.valid());
  const double threshold = config_threshold();
  const GaussLegendreRule rule(1024), energy_rule(256);
  std::vector<double> alpha;
  for (int p = 0; p <= h.lobes; ++p) {
    const std::string lobe = p < h.lobes ? set.metadata.at("lobes").at(static_cast<std::size_t>(p)).get<std::string>() : "residual";
    alpha.push_back(set.find("mp/" + lobe)->attributes.value("alpha", 0.0));
  }
  std::vector<double> phis;
  for (int j = 0; j <= 60; ++j) phis.push_back(kPi * j / 60.0);
  double worst = 0.0;
  for (double deg : kThetaDeg)
    for (double sa : kSigma)
      for (double h_frac : {-0.5, 0.0, 0.5}) {
        const double td = radians(deg), th = h_frac * (0.5 * kPi - td), to = th + td, ti = th - td;
        sampler::Fiber f;
        f.beta_m = radians(10.0), f.beta_n = radians(10.0);
        f.sigma_a[0] = f.sigma_a[1] = f.sigma_a[2] = sa;
        // S = Σ_p M_p(θi, θo) N_p(φ) + M_res E_res / 2π, each from the physics.
        const std::vector<double> e = lobe_energies(AttenuationSlice(h.eta, td, sa), LobeSet{h.lobes, true}, energy_rule);
        std::vector<double> want(phis.size(), 0.0);
        for (int p = 0; p <= h.lobes; ++p) {
          const double m = longitudinal_deon_tilted(f.beta_m * f.beta_m, alpha[static_cast<std::size_t>(p)], ti, to);
          const std::vector<double> n = p < h.lobes ? direct_np(h.eta, td, sa, p, f.beta_n, phis, rule)
                                                    : std::vector<double>(phis.size(), e.back() / (2.0 * kPi));
          for (std::size_t j = 0; j < phis.size(); ++j) want[j] += m * n[j];
        }
        const double den = peak(want);
        for (std::size_t j = 0; j < phis.size(); ++j) {
          double rgb[3];
          rt.eval(f, to, ti, phis[j], rgb);
          INFO("S at theta_d " << deg << " deg, theta_h " << degrees(th) << " deg, sigma_a " << sa << ", phi " << degrees(phis[j])
                               << " deg: runtime " << rgb[0] << ", model " << want[j] << ", peak " << den);
          for (double v : rgb) {
            REQUIRE(std::isfinite(v));
            CHECK(v >= 0.0);
          }
          CHECK(std::fabs(rgb[0] - want[j]) <= threshold * den);
          worst = std::max(worst, std::fabs(rgb[0] - want[j]) / den);
        }
      }
  WARN("grazing theta_d 89.5 .. 90 deg: worst |S - S_model| " << worst << " of the peak of S_model over phi (threshold " << threshold << ")");
}

TEST_CASE("grazing: nothing is NaN or negative at exactly theta_d = 90 deg", "[grazing]") {
  const TableSet& set = default_tables();
  const auto h = hair_tables<float, double>(set);
  const double td = 0.5 * kPi;
  for (double sa : {0.0, 1e-4, 0.5, 16.0})
    for (double beta : {radians(4.0), radians(45.0)})
      for (int j = 0; j <= 12; ++j) {
        const double phi = kPi * j / 12.0;
        for (int p = 0; p < h.lobes; ++p) {
          for (double v : {h.np_value(p, beta, sa, td, phi), h.np_value(p, beta, sa, -td, -phi), h.np[p].energy(sa, td)}) {
            CHECK(std::isfinite(v));
            CHECK(v >= 0.0);
          }
        }
        const double r = h.np_residual(sa, td);
        CHECK(std::isfinite(r));
        CHECK(r >= 0.0);
      }
  // The R lobe keeps all the energy at grazing (F → 1); the others vanish.
  CHECK(h.np[0].energy(0.0, td) == Approx(1.0).epsilon(1e-3));
  for (int p = 1; p < h.lobes; ++p) CHECK(h.np[p].energy(0.0, td) < 1e-30);
}

TEST_CASE("grazing: the residual's grazing factor follows its energy across the corner sigma_a -> 0, theta_d -> 90 deg", "[grazing]") {
  // e_res / g_res against its limit (π/4) k T∞^{P−1} (docs/table-format.md) at cos θd = 1e-6 (where the
  // O(cos θd) terms are below 2e-5), for
  // σa from 0 to where x = expm1(τ σa) / k is 1e6 times cos θd: the energy from the model's own
  // quadrature, g_res from the shipped file's attributes.
  const TableSet& set = default_tables();
  const Table* t = set.find("np/energy_residual");
  REQUIRE(t);
  const sampler::GrazingFactor g = t->grazing_factor();
  REQUIRE(g.x_scale > 0.0);
  const auto h = hair_tables<float, double>(set);
  const double eta = h.eta, k = 2.0 * (1.0 + eta * eta) / std::sqrt(eta * eta - 1.0), u = 1e-6, td = std::acos(u);
  const GaussLegendreRule rule(2048);
  double worst = 0.0;
  for (double a : {0.0, 1e-3, 0.01, 0.1, 0.3, 1.0, 2.0, 5.0, 20.0, 100.0, 1e3, 1e4, 1e6}) {
    const double sigma_a = std::log1p(a * u / g.x_scale) / g.tau;
    const double e = lobe_energies(AttenuationSlice(eta, td, sigma_a), LobeSet{h.lobes, true}, rule).back();
    const double limit = 0.25 * kPi * k * std::exp(-g.tau * sigma_a * (h.lobes - 1));
    INFO("a = " << a << ", sigma_a = " << sigma_a << ": e / g = " << e / g(sigma_a, td) << ", limit " << limit);
    worst = std::max(worst, std::fabs(e / g(sigma_a, td) / limit - 1.0));
  }
  WARN("residual energy over its grazing factor at cos theta_d = 1e-6: within " << worst << " of its limit across the corner");
  CHECK(worst <= 1e-4);
}
