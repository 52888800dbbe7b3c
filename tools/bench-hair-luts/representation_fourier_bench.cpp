// bench-hair-luts, section "representations": the Fourier representation (representation_fourier.hpp,
// C_n(θd, σa) tabulated, β and φ exact) measured at the same random points, against the same
// reference and denominators as the tables of the generic N_p domain, with its lookup timed as
// theirs are (random points over the same axes, one thread, thread CPU time, best of 3 after a
// warm-up run). Also the error of the truncation alone: the same series with exact C_n at each
// point, no table.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <hairlut/physics/azimuthal_fourier.hpp>
#include <hairlut/physics/fiber_geometry.hpp>
#include <hairlut/util/angles.hpp>
#include <hairlut/util/quadrature.hpp>
#include <map>
#include <random>

#include "bench_common.hpp"
#include "representation_fourier.hpp"
#include "representations.hpp"

namespace bench {
namespace {

using namespace hairlut;

// ns per lookup of lobe p (N_p at a random (β, σa, θd, φ) of the axes' ranges, drawn as the
// tables' lookups draw them), one thread, thread CPU time, best of 3 after a warm-up run.
double fourier_lookup_ns(const FourierTable<float>& table, int p, const std::vector<GridAxis>& axes, int lookups, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<double> xs(static_cast<std::size_t>(lookups) * 4);
  for (int i = 0; i < lookups; ++i)
    for (int d = 0; d < 4; ++d) xs[static_cast<std::size_t>(i * 4 + d)] = draw(axes[static_cast<std::size_t>(d)], rng);
  double sink = 0.0;
  auto run = [&] {
    const double t0 = thread_cpu_seconds();
    for (int i = 0; i < lookups; ++i) {
      const double* x = &xs[static_cast<std::size_t>(i * 4)];
      sink += table.value(p, x[0], x[1], x[2], x[3]);
    }
    return (thread_cpu_seconds() - t0) * 1e9 / lookups;
  };
  run();
  double best = 1e300;
  for (int r = 0; r < 3; ++r) best = std::min(best, run());
  if (sink == -1.0) std::printf(" ");
  return best;
}

// The truncation alone: at each point the series with C_n integrated at the point's own (σa, θd)
// (no table, double), N(β) terms at `tolerance`, the stored count at beta_min as the cap.
std::map<std::string, ErrorStats> truncation_errors(const NpPoints& pts, double eta, double beta_min, double tolerance) {
  const int N = fourier_terms(beta_min, tolerance);
  GaussLegendreCache rules;
  std::vector<double> C;
  return np_errors(pts, [&, key = std::vector<double>{-1.0, -1.0, -1.0}](int p, const std::vector<double>& x) mutable {
    if (key[0] != p || key[1] != x[1] || key[2] != x[2]) {  // the points of a lobe come in slabs of one (σa, θd)
      const FiberGeometry g = FiberGeometry::make(eta, x[2]);
      fourier_coefficients(g, AbsorptionPath::chord, p, std::span<const double>(&x[1], 1), N, rules.get(fourier_nodes(N, p, g, 1e-12)), C);
      key = {static_cast<double>(p), x[1], x[2]};
    }
    return std::max(0.0, fourier_series(C, x[0], x[3], tolerance));
  });
}

std::string store_name(FourierTableConfig::Store s) {
  switch (s) {
    case FourierTableConfig::Store::raw: return "C_n";
    case FourierTableConfig::Store::absorption: return "C_n/F";
    case FourierTableConfig::Store::ratio: return "C_0/F, C_n/C_0";
  }
  return "";
}

}  // namespace

json fourier_representation_rows(const std::vector<FourierCase>& cases, const NpPoints& pts, const std::vector<GridAxis>& axes, double eta,
                                 int lookups, bool quiet) {
  json rows = json::array();
  std::map<double, std::map<std::string, ErrorStats>> truncation;
  for (const FourierCase& fc : cases) {
    const FourierTableConfig& c = fc.config;
    if (!quiet)
      std::fprintf(stderr, "representations: generic: %s %dx%d (%s, %s theta_d, %s sigma_a, tolerance %g)\n", fc.label.c_str(), c.theta_count,
                   c.sigma_count, store_name(c.store).c_str(), c.theta_cos ? "cos" : "uniform", c.sigma_sqrt ? "sqrt" : "uniform", c.tolerance);
    const double t0 = thread_cpu_seconds();
    const FourierTable<float> table(c);
    const double build_s = thread_cpu_seconds() - t0;
    const auto errors = np_errors(pts, [&](int p, const std::vector<double>& x) { return table.value(p, x[0], x[1], x[2], x[3]); });
    if (!truncation.count(c.tolerance)) truncation[c.tolerance] = truncation_errors(pts, eta, c.beta_min, c.tolerance);
    json row = {{"domain", "generic"},
                {"representation", fc.representation},
                {"label", fc.label},
                {"counts", {{"terms", table.terms()}, {"theta_d", c.theta_count}, {"sigma_a", c.sigma_count}}},
                {"entries_per_lobe", table.entries_per_lobe()},
                {"entries_total", table.entries_per_lobe() * static_cast<std::size_t>(c.lobes)},
                {"bytes", table.bytes()},
                {"points_per_lobe", pts.x.empty() ? 0 : pts.x.front().size()},
                {"fourier",
                 {{"stored", store_name(c.store)},
                  {"theta_d_spacing", c.theta_cos ? "cos" : "uniform"},
                  {"sigma_a_spacing", c.sigma_sqrt ? "sqrt" : "uniform"},
                  {"interpolation", c.cubic ? "catmull-rom" : "linear"},
                  {"beta_min_deg", degrees(c.beta_min)},
                  {"tolerance", c.tolerance},
                  {"build_cpu_s", build_s}}}};
    add_errors(row, errors);
    json trunc;
    add_errors(trunc, truncation[c.tolerance]);
    trunc.erase("worst_at");
    row["fourier"]["truncation_alone"] = trunc;
    row["lookup_ns"] = fourier_lookup_ns(table, 2, axes, lookups, 3);
    rows.push_back(row);
  }
  return rows;
}

std::vector<FourierCase> fourier_cases(bool quick) {
  std::vector<FourierCase> cases;
  auto add = [&](const std::string& rep, const std::string& label, int theta, int sigma, FourierTableConfig::Store store, bool theta_cos,
                 bool sigma_sqrt, bool cubic, double tolerance) {
    FourierTableConfig c;
    c.beta_min = radians(2.0), c.theta_max = radians(89.0), c.sigma_max = 10.0;
    c.theta_count = theta, c.sigma_count = sigma, c.store = store, c.theta_cos = theta_cos, c.sigma_sqrt = sigma_sqrt, c.cubic = cubic;
    c.tolerance = tolerance;
    cases.push_back({rep, label, c});
  };
  using S = FourierTableConfig::Store;
  // θd carries the error (the C_n oscillate along θd as the caustics and the fibre's edge move, the
  // faster the higher n); σa needs few nodes once the absorption at the edge is factored out.
  const std::string best = "Fourier C_n(theta_d, sigma_a), C_n/F, cubic";
  if (quick) {
    add("fourier", best, 128, 16, S::absorption, true, true, true, 1e-4);
    return cases;
  }
  add("fourier", best, 64, 16, S::absorption, true, true, true, 1e-4);
  add("fourier", best, 128, 16, S::absorption, true, true, true, 1e-4);
  add("fourier", best, 256, 16, S::absorption, true, true, true, 1e-4);
  add("fourier", best, 256, 32, S::absorption, true, true, true, 1e-4);
  add("fourier-raw", "Fourier, raw C_n, cubic", 256, 16, S::raw, true, true, true, 1e-4);
  add("fourier-ratio", "Fourier, C_0/F and C_n/C_0, cubic", 256, 16, S::ratio, true, true, true, 1e-4);
  add("fourier-uniform-theta", "Fourier, C_n/F, uniform theta_d, cubic", 256, 16, S::absorption, false, true, true, 1e-4);
  add("fourier-linear", "Fourier, C_n/F, linear", 256, 16, S::absorption, true, true, false, 1e-4);
  add("fourier-tolerance-1e-3", "Fourier, C_n/F, cubic, terms for tolerance 1e-3", 128, 16, S::absorption, true, true, true, 1e-3);
  return cases;
}

}  // namespace bench
