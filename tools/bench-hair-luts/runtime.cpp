// Section "runtime": what a path tracer pays per shading point with HairScattering (eval, sample,
// pdf) against pbrt-v4's analytic HairBxDF::f, Sample_f and PDF (pbrt_hair.cpp) in the same run, on
// the same directions and random numbers, for both kinds of tables a renderer loads: the shipped
// generic default tables (σa and β per call), the 1e-3 set's Fourier N_p (tables/configs/generic-1e-3.json,
// with the default config's M_p and tilts), the tables of one material (σa and β baked), and the
// generic and Fourier sets prepared for the fiber's roughness (prepared_scattering.hpp: σa per
// fiber); the prepared runtimes' S against the runtimes they were prepared from; and the per-sample
// weight S / pdf of a white fiber (σa = 0), the quantity pbrt-v4's SamplingWeights test bounds.
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/io/table_io.hpp>
#include <hairlut/physics/melanin.hpp>
#include <hairlut/tables/hair_views.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "bench_common.hpp"
#include "pbrt_hair.hpp"

namespace bench {

namespace {

constexpr double kPiD = 3.14159265358979323846;
using Runtime = hairlut::sampler::HairScattering<float>;

struct Point {
  double wo[3], u[3];
  int h;
};

std::vector<Point> points(std::size_t n, int hs) {
  SplitMix uniform{424242};
  std::vector<Point> p(n);
  for (Point& x : p) {
    const double z = 2.0 * uniform() - 1.0, a = 2.0 * kPiD * uniform(), r = std::sqrt(1.0 - z * z);
    x.wo[0] = z, x.wo[1] = r * std::cos(a), x.wo[2] = r * std::sin(a);
    for (double& u : x.u) u = uniform();
    x.h = static_cast<int>(uniform() * hs);
  }
  return p;
}

// pbrt's roughness 0.3 in hairlut's units: β_m = √v of pbrt's variance map, β_n the standard
// deviation of pbrt's trimmed logistic (π s / √3).
double beta_m_of(double b) { return 0.726 * b + 0.812 * b * b + 3.7 * std::pow(b, 20); }
double beta_n_of(double b) { return kPiD / std::sqrt(3.0) * std::sqrt(kPiD / 8.0) * (0.265 * b + 1.194 * b * b + 5.372 * std::pow(b, 22)); }

// The shipped per-show example config reduced to one material, pbrt's fiber: its σa, and per lobe
// pbrt's longitudinal deviations (R β_m, TT β_m / 2, TRT and beyond 2 β_m) with β_n; the default
// tables' tilts. The axes are pinned to those of docs/bench/runtime.md's figures, so that a rerun
// measures the same tables whatever resolution the shipped config settles on.
hairlut::TableSet bake_material(const Settings& st, const double* sigma_a, double beta_m, double beta_n, bool float64 = false) {
  std::ifstream in(st.source_dir + "/tables/configs/show-example.json");
  json j = json::parse(in);
  const double m = beta_m * 180.0 / kPiD, n = beta_n * 180.0 / kPiD;
  j["lobes"]["tilt_deg"] = {{"R", -4}, {"TT", 2}, {"TRT", 6}, {"TRRT", 10}, {"residual", 10}};
  j["tables"]["np"]["axes"]["theta_d"]["count"] = 64;
  j["tables"]["np"]["axes"]["phi"]["count"] = 129;
  j["tables"]["mp"]["axes"]["theta_i"]["count"] = 91;
  j["tables"]["mp"]["axes"]["theta_r"]["count"] = 181;
  j["scene"]["materials"] = json::array();
  j["scene"]["materials"].push_back({{"name", "pbrt"},
                                     {"sigma_a", {sigma_a[0], sigma_a[1], sigma_a[2]}},
                                     {"beta_deg", {{"R", m}, {"TT", m / 2.0}, {"TRT", 2.0 * m}, {"residual", 2.0 * m}}},
                                     {"beta_n_deg", {{"R", n}, {"residual", n}}}});
  j["output"]["formats"] = {"hdf5"};
  j["output"]["directory"] = ".";
  if (float64) j["output"]["hdf5"]["precision"] = "float64";
  hairlut::BakeOptions options;
  options.threads = 0;
  return hairlut::bake(hairlut::parse_config(j, "runtime-material.json", st.source_dir + "/tables/configs"), options);
}

// tables/configs/generic-1e-3.json's Fourier N_p with the default config's lobes (tilts) and M_p
// tables: what a renderer that wants 1e-3 with σa and β per strand loads.
hairlut::TableSet bake_fourier(const Settings& st) {
  std::ifstream fin(st.source_dir + "/tables/configs/generic-1e-3.json"), din(st.source_dir + "/tables/configs/default.json");
  json j = json::parse(fin);
  const json d = json::parse(din);
  j["lobes"] = d["lobes"];
  j["tables"]["mp"] = d["tables"]["mp"];
  j["output"]["formats"] = {"hdf5"};
  j["output"]["directory"] = ".";
  hairlut::BakeOptions options;
  options.threads = 0;
  return hairlut::bake(hairlut::parse_config(j, "runtime-fourier.json", st.source_dir + "/tables/configs"), options);
}

struct Costs {
  double sample = 0.0, pdf = 0.0, eval = 0.0, point = 0.0;
};
// The four costs of one runtime at the points; pdf and eval at its own drawn directions.
template <class R, class F>
Costs time_runtime(const R& rt, const F& fiber, const std::vector<Point>& pts, int repeats) {
  const std::size_t n = pts.size();
  std::vector<std::array<double, 3>> wi(n);
  for (std::size_t i = 0; i < n; ++i) {
    wi[i] = {0.0, 1.0, 0.0};
    const auto s = rt.sample(fiber, pts[i].wo, pts[i].u);
    if (s.pdf > 0.0) wi[i] = {s.wi[0], s.wi[1], s.wi[2]};
  }
  volatile double sink = 0.0;
  Costs c;
  c.sample = best_ns(n, repeats, [&] {
    double acc = 0.0;
    for (const Point& p : pts) acc += rt.sample(fiber, p.wo, p.u).pdf;
    sink = acc;
  });
  c.pdf = best_ns(n, repeats, [&] {
    double acc = 0.0;
    for (std::size_t i = 0; i < n; ++i) acc += rt.pdf(fiber, pts[i].wo, wi[i].data());
    sink = acc;
  });
  c.eval = best_ns(n, repeats, [&] {
    double acc = 0.0, rgb[3];
    for (std::size_t i = 0; i < n; ++i) {
      rt.eval(fiber, pts[i].wo, wi[i].data(), rgb);
      acc += rgb[0];
    }
    sink = acc;
  });
  // One shading point as a path tracer visits it: the BSDF built for (fiber, wo), one sample drawn,
  // and one light direction weighed by pdf() and eval() (MIS).
  c.point = best_ns(n, repeats, [&] {
    double acc = 0.0, rgb[3];
    for (std::size_t i = 0; i < n; ++i) {
      const auto sp = rt.at(fiber, pts[i].wo);
      acc += sp.sample(pts[i].u).pdf + sp.pdf(wi[(i + 1) % n].data());
      sp.eval(wi[(i + 1) % n].data(), rgb);
      acc += rgb[0];
    }
    sink = acc;
  });
  (void)sink;
  return c;
}

// Weights of a white fiber at the points: their range, the share outside 1% and 10%, and the same
// for weight / albedo(wo).
template <class F>
json white_weights(const Runtime& rt, const F& white, const std::vector<Point>& pts, const std::string& label, std::ostringstream& md) {
  double lo = 1e300, hi = 0.0, rlo = 1e300, rhi = 0.0;
  std::size_t out1 = 0, out10 = 0, rout1 = 0, count = 0;
  for (const Point& p : pts) {
    const auto s = rt.sample(white, p.wo, p.u);
    const double w = s.pdf > 0.0 ? (s.weight[0] + s.weight[1] + s.weight[2]) / 3.0 : 0.0, r = w / rt.albedo(white, p.wo);
    ++count;
    lo = std::min(lo, w), hi = std::max(hi, w), rlo = std::min(rlo, r), rhi = std::max(rhi, r);
    out1 += !(w > 0.99 && w < 1.01), out10 += !(w >= 0.9 && w <= 1.1), rout1 += !(r > 0.99 && r < 1.01);
  }
  const double c = static_cast<double>(count);
  md << "| " << label << " | " << count << " | " << fmt(lo, 4) << " | " << fmt(hi, 4) << " | " << fmt(100.0 * static_cast<double>(out1) / c, 3) << "% | "
     << fmt(100.0 * static_cast<double>(out10) / c, 3) << "% | " << fmt(rlo, 5) << " | " << fmt(rhi, 5) << " | " << fmt(100.0 * static_cast<double>(rout1) / c, 3) << "% |\n";
  return {{"tables", label}, {"samples", count}, {"weight_min", lo}, {"weight_max", hi},
          {"fraction_outside_1_percent", static_cast<double>(out1) / c}, {"fraction_outside_10_percent", static_cast<double>(out10) / c},
          {"weight_over_albedo_min", rlo}, {"weight_over_albedo_max", rhi},
          {"weight_over_albedo_fraction_outside_1_percent", static_cast<double>(rout1) / c}};
}

// S of a prepared runtime against the runtime it was prepared from, per channel at the directions the
// prepared runtime draws at the points (where a path tracer evaluates it): the relative error's
// median, 99th percentile and maximum, and the largest error relative to the largest S drawn at
// the same wo (of 8 draws per wo).
json prepared_error(const Runtime& from, const Runtime& prepared, const hairlut::sampler::Fiber& fiber, const std::vector<Point>& pts) {
  const hairlut::sampler::PreparedFiber pf = prepared.fiber(fiber);
  std::vector<double> rel;
  double to_peak = 0.0;
  SplitMix uniform{99};
  for (const Point& p : pts) {
    double peak = 0.0, worst = 0.0;
    for (int k = 0; k < 8; ++k) {
      const double u[3] = {uniform(), uniform(), uniform()};
      const auto s = prepared.sample(pf, p.wo, u);
      if (!(s.pdf > 0.0)) continue;
      double a[3], b[3];
      from.eval(fiber, p.wo, s.wi, a);
      prepared.eval(pf, p.wo, s.wi, b);
      for (int c = 0; c < 3; ++c) {
        peak = std::max(peak, a[c]), worst = std::max(worst, std::fabs(a[c] - b[c]));
        if (a[c] > 0.0) rel.push_back(std::fabs(a[c] - b[c]) / a[c]);
      }
    }
    if (peak > 0.0) to_peak = std::max(to_peak, worst / peak);
  }
  std::sort(rel.begin(), rel.end());
  auto at = [&](double q) { return rel.empty() ? 0.0 : rel[std::min(rel.size() - 1, static_cast<std::size_t>(q * static_cast<double>(rel.size())))]; };
  return {{"values", rel.size()}, {"relative_p50", at(0.5)}, {"relative_p99", at(0.99)}, {"relative_max", rel.empty() ? 0.0 : rel.back()}, {"max_over_peak_at_wo", to_peak}};
}

// Per-fiber setup of a prepared runtime: fiber() for fibers of varying σa [ns].
double time_fiber(const Runtime& rt, const hairlut::sampler::Fiber& fiber, int repeats) {
  const std::size_t n = 2000;
  volatile double sink = 0.0;
  return best_ns(n, repeats, [&] {
    double acc = 0.0;
    hairlut::sampler::Fiber f = fiber;
    for (std::size_t i = 0; i < n; ++i) {
      f.sigma_a[0] = fiber.sigma_a[0] * (0.5 + static_cast<double>(i) / static_cast<double>(n));
      acc += rt.fiber(f).e[0];
    }
    sink = acc;
  });
}

// The four costs of pbrt-v4's HairBxDF in Float arithmetic at the points (offset h per point):
// Sample_f, PDF and f at its own drawn directions, and its shading point (the constructor, Sample_f,
// PDF and f of a light direction).
template <class F>
Costs time_pbrt(const std::vector<PbrtHairT<F>>& pbrt, const typename PbrtHairT<F>::Spectrum& sigma, const std::vector<Point>& pts, int hs) {
  using Vec3 = PbrtVec3T<F>;
  const std::size_t n = pts.size();
  auto pwo = [&](const Point& p) { return Vec3{static_cast<F>(p.wo[0]), static_cast<F>(p.wo[1]), static_cast<F>(p.wo[2])}; };
  auto draw = [&](const PbrtHairT<F>& h, const Point& p) { return h.sample_f(pwo(p), static_cast<F>(p.u[0]), static_cast<F>(p.u[1]), static_cast<F>(p.u[2])); };
  std::vector<Vec3> pwi(n);
  for (std::size_t i = 0; i < n; ++i) pwi[i] = draw(pbrt[static_cast<std::size_t>(pts[i].h)], pts[i]).wi;
  volatile double sink = 0.0;
  Costs c;
  c.sample = best_ns(n, 1, [&] {
    F acc = 0;
    for (const Point& p : pts) acc += draw(pbrt[static_cast<std::size_t>(p.h)], p).pdf;
    sink = acc;
  });
  c.pdf = best_ns(n, 1, [&] {
    F acc = 0;
    for (std::size_t i = 0; i < n; ++i) acc += pbrt[static_cast<std::size_t>(pts[i].h)].pdf(pwo(pts[i]), pwi[i]);
    sink = acc;
  });
  c.eval = best_ns(n, 1, [&] {
    F acc = 0;
    for (std::size_t i = 0; i < n; ++i) acc += pbrt[static_cast<std::size_t>(pts[i].h)].f(pwo(pts[i]), pwi[i])[0];
    sink = acc;
  });
  c.point = best_ns(n, 1, [&] {
    F acc = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Point& p = pts[i];
      const PbrtHairT<F> h(-1.0f + (2.0f * static_cast<F>(p.h) + 1.0f) / static_cast<F>(hs), 1.55f, sigma, 0.3f, 0.3f, 2.0f);
      acc += draw(h, p).pdf;
      acc += h.pdf(pwo(p), pwi[(i + 1) % n]) + h.f(pwo(p), pwi[(i + 1) % n])[0];
    }
    sink = acc;
  });
  (void)sink;
  return c;
}

}  // namespace

json bench_runtime(const Settings& st) {
  log(st.quiet, "runtime: HairScattering eval/sample/pdf against pbrt-v4 f/Sample_f/PDF ...\n");
  const hairlut::Rgb sa = hairlut::melanin_sigma_a_rgb(0.8, 0.2);
  hairlut::sampler::Fiber fiber;
  fiber.sigma_a[0] = sa.r, fiber.sigma_a[1] = sa.g, fiber.sigma_a[2] = sa.b;
  fiber.beta_m = beta_m_of(0.3), fiber.beta_n = beta_n_of(0.3);

  const hairlut::TableSet generic = hairlut::load_tables(st.source_dir + "/tables/default/hairlut-default.h5");
  double t0 = thread_cpu_seconds();
  const Runtime rt_generic = hairlut::hair_scattering<float>(generic);
  const double prepare_generic_ms = (thread_cpu_seconds() - t0) * 1e3;
  const hairlut::TableSet fourier = bake_fourier(st);
  t0 = thread_cpu_seconds();
  const Runtime rt_fourier = hairlut::hair_scattering<float>(fourier);
  const double prepare_fourier_ms = (thread_cpu_seconds() - t0) * 1e3;
  const hairlut::TableSet material = bake_material(st, fiber.sigma_a, fiber.beta_m, fiber.beta_n);
  t0 = thread_cpu_seconds();
  const Runtime rt_material = hairlut::hair_scattering<float>(material, "materials/pbrt");
  const double prepare_material_ms = (thread_cpu_seconds() - t0) * 1e3;
  // The generic and Fourier sets prepared for the fiber's roughness (β_m, β_n, no extra tilt).
  t0 = thread_cpu_seconds();
  const Runtime rt_prepared(rt_generic, fiber);
  const double prepare_prepared_ms = (thread_cpu_seconds() - t0) * 1e3;
  t0 = thread_cpu_seconds();
  const Runtime rt_prepared_fourier(rt_fourier, fiber);
  const double prepare_prepared_fourier_ms = (thread_cpu_seconds() - t0) * 1e3;
  const hairlut::sampler::PreparedFiber pf = rt_prepared.fiber(fiber), pf_fourier = rt_prepared_fourier.fiber(fiber);
  const double zero[3] = {0.0, 0.0, 0.0};
  const hairlut::TableSet white_material = bake_material(st, zero, fiber.beta_m, fiber.beta_n);
  const Runtime rt_white = hairlut::hair_scattering<float>(white_material, "materials/pbrt");

  // pbrt's Float is float, or double in a build with PBRT_FLOAT_AS_DOUBLE: the double runtime
  // reads the same material's tables stored as float64.
  const hairlut::TableSet material64 = bake_material(st, fiber.sigma_a, fiber.beta_m, fiber.beta_n, true);
  const hairlut::sampler::HairScattering<double> rt_material64 = hairlut::hair_scattering<double>(material64, "materials/pbrt");
  const PbrtHair::Spectrum sigma = {static_cast<float>(sa.r), static_cast<float>(sa.g), static_cast<float>(sa.b), static_cast<float>((sa.r + sa.g + sa.b) / 3.0)};
  const PbrtHairT<double>::Spectrum sigma64 = {sa.r, sa.g, sa.b, (sa.r + sa.g + sa.b) / 3.0};
  const int hs = 64;
  std::vector<PbrtHair> pbrt;
  std::vector<PbrtHairT<double>> pbrt64;
  for (int i = 0; i < hs; ++i) {
    pbrt.emplace_back(-1.0f + (2.0f * static_cast<float>(i) + 1.0f) / hs, 1.55f, sigma, 0.3f, 0.3f, 2.0f);
    pbrt64.emplace_back(-1.0f + (2.0f * static_cast<double>(i) + 1.0f) / hs, 1.55f, sigma64, 0.3f, 0.3f, 2.0f);
  }

  const std::size_t n = st.quick ? 2000 : 20000;
  const auto pts = points(n, hs);
  // Rounds of every measurement in turn (pbrt, generic, material), the best of each kept: a slow
  // spell of a shared machine then hits all three alike instead of one section.
  const int repeats = st.quick ? 2 : 5;
  auto keep_best = [](Costs& best, const Costs& c) {
    best.sample = std::min(best.sample, c.sample), best.pdf = std::min(best.pdf, c.pdf), best.eval = std::min(best.eval, c.eval),
    best.point = std::min(best.point, c.point);
  };
  const Costs none{1e300, 1e300, 1e300, 1e300};
  Costs peer_best = none, gen = none, four = none, mat = none, peer64 = none, mat64 = none, prep = none, prep_four = none;
  double fiber_ns = 1e300, fiber_fourier_ns = 1e300;
  for (int round = 0; round < repeats; ++round) {
    keep_best(peer_best, time_pbrt(pbrt, sigma, pts, hs));
    keep_best(gen, time_runtime(rt_generic, fiber, pts, 1));
    keep_best(four, time_runtime(rt_fourier, fiber, pts, 1));
    keep_best(mat, time_runtime(rt_material, fiber, pts, 1));
    keep_best(prep, time_runtime(rt_prepared, pf, pts, 1));
    keep_best(prep_four, time_runtime(rt_prepared_fourier, pf_fourier, pts, 1));
    fiber_ns = std::min(fiber_ns, time_fiber(rt_prepared, fiber, 1));
    fiber_fourier_ns = std::min(fiber_fourier_ns, time_fiber(rt_prepared_fourier, fiber, 1));
    keep_best(peer64, time_pbrt(pbrt64, sigma64, pts, hs));
    keep_best(mat64, time_runtime(rt_material64, fiber, pts, 1));
  }
  const Costs& peer = peer_best;


  std::ostringstream wmd;
  wmd << "| tables | samples | weight min | weight max | outside (0.99, 1.01) | outside [0.9, 1.1] | weight / albedo(wo) min | max | outside (0.99, 1.01) |\n"
      << "|---|---|---|---|---|---|---|---|---|\n";
  json weights = json::array();
  for (double bm : {4.0, 10.0, 20.0, 45.0}) {
    hairlut::sampler::Fiber white;
    white.beta_m = bm * kPiD / 180.0, white.beta_n = 12.0 * kPiD / 180.0;
    weights.push_back(white_weights(rt_generic, white, pts, "generic default, beta_m " + fmt(bm) + " deg, beta_n 12 deg", wmd));
    const Runtime prepared(rt_generic, white);
    weights.push_back(white_weights(prepared, prepared.fiber(white), pts, "generic default prepared, beta_m " + fmt(bm) + " deg, beta_n 12 deg", wmd));
  }
  {
    hairlut::sampler::Fiber white;
    white.beta_m = 10.0 * kPiD / 180.0, white.beta_n = 12.0 * kPiD / 180.0;
    weights.push_back(white_weights(rt_fourier, white, pts, "Fourier N_p (1e-3 set), beta_m 10 deg, beta_n 12 deg", wmd));
    const Runtime prepared(rt_fourier, white);
    weights.push_back(white_weights(prepared, prepared.fiber(white), pts, "Fourier N_p (1e-3 set) prepared, beta_m 10 deg, beta_n 12 deg", wmd));
  }
  const json error_generic = prepared_error(rt_generic, rt_prepared, fiber, pts), error_fourier = prepared_error(rt_fourier, rt_prepared_fourier, fiber, pts);
  weights.push_back(white_weights(rt_white, hairlut::sampler::Fiber(), pts,
                                  "material, sigma_a 0, beta_m " + fmt(fiber.beta_m * 180.0 / kPiD) + " deg (TT half, TRT twice), beta_n " +
                                      fmt(fiber.beta_n * 180.0 / kPiD) + " deg",
                                  wmd));

  auto costs_json = [](const Costs& c) { return json{{"sample_ns", c.sample}, {"pdf_ns", c.pdf}, {"eval_ns", c.eval}, {"shading_point_ns", c.point}}; };
  json result = {{"machine", st.machine},
                 {"generic_tables", "tables/default/hairlut-default.h5 (shipped default: float32, cubic, tilts R -4, TT 2, TRT 6, TRRT and residual 10 deg)"},
                 {"fourier_tables", "tables/configs/generic-1e-3.json's Fourier N_p (256 cos theta_d x 64 sqrt sigma_a, 132 terms, float32) with "
                                    "tables/configs/default.json's M_p axes and tilts, baked in memory"},
                 {"material_tables", "tables/configs/show-example.json with N_p over 64 cos theta_d x 129 phi, M_p over 91 theta_i x 181 theta_r (linear, float32) baked for one "
                                     "material: the fiber's sigma_a, beta per lobe R beta_m, TT beta_m / 2, TRT and residual 2 beta_m (pbrt's variances), beta_n; the default tilts"},
                 {"peer", "tools/bench-hair-luts/pbrt_hair.cpp: pbrt-v4 HairBxDF f, Sample_f, PDF re-implemented in float (commits in pbrt_hair.hpp); "
                          "beta_m 0.3, beta_n 0.3, alpha 2 deg, eta 1.55, 4 spectral samples, 64 offsets h"},
                 {"fiber", "sigma_a of eumelanin 0.8 + pheomelanin 0.2 (RGB), beta_m " + fmt(fiber.beta_m * 180.0 / kPiD) + " deg, beta_n " + fmt(fiber.beta_n * 180.0 / kPiD) +
                               " deg (pbrt's 0.3 in hairlut's units)"},
                 {"arithmetic", "hairlut: float tables, double arithmetic (the prepared runtimes blend their shapes and energies in float, sum the lobes in double); pbrt: float. Double: hairlut's material tables "
                                "stored float64 (HairScattering<double>), pbrt in double (a PBRT_FLOAT_AS_DOUBLE build: FastExp stays float)"},
                 {"calls", n},
                 {"timing", "thread CPU time, best of " + std::to_string(repeats) + " rounds that time every call in turn; wo uniform on the sphere, u uniform; pdf and eval at each sampler's own drawn directions"},
                 {"prepare_generic_ms", prepare_generic_ms},
                 {"prepare_fourier_ms", prepare_fourier_ms},
                 {"prepare_material_ms", prepare_material_ms},
                 {"prepare_prepared_ms", prepare_prepared_ms},
                 {"prepare_prepared_fourier_ms", prepare_prepared_fourier_ms},
                 {"prepared_bytes", rt_prepared.preparation().bytes()},
                 {"prepared_fourier_bytes", rt_prepared_fourier.preparation().bytes()},
                 {"prepared_nodes", {{"phi", rt_prepared.preparation().phi_nodes()}, {"theta_i_theta_r", rt_prepared.preparation().theta_nodes()},
                                     {"theta_d", rt_prepared.preparation().theta_d_nodes()}}},
                 {"per_fiber_setup_ns", 0.0},
                 {"prepared_per_fiber_setup_ns", fiber_ns},
                 {"prepared_fourier_per_fiber_setup_ns", fiber_fourier_ns},
                 {"prepared_error", error_generic},
                 {"prepared_fourier_error", error_fourier},
                 {"hairlut_prepared", costs_json(prep)},
                 {"hairlut_prepared_fourier", costs_json(prep_four)},
                 {"pbrt", costs_json(peer)},
                 {"hairlut_generic", costs_json(gen)},
                 {"hairlut_fourier", costs_json(four)},
                 {"hairlut_material", costs_json(mat)},
                 {"pbrt_double", costs_json(peer64)},
                 {"hairlut_material_double", costs_json(mat64)},
                 {"white_fiber_weights", weights}};
  std::ostringstream md, csv;
  md << "Machine: " << st.machine.value("cpu", std::string("?")) << ", load average " << load_average() << "; command: bench-hair-luts --only runtime --out "
     << st.out_dir << (st.quick ? " --quick" : "") << "; " << result["timing"].get<std::string>() << ".\n\n";
  auto row = [&](const char* call, double p, double g, double f, double m, double q, double qf, const char* target) {
    md << "| " << call << " | " << fmt(p) << " | " << fmt(g) << " | " << fmt(g / p) << " | " << fmt(f) << " | " << fmt(f / p) << " | " << fmt(m) << " | " << fmt(m / p)
       << " | " << fmt(q) << " | " << fmt(q / p) << " | " << fmt(qf) << " | " << fmt(qf / p) << " | " << target << " |\n";
    csv << call << ',' << p << ',' << g << ',' << g / p << ',' << f << ',' << f / p << ',' << m << ',' << m / p << ',' << q << ',' << q / p << ',' << qf << ',' << qf / p << '\n';
  };
  md << "| call | pbrt-v4 (float) ns | generic tables ns | generic / pbrt | Fourier N_p ns | Fourier / pbrt | material tables ns | material / pbrt "
        "| generic prepared ns | prepared / pbrt | Fourier prepared ns | prepared / pbrt | target |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  csv << "call,pbrt_ns,generic_ns,generic_ratio,fourier_ns,fourier_ratio,material_ns,material_ratio,prepared_ns,prepared_ratio,prepared_fourier_ns,prepared_fourier_ratio\n";
  row("sample", peer.sample, gen.sample, four.sample, mat.sample, prep.sample, prep_four.sample, "<= 1");
  row("pdf", peer.pdf, gen.pdf, four.pdf, mat.pdf, prep.pdf, prep_four.pdf, "<= 1");
  row("eval", peer.eval, gen.eval, four.eval, mat.eval, prep.eval, prep_four.eval, "<= 0.5");
  row("shading point: BSDF for (fiber, wo), sample, pdf and eval of a light direction", peer.point, gen.point, four.point, mat.point, prep.point, prep_four.point, "");
  md << "| per-fiber setup | none | none | | none | | none | | " << fmt(fiber_ns) << " | | " << fmt(fiber_fourier_ns) << " | | <= 20 us |\n\n"
     << "Runtimes prepared from the loaded tables in " << fmt(prepare_generic_ms) << " ms (generic: M_p copied with theta_i last; N_p sampling data read from the file and checked), "
     << fmt(prepare_fourier_ms) << " ms (Fourier: the same for M_p, the energies on the coefficients' nodes) and "
     << fmt(prepare_material_ms) << " ms (material: tables interleaved per node, the theta_i rows and phi rows of the sampler tabulated).\n"
     << "Prepared runtimes: the generic and Fourier runtimes resampled for the fiber's beta_m and beta_n (every lobe's M_p at beta_m, as the generic tables "
        "read it), sigma_a per fiber, in "
     << fmt(prepare_prepared_ms) << " ms and " << fmt(prepare_prepared_fourier_ms) << " ms, holding " << fmt(static_cast<double>(rt_prepared.preparation().bytes()) / 1e6)
     << " MB and " << fmt(static_cast<double>(rt_prepared_fourier.preparation().bytes()) / 1e6) << " MB (" << rt_prepared.preparation().phi_nodes() << " phi x "
     << rt_prepared.preparation().theta_nodes() << " theta_i = theta_r x " << rt_prepared.preparation().theta_d_nodes()
     << " theta_d nodes; prepared_scattering.hpp); timed with the fiber's state built once (its setup is the per-fiber row).\n"
     << "Their S against the runtimes they were prepared from, per channel at their own drawn directions (8 per wo, " << n << " wo): relative error median / p99 / max "
     << fmt(error_generic["relative_p50"].get<double>(), 3) << " / " << fmt(error_generic["relative_p99"].get<double>(), 3) << " / "
     << fmt(error_generic["relative_max"].get<double>(), 3) << " (generic), " << fmt(error_fourier["relative_p50"].get<double>(), 3) << " / "
     << fmt(error_fourier["relative_p99"].get<double>(), 3) << " / " << fmt(error_fourier["relative_max"].get<double>(), 3)
     << " (Fourier); the largest error over the largest S drawn at the same wo " << fmt(error_generic["max_over_peak_at_wo"].get<double>(), 3) << " and "
     << fmt(error_fourier["max_over_peak_at_wo"].get<double>(), 3) << ".\n"
     << "Fiber: " << result["fiber"].get<std::string>() << "; generic and Fourier tables read at it per call (Fourier: "
     << result["fourier_tables"].get<std::string>() << "), material tables baked for it (" << result["material_tables"].get<std::string>() << ").\n"
     << "hairlut in double arithmetic over float tables (the prepared runtimes blend their shapes and energies in float), pbrt in float.\n\n"
     << "Double precision: pbrt-v4 with Float = double (its PBRT_FLOAT_AS_DOUBLE build; FastExp stays float, as there) against the\n"
     << "same material's tables stored as float64 (HairScattering<double>), in the same rounds:\n\n"
     << "| call | pbrt-v4 (double) ns | material tables (float64) ns | material / pbrt | target |\n|---|---|---|---|---|\n"
     << "| sample | " << fmt(peer64.sample) << " | " << fmt(mat64.sample) << " | " << fmt(mat64.sample / peer64.sample) << " | <= 1 |\n"
     << "| pdf | " << fmt(peer64.pdf) << " | " << fmt(mat64.pdf) << " | " << fmt(mat64.pdf / peer64.pdf) << " | <= 1 |\n"
     << "| eval | " << fmt(peer64.eval) << " | " << fmt(mat64.eval) << " | " << fmt(mat64.eval / peer64.eval) << " | <= 0.5 |\n"
     << "| shading point | " << fmt(peer64.point) << " | " << fmt(mat64.point) << " | " << fmt(mat64.point / peer64.point) << " | |\n\n"
     << "Weights S / pdf of a white fiber (sigma_a = 0), tilted tables, at the same " << n << " points. Their mean at wo is the\n"
     << "albedo there, which the tilted model holds away from 1 near grazing (docs/conventions.md); weight / albedo(wo) is the sampling's own spread:\n\n"
     << wmd.str();
  write_file(st, "runtime.json", result.dump(2) + "\n");
  write_file(st, "runtime.csv", csv.str());
  write_file(st, "runtime.md", md.str());
  return result;
}

}  // namespace bench
