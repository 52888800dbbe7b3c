// Section "runtime": what a path tracer pays per shading point with HairScattering (eval, sample,
// pdf from the shipped default tables) against pbrt-v4's analytic HairBxDF::f, Sample_f and PDF
// (pbrt_hair.cpp) in the same run, on the same directions and random numbers; and the per-sample
// weight S / pdf of a white fibre (σa = 0), the quantity pbrt-v4's SamplingWeights test bounds.
#include <hairlut/io/table_io.hpp>
#include <hairlut/physics/melanin.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <sstream>

#include "bench_common.hpp"
#include "pbrt_hair.hpp"

namespace bench {

namespace {

constexpr double kPiD = 3.14159265358979323846;

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

}  // namespace

json bench_runtime(const Settings& st) {
  log(st.quiet, "runtime: HairScattering eval/sample/pdf against pbrt-v4 f/Sample_f/PDF ...\n");
  const std::string tables = st.source_dir + "/tables/default/hairlut-default.h5";
  const hairlut::TableSet set = hairlut::load_tables(tables);
  double t0 = thread_cpu_seconds();
  const hairlut::sampler::HairScattering<float> rt = hairlut::hair_scattering<float>(set);
  const double prepare_ms = (thread_cpu_seconds() - t0) * 1e3;

  const hairlut::Rgb sa = hairlut::melanin_sigma_a_rgb(0.8, 0.2);
  hairlut::sampler::Fibre fibre;
  fibre.sigma_a[0] = sa.r, fibre.sigma_a[1] = sa.g, fibre.sigma_a[2] = sa.b;
  fibre.beta_m = beta_m_of(0.3), fibre.beta_n = beta_n_of(0.3);
  const PbrtHair::Spectrum sigma = {static_cast<float>(sa.r), static_cast<float>(sa.g), static_cast<float>(sa.b), static_cast<float>((sa.r + sa.g + sa.b) / 3.0)};
  const int hs = 64;
  std::vector<PbrtHair> pbrt;
  for (int i = 0; i < hs; ++i) pbrt.emplace_back(-1.0f + (2.0f * static_cast<float>(i) + 1.0f) / hs, 1.55f, sigma, 0.3f, 0.3f, 2.0f);

  const std::size_t n = st.quick ? 2000 : 20000;
  const auto pts = points(n, hs);
  // The directions each sampler draws, for pdf() and eval() at them.
  std::vector<std::array<double, 3>> wi(n);
  std::vector<PbrtVec3> pwi(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Point& p = pts[i];
    wi[i] = {0.0, 1.0, 0.0};
    const auto s = rt.sample(fibre, p.wo, p.u);
    if (s.pdf > 0.0) wi[i] = {s.wi[0], s.wi[1], s.wi[2]};
    const PbrtVec3 wo{static_cast<float>(p.wo[0]), static_cast<float>(p.wo[1]), static_cast<float>(p.wo[2])};
    pwi[i] = pbrt[static_cast<std::size_t>(p.h)].sample_f(wo, static_cast<float>(p.u[0]), static_cast<float>(p.u[1]), static_cast<float>(p.u[2])).wi;
  }
  const int repeats = st.quick ? 2 : 5;
  volatile double sink = 0.0;
  auto pwo = [&](const Point& p) { return PbrtVec3{static_cast<float>(p.wo[0]), static_cast<float>(p.wo[1]), static_cast<float>(p.wo[2])}; };
  const double pbrt_sample = best_ns(n, repeats, [&] {
    float acc = 0.0f;
    for (const Point& p : pts) acc += pbrt[static_cast<std::size_t>(p.h)].sample_f(pwo(p), static_cast<float>(p.u[0]), static_cast<float>(p.u[1]), static_cast<float>(p.u[2])).pdf;
    sink = acc;
  });
  const double pbrt_pdf = best_ns(n, repeats, [&] {
    float acc = 0.0f;
    for (std::size_t i = 0; i < n; ++i) acc += pbrt[static_cast<std::size_t>(pts[i].h)].pdf(pwo(pts[i]), pwi[i]);
    sink = acc;
  });
  const double pbrt_f = best_ns(n, repeats, [&] {
    float acc = 0.0f;
    for (std::size_t i = 0; i < n; ++i) acc += pbrt[static_cast<std::size_t>(pts[i].h)].f(pwo(pts[i]), pwi[i])[0];
    sink = acc;
  });
  const double rt_sample = best_ns(n, repeats, [&] {
    double acc = 0.0;
    for (const Point& p : pts) acc += rt.sample(fibre, p.wo, p.u).pdf;
    sink = acc;
  });
  const double rt_pdf = best_ns(n, repeats, [&] {
    double acc = 0.0;
    for (std::size_t i = 0; i < n; ++i) acc += rt.pdf(fibre, pts[i].wo, wi[i].data());
    sink = acc;
  });
  const double rt_eval = best_ns(n, repeats, [&] {
    double acc = 0.0, rgb[3];
    for (std::size_t i = 0; i < n; ++i) {
      rt.eval(fibre, pts[i].wo, wi[i].data(), rgb);
      acc += rgb[0];
    }
    sink = acc;
  });
  // One shading point as a path tracer visits it: the BSDF built for (fibre, wo), one sample drawn,
  // and one light direction weighed by pdf() and eval() (MIS), against pbrt's constructor,
  // Sample_f, PDF and f on the same points.
  const double pbrt_point = best_ns(n, repeats, [&] {
    float acc = 0.0f;
    for (std::size_t i = 0; i < n; ++i) {
      const Point& p = pts[i];
      const PbrtHair h(-1.0f + (2.0f * static_cast<float>(p.h) + 1.0f) / hs, 1.55f, sigma, 0.3f, 0.3f, 2.0f);
      acc += h.sample_f(pwo(p), static_cast<float>(p.u[0]), static_cast<float>(p.u[1]), static_cast<float>(p.u[2])).pdf;
      acc += h.pdf(pwo(p), pwi[(i + 1) % n]) + h.f(pwo(p), pwi[(i + 1) % n])[0];
    }
    sink = acc;
  });
  const double rt_point = best_ns(n, repeats, [&] {
    double acc = 0.0, rgb[3];
    for (std::size_t i = 0; i < n; ++i) {
      const auto sp = rt.at(fibre, pts[i].wo);
      acc += sp.sample(pts[i].u).pdf + sp.pdf(wi[(i + 1) % n].data());
      sp.eval(wi[(i + 1) % n].data(), rgb);
      acc += rgb[0];
    }
    sink = acc;
  });
  (void)sink;

  // Weights of a white fibre at the same points, over several roughnesses.
  json weights = json::array();
  std::ostringstream wmd;
  wmd << "| beta_m (deg) | beta_n (deg) | samples | weight min | weight max | outside (0.99, 1.01) | outside [0.9, 1.1] | weight / albedo(wo) min | max | outside (0.99, 1.01) |\n"
      << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (double bm : {4.0, 10.0, 20.0, 45.0}) {
    hairlut::sampler::Fibre white;
    white.beta_m = bm * kPiD / 180.0, white.beta_n = 12.0 * kPiD / 180.0;
    double lo = 1e300, hi = 0.0, rlo = 1e300, rhi = 0.0;
    std::size_t out1 = 0, out10 = 0, rout1 = 0, count = 0;
    for (const Point& p : pts) {
      const auto s = rt.sample(white, p.wo, p.u);
      const double w = s.pdf > 0.0 ? (s.weight[0] + s.weight[1] + s.weight[2]) / 3.0 : 0.0, r = w / rt.albedo(white, p.wo);
      ++count;
      lo = std::min(lo, w), hi = std::max(hi, w), rlo = std::min(rlo, r), rhi = std::max(rhi, r);
      out1 += !(w > 0.99 && w < 1.01), out10 += !(w >= 0.9 && w <= 1.1), rout1 += !(r > 0.99 && r < 1.01);
    }
    weights.push_back({{"beta_m_deg", bm}, {"beta_n_deg", 12.0}, {"samples", count}, {"weight_min", lo}, {"weight_max", hi},
                       {"fraction_outside_1_percent", static_cast<double>(out1) / static_cast<double>(count)},
                       {"fraction_outside_10_percent", static_cast<double>(out10) / static_cast<double>(count)},
                       {"weight_over_albedo_min", rlo}, {"weight_over_albedo_max", rhi},
                       {"weight_over_albedo_fraction_outside_1_percent", static_cast<double>(rout1) / static_cast<double>(count)}});
    wmd << "| " << bm << " | 12 | " << count << " | " << fmt(lo, 4) << " | " << fmt(hi, 4) << " | " << fmt(100.0 * static_cast<double>(out1) / static_cast<double>(count), 3) << "% | "
        << fmt(100.0 * static_cast<double>(out10) / static_cast<double>(count), 3) << "% | " << fmt(rlo, 5) << " | " << fmt(rhi, 5) << " | "
        << fmt(100.0 * static_cast<double>(rout1) / static_cast<double>(count), 3) << "% |\n";
  }

  json result = {{"machine", st.machine},
                 {"tables", "tables/default/hairlut-default.h5 (shipped default: float32, cubic, tilts R -4, TT 2, TRT 6, TRRT and residual 10 deg)"},
                 {"peer", "tools/bench-hair-luts/pbrt_hair.cpp: pbrt-v4 HairBxDF f, Sample_f, PDF re-implemented in float (commits in pbrt_hair.hpp); "
                          "beta_m 0.3, beta_n 0.3, alpha 2 deg, eta 1.55, 4 spectral samples, 64 offsets h"},
                 {"fibre", "sigma_a of eumelanin 0.8 + pheomelanin 0.2 (RGB), beta_m " + fmt(fibre.beta_m * 180.0 / kPiD) + " deg, beta_n " + fmt(fibre.beta_n * 180.0 / kPiD) +
                               " deg (pbrt's 0.3 in hairlut's units)"},
                 {"arithmetic", "hairlut: float tables, double arithmetic (the runtime has no float path); pbrt: float"},
                 {"calls", n},
                 {"timing", "thread CPU time, best of " + std::to_string(repeats) + " runs; wo uniform on the sphere, u uniform; pdf and eval at each sampler's own drawn directions"},
                 {"prepare_ms", prepare_ms},
                 {"per_fibre_setup_ns", 0.0},
                 {"pbrt_sample_f_ns", pbrt_sample},
                 {"pbrt_pdf_ns", pbrt_pdf},
                 {"pbrt_f_ns", pbrt_f},
                 {"hairlut_sample_ns", rt_sample},
                 {"hairlut_pdf_ns", rt_pdf},
                 {"hairlut_eval_ns", rt_eval},
                 {"pbrt_shading_point_ns", pbrt_point},
                 {"hairlut_shading_point_ns", rt_point},
                 {"white_fibre_weights", weights}};
  std::ostringstream md, csv;
  md << "Machine: " << st.machine.value("cpu", std::string("?")) << ", load average " << load_average() << "; command: bench-hair-luts --only runtime --out "
     << st.out_dir << (st.quick ? " --quick" : "") << "; " << result["timing"].get<std::string>() << ".\n\n";
  md << "| call | pbrt-v4 (float) ns | hairlut HairScattering ns | hairlut / pbrt | target |\n|---|---|---|---|---|\n"
     << "| sample | " << fmt(pbrt_sample) << " | " << fmt(rt_sample) << " | " << fmt(rt_sample / pbrt_sample) << " | <= 1 |\n"
     << "| pdf | " << fmt(pbrt_pdf) << " | " << fmt(rt_pdf) << " | " << fmt(rt_pdf / pbrt_pdf) << " | <= 1 |\n"
     << "| eval | " << fmt(pbrt_f) << " | " << fmt(rt_eval) << " | " << fmt(rt_eval / pbrt_f) << " | <= 0.5 |\n"
     << "| per-fibre setup | none | none | | <= 20 us |\n"
     << "| shading point: BSDF for (fibre, wo), sample, pdf and eval of a light direction | " << fmt(pbrt_point) << " | " << fmt(rt_point) << " | "
     << fmt(rt_point / pbrt_point) << " | |\n\n"
     << "Runtime prepared from the file in " << fmt(prepare_ms) << " ms (M_p copied with theta_i last, its sampling data computed).\n"
     << "Fibre: " << result["fibre"].get<std::string>() << "; hairlut in double arithmetic over float tables, pbrt in float.\n\n"
     << "Weights S / pdf of a white fibre (sigma_a = 0) on the shipped (tilted) tables, at the same " << n << " points. Their mean at wo is the\n"
     << "albedo there, which the tilted model holds away from 1 near grazing (docs/conventions.md); weight / albedo(wo) is the sampling's own spread:\n\n"
     << wmd.str();
  csv << "call,pbrt_ns,hairlut_ns,ratio\nshading_point," << pbrt_point << ',' << rt_point << ',' << rt_point / pbrt_point << "\nsample," << pbrt_sample << ',' << rt_sample << ',' << rt_sample / pbrt_sample << "\npdf," << pbrt_pdf << ',' << rt_pdf << ','
      << rt_pdf / pbrt_pdf << "\neval," << pbrt_f << ',' << rt_eval << ',' << rt_eval / pbrt_f << "\n";
  write_file(st, "runtime.json", result.dump(2) + "\n");
  write_file(st, "runtime.csv", csv.str());
  write_file(st, "runtime.md", md.str());
  return result;
}

}  // namespace bench
