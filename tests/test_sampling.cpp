// Importance sampling of hairlut tables through the renderer runtime (HairScattering), tested as
// renderers test their BSDFs: the sampled axis against independent quadrature of the interpolant
// the sampler evaluates, eval against the library's own table evaluation, pdf against the density
// the runtime documents built from independent lookups and quadrature, pdf normalisation,
// chi-square goodness of fit of sampled directions against the pdf integrated over bins (as
// Mitsuba's and pbrt's suites do), and white furnaces estimated through sampling, for each
// explicit lobe alone and for the mixture of all lobes, on the default and per-material tables.
#include "sampling_checks.hpp"

using namespace sampling_checks;  // and the hairlut names it brings (sampling_checks.hpp)

TEST_CASE("Axis sampling: density, mass and inverse CDF are those of the clamped interpolant", "[sampling]") {
  // A table over (a, b, x) with Catmull–Rom along each axis and values that overshoot below 0:
  // the sampled density must be max(0, the sampler's value) exactly, its mass and CDF those of
  // an independent quadrature of it.
  for (int wrap = 0; wrap < 2; ++wrap)
    for (int cubic = 0; cubic < 2; ++cubic) {
      const int na = 4, nb = 3, nx = 17;
      std::vector<double> data(static_cast<std::size_t>(na * nb * nx));
      std::mt19937_64 rng(7 + static_cast<unsigned>(wrap * 2 + cubic));
      std::uniform_real_distribution<double> u(0.0, 1.0);
      for (double& v : data) v = u(rng) < 0.3 ? 5.0 * u(rng) : (u(rng) < 0.5 ? 0.0 : 0.05 * u(rng));
      const sampler::Interpolation interp = cubic ? sampler::Interpolation::cubic : sampler::Interpolation::linear;
      sampler::Axis axes[3];
      random_table_axes(axes, na, nb, nx, wrap, sampler::Interpolation::cubic, sampler::Interpolation::linear, interp);
      const sampler::TableView<double> view(data.data(), axes, 3);
      const sampler::Measure measure = wrap == 0 ? sampler::Measure::cosine : sampler::Measure::plain;
      const AxisSampler<double> axis(data.data(), axes, 3, measure);
      REQUIRE(axis.supported());
      const double lo = wrap == 0 ? -0.5 * kPi : -kPi, hi = wrap == 0 ? 0.5 * kPi : kPi;
      AxisRow row;
      for (int trial = 0; trial < 6; ++trial) {
        double x[3] = {0.1 + 0.9 * u(rng), 2.0 * u(rng), 0.0};
        axis.blend(x, row);
        REQUIRE(row.ok);
        auto reference = [&](double t) {
          x[2] = t;
          const double v = std::max(0.0, view(x));
          return measure == sampler::Measure::cosine ? v * std::cos(t) : v;
        };
        double vmax = 0.0;
        for (int k = 0; k <= 400; ++k) vmax = std::max(vmax, reference(lo + (hi - lo) * k / 400.0));
        for (int k = 0; k < 200; ++k) {
          const double t = lo + (hi - lo) * u(rng);
          REQUIRE(std::fabs(axis.density(row, t) - reference(t)) <= 1e-12 * vmax);
        }
        // The reference: composite Gauss–Legendre on cells 256× finer than the table's. Where the
        // interpolant crosses 0 inside a cell (a kink of max(0, ·)) its error is O(slope · h²),
        // ~1e-8 of the mass here (it falls 16× when the cells are halved twice).
        const int cells = (nx - 1) * 256 * (wrap ? 2 : 1);
        const double total = integrate(reference, lo, hi, cells);
        CHECK(std::fabs(row.total - total) <= 1e-7 * total);
        for (int k = 0; k < 20; ++k) {
          const double uu = (k + 0.5) / 20.0, t = axis.sample(row, uu);
          REQUIRE(t >= lo);
          REQUIRE(t <= hi);
          const double cdf = integrate(reference, lo, t, cells) / total;
          CHECK(std::fabs(cdf - uu) <= 1e-7);
          CHECK(axis.density(row, t) > 0.0);
        }
      }
    }
}

TEST_CASE("Sampling: eval is the library's table evaluation, pdf is the documented density over independent integrals", "[sampling]") {
  const TableSet& set = default_tables();
  const std::vector<std::string> names = lobe_names(set);
  REQUIRE(names.size() == 4);
  REQUIRE(set.find("np/residual"));
  const Runtime all = hair_scattering<float>(set);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Each explicit lobe alone; then the mixture, whose eval adds the residual.
  for (int p = 0; p <= static_cast<int>(names.size()); ++p) {
    const bool mixture = p == static_cast<int>(names.size());
    const OneGroup one = mixture ? OneGroup{} : group_runtime(set, "", p);
    const Runtime& rt = mixture ? all : one.runtime();
    for (int k = 0; k < 40; ++k) {
      const double beta = std::exp(std::log(4.5 * kDeg) + u(rng) * std::log(40.0 / 4.5)), sigma_a = 4.0 * u(rng) * u(rng);
      const sampler::Fiber f = grey_fiber(beta, sigma_a);
      // θi sampled, θo (the tables' θr) held.
      const double ti = (u(rng) - 0.5) * 170.0 * kDeg, to = (u(rng) - 0.5) * 170.0 * kDeg, phi = (2.0 * u(rng) - 1.0) * kPi;
      const double td = 0.5 * (to - ti);
      // eval: the library's TableSet::sample_value of M_p and N_p (factor included), summed.
      double expected_s = 0.0;
      for (std::size_t q = 0; q <= names.size(); ++q) {
        if (!mixture && static_cast<int>(q) != p) continue;
        const std::string lobe = q < names.size() ? names[q] : std::string("residual");
        const Table& np = *set.find("np/" + lobe);
        const double m = set.sample_value(*set.find("mp/" + lobe), {beta, ti, to});
        expected_s += m * (lobe == "residual" ? set.sample_value(np, {sigma_a, td}) : set.sample_value(np, {beta, sigma_a, td, phi}));
      }
      double rgb[3];
      rt.eval(f, to, ti, phi, rgb);
      for (int c = 0; c < 3; ++c) REQUIRE(std::fabs(rgb[c] - expected_s) <= 1e-6 * std::max(1e-30, expected_s));
      if (mixture) continue;
      // pdf of one lobe = max(0, M̃) Ê / ∫ max(0, M̃) Ê cos θi dθi × max(0, Ñ) / ∫ max(0, Ñ) dφ, with
      // M̃ and Ñ (the N_p shape) by Table::sample, Ê as above, the integrals by quadrature.
      const Table& np = *set.find("np/" + names[static_cast<std::size_t>(p)]);
      const Table& mp = *set.find("mp/" + names[static_cast<std::size_t>(p)]);
      const Table& energy = *set.find(np.factor());
      auto shaped = [&](double t) { return std::max(0.0, mp.sample({beta, t, to})) * energy_hat(energy, mp.axes[1], sigma_a, to, t); };
      const double zm = integrate([&](double t) { return shaped(t) * std::cos(t); }, -0.5 * kPi, 0.5 * kPi, 160 * 8);
      const double zn = integrate([&](double t) { return std::max(0.0, np.sample({beta, sigma_a, td, t})); }, -kPi, kPi, 190 * 8);
      const double pn = std::max(0.0, np.sample({beta, sigma_a, td, phi})) / zn, expected = shaped(ti) / zm * pn;
      // The runtime cuts the θi cells where M̃ stays below 1e-12 of its peak along θi (product_row.hpp):
      // there the pdf may be 0 where the reference is not, by at most the reference with M̃ at that cut.
      const double cut = 1e-12 * row_peak([&](double t) { return mp.sample({beta, t, to}); }) *
                         energy_hat(energy, mp.axes[1], sigma_a, to, ti) / zm * pn;
      const double pdf = rt.at(f, Held(to).wo).pdf(ti, phi);
      INFO(names[static_cast<std::size_t>(p)] << " theta_i " << ti << " theta_o " << to << " phi " << phi << ": pdf " << pdf << ", expected " << expected);
      CHECK(std::fabs(pdf - expected) <= 1e-7 * std::max(expected, 1e-12) + cut);
    }
  }
}

namespace {
// Chi-square fit and pdf normalisation of each explicit lobe and of the mixture of all lobes of the
// default tables.
void chi_square_case(const Case& c, unsigned seed) {
  const TableSet& set = default_tables();
  const int lobes = static_cast<int>(lobe_names(set).size());
  for (int p = -1; p < lobes; ++p) {
    const sampler::Fiber f = grey_fiber(c.beta, 0.0);
    const OneGroup g = group_runtime(set, "", p);
    double integral = 0.0;
    const double pvalue = chi_square(g.runtime(), f, c.theta_o, 200000, seed + static_cast<unsigned>(p + 1), &integral);
    INFO(c.name << " lobe " << g.lobe << ": p-value " << pvalue << ", integral of pdf " << integral);
    // The bins' Gauss–Legendre rule (6 × 6 points on bins of 3° × 5.6°) integrates the
    // piecewise-cubic pdf to ~1e-5; the check allows 1e-3.
    CHECK(std::fabs(integral - 1.0) <= 1e-3);
    CHECK(pvalue > 0.01 / 15.0);  // significance 0.01 over the 15 fits of the default tables (Šidák-like)
  }
}
}  // namespace

TEST_CASE("Sampling: chi-square fit and pdf normalisation, default tables, narrow roughness", "[sampling]") {
  chi_square_case(kGenericCases[0], 100);
}
TEST_CASE("Sampling: chi-square fit and pdf normalisation, default tables, wide roughness", "[sampling]") {
  chi_square_case(kGenericCases[1], 200);
}
TEST_CASE("Sampling: chi-square fit and pdf normalisation, default tables, grazing incidence", "[sampling]") {
  chi_square_case(kGenericCases[2], 300);
}

namespace {
// The furnace of the physics the tables stand for at held θo, ∫ S dω = Σ_p ∫ M_p(θi, θo) cos θi
// e_p(θd) dθi with d'Eon's M_p (the lobe's tilt and β) and the exact lobe energies e_p = ∫ N_p dφ
// (adaptive reference): no table involved. With every lobe untilted it is 1 at σa = 0; tilts move
// each lobe's M_p, and e_p depends on θd, so a tilted white fiber's furnace differs from 1.
double physics_furnace(const TableSet& set, const std::string& group, double beta, double theta_o, double sigma_a) {
  const double eta = set.metadata.at("eta").get<double>();
  const AbsorptionPath path = parse_absorption_path(set.metadata.at("absorption_path").get<std::string>());
  std::vector<std::string> names = lobe_names(set);
  names.push_back("residual");
  const int lobes = static_cast<int>(names.size());
  std::vector<double> alpha, betas;
  for (const std::string& lobe : names) {
    // The M_p table of the lobe carries its tilt (and, per material, its β).
    const Table* m = set.find(group.empty() ? "mp/" + lobe : group + "/mp_" + lobe);
    REQUIRE(m);
    alpha.push_back(m->attributes.value("alpha", 0.0));
    betas.push_back(m->attributes.contains("beta") ? m->attributes["beta"].get<double>() : beta);
  }
  const LobeSet set_of_lobes{lobes - 1, true};
  return integrate(
      [&](double ti) {
        const double td = 0.5 * (theta_o - ti);
        const AttenuationSlice slice(eta, std::fabs(td), sigma_a, path);
        const std::vector<double> e = lobe_energies_reference(slice, set_of_lobes, 1e-12).value;
        double sum = 0.0;
        for (int p = 0; p < lobes; ++p)
          sum += longitudinal_deon_tilted(betas[static_cast<std::size_t>(p)] * betas[static_cast<std::size_t>(p)], alpha[static_cast<std::size_t>(p)],
                                          ti, theta_o) * e[static_cast<std::size_t>(p)];
        return sum * std::cos(ti);
      },
      -0.5 * kPi, 0.5 * kPi, 360);
}

// The white furnace of one table group through sampling: the estimate of ∫ S dω from n samples
// must agree with the quadrature of eval within its confidence interval (4 standard errors) plus
// the quadrature's own error (the runtime samples close to S, so its weights vary little), for
// the mixture of all lobes (n = 10⁶) and for each explicit lobe alone (the lobe's energy, 10⁵
// samples); and the tables' furnace must be the physics' within the M_p energy tolerance their
// config declares (the N_p shapes integrate to 1 and the energies are exact at the nodes; the M_p
// tables carry the error the validator bounds).
void furnace_case(const TableSet& set, const std::string& group, const sampler::Fiber& f, double theta_o, double tolerance, unsigned seed,
                  bool mixture) {
  const int lobes = static_cast<int>(lobe_names(set).size());
  const double physics = mixture ? physics_furnace(set, group, f.beta_m, theta_o, f.sigma_a[0]) : 0.0;
  for (int p = mixture ? -1 : 0; p < (mixture ? 0 : lobes); ++p) {
    const OneGroup g = group_runtime(set, group, p);
    const Quadrature exact = quadrature_energy(set, group, g.runtime(), f, theta_o);
    const Estimate e = furnace(g.runtime(), f, theta_o, p < 0 ? 1000000 : 100000, seed + static_cast<unsigned>(p + 1));
    INFO(group << " lobe " << g.lobe << " theta_o " << theta_o / kDeg << " deg: estimate " << e.mean << " +- " << e.error
               << ", quadrature of the tables " << exact.value << " +- " << exact.error << ", physics " << physics);
    CHECK(std::fabs(e.mean - exact.value) <= 4.0 * e.error + exact.error + kCutBias * exact.value);
    if (p < 0) {
      CHECK(std::fabs(exact.value - physics) <= tolerance);
      CHECK(std::fabs(e.mean - physics) <= tolerance + 4.0 * e.error);
    }
  }
}
double energy_tolerance(const TableSet& set) {
  const nlohmann::ordered_json& c = set.metadata.at("config");
  if (c.contains("validate") && c["validate"].contains("thresholds") && c["validate"]["thresholds"].contains("mp_table_energy"))
    return c["validate"]["thresholds"]["mp_table_energy"].get<double>();
  return ValidationThresholds{}.mp_table_energy;
}
}  // namespace

TEST_CASE("Sampling: white furnace through sampling, default tables, narrow roughness, all lobes", "[sampling]") {
  const TableSet& set = default_tables();
  const Case& c = kGenericCases[0];
  furnace_case(set, "", grey_fiber(c.beta, 0.0), c.theta_o, energy_tolerance(set), 1000, true);
}
TEST_CASE("Sampling: white furnace through sampling, default tables, narrow roughness, each lobe", "[sampling]") {
  const TableSet& set = default_tables();
  const Case& c = kGenericCases[0];
  furnace_case(set, "", grey_fiber(c.beta, 0.0), c.theta_o, energy_tolerance(set), 1000, false);
}
TEST_CASE("Sampling: white furnace through sampling, default tables, wide roughness, all lobes", "[sampling]") {
  const TableSet& set = default_tables();
  const Case& c = kGenericCases[1];
  furnace_case(set, "", grey_fiber(c.beta, 0.0), c.theta_o, energy_tolerance(set), 2000, true);
}
TEST_CASE("Sampling: white furnace through sampling, default tables, wide roughness, each lobe", "[sampling]") {
  const TableSet& set = default_tables();
  const Case& c = kGenericCases[1];
  furnace_case(set, "", grey_fiber(c.beta, 0.0), c.theta_o, energy_tolerance(set), 2000, false);
}
TEST_CASE("Sampling: white furnace through sampling, default tables, grazing incidence, all lobes", "[sampling]") {
  const TableSet& set = default_tables();
  const Case& c = kGenericCases[2];
  furnace_case(set, "", grey_fiber(c.beta, 0.0), c.theta_o, energy_tolerance(set), 3000, true);
}
TEST_CASE("Sampling: white furnace through sampling, default tables, grazing incidence, each lobe", "[sampling]") {
  const TableSet& set = default_tables();
  const Case& c = kGenericCases[2];
  furnace_case(set, "", grey_fiber(c.beta, 0.0), c.theta_o, energy_tolerance(set), 3000, false);
}

namespace {
void material_chi_square(const char* material, unsigned seed) {
  const TableSet& set = material_tables();
  const std::string group = std::string("materials/") + material;
  const int lobes = static_cast<int>(lobe_names(set).size());
  int tests = 0;
  for (const Case& c : kMaterialCases)
    for (int p = -1; p < lobes; ++p) {
      const sampler::Fiber f;  // the material's tables fix σa and β
      const OneGroup g = group_runtime(set, group, p);
      double integral = 0.0;
      const double pvalue = chi_square(g.runtime(), f, c.theta_o, 100000, seed + static_cast<unsigned>(tests), &integral);
      INFO(group << " " << c.name << " lobe " << g.lobe << ": p-value " << pvalue << ", integral of pdf " << integral);
      CHECK(std::fabs(integral - 1.0) <= 1e-3);
      CHECK(pvalue > 0.01 / 20.0);  // significance 0.01 over the 20 fits of the two materials
      ++tests;
    }
}
}  // namespace

TEST_CASE("Sampling: per-material tables, chi-square fit, blonde", "[sampling]") { material_chi_square("blonde", 500); }
TEST_CASE("Sampling: per-material tables, chi-square fit, white", "[sampling]") { material_chi_square("white", 600); }

namespace {
// The white material (σa = 0, every lobe untilted with one β, so that the M_p of all lobes are one
// function and the energies sum to 1 under it): its furnace reaches 1.
void white_material_furnace(const Case& c, unsigned seed) {
  const TableSet& set = material_tables();
  CHECK(std::fabs(physics_furnace(set, "materials/white", 0.0, c.theta_o, 0.0) - 1.0) <= 1e-9);
  furnace_case(set, "materials/white", sampler::Fiber{}, c.theta_o, energy_tolerance(set), seed, true);
}
}  // namespace

TEST_CASE("Sampling: per-material tables, white furnace through sampling, normal incidence", "[sampling]") {
  white_material_furnace(kMaterialCases[0], 4000);
}
TEST_CASE("Sampling: per-material tables, white furnace through sampling, grazing incidence", "[sampling]") {
  white_material_furnace(kMaterialCases[1], 4100);
}

TEST_CASE("Sampling: per-material tables, each lobe's furnace through sampling", "[sampling]") {
  const TableSet& set = material_tables();
  for (const Case& c : kMaterialCases) furnace_case(set, "materials/white", sampler::Fiber{}, c.theta_o, energy_tolerance(set), 5000, false);
}
