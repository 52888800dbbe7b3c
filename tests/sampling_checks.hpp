// Shared by the sampling tests (test_sampling.cpp, test_sampling_mixture.cpp): independent
// quadrature, the default and per-material tables, chi-square and furnace estimators.
#pragma once

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

namespace sampling_checks {
using namespace hairlut;
using sampler::AxisRow;
using sampler::AxisSampler;
using sampler::FibreCoordinates;
using sampler::HairSampler;
}  // namespace sampling_checks

namespace sampling_checks {

constexpr double kDeg = kPi / 180.0;

// The axes of the random 3D test tables of the axis-sampling tests: a (log, 0.1–1) and b (uniform,
// 0–2) with their own interpolations, then the sampled axis — θr-like (clamped, −π/2 … π/2, for
// wrap 0) or φ-like (even, 0 … π) — with `interp`.
inline void random_table_axes(sampler::Axis axes[3], int na, int nb, int nx, int wrap, sampler::Interpolation a_interp,
                              sampler::Interpolation b_interp, sampler::Interpolation interp) {
  axes[0] = {sampler::Spacing::log, sampler::Placement::edges, sampler::Wrap::clamp, 0.1, 1.0, na, nullptr, a_interp};
  axes[1] = {sampler::Spacing::uniform, sampler::Placement::edges, sampler::Wrap::clamp, 0.0, 2.0, nb, nullptr, b_interp};
  if (wrap == 0)
    axes[2] = {sampler::Spacing::uniform, sampler::Placement::edges, sampler::Wrap::clamp, -0.5 * kPi, 0.5 * kPi, nx, nullptr, interp};
  else
    axes[2] = {sampler::Spacing::uniform, sampler::Placement::edges, sampler::Wrap::even, 0.0, kPi, nx, nullptr, interp};
}

// Gauss–Legendre nodes and weights of order m on [0, 1] (Newton on the Legendre recurrence).
inline void gauss_legendre01(int m, std::vector<double>& x, std::vector<double>& w) {
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
inline double chi2_pvalue(double chi2, int k) {
  const double v = 2.0 / (9.0 * k);
  const double z = (std::cbrt(chi2 / k) - (1.0 - v)) / std::sqrt(v);
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

inline const TableSet& default_tables() {
  static const TableSet set = load_tables(std::string(HAIRLUT_SOURCE_DIR) + "/tables/default/hairlut-default.h5");
  return set;
}

// Per-material tables of two materials (one white) baked in memory, small enough for a test.
inline const TableSet& material_tables() {
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
inline OneGroup group_sampler(const TableSet& set, const std::string& group, int p, const FibreCoordinates& f) {
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

}  // namespace sampling_checks
