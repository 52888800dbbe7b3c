// Importance sampling of hairlut tables (sampling.hpp), tested as renderers test their BSDFs:
// the sampled axis against independent quadrature of the interpolant the sampler evaluates,
// eval/pdf consistency, pdf normalisation, chi-square goodness of fit of sampled directions
// against the pdf integrated over bins (as Mitsuba's and pbrt's suites do), and white furnaces
// estimated through sampling, for every lobe of the default tables and of per-material tables.
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

TEST_CASE("Sampling: eval is the library's table evaluation, pdf is eval over the interpolant's integrals", "[sampling]") {
  const TableSet& set = default_tables();
  const HairTables h = hair_tables(set, "");
  REQUIRE(h.lobes.size() == 5);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  HairSampler<float>::Workspace ws;
  for (std::size_t p = 0; p < h.lobes.size(); ++p) {
    const HairSampler<float> one(&h.lobes[p], 1);
    const std::string lobe = h.lobe_names[p];
    const Table& np = *set.find("np/" + lobe);
    const Table& mp = *set.find("mp/" + lobe);
    for (int k = 0; k < 40; ++k) {
      const FibreCoordinates f{std::exp(std::log(4.5 * kDeg) + u(rng) * std::log(40.0 / 4.5)), 4.0 * u(rng) * u(rng), 0.0};
      const double ti = (u(rng) - 0.5) * 170.0 * kDeg, tr = (u(rng) - 0.5) * 170.0 * kDeg, phi = (2.0 * u(rng) - 1.0) * kPi;
      const double td = 0.5 * (tr - ti);
      // eval: the library's TableSet::sample_value of M_p and N_p (factor included).
      const double m = set.sample_value(mp, {f.beta, ti, tr});
      const double n = lobe == "residual" ? set.sample_value(np, {f.sigma_a, td}) : set.sample_value(np, {f.beta, f.sigma_a, td, phi});
      const double value = one.eval(f, ti, tr, phi);
      REQUIRE(std::fabs(value - m * n) <= 1e-6 * std::max(1e-30, m * n));
      // pdf = max(0, M̃)/∫max(0, M̃) cos θr dθr × max(0, Ñ)/∫max(0, Ñ) dφ, integrals by quadrature.
      const double zm = integrate([&](double t) { return std::max(0.0, mp.sample({f.beta, ti, t})) * std::cos(t); }, -0.5 * kPi, 0.5 * kPi, 160 * 8);
      double pn = 1.0 / (2.0 * kPi);
      if (lobe != "residual") {
        const double zn = integrate([&](double t) { return std::max(0.0, np.sample({f.beta, f.sigma_a, td, t})); }, -kPi, kPi, 190 * 8);
        pn = std::max(0.0, np.sample({f.beta, f.sigma_a, td, phi})) / zn;
      }
      const double expected = std::max(0.0, mp.sample({f.beta, ti, tr})) / zm * pn;
      const double pdf = one.pdf(f, ti, tr, phi, ws);
      CHECK(std::fabs(pdf - expected) <= 1e-7 * std::max(expected, 1e-12));
    }
  }
}

TEST_CASE("Sampling: a fibre's prepared sampler gives the full tables' eval, pdf and samples", "[sampling]") {
  const TableSet& set = default_tables();
  const HairTables h = hair_tables(set, "");
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  HairSampler<float>::Workspace ws;
  HairSampler<double>::Workspace wd;
  for (int k = 0; k < 6; ++k) {
    const FibreCoordinates f{std::exp(std::log(4.5 * kDeg) + u(rng) * std::log(40.0 / 4.5)), 4.0 * u(rng) * u(rng), 0.0};
    const sampler::FibreSampler<float> fs(h.lobes.data(), static_cast<int>(h.lobes.size()), f);
    REQUIRE(fs.sampler().supported());
    for (int j = 0; j < 50; ++j) {
      const double ti = (u(rng) - 0.5) * 178.0 * kDeg, tr = (u(rng) - 0.5) * 178.0 * kDeg, phi = (2.0 * u(rng) - 1.0) * kPi;
      const double v = h.sampler->eval(f, ti, tr, phi), vf = fs.sampler().eval(f, ti, tr, phi);
      const double q = h.sampler->pdf(f, ti, tr, phi, ws), qf = fs.sampler().pdf(f, ti, tr, phi, wd);
      // The same sums in another order: rounding of up to 256 terms of values up to ~10² (M_p
      // times the N_p shape), relative to the value or to that scale.
      REQUIRE(std::fabs(v - vf) <= 1e-12 * std::max(v, 1.0));
      REQUIRE(std::fabs(q - qf) <= 1e-12 * std::max(q, 1.0));
      const double a = u(rng), b = u(rng), c = u(rng);
      const auto s0 = h.sampler->sample(f, ti, a, b, c, ws), s1 = fs.sampler().sample(f, ti, a, b, c, wd);
      REQUIRE(s0.lobe == s1.lobe);
      REQUIRE(std::fabs(s0.theta_r - s1.theta_r) <= 1e-9);
      REQUIRE(std::fabs(s0.phi - s1.phi) <= 1e-9);
    }
  }
}

namespace {
// Chi-square fit and pdf normalisation of every lobe (and their mixture) of the default tables.
void chi_square_case(const Case& c, unsigned seed) {
  const TableSet& set = default_tables();
  const int lobes = static_cast<int>(hair_tables(set, "").lobes.size());
  for (int p = -1; p < lobes; ++p) {
    const FibreCoordinates f{c.beta, 0.0, 0.0};
    const OneGroup g = group_sampler(set, "", p, f);
    double integral = 0.0;
    const double pvalue = chi_square(g.sampler(), f, c.theta_i, 200000, seed + static_cast<unsigned>(p + 1), &integral);
    INFO(c.name << " lobe " << (p < 0 ? std::string("all") : g.all.lobe_names[static_cast<std::size_t>(p)]) << ": p-value " << pvalue
                << ", integral of pdf " << integral);
    // The bins' Gauss–Legendre rule (6 × 6 points on bins of 3° × 5.6°) integrates the
    // piecewise-cubic pdf to ~1e-5; the check allows 1e-3.
    CHECK(std::fabs(integral - 1.0) <= 1e-3);
    CHECK(pvalue > 0.01 / 18.0);  // significance 0.01 over the 18 fits of the default tables (Šidák-like)
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
// The furnace of the physics the tables stand for, ∫ S dω = Σ_p ∫ M_p(θi, θr) cos θr e_p(θd) dθr
// with d'Eon's M_p (the lobe's tilt and β) and the exact lobe energies e_p = ∫ N_p dφ (adaptive
// reference): no table involved. With every lobe untilted it is 1 at σa = 0; tilts move each
// lobe's M_p, and e_p depends on θd, so a tilted white fibre's furnace differs from 1.
double physics_furnace(const TableSet& set, const HairTables& h, const FibreCoordinates& f, double theta_i, double sigma_a) {
  const double eta = set.metadata.at("eta").get<double>();
  const AbsorptionPath path = parse_absorption_path(set.metadata.at("absorption_path").get<std::string>());
  const int lobes = static_cast<int>(h.lobes.size());
  std::vector<double> alpha, beta;
  for (std::size_t p = 0; p < h.lobes.size(); ++p) {
    // The M_p table of the lobe carries its tilt (and, per material, its β).
    const Table* m = nullptr;
    for (const Table& t : set.tables)
      if (t.f32.data() == h.lobes[p].mp.data) m = &t;
    REQUIRE(m);
    alpha.push_back(m->attributes.value("alpha", 0.0));
    beta.push_back(m->attributes.contains("beta") ? m->attributes["beta"].get<double>() : f.beta);
  }
  const LobeSet set_of_lobes{lobes - 1, true};
  return integrate(
      [&](double tr) {
        const double td = 0.5 * (tr - theta_i);
        const AttenuationSlice slice(eta, std::fabs(td), sigma_a, path);
        const std::vector<double> e = lobe_energies_reference(slice, set_of_lobes, 1e-12).value;
        double sum = 0.0;
        for (int p = 0; p < lobes; ++p)
          sum += longitudinal_deon_tilted(beta[static_cast<std::size_t>(p)] * beta[static_cast<std::size_t>(p)], alpha[static_cast<std::size_t>(p)],
                                          theta_i, tr) * e[static_cast<std::size_t>(p)];
        return sum * std::cos(tr);
      },
      -0.5 * kPi, 0.5 * kPi, 360);
}

// The white furnace of one table group through sampling: the estimate of ∫ S dω from n samples
// must agree with the quadrature of eval within its confidence interval (4 standard errors), for
// the mixture of all lobes (n = 10⁶) and for each lobe alone (the lobe's energy, 10⁵ samples);
// and the tables' furnace must be the physics' within the M_p energy tolerance their config
// declares (the N_p shapes integrate to 1 and the energies are exact at the nodes; the M_p
// tables carry the error the validator bounds).
void furnace_case(const TableSet& set, const std::string& group, const FibreCoordinates& f, double theta_i, double sigma_a, double tolerance,
                  unsigned seed, bool mixture) {
  const HairTables h = hair_tables(set, group);
  const int lobes = static_cast<int>(h.lobes.size());
  const double physics = mixture ? physics_furnace(set, h, f, theta_i, sigma_a) : 0.0;
  for (int p = mixture ? -1 : 0; p < (mixture ? 0 : lobes); ++p) {
    const OneGroup g = group_sampler(set, group, p, f);
    const double exact = quadrature_energy(g.sampler(), f, theta_i);
    const Estimate e = furnace(g.sampler(), f, theta_i, p < 0 ? 1000000 : 100000, seed + static_cast<unsigned>(p + 1));
    INFO(group << " lobe " << (p < 0 ? std::string("all") : g.all.lobe_names[static_cast<std::size_t>(p)]) << " theta_i "
               << theta_i / kDeg << " deg: estimate " << e.mean << " +- " << e.error << ", quadrature of the tables " << exact
               << ", physics " << physics);
    CHECK(std::fabs(e.mean - exact) <= 4.0 * e.error);
    if (p < 0) {
      CHECK(std::fabs(exact - physics) <= tolerance);
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
  furnace_case(set, "", FibreCoordinates{c.beta, 0.0, 0.0}, c.theta_i, 0.0, energy_tolerance(set), 1000, true);
}
TEST_CASE("Sampling: white furnace through sampling, default tables, narrow roughness, each lobe", "[sampling]") {
  const TableSet& set = default_tables();
  const Case& c = kGenericCases[0];
  furnace_case(set, "", FibreCoordinates{c.beta, 0.0, 0.0}, c.theta_i, 0.0, energy_tolerance(set), 1000, false);
}
TEST_CASE("Sampling: white furnace through sampling, default tables, wide roughness, all lobes", "[sampling]") {
  const TableSet& set = default_tables();
  const Case& c = kGenericCases[1];
  furnace_case(set, "", FibreCoordinates{c.beta, 0.0, 0.0}, c.theta_i, 0.0, energy_tolerance(set), 2000, true);
}
TEST_CASE("Sampling: white furnace through sampling, default tables, wide roughness, each lobe", "[sampling]") {
  const TableSet& set = default_tables();
  const Case& c = kGenericCases[1];
  furnace_case(set, "", FibreCoordinates{c.beta, 0.0, 0.0}, c.theta_i, 0.0, energy_tolerance(set), 2000, false);
}
TEST_CASE("Sampling: white furnace through sampling, default tables, grazing incidence, all lobes", "[sampling]") {
  const TableSet& set = default_tables();
  const Case& c = kGenericCases[2];
  furnace_case(set, "", FibreCoordinates{c.beta, 0.0, 0.0}, c.theta_i, 0.0, energy_tolerance(set), 3000, true);
}
TEST_CASE("Sampling: white furnace through sampling, default tables, grazing incidence, each lobe", "[sampling]") {
  const TableSet& set = default_tables();
  const Case& c = kGenericCases[2];
  furnace_case(set, "", FibreCoordinates{c.beta, 0.0, 0.0}, c.theta_i, 0.0, energy_tolerance(set), 3000, false);
}

namespace {
void material_chi_square(const char* material, unsigned seed) {
  const TableSet& set = material_tables();
  const std::string group = std::string("materials/") + material;
  const int lobes = static_cast<int>(hair_tables(set, group).lobes.size());
  int tests = 0;
  for (const Case& c : kMaterialCases)
    for (int p = -1; p < lobes; ++p) {
      const FibreCoordinates f{0.0, 0.0, 1.0};
      const OneGroup g = group_sampler(set, group, p, f);
      double integral = 0.0;
      const double pvalue = chi_square(g.sampler(), f, c.theta_i, 100000, seed + static_cast<unsigned>(tests), &integral);
      INFO(group << " " << c.name << " lobe " << (p < 0 ? std::string("all") : g.all.lobe_names[static_cast<std::size_t>(p)])
                 << ": p-value " << pvalue << ", integral of pdf " << integral);
      CHECK(std::fabs(integral - 1.0) <= 1e-3);
      CHECK(pvalue > 0.01 / 24.0);  // significance 0.01 over the 24 fits of the two materials
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
  const HairTables h = hair_tables(set, "materials/white");
  CHECK(std::fabs(physics_furnace(set, h, FibreCoordinates{0.0, 0.0, 1.0}, c.theta_i, 0.0) - 1.0) <= 1e-9);
  furnace_case(set, "materials/white", FibreCoordinates{0.0, 0.0, 1.0}, c.theta_i, 0.0, energy_tolerance(set), seed, true);
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
  for (const Case& c : kMaterialCases) furnace_case(set, "materials/white", FibreCoordinates{0.0, 0.0, 1.0}, c.theta_i, 0.0, energy_tolerance(set), 5000, false);
}
