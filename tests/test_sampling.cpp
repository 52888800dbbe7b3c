// Importance sampling of hairlut tables (sampling.hpp), tested as renderers test their BSDFs:
// the sampled axis against independent quadrature of the interpolant the sampler evaluates,
// eval/pdf consistency, pdf normalisation, chi-square goodness of fit of sampled directions
// against the pdf integrated over bins (as Mitsuba's and pbrt's suites do), and white furnaces
// estimated through sampling, for every lobe of the default tables and of per-material tables.
#include <algorithm>
#include <cmath>
#include <hairlut/bake.hpp>
#include <hairlut/config.hpp>
#include <hairlut/sampling.hpp>
#include <hairlut/table_io.hpp>
#include <hairlut/table_sampling.hpp>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "catch.hpp"

using namespace hairlut;
using sampler::AxisRow;
using sampler::AxisSampler;
using sampler::Fibre;
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

// ∫_a^b f by composite Gauss–Legendre of order 8 over `cells` equal cells.
template <class F>
double integrate(F f, double a, double b, int cells) {
  std::vector<double> x, w;
  gauss_legendre01(8, x, w);
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
                 "tilt_deg": { "R": -5, "TT": 2.5, "TRT": 7.5, "TRRT": 12.5, "residual": 12.5 } },
      "tables": {
        "np": { "axes": { "theta_d": { "count": 40, "range_deg": [0, 89.5], "spacing": "cos" },
                          "phi": { "count": 97, "symmetry": "even" } } },
        "mp": { "axes": { "theta_i": { "count": 61, "range_deg": [-90, 90] },
                          "theta_r": { "count": 121, "range_deg": [-90, 90] } } }
      },
      "scene": { "mode": "per-material", "materials": [
        { "name": "blonde", "melanin": { "eumelanin": 0.3, "pheomelanin": 0.15 }, "beta_deg": { "R": 5, "TT": 2.5, "TRT": 10 } },
        { "name": "white", "sigma_a": [0.0, 0.0, 0.0], "beta_deg": { "R": 8, "TT": 4, "TRT": 16, "residual": 20 } } ] },
      "output": { "basename": "sampling-test", "formats": ["hdf5"] }
    })");
    BakeOptions options;
    options.threads = 1;
    return bake(parse_config(j, "sampling-test.json", "."), options);
  }();
  return set;
}

// A sampler of one lobe (index p) of a group's tables, or of all of them (p < 0).
struct OneGroup {
  HairTables all;
  std::unique_ptr<HairSampler<float>> one;
  const HairSampler<float>& sampler() const { return one ? *one : *all.sampler; }
};
OneGroup group_sampler(const TableSet& set, const std::string& group, int p) {
  OneGroup g{hair_tables(set, group), nullptr};
  if (p >= 0) g.one = std::make_unique<HairSampler<float>>(&g.all.lobes[static_cast<std::size_t>(p)], 1);
  return g;
}

// ∫ S dω by quadrature of eval (independent of the sampling code): composite Gauss–Legendre
// over θr ∈ [−π/2, π/2] and φ ∈ [0, π] (S is even in φ), cells finer than the table's.
double quadrature_energy(const HairSampler<float>& s, const Fibre& f, double theta_i) {
  return integrate(
      [&](double tr) {
        return 2.0 * std::cos(tr) * integrate([&](double phi) { return s.eval(f, theta_i, tr, phi); }, 0.0, kPi, 192);
      },
      -0.5 * kPi, 0.5 * kPi, 320);
}

struct Estimate {
  double mean, error;  // mean and its standard error
};
Estimate furnace(const HairSampler<float>& s, const Fibre& f, double theta_i, int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  HairSampler<float>::Workspace ws;
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
double chi_square(const HairSampler<float>& s, const Fibre& f, double theta_i, int n, unsigned seed, double* pdf_integral) {
  const int nt = 60, np = 64;
  std::vector<double> observed(static_cast<std::size_t>(nt * np), 0.0), expected(observed.size(), 0.0);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  HairSampler<float>::Workspace ws;
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
      const Fibre f{std::exp(std::log(4.5 * kDeg) + u(rng) * std::log(40.0 / 4.5)), 4.0 * u(rng) * u(rng), 0.0};
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

TEST_CASE("Sampling: chi-square fit and pdf normalisation, every lobe of the default tables", "[sampling]") {
  const TableSet& set = default_tables();
  const int lobes = static_cast<int>(hair_tables(set, "").lobes.size());
  int tests = 0;
  for (const Case& c : kGenericCases) {
    for (int p = -1; p < lobes; ++p) {
      const OneGroup g = group_sampler(set, "", p);
      double integral = 0.0;
      const double pvalue = chi_square(g.sampler(), Fibre{c.beta, 0.0, 0.0}, c.theta_i, 200000, 100u + static_cast<unsigned>(tests), &integral);
      INFO(c.name << " lobe " << (p < 0 ? std::string("all") : g.all.lobe_names[static_cast<std::size_t>(p)]) << ": p-value " << pvalue
                  << ", integral of pdf " << integral);
      CHECK(std::fabs(integral - 1.0) <= 1e-3);
      CHECK(pvalue > 0.01 / 18.0);  // Šidák-like correction for the 18 tests of this case
      ++tests;
    }
  }
}
