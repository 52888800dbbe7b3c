// N_p baked in β bands (beta_bands.hpp): each band an ordinary 4D table on its own β range and
// counts, the band rule at shared edges, the typed views' band choice. References: the adaptive
// N_p integrator (azimuthal_np_reference) and lobe energies (lobe_energies_reference), not the
// baker's Fourier method.
#include <cmath>
#include <hairlut/util/angles.hpp>
#include <hairlut/physics/attenuation.hpp>
#include <hairlut/physics/azimuthal_np.hpp>
#include <hairlut/bake/bake.hpp>
#include <hairlut/tables/beta_bands.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <hairlut/physics/lobe_energy.hpp>
#include <random>
#include <string>

#include "catch.hpp"

using namespace hairlut;
using json = nlohmann::json;

namespace {

json banded_config() {
  return json::parse(R"({
    "name": "bands",
    "lobes": { "explicit": ["R", "TT", "TRT"], "residual": false },
    "tables": {
      "np": {
        "normalize": "energy",
        "axes": {
          "theta_d": { "count": 6, "range_deg": [0, 80], "interpolation": "cubic" },
          "phi": { "count": 16, "symmetry": "even", "interpolation": "cubic" },
          "sigma_a": { "count": 4, "range": [0, 4], "spacing": "sqrt", "interpolation": "cubic", "lo_end": "mirror" },
          "beta": { "count": 3, "range_deg": [2, 20], "spacing": "log" } },
        "beta_bands": [
          { "beta": { "count": 3, "range_deg": [2, 6], "spacing": "log", "interpolation": "cubic" } },
          { "beta": { "count": 3, "range_deg": [6, 20], "interpolation": "cubic" }, "phi": { "count": 12 } } ] },
      "mp": { "axes": {
        "theta_i": { "count": 5, "range_deg": [-90, 90], "spacing": "sin" },
        "theta_r": { "count": 5, "range_deg": [-90, 90] },
        "beta": { "count": 2, "range_deg": [5, 20] } } } },
    "output": { "basename": "bands", "formats": ["hdf5"] }
  })");
}

const TableSet& banded_set() {
  static const TableSet set = bake(parse_config(banded_config(), "bands.json", "."));
  return set;
}

std::string config_error(const json& j) {
  try {
    parse_config(j, "bands.json", ".");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("beta bands: the band of a beta, shared edges read the lower band", "[bands]") {
  const std::vector<double> his = {0.1, 0.2, 0.5};
  CHECK(beta_band_of(his, 0.01) == 0);
  CHECK(beta_band_of(his, 0.1) == 0);
  CHECK(beta_band_of(his, std::nextafter(0.1, 1.0)) == 1);
  CHECK(beta_band_of(his, 0.2) == 1);
  CHECK(beta_band_of(his, 0.3) == 2);
  CHECK(beta_band_of(his, 9.0) == 2);
  CHECK(beta_band_suffix(0).empty());
  CHECK(beta_band_suffix(2) == "_band2");
}

TEST_CASE("beta bands: one table per band and lobe on its own axes, exact at its nodes", "[bands]") {
  const TableSet& set = banded_set();
  REQUIRE(set.metadata.contains("np_beta_bands"));
  CHECK(set.metadata["np_beta_bands"].size() == 2);
  for (const char* lobe : {"R", "TT", "TRT"}) {
    const Table* b0 = set.find(std::string("np/") + lobe);
    const Table* b1 = set.find(std::string("np/") + lobe + "_band1");
    REQUIRE(b0);
    REQUIRE(b1);
    CHECK(b0->attributes["beta_band"]["index"] == 0);
    CHECK(b1->attributes["beta_band"]["index"] == 1);
    CHECK(b0->axes[0].hi == Approx(radians(6.0)).epsilon(1e-15));
    CHECK(b1->axes[0].lo == b0->axes[0].hi);
    CHECK(b1->axes[0].hi == Approx(radians(20.0)).epsilon(1e-15));
    CHECK(b1->axes[3].count == 12);
    CHECK(b1->axes[2].count == 6);
    CHECK(b1->axes[1].lo_end == End::mirror);
    CHECK(b1->factor() == std::string("np/energy_") + lobe);
  }
  // At the band's nodes, shape × energy factor is N_p: against the adaptive integrator, relative to
  // the slice's largest value over the φ nodes.
  std::mt19937_64 rng(3);
  for (int p = 0; p < 3; ++p) {
    const Table& t = *set.find("np/" + lobe_name(p) + "_band1");
    for (int trial = 0; trial < 12; ++trial) {
      std::vector<double> x(4);
      for (std::size_t k = 0; k < 3; ++k) x[k] = t.axes[k].nodes()[rng() % static_cast<std::size_t>(t.axes[k].count)];
      const AttenuationSlice slice(1.55, x[2], x[1], AbsorptionPath::chord);
      double peak = 0.0, worst = 0.0;
      for (double phi : t.axes[3].nodes()) {
        x[3] = phi;
        const double ref = azimuthal_np_reference(slice, p, x[0], phi, 1e-10).value[0];
        peak = std::max(peak, ref);
        worst = std::max(worst, std::abs(set.sample_value(t, x) - ref));
      }
      // Float storage (the energy table shares this band's σa and θd nodes).
      CHECK(worst <= 1e-5 * peak + 1e-30);
    }
  }
}

TEST_CASE("beta bands: typed views pick the band of beta", "[bands][views]") {
  const TableSet& set = banded_set();
  const auto h = hair_tables<float, double>(set);
  REQUIRE(h.beta_bands == 2);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const int p = static_cast<int>(rng() % 3);
    const double beta = radians(2.0 + 18.0 * u(rng)), sigma = 4.0 * u(rng), theta = radians(80.0 * u(rng)), phi = kPi * u(rng);
    const Table& t = *set.find("np/" + lobe_name(p) + (beta <= radians(6.0) ? "" : "_band1"));
    const double ref = std::max(0.0, set.sample_value(t, {beta, sigma, theta, phi}));
    CHECK(h.np_value(p, beta, sigma, theta, phi) == Approx(ref).epsilon(1e-12).margin(1e-300));
  }
  // On the shared edge: the lower band.
  const double edge = set.find("np/R")->axes[0].hi;
  CHECK(h.band_of(edge) == 0);
  CHECK(h.band_of(std::nextafter(edge, 1.0)) == 1);
  CHECK(h.band_of(radians(40.0)) == 1);
}

TEST_CASE("beta bands: configs that cannot form bands are refused", "[bands][config]") {
  json gap = banded_config();
  gap["tables"]["np"]["beta_bands"][1]["beta"]["range_deg"] = {7, 20};
  CHECK(config_error(gap).find("tables.np.beta_bands[1].beta.range") != std::string::npos);
  json cover = banded_config();
  cover["tables"]["np"]["axes"]["beta"]["range_deg"] = {2, 30};
  CHECK(config_error(cover).find("tables.np.beta_bands") != std::string::npos);
  json sigma = banded_config();
  sigma["tables"]["np"]["beta_bands"][1]["sigma_a"] = {{"spacing", "uniform"}};
  CHECK(config_error(sigma).find("lo_end") != std::string::npos);
  json target = banded_config();
  target["tables"]["np"]["target_error"] = 1e-3;
  CHECK(config_error(target).find("tables.np.beta_bands") != std::string::npos);
  CHECK(config_error(banded_config()).empty());
}
