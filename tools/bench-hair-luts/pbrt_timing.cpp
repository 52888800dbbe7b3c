// Section "pbrt-v4 HairBxDF::f": cost per call of the analytic hair BSDF evaluation renderers pay
// per shading sample (pbrt_hair.cpp, a re-implementation of pbrt-v4's), on fixed pseudo-random
// directions; the table lookups of the sampler can be timed against it on the same directions.
#include <cmath>
#include <cstdint>
#include <hairlut/physics/melanin.hpp>
#include <sstream>

#include "bench_common.hpp"
#include "pbrt_hair.hpp"

namespace bench {

namespace {

// Directions and offsets of the pbrt section: unit vectors uniform on the sphere, h uniform.
struct Sample {
  PbrtVec3 wo, wi;
  int h;
};

std::vector<Sample> pbrt_samples(std::size_t n, int hs) {
  SplitMix uniform{12345};
  auto dir = [&]() {
    const double z = 2.0 * uniform() - 1.0, a = 2.0 * 3.141592653589793 * uniform(), r = std::sqrt(1.0 - z * z);
    return PbrtVec3{static_cast<float>(z), static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a))};
  };
  std::vector<Sample> s(n);
  for (auto& x : s) x = {dir(), dir(), static_cast<int>(uniform() * hs)};
  return s;
}

}  // namespace

json bench_pbrt(const Settings& st) {
  log(st.quiet, "pbrt-v4 HairBxDF::f ...\n");
  const hairlut::Rgb sa = hairlut::melanin_sigma_a_rgb(0.8, 0.2);
  const PbrtHair::Spectrum sigma = {static_cast<float>(sa.r), static_cast<float>(sa.g), static_cast<float>(sa.b),
                                    static_cast<float>((sa.r + sa.g + sa.b) / 3.0)};
  const int hs = 64;
  std::vector<PbrtHair> bxdfs;
  for (int i = 0; i < hs; ++i) bxdfs.emplace_back(-1.0f + (2.0f * static_cast<float>(i) + 1.0f) / hs, 1.55f, sigma, 0.3f, 0.3f, 2.0f);
  const std::size_t n = st.quick ? 20000 : 200000;
  const auto samples = pbrt_samples(n, hs);
  std::vector<double> t_f, t_cf;
  volatile float sink = 0.0f;
  for (int r = 0; r < (st.quick ? 3 : 7); ++r) {
    // Thread CPU time: on a shared machine, wall time also counts the waits for a core.
    double t0 = thread_cpu_seconds();
    float acc = 0.0f;
    for (const Sample& s : samples) acc += bxdfs[static_cast<std::size_t>(s.h)].f(s.wo, s.wi)[0];
    t_f.push_back((thread_cpu_seconds() - t0) / static_cast<double>(n) * 1e9);
    t0 = thread_cpu_seconds();
    for (const Sample& s : samples) {
      const PbrtHair h(-1.0f + (2.0f * static_cast<float>(s.h) + 1.0f) / hs, 1.55f, sigma, 0.3f, 0.3f, 2.0f);
      acc += h.f(s.wo, s.wi)[1];
    }
    t_cf.push_back((thread_cpu_seconds() - t0) / static_cast<double>(n) * 1e9);
    sink = acc;
  }
  (void)sink;
  json result = {{"machine", st.machine},
                 {"code", "tools/bench-hair-luts/pbrt_hair.cpp: pbrt-v4 HairBxDF::f re-implemented (mmp/pbrt-v4 5f7a606, src/pbrt/bxdfs.cpp)"},
                 {"setup", "beta_m 0.3, beta_n 0.3, alpha 2 deg, eta 1.55, 4 spectral samples (sigma_a RGB of eumelanin 0.8 + pheomelanin 0.2 and their mean), "
                           "64 offsets h, directions uniform on the sphere, one thread, thread CPU time"},
                 {"calls", n},
                 {"f_ns_per_call_min", minimum(t_f)},
                 {"f_ns_per_call_median", median(t_f)},
                 {"constructor_and_f_ns_per_call_min", minimum(t_cf)},
                 {"constructor_and_f_ns_per_call_median", median(t_cf)}};
  std::ostringstream md, csv;
  md << "| evaluation | ns per call (min) | ns per call (median) |\n|---|---|---|\n"
     << "| pbrt-v4 HairBxDF::f (re-implementation, object reused) | " << fmt(minimum(t_f)) << " | " << fmt(median(t_f)) << " |\n"
     << "| pbrt-v4 HairBxDF constructor + f | " << fmt(minimum(t_cf)) << " | " << fmt(median(t_cf)) << " |\n";
  csv << "evaluation,ns_per_call_min,ns_per_call_median\nf," << minimum(t_f) << ',' << median(t_f) << "\nconstructor_and_f," << minimum(t_cf) << ','
      << median(t_cf) << "\n";
  write_file(st, "pbrt-hair.json", result.dump(2) + "\n");
  write_file(st, "pbrt-hair.csv", csv.str());
  write_file(st, "pbrt-hair.md", md.str());
  return result;
}

}  // namespace bench
