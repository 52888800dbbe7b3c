// bench-hair-luts, section "representations": N_p in the Fourier representation (baked by the library,
// tables.np.representation "fourier"; read by sampler::FourierNp, fourier_np.hpp) at the same random
// points, against the same reference and denominators as the tensor tables of the generic domain;
// its size; the error of the truncation alone (the same series with exact C_n at each point, no
// table); and its lookup cost against a plain multilinear lookup of the generic domain in the same
// sampler (FixedView, all axes linear), in the same run at the same points: float and double
// arithmetic, β log-uniform over the domain and at its narrowest β, in cache (256 points repeated)
// and out of cache (2^20 points), one thread, thread CPU time, best of 3.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/physics/azimuthal_fourier.hpp>
#include <hairlut/physics/fiber_geometry.hpp>
#include <hairlut/sampler/fourier_np.hpp>
#include <hairlut/sampler/sampler_fixed.hpp>
#include <hairlut/tables/fourier_tables.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <hairlut/util/angles.hpp>
#include <hairlut/util/quadrature.hpp>
#include <map>
#include <random>

#include "bench_common.hpp"
#include "representations.hpp"

namespace bench {
namespace {

using namespace hairlut;

// The config of one case over the generic domain (β 2°–30°, σa 0–10, θd 0–89°; R, TT, TRT, TRRT).
json fourier_tables_json(const FourierCase& fc) {
  json sigma = {{"count", fc.sigma}, {"range", {0, 10}}, {"spacing", "sqrt"}, {"interpolation", fc.sigma_interpolation}};
  if (fc.sigma_interpolation == "cubic") sigma["lo_end"] = "mirror";
  json theta = {{"count", fc.theta}, {"range_deg", {0, 89}}, {"spacing", fc.theta_spacing}, {"interpolation", fc.theta_interpolation}};
  return {{"np",
           {{"representation", "fourier"},
            {"axes", {{"beta", {{"range_deg", {2, 30}}}}, {"sigma_a", sigma}, {"theta_d", theta}}},
            {"fourier", {{"tolerance", fc.tolerance}}}}}};
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
    return fourier_np(C, 1, x[0], x[3], tolerance);
  });
}

// Random lookup points (float, as a renderer passes them): β log-uniform over [2°, 30°] or fixed.
struct LookupPoints {
  std::vector<float> beta, sigma, theta, phi;
};
LookupPoints lookup_points(std::size_t n, double fixed_beta, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  LookupPoints p;
  for (std::size_t i = 0; i < n; ++i) {
    const double b = fixed_beta > 0.0 ? fixed_beta : radians(2.0) * std::pow(15.0, u(rng));
    p.beta.push_back(static_cast<float>(b));
    p.sigma.push_back(static_cast<float>(10.0 * u(rng)));
    p.theta.push_back(static_cast<float>(radians(89.0) * u(rng)));
    p.phi.push_back(static_cast<float>(kPi * u(rng)));
  }
  return p;
}

// ns per lookup of the Fourier TRT table and of the plain multilinear table, arithmetic R, at the
// same points (cycled through `calls` times).
template <class R>
json time_pair(const TableSet& fourier, const Table& plain, const LookupPoints& pts, std::size_t calls) {
  const sampler::FourierNp<float, R> f = fourier_np<float, R>(fourier, "TRT");
  sampler::Axis lin[4];
  for (int d = 0; d < 4; ++d) lin[d] = plain.axes[static_cast<std::size_t>(d)].view(), lin[d].interpolation = sampler::Interpolation::linear;
  const sampler::FixedView<float, 4, R> m(plain.f32.data(), lin);
  const std::size_t n = pts.beta.size();
  volatile R sink = 0;
  const double ns_fourier = best_ns(calls, 3, [&] {
    R s = 0;
    for (std::size_t i = 0, k = 0; i < calls; ++i, k = k + 1 == n ? 0 : k + 1)
      s += f(static_cast<R>(pts.beta[k]), static_cast<R>(pts.sigma[k]), static_cast<R>(pts.theta[k]), static_cast<R>(pts.phi[k]));
    sink = sink + s;
  });
  const double ns_plain = best_ns(calls, 3, [&] {
    R s = 0;
    for (std::size_t i = 0, k = 0; i < calls; ++i, k = k + 1 == n ? 0 : k + 1) {
      const R x[4] = {static_cast<R>(pts.beta[k]), static_cast<R>(pts.sigma[k]), static_cast<R>(pts.theta[k]), static_cast<R>(pts.phi[k])};
      s += m(x);
    }
    sink = sink + s;
  });
  return {{"ns_fourier", ns_fourier}, {"ns_multilinear", ns_plain}, {"ratio", ns_fourier / ns_plain}};
}

// The lookup comparison of one Fourier set against the plain multilinear table.
json lookup_comparison(const TableSet& fourier, const Table& plain, bool quick) {
  const std::size_t calls = quick ? (1u << 15) : (1u << 20), far = quick ? (1u << 16) : (1u << 20);
  json rows = json::array();
  const std::string before = load_average();
  for (const double beta : {0.0, radians(2.0)})
    for (const bool in_cache : {true, false}) {
      const LookupPoints pts = lookup_points(in_cache ? 256 : far, beta, 11);
      json r = {{"points", beta > 0.0 ? "beta = 2 deg (the most terms)" : "beta log-uniform over 2-30 deg"},
                {"cache", in_cache ? "in cache (256 points repeated)" : "out of cache (" + std::to_string(far) + " random points)"}};
      r["float"] = time_pair<float>(fourier, plain, pts, calls);
      r["double"] = time_pair<double>(fourier, plain, pts, calls);
      rows.push_back(r);
    }
  return {{"load_average_before", before}, {"load_average_after", load_average()}, {"multilinear_table", plain.path() + " 16 x 32 x 64 x 128, every axis linear"},
          {"timing", "thread CPU time per lookup, best of 3, one thread; sigma_a, theta_d, phi uniform over the domain"}, {"rows", rows}};
}

}  // namespace

json fourier_representation_rows(const std::vector<FourierCase>& cases, const NpPoints& pts, const std::vector<GridAxis>& axes, double eta,
                                 int lookups, bool quiet, const TableSet& plain, bool quick) {
  json rows = json::array();
  std::map<double, std::map<std::string, ErrorStats>> truncation;
  for (const FourierCase& fc : cases) {
    if (!quiet)
      std::fprintf(stderr, "representations: generic: %s %dx%d (%s theta_d %s, sigma_a %s, tolerance %g)\n", fc.label.c_str(), fc.theta, fc.sigma,
                   fc.theta_spacing.c_str(), fc.theta_interpolation.c_str(), fc.sigma_interpolation.c_str(), fc.tolerance);
    const double t0 = thread_cpu_seconds();
    const TableSet set = bake_tables(fourier_tables_json(fc), "repr-fourier");
    const double build_s = thread_cpu_seconds() - t0;
    std::vector<sampler::FourierNp<float, double>> views;
    for (const std::string& l : pts.lobes) views.push_back(fourier_np<float, double>(set, l));
    const auto errors = np_errors(pts, [&](int p, const std::vector<double>& x) { return views[static_cast<std::size_t>(p)](x[0], x[1], x[2], x[3]); });
    if (!truncation.count(fc.tolerance)) truncation[fc.tolerance] = truncation_errors(pts, eta, radians(2.0), fc.tolerance);
    const Table& trt = *set.find("np_fourier/TRT");
    json row = {{"domain", "generic"},
                {"representation", fc.representation},
                {"label", fc.label},
                {"counts", {{"terms", trt.axes[2].count}, {"theta_d", fc.theta}, {"sigma_a", fc.sigma}}},
                {"entries_per_lobe", trt.size()},
                {"entries_total", trt.size() * pts.lobes.size()},
                {"bytes", set.bytes()},
                {"points_per_lobe", pts.x.empty() ? 0 : pts.x.front().size()},
                {"fourier",
                 {{"stored", "C_n/F"},
                  {"theta_d_spacing", fc.theta_spacing},
                  {"theta_d_interpolation", fc.theta_interpolation},
                  {"sigma_a_spacing", "sqrt"},
                  {"sigma_a_interpolation", fc.sigma_interpolation},
                  {"beta_min_deg", 2.0},
                  {"tolerance", fc.tolerance},
                  {"bake_cpu_s", build_s}}}};
    add_errors(row, errors);
    json trunc;
    add_errors(trunc, truncation[fc.tolerance]);
    trunc.erase("worst_at");
    row["fourier"]["truncation_alone"] = trunc;
    // The column every row has: double arithmetic at random points over the axes (as the tensor rows).
    std::mt19937_64 rng(3);
    std::vector<double> xs(static_cast<std::size_t>(lookups) * 4);
    for (std::size_t i = 0; i < xs.size(); ++i) xs[i] = draw(axes[i % 4], rng);
    const sampler::FourierNp<float, double>& v = views[2];
    volatile double sink = 0.0;
    row["lookup_ns"] = best_ns(static_cast<std::size_t>(lookups), 3, [&] {
      double s = 0.0;
      for (std::size_t i = 0; i < xs.size(); i += 4) s += v(xs[i], xs[i + 1], xs[i + 2], xs[i + 3]);
      sink = sink + s;
    });
    if (fc.compare_lookup && plain.find("np/TRT")) row["fourier_lookup"] = lookup_comparison(set, *plain.find("np/TRT"), quick);
    rows.push_back(row);
  }
  return rows;
}

std::vector<FourierCase> fourier_cases(bool quick) {
  std::vector<FourierCase> cases;
  auto add = [&](const std::string& rep, const std::string& label, int theta, const std::string& ti, int sigma, const std::string& si,
                 double tolerance, bool compare, const std::string& spacing = "cos") {
    cases.push_back({rep, label, theta, sigma, ti, si, spacing, tolerance, compare});
  };
  // θd carries the error (the C_n oscillate along θd as the caustics and the fiber's edge move, the
  // faster the higher n); σa needs few nodes once the absorption at the edge is factored out.
  if (quick) {
    add("fourier-cubic", "Fourier C_n/F, cubic theta_d and sigma_a", 128, "cubic", 16, "cubic", 1e-3, true);
    return cases;
  }
  add("fourier-cubic", "Fourier C_n/F, cubic theta_d and sigma_a", 64, "cubic", 16, "cubic", 1e-3, false);
  add("fourier-cubic", "Fourier C_n/F, cubic theta_d and sigma_a", 128, "cubic", 16, "cubic", 1e-3, false);
  add("fourier-cubic", "Fourier C_n/F, cubic theta_d and sigma_a", 256, "cubic", 16, "cubic", 1e-3, true);
  add("fourier-cubic", "Fourier C_n/F, cubic theta_d and sigma_a", 256, "cubic", 32, "cubic", 1e-3, false);
  add("fourier-cubic-tolerance-1e-4", "Fourier C_n/F, cubic, terms for tolerance 1e-4", 256, "cubic", 16, "cubic", 1e-4, false);
  add("fourier-cubic-uniform-theta", "Fourier C_n/F, cubic, uniform theta_d", 256, "cubic", 16, "cubic", 1e-3, false, "uniform");
  add("fourier-cubic-linear", "Fourier C_n/F, cubic theta_d, linear sigma_a (generic-1e-3)", 256, "cubic", 64, "linear", 1e-3, true);
  add("fourier-linear", "Fourier C_n/F, linear theta_d and sigma_a", 512, "linear", 55, "linear", 1e-3, true);
  return cases;
}

}  // namespace bench
