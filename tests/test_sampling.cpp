// Importance sampling of hairlut tables (sampling.hpp), tested as renderers test their BSDFs:
// the sampled axis against independent quadrature of the interpolant the sampler evaluates,
// eval/pdf consistency, pdf normalisation, chi-square goodness of fit of sampled directions
// against the pdf integrated over bins (as Mitsuba's and pbrt's suites do), and white furnaces
// estimated through sampling, for every lobe of the default tables and of per-material tables.
#include <algorithm>
#include <cmath>
#include <hairlut/physics/attenuation.hpp>
#include <hairlut/bake/bake.hpp>
#include <hairlut/physics/lobe_energy.hpp>
#include <hairlut/physics/longitudinal_mp.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/sampler/sampling.hpp>
#include <hairlut/io/table_io.hpp>
#include <hairlut/tables/table_sampling.hpp>
#include <hairlut/report/validate.hpp>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "catch.hpp"

using namespace hairlut;
using sampler::AxisRow;
using sampler::AxisSampler;
using sampler::FibreCoordinates;
using sampler::HairSampler;

namespace {

constexpr double kDeg = kPi / 180.0;

// Gauss–Legendre nodes and weights of order m on [0, 1] (Newton on the Legendre recurrence).
void gauss_legendre01(int m, std::vector<double>& x, std::vector<double>& w) {
  x.assign(static_cast<std::size_t>(m), 0.0);
  w.assign(static_cast<std::size_t>(m), 0.0);
  for (int i = 0; i < m; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (m + 0.5)), dp = 0.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = 0.0;
      for (int j = 1; j <= m; ++j) {
        const double p2 = p1;
        p1 = p0;
        p0 = ((2.0 * j - 1.0) * z * p1 - (j - 1.0) * p2) / j;
      }
      dp = m * (z * p0 - p1) / (z * z - 1.0);
      const double dz = p0 / dp;
      z -= dz;
      if (std::fabs(dz) < 1e-16) break;
    }
    x[static_cast<std::size_t>(i)] = 0.5 * (1.0 - z);
    w[static_cast<std::size_t>(i)] = 1.0 / ((1.0 - z * z) * dp * dp);
  }
}

// ∫_a^b f by composite Gauss–Legendre of order m over `cells` equal cells.
template <class F>
double integrate(F f, double a, double b, int cells, int m = 8) {
  std::vector<double> x, w;
  gauss_legendre01(m, x, w);
  double s = 0.0;
  const double h = (b - a) / cells;
  for (int c = 0; c < cells; ++c)
    for (std::size_t g = 0; g < x.size(); ++g) s += w[g] * f(a + (c + x[g]) * h);
  return s * h;
}

// Upper tail of the chi-square distribution with k degrees of freedom (Wilson–Hilferty: the cube
// root of χ²/k is close to normal; accurate to a few percent of p for k ≥ 30).
double chi2_pvalue(double chi2, int k) {
  const double v = 2.0 / (9.0 * k);
  const double z = (std::cbrt(chi2 / k) - (1.0 - v)) / std::sqrt(v);
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

const TableSet& default_tables() {
  static const TableSet set = load_tables(std::string(HAIRLUT_SOURCE_DIR) + "/tables/default/hairlut-default.h5");
  return set;
}

// Per-material tables of two materials (one white) baked in memory, small enough for a test.
const TableSet& material_tables() {
  static const TableSet set = [] {
    const nlohmann::json j = nlohmann::json::parse(R"({
      "name": "sampling-test",
      "model": "deon2011",
      "fiber": { "eta": 1.55 },
      "lobes": { "explicit": ["R", "TT", "TRT", "TRRT"], "residual": true,
                 "tilt_deg": { "R": 0, "TT": 0, "TRT": 0, "TRRT": 0, "residual": 0 } },
      "tables": {
        "np": { "axes": { "theta_d": { "count": 40, "range_deg": [0, 89.5], "spacing": "cos" },
                          "phi": { "count": 97, "symmetry": "even" } } },
        "mp": { "axes": { "theta_i": { "count": 61, "range_deg": [-90, 90] },
                          "theta_r": { "count": 121, "range_deg": [-90, 90] } } }
      },
      "scene": { "mode": "per-material", "materials": [
        { "name": "blonde", "melanin": { "eumelanin": 0.3, "pheomelanin": 0.15 }, "beta_deg": { "R": 5, "TT": 2.5, "TRT": 10 } },
        { "name": "white", "sigma_a": [0.0, 0.0, 0.0], "beta_deg": { "R": 6, "TT": 6, "TRT": 6, "TRRT": 6, "residual": 6 } } ] },
      "output": { "basename": "sampling-test", "formats": ["hdf5"] }
    })");
    BakeOptions options;
    options.threads = 1;
    return bake(parse_config(j, "sampling-test.json", "."), options);
  }();
  return set;
}

// A sampler of one lobe (index p) of a group's tables, or of all of them (p < 0), prepared for
// one fibre (FibreSampler: the tests that follow compare it with the full tables first).
struct OneGroup {
  HairTables all;
  std::unique_ptr<sampler::FibreSampler<float>> fibre;
  const HairSampler<double>& sampler() const { return fibre->sampler(); }
};
OneGroup group_sampler(const TableSet& set, const std::string& group, int p, const FibreCoordinates& f) {
  OneGroup g{hair_tables(set, group), nullptr};
  const sampler::LobeTables<float>* first = p >= 0 ? &g.all.lobes[static_cast<std::size_t>(p)] : g.all.lobes.data();
  g.fibre = std::make_unique<sampler::FibreSampler<float>>(first, p >= 0 ? 1 : static_cast<int>(g.all.lobes.size()), f);
  return g;
}

// ∫ S dω by quadrature of eval (independent of the sampling code): composite Gauss–Legendre of
// order 4 over θr ∈ [−π/2, π/2] and φ ∈ [0, π] (S is even in φ) on cells of half the tables'
// default node spacing (exact for the cubic pieces that fall inside a cell; a relative error
// well below 1e-5 for the piecewise-cubic S, which the 4σ criterion of 10⁶ samples never sees).
template <class S>
double quadrature_energy(const S& s, const FibreCoordinates& f, double theta_i) {
  return integrate(
      [&](double tr) {
        return 2.0 * std::cos(tr) * integrate([&](double phi) { return s.eval(f, theta_i, tr, phi); }, 0.0, kPi, 190, 4);
      },
      -0.5 * kPi, 0.5 * kPi, 320, 4);
}

struct Estimate {
  double mean, error;  // mean and its standard error
};
template <class S>
Estimate furnace(const S& s, const FibreCoordinates& f, double theta_i, int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  typename S::Workspace ws;
  double sum = 0.0, sum2 = 0.0;
  for (int k = 0; k < n; ++k) {
    const double a = u(rng), b = u(rng), c = u(rng);
    const sampler::HairSample r = s.sample(f, theta_i, a, b, c, ws);
    const double x = r.pdf > 0.0 ? r.value / r.pdf : 0.0;
    sum += x;
    sum2 += x * x;
  }
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n)};
}

// Chi-square test of n sampled directions against the pdf integrated over θr × φ bins.
// Returns the p-value; bins expecting fewer than 5 samples are pooled (Mitsuba's rule).
template <class S>
double chi_square(const S& s, const FibreCoordinates& f, double theta_i, int n, unsigned seed, double* pdf_integral) {
  const int nt = 60, np = 64;
  std::vector<double> observed(static_cast<std::size_t>(nt * np), 0.0), expected(observed.size(), 0.0);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  typename S::Workspace ws;
  auto bin_of = [&](double tr, double phi) {
    const int i = std::min(nt - 1, std::max(0, static_cast<int>((tr + 0.5 * kPi) / kPi * nt)));
    const int j = std::min(np - 1, std::max(0, static_cast<int>((phi + kPi) / (2.0 * kPi) * np)));
    return static_cast<std::size_t>(i * np + j);
  };
  for (int k = 0; k < n; ++k) {
    const double a = u(rng), b = u(rng), c = u(rng);
    const sampler::HairSample r = s.sample(f, theta_i, a, b, c, ws);
    if (r.pdf > 0.0) observed[bin_of(r.theta_r, r.phi)] += 1.0;
  }
  std::vector<double> gx, gw;
  gauss_legendre01(6, gx, gw);
  double total = 0.0;
  const double ht = kPi / nt, hp = 2.0 * kPi / np;
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j) {
      double e = 0.0;
      for (std::size_t a = 0; a < gx.size(); ++a)
        for (std::size_t b = 0; b < gx.size(); ++b) {
          const double tr = -0.5 * kPi + (i + gx[a]) * ht, phi = -kPi + (j + gx[b]) * hp;
          e += gw[a] * gw[b] * s.pdf(f, theta_i, tr, phi, ws) * std::cos(tr);
        }
      e *= ht * hp;
      total += e;
      expected[static_cast<std::size_t>(i * np + j)] = e * n;
    }
  *pdf_integral = total;
  double chi2 = 0.0, pool_o = 0.0, pool_e = 0.0;
  int bins = 0;
  for (std::size_t k = 0; k < observed.size(); ++k) {
    if (expected[k] < 5.0) {
      pool_o += observed[k], pool_e += expected[k];
      continue;
    }
    chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
    ++bins;
  }
  if (pool_e > 0.0) chi2 += (pool_o - pool_e) * (pool_o - pool_e) / std::max(pool_e, 5.0), ++bins;
  return chi2_pvalue(chi2, bins - 1);
}

// The cases of the renderer tests: narrow and wide roughness, normal and grazing incidence.
struct Case {
  const char* name;
  double beta, theta_i;
};
const Case kGenericCases[] = {{"narrow", 4.5 * kDeg, 30.0 * kDeg}, {"wide", 30.0 * kDeg, -20.0 * kDeg}, {"grazing", 10.0 * kDeg, 85.0 * kDeg}};
const Case kMaterialCases[] = {{"normal", 0.0, 10.0 * kDeg}, {"grazing", 0.0, -85.0 * kDeg}};

}  // namespace

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
      axes[0] = {sampler::Spacing::log, sampler::Placement::edges, sampler::Wrap::clamp, 0.1, 1.0, na, nullptr, sampler::Interpolation::cubic};
      axes[1] = {sampler::Spacing::uniform, sampler::Placement::edges, sampler::Wrap::clamp, 0.0, 2.0, nb, nullptr, sampler::Interpolation::linear};
      if (wrap == 0)
        axes[2] = {sampler::Spacing::uniform, sampler::Placement::edges, sampler::Wrap::clamp, -0.5 * kPi, 0.5 * kPi, nx, nullptr, interp};
      else
        axes[2] = {sampler::Spacing::uniform, sampler::Placement::edges, sampler::Wrap::even, 0.0, kPi, nx, nullptr, interp};
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

TEST_CASE("Axis sampling: the mixture fast path has the general path's density and normalisation, and draws from it", "[sampling]") {
  // Tables over (a, b, x) with linear a and b (weights ≥ 0) and x linear or Catmull–Rom: where
  // mix() holds, its normalisation and pdf must equal the blended row's to rounding, and its
  // draws must follow the CDF of an independent quadrature of the clamped interpolant. Cubic
  // rows with spikes overshoot below 0: there mix() must refuse (the general path applies).
  for (int wrap = 0; wrap < 2; ++wrap)
    for (int cubic = 0; cubic < 2; ++cubic) {
      const int na = 4, nb = 3, nx = 17;
      std::vector<double> data(static_cast<std::size_t>(na * nb * nx));
      std::mt19937_64 rng(70 + static_cast<unsigned>(wrap * 2 + cubic));
      std::uniform_real_distribution<double> u(0.0, 1.0);
      // Smooth positive rows (no overshoot) for slices a < 2, spiky rows (Catmull–Rom dips
      // below 0 next to a spike) for a ≥ 2.
      for (int ia = 0; ia < na; ++ia)
        for (int ib = 0; ib < nb; ++ib)
          for (int ix = 0; ix < nx; ++ix) {
            double& v = data[static_cast<std::size_t>((ia * nb + ib) * nx + ix)];
            v = ia < 2 ? 1.0 + 0.5 * std::sin(0.4 * ix + ia + 2.0 * ib) + 0.2 * u(rng) : (u(rng) < 0.3 ? 5.0 * u(rng) : 0.0);
          }
      const sampler::Interpolation interp = cubic ? sampler::Interpolation::cubic : sampler::Interpolation::linear;
      sampler::Axis axes[3];
      axes[0] = {sampler::Spacing::log, sampler::Placement::edges, sampler::Wrap::clamp, 0.1, 1.0, na, nullptr, sampler::Interpolation::linear};
      axes[1] = {sampler::Spacing::uniform, sampler::Placement::edges, sampler::Wrap::clamp, 0.0, 2.0, nb, nullptr, sampler::Interpolation::linear};
      if (wrap == 0)
        axes[2] = {sampler::Spacing::uniform, sampler::Placement::edges, sampler::Wrap::clamp, -0.5 * kPi, 0.5 * kPi, nx, nullptr, interp};
      else
        axes[2] = {sampler::Spacing::uniform, sampler::Placement::edges, sampler::Wrap::even, 0.0, kPi, nx, nullptr, interp};
      const sampler::TableView<double> view(data.data(), axes, 3);
      const sampler::Measure measure = wrap == 0 ? sampler::Measure::cosine : sampler::Measure::plain;
      const AxisSampler<double> axis(data.data(), axes, 3, measure);
      REQUIRE(axis.has_mixture());
      const double lo = wrap == 0 ? -0.5 * kPi : -kPi, hi = wrap == 0 ? 0.5 * kPi : kPi;
      AxisRow row;
      AxisSampler<double>::Mix m;
      int fast = 0, refused = 0;
      for (int trial = 0; trial < 16; ++trial) {
        // Half the trials among the smooth slices (a between the first two nodes), half anywhere.
        const double a = trial % 2 == 0 ? std::exp(std::log(0.1) + u(rng) * (std::log(1.0) - std::log(0.1)) / 3.0) : 0.1 + 0.9 * u(rng);
        double x[3] = {a, 2.0 * u(rng), 0.0};
        axis.blend(x, row);
        REQUIRE(row.ok);
        if (!axis.mix(x, m)) {
          ++refused;
          continue;
        }
        ++fast;
        CHECK(std::fabs(m.total - row.total) <= 1e-12 * row.total);
        for (int k = 0; k < 100; ++k) {
          const double t = lo + (hi - lo) * u(rng);
          const double general = axis.pdf(row, t);
          const double fastpdf = axis.mix_value(m, t) * (measure == sampler::Measure::cosine ? std::cos(t) : 1.0) / m.total;
          CHECK(std::fabs(fastpdf - general) <= 1e-12 * std::max(general, 1.0 / (hi - lo)));
        }
        auto reference = [&](double t) {
          x[2] = t;
          const double v = std::max(0.0, view(x));
          return measure == sampler::Measure::cosine ? v * std::cos(t) : v;
        };
        const int cells = (nx - 1) * 256 * (wrap ? 2 : 1);
        const double total = integrate(reference, lo, hi, cells);
        CHECK(std::fabs(m.total - total) <= 1e-7 * total);
        // The mixture's draws are not monotone in u, so the check is of their distribution: n
        // stratified u, the reference CDF at each sorted draw. The u falling to slice c are
        // stratified in that slice's own u', so the count of its draws below any x is within 1
        // of n s_c F_c(x) (s_c its share); summed over the slices (and the two halves of an even
        // axis, drawn separately), the empirical CDF is within slices × halves / n of the exact
        // one, plus rounding.
        const int n = 2000;
        std::vector<double> cdf;
        for (int k = 0; k < n; ++k) {
          const double t = axis.sample_mix(m, (k + 0.5) / n);
          REQUIRE(t >= lo);
          REQUIRE(t <= hi);
          CHECK(axis.mix_value(m, t) > 0.0);
          cdf.push_back(t);
        }
        std::sort(cdf.begin(), cdf.end());
        // Cumulative reference integral at each sorted draw, accumulated piecewise.
        double acc = 0.0, prev = lo, ks = 0.0;
        for (int k = 0; k < n; ++k) {
          acc += integrate(reference, prev, cdf[static_cast<std::size_t>(k)], 8);
          prev = cdf[static_cast<std::size_t>(k)];
          ks = std::max(ks, std::fabs(acc / total - (k + 0.5) / n));
        }
        CHECK(ks <= (m.count * (wrap ? 2.0 : 1.0) + 0.5) / n + 1e-6);  // + ½/n: the sorted draw k stands for (k + ½)/n
      }
      INFO("wrap " << wrap << " cubic " << cubic << ": fast " << fast << ", refused " << refused);
      CHECK(fast >= 4);
      if (cubic) CHECK(refused >= 1);
      else CHECK(refused == 0);
    }
}

namespace {
// The default tables with linear interpolation along every N_p and M_p axis (the same nodes): the
// reconstruction on which the sampler's mixture fast path applies at every lookup.
HairTables linear_tables(const TableSet& set, bool cubic_sampled_axis) {
  HairTables h = hair_tables(set, "");
  for (sampler::LobeTables<float>& l : h.lobes)
    for (sampler::TableRef<float>* t : {&l.np, &l.mp})
      for (int d = 0; d < t->dims; ++d) {
        sampler::Axis& a = const_cast<sampler::Axis&>(t->axes[d]);
        if (a.interpolation == sampler::Interpolation::cubic && !(cubic_sampled_axis && d + 1 == t->dims)) a.interpolation = sampler::Interpolation::linear;
      }
  h.sampler = std::make_unique<HairSampler<float>>(h.lobes.data(), static_cast<int>(h.lobes.size()));
  return h;
}
}  // namespace

TEST_CASE("Sampling: the mixture fast path on linear tables, pdf against quadrature, chi-square and furnace", "[sampling]") {
  const TableSet& set = default_tables();
  for (int cubic_sampled = 0; cubic_sampled < 2; ++cubic_sampled) {
    const HairTables h = linear_tables(set, cubic_sampled != 0);
    REQUIRE(h.sampler->supported());
    std::mt19937_64 rng(21 + static_cast<unsigned>(cubic_sampled));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    HairSampler<float>::Workspace ws;
    // pdf of each lobe = max(0, M̃)/∫ M̃ cos θr dθr × max(0, Ñ)/∫ Ñ dφ, from TableView lookups of
    // the linearised tables and independent quadrature.
    for (std::size_t p = 0; p < h.lobes.size(); ++p) {
      const HairSampler<float> one(&h.lobes[p], 1);
      const sampler::LobeTables<float>& l = h.lobes[p];
      const sampler::TableView<float> mp(l.mp.data, l.mp.axes, l.mp.dims), np(l.np.data, l.np.axes, l.np.dims);
      const bool has_phi = l.np.dims == 4;
      for (int k = 0; k < 20; ++k) {
        const FibreCoordinates f{std::exp(std::log(4.5 * kDeg) + u(rng) * std::log(40.0 / 4.5)), 4.0 * u(rng) * u(rng), 0.0};
        const double ti = (u(rng) - 0.5) * 170.0 * kDeg, tr = (u(rng) - 0.5) * 170.0 * kDeg, phi = (2.0 * u(rng) - 1.0) * kPi;
        const double td = 0.5 * (tr - ti);
        auto m_at = [&](double t) {
          const double x[3] = {f.beta, ti, t};
          return std::max(0.0, mp(x));
        };
        auto n_at = [&](double t) {
          const double x[4] = {f.beta, f.sigma_a, td, t};
          return std::max(0.0, np(x));
        };
        const double zm = integrate([&](double t) { return m_at(t) * std::cos(t); }, -0.5 * kPi, 0.5 * kPi, 160 * 8);
        const double pn = has_phi ? n_at(phi) / integrate(n_at, -kPi, kPi, 190 * 8) : 1.0 / (2.0 * kPi);
        const double expected = m_at(tr) / zm * pn;
        CHECK(std::fabs(one.pdf(f, ti, tr, phi, ws) - expected) <= 1e-7 * std::max(expected, 1e-12));
      }
    }
    // Chi-square and ∫ pdf = 1 of the mixture of all lobes at wide and narrow roughness, and a
    // furnace through sampling against quadrature of eval.
    for (const Case& c : {kGenericCases[0], kGenericCases[1]}) {
      const FibreCoordinates f{c.beta, 0.5, 0.0};
      double integral = 0.0;
      const double pvalue = chi_square(*h.sampler, f, c.theta_i, 200000, 700 + static_cast<unsigned>(cubic_sampled), &integral);
      const double exact = quadrature_energy(*h.sampler, f, c.theta_i);
      const Estimate e = furnace(*h.sampler, f, c.theta_i, 200000, 800 + static_cast<unsigned>(cubic_sampled));
      INFO(c.name << (cubic_sampled ? ", cubic sampled axes" : ", linear") << ": p-value " << pvalue << ", integral of pdf " << integral
                  << ", furnace " << e.mean << " +- " << e.error << ", quadrature " << exact);
      CHECK(std::fabs(integral - 1.0) <= 1e-3);
      CHECK(pvalue > 0.01 / 4.0);  // significance 0.01 over the 4 fits
      CHECK(std::fabs(e.mean - exact) <= 4.0 * e.error);
    }
  }
}
