// Section "lookup": what a renderer pays per table lookup and per full RGB S(θi, θr, φ).
//
// - ns per lookup of the fixed-dimension views (sampler_fixed.hpp) against the generic TableView
//   (sampler.hpp), 3D (M_p's axes: β log, θi, θr) and 4D (N_p's axes: β log, σa sqrt, θd even,
//   φ even), all-linear, cubic along the last (contiguous) axis only, and all-cubic; stored float,
//   computed in double and in float. "in cache": a small table and 256 points visited over and
//   over; "out of cache": a table of the default's size and one of 8.4 M (4D) / 4.2 M (3D)
//   entries, with 2^20 random points (uniform on each axis, log-uniform in β).
// - the typed N_p view of the shipped default tables (4D shape × 2D energy) at random points.
// - S per RGB from the default tables through the renderer runtime's eval
//   (sampler::HairScattering: R, TT, TRT, TRRT and the residual) against pbrt-v4's analytic
//   HairBxDF::f (pbrt_hair.cpp, a re-implementation), on the same directions (uniform on the
//   sphere), in the same run, one thread; the runtime is timed from the direction vectors (its
//   std::asin and std::atan2, as pbrt's f computes its angles) and from angles.
// Times are thread CPU time, the best of several repeats (the machine may be shared).
#include <cmath>
#include <cstdint>
#include <fstream>
#include <hairlut/util/angles.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <hairlut/physics/melanin.hpp>
#include <hairlut/sampler/sampler_fixed.hpp>
#include <hairlut/io/table_io.hpp>
#include <random>
#include <sstream>

#include "bench_common.hpp"
#include "pbrt_hair.hpp"

namespace bench {

namespace {

using namespace hairlut;
using sampler::Axis;

enum class Interp { linear, cubic_last, cubic };
const char* name(Interp i) { return i == Interp::linear ? "linear" : i == Interp::cubic_last ? "cubic-last-axis" : "cubic"; }

std::vector<Axis> np_axes(const std::vector<int>& counts, Interp interp) {
  std::vector<Axis> a(4);
  a[0].spacing = sampler::Spacing::log, a[0].lo = radians(4.0), a[0].hi = radians(45.0);
  a[1].spacing = sampler::Spacing::sqrt, a[1].lo = 0.0, a[1].hi = 16.0;
  a[2].wrap = sampler::Wrap::even, a[2].lo = 0.0, a[2].hi = radians(89.0);
  a[3].wrap = sampler::Wrap::even, a[3].lo = 0.0, a[3].hi = kPi;
  for (std::size_t d = 0; d < 4; ++d) a[d].count = counts[d];
  for (std::size_t d = 0; d < 4; ++d)
    a[d].interpolation = interp == Interp::cubic || (interp == Interp::cubic_last && d == 3) ? sampler::Interpolation::cubic : sampler::Interpolation::linear;
  return a;
}

std::vector<Axis> mp_axes(const std::vector<int>& counts, Interp interp) {
  std::vector<Axis> a(3);
  a[0].spacing = sampler::Spacing::log, a[0].lo = radians(4.0), a[0].hi = radians(45.0);
  a[1].lo = -kHalfPi, a[1].hi = kHalfPi;
  a[2].lo = -kHalfPi, a[2].hi = kHalfPi;
  for (std::size_t d = 0; d < 3; ++d) a[d].count = counts[d];
  for (std::size_t d = 0; d < 3; ++d)
    a[d].interpolation = interp == Interp::cubic || (interp == Interp::cubic_last && d == 2) ? sampler::Interpolation::cubic : sampler::Interpolation::linear;
  return a;
}

// Random points over the axes' ranges (log-uniform on log axes), `distinct` of them repeated to n.
template <class X>
std::vector<X> points(const std::vector<Axis>& axes, std::size_t n, std::size_t distinct, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::size_t D = axes.size();
  std::vector<X> p(n * D);
  for (std::size_t i = 0; i < distinct; ++i)
    for (std::size_t d = 0; d < D; ++d) {
      const Axis& a = axes[d];
      const double x = a.spacing == sampler::Spacing::log ? a.lo * std::pow(a.hi / a.lo, u(rng)) : a.lo + u(rng) * (a.hi - a.lo);
      p[i * D + d] = static_cast<X>(x);
    }
  for (std::size_t i = distinct; i < n; ++i)
    for (std::size_t d = 0; d < D; ++d) p[i * D + d] = p[(i % distinct) * D + d];
  return p;
}

template <int D>
json time_table(const std::string& kind, const std::string& size, const std::vector<Axis>& axes, Interp interp, bool in_cache, bool quick) {
  std::size_t entries = 1;
  for (const Axis& a : axes) entries *= static_cast<std::size_t>(a.count);
  std::vector<float> v(entries);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (float& x : v) x = u(rng);
  const std::size_t n = quick ? (1u << 17) : (1u << 20);
  // In cache, the 256 points are visited over and over from a 256-point array (the coordinates
  // stay in L1 like the table); out of cache, 2^20 distinct points stream past.
  const std::size_t distinct = in_cache ? 256 : n, mask = distinct - 1;
  const auto pd = points<double>(axes, distinct, distinct, 9);
  const auto pf = points<float>(axes, distinct, distinct, 9);
  const sampler::FixedView<float, D> fd(v.data(), axes.data());
  const sampler::FixedView<float, D, float> ff(v.data(), axes.data());
  const sampler::TableView<float> generic(v.data(), axes.data(), D);
  // The three views take turns, each repeat timing each once, and each keeps its fastest: a spell
  // of load on this shared host then falls on all three alike instead of on one view's repeats.
  const int reps = quick ? 2 : 9;
  volatile double sink = 0.0;
  const std::size_t ng = n / 4;
  double t_double = 1e300, t_float = 1e300, t_generic = 1e300;
  for (int r = 0; r < reps; ++r) {
    t_double = std::min(t_double, best_ns(n, 1, [&] {
                          double acc = 0.0;
                          for (std::size_t i = 0; i < n; ++i) acc += fd(&pd[(i & mask) * D]);
                          sink = acc;
                        }));
    t_float = std::min(t_float, best_ns(n, 1, [&] {
                         float acc = 0.0f;
                         for (std::size_t i = 0; i < n; ++i) acc += ff(&pf[(i & mask) * D]);
                         sink = acc;
                       }));
    t_generic = std::min(t_generic, best_ns(ng, 1, [&] {
                           double acc = 0.0;
                           for (std::size_t i = 0; i < ng; ++i) acc += generic(&pd[(i & mask) * D]);
                           sink = acc;
                         }));
  }
  (void)sink;
  std::string counts;
  for (const Axis& a : axes) counts += (counts.empty() ? "" : "x") + std::to_string(a.count);
  return {{"table", kind},
          {"size", size},
          {"counts", counts},
          {"entries", entries},
          {"bytes", entries * sizeof(float)},
          {"interpolation", name(interp)},
          {"cache", in_cache ? "in cache (256 points repeated)" : "out of cache (2^20 random points)"},
          {"ns_double", t_double},
          {"ns_float", t_float},
          {"ns_generic_tableview", t_generic}};
}

// Directions uniform on the sphere (pbrt's hair frame: x along the fiber).
std::vector<PbrtVec3> directions(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<PbrtVec3> d(n);
  for (auto& w : d) {
    const double z = 2.0 * u(rng) - 1.0, a = kTwoPi * u(rng), r = std::sqrt(1.0 - z * z);
    w = {static_cast<float>(z), static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a))};
  }
  return d;
}

}  // namespace

json bench_lookup(const Settings& st) {
  log(st.quiet, "lookup: fixed views, typed N_p, S from tables against pbrt-v4 HairBxDF::f ...\n");
  const std::string load_before = load_average();
  json rows = json::array();
  for (Interp interp : {Interp::linear, Interp::cubic_last, Interp::cubic}) {
    rows.push_back(time_table<4>("4D N_p axes", "small", np_axes({6, 6, 8, 16}, interp), interp, true, st.quick));
    rows.push_back(time_table<4>("4D N_p axes", "default", np_axes({10, 9, 48, 72}, interp), interp, false, st.quick));
    if (!st.quick) rows.push_back(time_table<4>("4D N_p axes", "large", np_axes({32, 32, 64, 128}, interp), interp, false, st.quick));
    rows.push_back(time_table<3>("3D M_p axes", "small", mp_axes({6, 16, 16}, interp), interp, true, st.quick));
    rows.push_back(time_table<3>("3D M_p axes", "default", mp_axes({12, 109, 161}, interp), interp, false, st.quick));
    if (!st.quick) rows.push_back(time_table<3>("3D M_p axes", "large", mp_axes({64, 256, 256}, interp), interp, false, st.quick));
  }
  auto find = [&](const std::string& kind, const std::string& size, const std::string& interp) -> const json& {
    for (const json& r : rows)
      if (r["table"] == kind && r["size"] == size && r["interpolation"] == interp) return r;
    return rows[0];
  };
  json ratios = json::object();
  for (const std::string size : {"small", "default"})
    for (const std::string interp : {"cubic-last-axis", "cubic"})
      ratios["4D " + size + " " + interp + " / linear (double)"] =
          find("4D N_p axes", size, interp)["ns_double"].get<double>() / find("4D N_p axes", size, "linear")["ns_double"].get<double>();

  // The shipped default tables: the typed N_p view and S of a fiber against pbrt-v4.
  const std::string file = st.source_dir + "/tables/default/hairlut-default.h5";
  const TableSet set = load_tables(file);
  const auto hd = hair_tables<float, double>(set);
  const auto hf = hair_tables<float, float>(set);  // the typed views in float arithmetic
  const std::size_t n = st.quick ? 20000 : 200000;
  const int reps = st.quick ? 3 : 7;
  volatile double sink = 0.0;
  std::vector<Axis> na;
  for (int d = 0; d < 4; ++d) na.push_back(hd.np[2].table().axis(d).axis());
  const auto pd = points<double>(na, n, n, 21);
  const auto pf = points<float>(na, n, n, 21);
  json typed = {{"table", "np/TRT of " + std::string("tables/default/hairlut-default.h5") + " (shape x energy factor)"}};
  typed["ns_double"] = best_ns(n, reps, [&] {
    double acc = 0.0;
    for (std::size_t i = 0; i < n; ++i) acc += hd.np[2](pd[4 * i], pd[4 * i + 1], pd[4 * i + 2], pd[4 * i + 3]);
    sink = acc;
  });
  typed["ns_float"] = best_ns(n, reps, [&] {
    float acc = 0.0f;
    for (std::size_t i = 0; i < n; ++i) acc += hf.np[2](pf[4 * i], pf[4 * i + 1], pf[4 * i + 2], pf[4 * i + 3]);
    sink = acc;
  });

  // S per RGB: the pbrt section's fiber (eumelanin 0.8, pheomelanin 0.2), β_m = β_n = 0.3 in
  // pbrt's units; the tables' fiber takes β 10° (M_p) and 12° (N_p), within the tables' range. The
  // runtime is built once per table set (no per-fiber setup).
  const sampler::Fiber fiber = fiber_from_melanin(0.8, 0.2, radians(10.0), radians(12.0));
  double t_build = 0.0;
  {
    const double t0 = thread_cpu_seconds();
    const sampler::HairScattering<float> b = hair_scattering<float>(set);
    t_build = (thread_cpu_seconds() - t0) * 1e3;
    sink = static_cast<double>(b.lobes());
  }
  const sampler::HairScattering<float> rt = hair_scattering<float>(set);
  const auto wo = directions(n, 31), wi = directions(n, 32);
  // wo held (θo), wi the other direction (θi), φ = φo − φi, as the runtime's eval takes them.
  std::vector<double> vo(3 * n), vi(3 * n), angles(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    vo[3 * i] = wo[i].x, vo[3 * i + 1] = wo[i].y, vo[3 * i + 2] = wo[i].z;
    vi[3 * i] = wi[i].x, vi[3 * i + 1] = wi[i].y, vi[3 * i + 2] = wi[i].z;
    angles[3 * i] = std::asin(static_cast<double>(wo[i].x)), angles[3 * i + 1] = std::asin(static_cast<double>(wi[i].x));
    angles[3 * i + 2] = std::atan2(static_cast<double>(wo[i].z), static_cast<double>(wo[i].y)) - std::atan2(static_cast<double>(wi[i].z), static_cast<double>(wi[i].y));
  }
  const Rgb sa = melanin_sigma_a_rgb(0.8, 0.2);
  const PbrtHair::Spectrum sigma = {static_cast<float>(sa.r), static_cast<float>(sa.g), static_cast<float>(sa.b), static_cast<float>((sa.r + sa.g + sa.b) / 3.0)};
  const PbrtHair pbrt(0.3f, 1.55f, sigma, 0.3f, 0.3f, 2.0f);
  double t_pbrt = 1e300, t_vectors = 1e300, t_angles = 1e300;
  for (int r = 0; r < reps; ++r) {  // alternating, so that both see the same machine
    t_pbrt = std::min(t_pbrt, best_ns(n, 1, [&] {
                        float acc = 0.0f;
                        for (std::size_t i = 0; i < n; ++i) acc += pbrt.f(wo[i], wi[i])[1];
                        sink = acc;
                      }));
    t_vectors = std::min(t_vectors, best_ns(n, 1, [&] {
                           double acc = 0.0, rgb[3];
                           for (std::size_t i = 0; i < n; ++i) {
                             rt.eval(fiber, &vo[3 * i], &vi[3 * i], rgb);  // the angles, then the lookups
                             acc += rgb[1];
                           }
                           sink = acc;
                         }));
    t_angles = std::min(t_angles, best_ns(n, 1, [&] {
                          double acc = 0.0, rgb[3];
                          for (std::size_t i = 0; i < n; ++i) {
                            rt.eval(fiber, angles[3 * i], angles[3 * i + 1], angles[3 * i + 2], rgb);
                            acc += rgb[1];
                          }
                          sink = acc;
                        }));
  }
  (void)sink;
  json s = {{"tables", "tables/default/hairlut-default.h5: R, TT, TRT, TRRT and the residual (N_p shape x energy, M_p), RGB"},
            {"fiber", "eumelanin 0.8, pheomelanin 0.2 (d'Eon RGB sigma_a), beta_m 10 deg, beta_n 12 deg"},
            {"pbrt", "pbrt_hair.cpp: pbrt-v4 HairBxDF::f re-implemented (mmp/pbrt-v4 5f7a606), beta_m = beta_n = 0.3, h = 0.3, 4 spectral samples"},
            {"runtime", "HairScattering<float>::eval (float32 tables, double arithmetic), built once per table set"},
            {"directions", std::to_string(n) + " pairs uniform on the sphere, the same for both"},
            {"build_ms", t_build},
            {"pbrt_f_ns", t_pbrt},
            {"tables_S_ns_from_vectors", t_vectors},
            {"tables_S_ns_from_angles", t_angles},
            {"speedup_from_vectors", t_pbrt / t_vectors}};
  const std::string load_after = load_average();
  json result = {{"machine", st.machine},
                 {"load_average_before", load_before},
                 {"load_average_after", load_after},
                 {"code", "lib/include/hairlut/sampler/sampler_fixed.hpp (FixedView), sampler.hpp (TableView), sampler_fiber.hpp (NpLobe), "
                          "hair_scattering.hpp (HairScattering), tools/bench-hair-luts/lookup.cpp"},
                 {"timing", "thread CPU time, best of repeats, one thread; values stored as float32"},
                 {"lookups", rows},
                 {"cubic_over_linear", ratios},
                 {"typed_np", typed},
                 {"S", s}};
  std::ostringstream md, csv;
  if (!load_before.empty()) md << "Load average (1, 5, 15 min) before: " << load_before << "; after: " << load_after << ".\n\n";
  md << "| axes | table | interpolation | points | double | float | generic TableView |\n|---|---|---|---|---|---|---|\n";
  csv << "table,size,counts,entries,interpolation,cache,ns_double,ns_float,ns_generic_tableview\n";
  for (const json& r : rows) {
    md << "| " << r["table"].get<std::string>() << " | " << r["size"].get<std::string>() << " " << r["counts"].get<std::string>() << " | "
       << r["interpolation"].get<std::string>() << " | " << r["cache"].get<std::string>() << " | " << fmt(r["ns_double"].get<double>())
       << " ns | " << fmt(r["ns_float"].get<double>()) << " ns | " << fmt(r["ns_generic_tableview"].get<double>()) << " ns |\n";
    csv << r["table"].get<std::string>() << ',' << r["size"].get<std::string>() << ',' << r["counts"].get<std::string>() << ',' << r["entries"]
        << ',' << r["interpolation"].get<std::string>() << ",\"" << r["cache"].get<std::string>() << "\"," << r["ns_double"] << ','
        << r["ns_float"] << ',' << r["ns_generic_tableview"] << "\n";
  }
  md << "\nCubic over linear, 4D: ";
  for (const auto& [k, v] : ratios.items()) md << k << " " << fmt(v.get<double>()) << "; ";
  md << "\n\nTyped N_p view (" << typed["table"].get<std::string>() << "), random points: " << fmt(typed["ns_double"].get<double>())
     << " ns (double), " << fmt(typed["ns_float"].get<double>()) << " ns (float).\n\n";
  md << "| full RGB S, same directions | ns per call |\n|---|---|\n"
     << "| pbrt-v4 HairBxDF::f (re-implementation, 4 spectral samples) | " << fmt(t_pbrt) << " |\n"
     << "| HairScattering<float>::eval(f, wo, wi), from direction vectors | " << fmt(t_vectors) << " (" << fmt(t_pbrt / t_vectors) << "x faster) |\n"
     << "| HairScattering<float>::eval(f, θo, θi, φ), from angles | " << fmt(t_angles) << " |\n"
     << "\nThe runtime reads the float32 tables in double arithmetic through the typed views, with no per-fiber setup; building it\n"
     << "over the loaded table set (once per set) took " << fmt(t_build) << " ms.\n";
  write_file(st, "lookup.json", result.dump(2) + "\n");
  write_file(st, "lookup.csv", csv.str());
  write_file(st, "lookup.md", md.str());
  return result;
}

}  // namespace bench
