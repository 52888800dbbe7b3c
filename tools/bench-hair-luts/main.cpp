// bench-hair-luts: run time against error of the ways hairlut can integrate N_p, the generic and
// per-material bakes against their targets and against Tungsten's precompute (baseline_tungsten.cpp),
// pbrt-v4's analytic evaluation (pbrt_hair.cpp), interpolation error against table resolution,
// thread scaling and peak memory. Writes bench.json, bench.csv, bench.md, pareto.svg and one set of
// files per section (per-material, end-to-end, scaling, pbrt-hair, presets).
#include <unistd.h>

#include "common/cli.hpp"
#include "common/paths.hpp"
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <hairlut/physics/azimuthal_fourier.hpp>
#include <hairlut/bake/bake.hpp>
#include <hairlut/report/benchmark.hpp>
#include <hairlut/hairlut.hpp>
#include <hairlut/bake/resolution.hpp>
#include <hairlut/report/svg_plot.hpp>

#include "representations.hpp"
#include <hairlut/util/version.hpp>
#include <map>
#include <omp.h>
#include <sstream>

#include "bench_common.hpp"

#include "../common/cancel.hpp"

namespace bench {
json bench_lookup(const Settings& s);  // lookup.cpp
}

namespace {

using namespace hairlut;
using namespace bench;

// ---- Methods on the stress set -------------------------------------------------------------

struct Method {
  std::string name, setting;
  NpQuadratureConfig q;
};

// A smoke run (quick) leaves out the two largest fixed orders, which alone take most of its time.
std::vector<Method> methods(bool quick) {
  std::vector<Method> m;
  for (int order : {8, 16, 35, 64, 128, 256, 512, 1024, 2048, 4096}) {
    if (quick && order > 1024) continue;
    NpQuadratureConfig q;
    q.method = NpQuadratureConfig::Method::gauss_legendre;
    q.order = order;
    m.push_back({"gauss-legendre (gamma)", "order " + std::to_string(order), q});
  }
  for (int order : {35, 140}) {
    NpQuadratureConfig q;
    q.method = NpQuadratureConfig::Method::gauss_legendre;
    q.order = order;
    q.variable = IntegrationVariable::h;
    m.push_back({"gauss-legendre (h, d'Eon)", "order " + std::to_string(order), q});
  }
  for (double tol : {1e-6, 1e-9, 1e-12}) {
    NpQuadratureConfig q;
    q.method = NpQuadratureConfig::Method::fourier;
    q.tolerance = tol;
    char buf[32];
    std::snprintf(buf, sizeof buf, "tolerance %.0e", tol);
    m.push_back({"fourier", buf, q});
  }
  NpQuadratureConfig q;
  q.method = NpQuadratureConfig::Method::adaptive;
  q.tolerance = 1e-10;
  m.push_back({"adaptive reference", "tolerance 1e-10", q});
  return m;
}

// Evaluates one stress slice over the φ grid with a method.
std::vector<double> evaluate_slice(const StressSlice& s, const std::vector<double>& phis, const NpQuadratureConfig& q) {
  NpGridRequest r;
  r.eta = s.eta;
  r.quadrature = q;
  r.lobes = s.p + 1;
  r.sigmas = {s.sigma_a};
  r.thetas = {s.theta_d};
  r.phis = phis;
  r.betas_of = [&](int) { return std::vector<double>{s.beta}; };
  std::vector<double> out(phis.size());
  BakeOptions o;
  o.threads = 1;
  // Only the slice's own lobe is wanted; lower lobes are cheap by comparison.
  bake_np_grid(r, o, "", [&](int p, std::size_t, std::size_t, std::size_t, std::size_t j, double v) {
    if (p == s.p) out[j] = v;
  });
  return out;
}

// Time per entry of a method on a batch shaped like the generic table (θd subset; n_beta of its 32
// β nodes, spread over the same range).
double time_per_entry(const NpQuadratureConfig& q, std::size_t n_theta, std::size_t n_sigma, int repeats, int threads, int n_beta = 32) {
  NpGridRequest r;
  r.eta = 1.55;
  r.quadrature = q;
  r.lobes = 4;
  for (std::size_t t = 0; t < n_theta; ++t) r.thetas.push_back(std::acos(1.0 - (static_cast<double>(t) + 0.5) / static_cast<double>(n_theta) * (1.0 - std::cos(radians(89.5)))));
  for (std::size_t k = 0; k < n_sigma; ++k) r.sigmas.push_back(20.0 * std::pow((static_cast<double>(k) + 0.5) / static_cast<double>(n_sigma), 2));
  for (int j = 0; j < 128; ++j) r.phis.push_back(kPi * j / 127.0);
  std::vector<double> betas;
  for (int b = 0; b < n_beta; ++b) betas.push_back(radians(0.5) * std::pow(120.0, n_beta > 1 ? b / (n_beta - 1.0) : 0.0));
  r.betas_of = [&](int) { return betas; };
  BakeOptions o;
  o.threads = threads;
  const double entries = static_cast<double>(n_theta * n_sigma * 128 * static_cast<std::size_t>(n_beta) * 4);
  std::vector<double> t;
  volatile double sink = 0.0;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = clock_type::now();
    bake_np_grid(r, o, "", [&](int, std::size_t, std::size_t, std::size_t, std::size_t, double v) { sink = v; });
    t.push_back(seconds_since(t0));
  }
  (void)sink;
  return median(t) / entries * 1e9;
}

}  // namespace

namespace bench {
json bench_sampling(const Settings& s);  // sampling.cpp
json bench_runtime(const Settings& s);   // runtime.cpp
json bench_bands(const Settings& s);  // bands.cpp
}

static int bench_main(int argc, char** argv) {
  hairlut_tools::install_cancel_handlers("bench-hair-luts");
  CLI::App app{"bench-hair-luts: run time against error of hairlut's N_p methods, bake targets, resolution and scaling"};
  std::string out_dir = "bench", bake_tool, generic_config;
  std::size_t slices = 80;
  bool quick = false, quiet = false, presets_only = false, representations_only = false;
  // Installed: the installed baker and share/hairlut; in the build tree: its baker and the sources.
  const std::string data = hairlut::tools::data_root(HAIRLUT_SOURCE_DIR);
  bake_tool = hairlut::tools::sibling_tool("bake-hair-luts");
  // generic.json is the benchmark's input, not a starting point: an installation keeps it apart from
  // the configs, under share/hairlut/bench.
  generic_config = data == HAIRLUT_SOURCE_DIR ? data + "/tables/configs/generic.json" : data + "/bench/generic.json";
  app.add_option("--out", out_dir, "output directory")->capture_default_str();
  app.add_option("--slices", slices, "stress slices for the accuracy sweep")->check(CLI::Range(std::size_t{1}, std::size_t{100000}))->capture_default_str();
  // Checked when given (a missing input is a command-line error, exit 2); the defaults, which a
  // quick run does not use, are not.
  app.add_option("--bake-tool", bake_tool, "bake-hair-luts binary for the generic-table run")->check(CLI::ExistingFile)->capture_default_str();
  app.add_option("--generic-config", generic_config, "config of the generic table")->check(CLI::ExistingFile)->capture_default_str();
  app.add_flag("--quick", quick, "a smoke run: fewer slices, no generic-table bake, fewer repeats");
  app.add_flag("--quiet,-q", quiet, "no progress on stderr");
  app.add_flag("--presets-only", presets_only, "only time the export presets (writes presets.json, presets.csv, presets.md)");
  app.add_flag("--representations-only", representations_only,
               "only measure table representations: entries against sampled error and lookup ns (writes representations.*)");
  std::string only;
  app.add_option("--only", only,
                 "run one section and write only its files: per-material, end-to-end, scaling, pbrt, presets, lookup, sampling, runtime (the full run "
                 "also writes bench.json/csv/md and pareto.svg)")
      ->check(CLI::IsMember({"per-material", "end-to-end", "scaling", "pbrt", "presets", "lookup", "sampling", "runtime", "bands"}));
  app.footer("Example: bench-hair-luts --out bench/   (about a minute on 2 cores; --quick for seconds)\n\n"
             "Exit status: 0 done, 1 a section failed, 2 bad command line or a missing --bake-tool or --generic-config (one line\n"
             "\"bench-hair-luts: error: ...\" on stderr), 130/143/129 interrupted by SIGINT/SIGTERM/SIGHUP.");
  if (const auto rc = hairlut::tools::parse_command_line(app, "bench-hair-luts", argc, argv)) return *rc;
  // Before the work: the results of minutes of timing must have somewhere to go.
  if (const auto why = hairlut::tools::unwritable_directory(out_dir)) {
    hairlut::tools::print_error("bench-hair-luts", "--out " + *why);
    return 1;
  }
  if (quick) slices = std::min<std::size_t>(slices, 16);
  const int repeats = quick ? 1 : 3;
  const int max_threads = omp_get_max_threads();

  json report;
  char date[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d", std::gmtime(&now));
  std::string loadavg;
  std::getline(std::ifstream("/proc/loadavg"), loadavg);
  report["machine"] = {{"cpu", cpu_model()}, {"cores", max_threads}, {"date", date}, {"hairlut_version", kVersion},
                       {"load_average_at_start", loadavg.substr(0, loadavg.find(' ', loadavg.find(' ', loadavg.find(' ') + 1) + 1))}};
  report["command"] = "bench-hair-luts --out " + out_dir + (quick ? " --quick" : "") + " --slices " + std::to_string(slices);
  if (representations_only) {
    std::filesystem::create_directories(out_dir);
    bench::write_representations(bench::bench_representations(quick, quiet), report["machine"], out_dir);
    if (!quiet) {
      std::ostringstream md;
      md << std::ifstream(out_dir + "/representations.md").rdbuf();
      std::printf("%s\nwrote %s/representations.json, .csv, .md, .svg\n", md.str().c_str(), out_dir.c_str());
    }
    return 0;
  }
  Settings st;
  st.out_dir = out_dir, st.bake_tool = bake_tool, st.source_dir = data;
  st.quick = quick, st.quiet = quiet, st.repeats = repeats, st.max_threads = max_threads, st.machine = report["machine"];
  if (presets_only) only = "presets";
  if (!only.empty()) {
    const std::map<std::string, std::string> files = {{"presets", "presets"}, {"per-material", "per-material"}, {"end-to-end", "end-to-end"},
                                                      {"scaling", "scaling"}, {"pbrt", "pbrt-hair"}, {"lookup", "lookup"}, {"sampling", "sampling"}, {"runtime", "runtime"}, {"bands", "bands"}};
    if (only == "presets") write_presets(bench_presets(st), st);
    if (only == "per-material") bench_per_material(st);
    if (only == "end-to-end") bench_end_to_end(st);
    if (only == "scaling") bench_scaling(st);
    if (only == "pbrt") bench_pbrt(st);
    if (only == "lookup") bench_lookup(st);
    if (only == "sampling") bench_sampling(st);  // sampling.cpp
    if (only == "runtime") bench_runtime(st);    // runtime.cpp
    if (only == "bands") bench_bands(st);  // bands.cpp
    const std::string base = files.at(only);
    if (!quiet) {
      std::ostringstream md;
      md << std::ifstream(out_dir + "/" + base + ".md").rdbuf();
      std::printf("%s\nwrote %s/%s.json, .csv, .md\n", md.str().c_str(), out_dir.c_str(), base.c_str());
    }
    return 0;
  }

  // ---- 1. Accuracy of every method on the stress set, against the adaptive reference.
  log(quiet, "stress set: %zu slices x 48 phi, reference ...\n", slices);
  const auto stress = stress_slices(slices);
  std::vector<double> phis;
  for (int j = 0; j < 48; ++j) phis.push_back(kPi * j / 47.0);
  std::vector<std::vector<double>> ref(stress.size(), std::vector<double>(phis.size()));
  std::vector<double> energy(stress.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t i = 0; i < stress.size(); ++i) {
    const StressSlice& s = stress[i];
    const AttenuationSlice slice(s.eta, s.theta_d, s.sigma_a);
    for (std::size_t j = 0; j < phis.size(); ++j) ref[i][j] = azimuthal_np_reference(slice, s.p, s.beta, phis[j], 1e-13).value[0];
    energy[i] = lobe_energies_reference(slice, {s.p + 1, false}, 1e-14).value.back();
  }
  json rows = json::array();
  for (const Method& m : methods(quick)) {
    log(quiet, "  %s, %s\n", m.name.c_str(), m.setting.c_str());
    if (m.q.method == NpQuadratureConfig::Method::adaptive) continue;  // the reference itself
    std::vector<double> rel, rel_target, abs_err, energy_err;
    for (std::size_t i = 0; i < stress.size(); ++i) {
      const auto v = evaluate_slice(stress[i], phis, m.q);
      const double peak = *std::max_element(ref[i].begin(), ref[i].end());
      for (std::size_t j = 0; j < phis.size(); ++j) {
        const double e = std::abs(v[j] - ref[i][j]);
        abs_err.push_back(e);
        if (peak > 1e-250) {
          rel.push_back(e / peak);
          if (stress[i].beta >= radians(0.5) - 1e-12) rel_target.push_back(e / peak);
        }
      }
      // Energy: ∫ N dφ by the trapezoid rule over 256 points (exact to ~1e−18 for β ≥ 2°).
      if (stress[i].beta >= radians(2.0) && energy[i] > 1e-250) {
        std::vector<double> fine;
        for (int j = 0; j < 256; ++j) fine.push_back(kPi * j / 256.0);
        fine.push_back(kPi);
        const auto vf = evaluate_slice(stress[i], fine, m.q);
        double integral = 0.0;
        for (std::size_t j = 0; j + 1 < fine.size(); ++j) integral += 0.5 * (vf[j] + vf[j + 1]) * (fine[j + 1] - fine[j]);
        energy_err.push_back(std::abs(2.0 * integral - energy[i]) / energy[i]);
      }
    }
    json row = {{"method", m.name},
                {"setting", m.setting},
                {"max_rel", rel.empty() ? 0.0 : *std::max_element(rel.begin(), rel.end())},
                {"p99_rel", percentile(rel, 0.99)},
                {"max_rel_target_domain", rel_target.empty() ? 0.0 : *std::max_element(rel_target.begin(), rel_target.end())},
                {"max_abs", abs_err.empty() ? 0.0 : *std::max_element(abs_err.begin(), abs_err.end())},
                {"max_energy_rel", energy_err.empty() ? 0.0 : *std::max_element(energy_err.begin(), energy_err.end())}};
    rows.push_back(row);
  }

  // ---- 2. Time per entry on a generic-table-shaped batch, one thread.
  log(quiet, "timing per entry ...\n");
  std::size_t mi = 0;
  const int timing_betas = quick ? 4 : 32;  // a smoke run times a batch of 4 β instead of 32
  for (const Method& m : methods(quick)) {
    double tpe = 0.0;
    if (m.q.method == NpQuadratureConfig::Method::fourier) tpe = time_per_entry(m.q, quick ? 2 : 4, 32, repeats, 1, timing_betas);
    else if (m.q.method == NpQuadratureConfig::Method::adaptive) tpe = time_per_entry(m.q, 1, 1, 1, 1, timing_betas);
    else tpe = time_per_entry(m.q, 1, m.q.order >= 1024 ? 1 : 4, repeats, 1, timing_betas);
    if (m.q.method == NpQuadratureConfig::Method::adaptive) {
      rows.push_back({{"method", m.name}, {"setting", m.setting}, {"max_rel", 0.0}, {"p99_rel", 0.0}, {"max_rel_target_domain", 0.0},
                      {"max_abs", 0.0}, {"max_energy_rel", 0.0}, {"note", "the reference (1e-13) is the adaptive integrator itself"}});
    }
    rows[mi]["time_per_entry_ns"] = tpe;
    rows[mi]["threads"] = 1;
    ++mi;
  }
  report["methods"] = rows;
  // Same accuracy: the cheapest fixed-order rule that reaches 1e−10 of the peak on the target domain.
  const json* fourier = nullptr;
  const json* gl_same = nullptr;
  for (const json& r : rows) {
    if (r["method"] == "fourier" && r["setting"] == "tolerance 1e-12") fourier = &r;
    if (r["method"] == "gauss-legendre (gamma)" && r["max_rel_target_domain"].get<double>() <= 1e-10 && !gl_same) gl_same = &r;
  }
  if (fourier) {
    json s = {{"fourier_time_per_entry_ns", (*fourier)["time_per_entry_ns"]},
              {"fourier_max_rel_target_domain", (*fourier)["max_rel_target_domain"]}};
    if (gl_same) {
      s["gauss_legendre_setting"] = (*gl_same)["setting"];
      s["gauss_legendre_time_per_entry_ns"] = (*gl_same)["time_per_entry_ns"];
      s["speedup"] = (*gl_same)["time_per_entry_ns"].get<double>() / (*fourier)["time_per_entry_ns"].get<double>();
    } else {
      s["note"] = "no fixed Gauss-Legendre order up to 4096 reaches 1e-10 of the peak on the target domain";
      const json* best = nullptr;
      for (const json& r : rows)
        if (r["method"] == "gauss-legendre (gamma)" && (!best || r["max_rel_target_domain"] < (*best)["max_rel_target_domain"])) best = &r;
      if (best) {
        s["best_gauss_legendre_setting"] = (*best)["setting"];
        s["best_gauss_legendre_max_rel"] = (*best)["max_rel_target_domain"];
        s["speedup_over_best"] = (*best)["time_per_entry_ns"].get<double>() / (*fourier)["time_per_entry_ns"].get<double>();
      }
    }
    report["same_accuracy"] = s;
  }

  // ---- 3. The generic table, baked by the tool (wall time, peak memory).
  if (!quick) {
    log(quiet, "generic table with %s ...\n", bake_tool.c_str());
    const std::string tmp = (std::filesystem::temp_directory_path() / ("hairlut-bench-" + std::to_string(::getpid()))).string();
    const ChildResult c = run_child({bake_tool, "--config", generic_config, "--output-dir", tmp, "--force", "--quiet"});
    std::error_code ec;
    std::filesystem::remove_all(tmp, ec);
    const double table_bytes = 64.0 * 128 * 32 * 32 * 4 * 4 + 64.0 * 32 * 6 * 4;  // four N_p lobes + energies/residual, float32
    report["generic_table"] = {{"config", generic_config}, {"exit_status", c.status}, {"wall_seconds", c.seconds}, {"threads", max_threads},
                               {"entries", 64 * 128 * 32 * 32 * 4}, {"peak_rss_bytes", static_cast<double>(c.peak_rss_kb) * 1024.0},
                               {"table_bytes", table_bytes}, {"peak_rss_over_tables", static_cast<double>(c.peak_rss_kb) * 1024.0 / table_bytes}};
  }

  // ---- 4. Per material: Tungsten's precompute (re-implemented) against hairlut, one thread; the
  // same shape end to end through bake-hair-luts; pbrt-v4's analytic evaluation per call.
  report["per_material"] = bench_per_material(st);
  report["end_to_end"] = bench_end_to_end(st);
  report["pbrt_hair"] = bench_pbrt(st);
  report["lookup"] = bench_lookup(st);
  report["sampling"] = bench_sampling(st);
  report["runtime"] = bench_runtime(st);

  // ---- 5. Interpolation error against resolution, per axis of the generic table.
  log(quiet, "resolution ...\n");
  {
    auto axis = [](const char* name, Spacing sp, double lo, double hi, Wrap w) {
      GridAxis a;
      a.name = name, a.spacing = sp, a.lo = lo, a.hi = hi, a.wrap = w, a.count = 2;
      return a;
    };
    const std::vector<GridAxis> axes = {axis("beta", Spacing::log, radians(0.5), radians(60.0), Wrap::clamp),
                                        axis("sigma_a", Spacing::sqrt, 0.0, 20.0, Wrap::clamp),
                                        axis("theta_d", Spacing::cos, 0.0, radians(89.5), Wrap::clamp),
                                        axis("phi", Spacing::uniform, 0.0, kPi, Wrap::even)};
    const AxisErrorProbe probe(axes, 1.55, AbsorptionPath::chord, 3, quick ? 3 : 8);
    json res = json::array();
    for (std::size_t a = 0; a < 4; ++a) {
      json ax = {{"axis", axes[a].name}, {"spacing", std::string(to_string(axes[a].spacing))}, {"counts", json::array()}, {"max_rel", json::array()}};
      std::vector<double> counts, errs;
      for (int n : {8, 16, 32, 64, 128, 256}) {
        if (quick && n > 32) break;
        const double e = probe.error(a, n);
        counts.push_back(n), errs.push_back(e);
        ax["counts"].push_back(n), ax["max_rel"].push_back(e);
      }
      // Nodes needed for 1e−2, 1e−3, 1e−4, from the log–log slope of the last two counts.
      for (double target : {1e-2, 1e-3, 1e-4}) {
        double need = -1;
        for (std::size_t i = 0; i < counts.size(); ++i)
          if (errs[i] <= target) { need = counts[i]; break; }
        if (need < 0 && counts.size() >= 2 && errs.back() > 0 && errs[errs.size() - 2] > errs.back()) {
          const double slope = std::log(errs[errs.size() - 2] / errs.back()) / std::log(counts.back() / counts[counts.size() - 2]);
          need = std::ceil(counts.back() * std::pow(errs.back() / target, 1.0 / slope));
        }
        ax["nodes_for_" + fmt(target, 1)] = need;
      }
      res.push_back(ax);
    }
    report["resolution"] = {{"note", "linear interpolation in the axis's mapped coordinate at cell midpoints, the other axes at fixed "
                                     "probes over the generic table's domain, lobes R, TT, TRT, relative to the lobe's peak over the domain"},
                            {"axes", res}};
  }

  // ---- 6. Thread scaling with stage timings; 7. the export presets.
  report["scaling"] = bench_scaling(st);
  report["presets"] = bench_presets(st);

  // ---- 8. Table representations: entries against sampled error and lookup cost.
  report["representations"] = bench::bench_representations(quick, quiet);

  // ---- Outputs.
  std::filesystem::create_directories(out_dir);
  write_presets(report["presets"], st);
  bench::write_representations(report["representations"], report["machine"], out_dir);
  {
    std::ofstream(out_dir + "/bench.json") << report.dump(2) << "\n";
    std::ofstream csv(out_dir + "/bench.csv");
    csv << "method,setting,time_per_entry_ns,threads,max_rel,p99_rel,max_rel_target_domain,max_abs,max_energy_rel\n";
    for (const json& r : report["methods"])
      csv << '"' << r["method"].get<std::string>() << "\",\"" << r["setting"].get<std::string>() << "\"," << r["time_per_entry_ns"] << ','
          << r["threads"] << ',' << r["max_rel"] << ',' << r["p99_rel"] << ',' << r["max_rel_target_domain"] << ',' << r["max_abs"] << ','
          << r["max_energy_rel"] << "\n";
    svg::LinePlot plot;
    plot.title = "N_p: error against time per entry (stress set, one thread)";
    plot.xlabel = "time per table entry [ns]";
    plot.ylabel = "max error / lobe peak";
    plot.log_x = plot.log_y = true;
    plot.width = 640;
    plot.height = 380;
    std::map<std::string, svg::Series> series;
    for (const json& r : report["methods"]) {
      if (r["method"] == "adaptive reference") continue;
      auto& s = series[r["method"].get<std::string>()];
      s.name = r["method"].get<std::string>();
      s.markers = true;
      s.x.push_back(r["time_per_entry_ns"].get<double>());
      s.y.push_back(std::max(r["max_rel_target_domain"].get<double>(), 1e-16));
    }
    for (auto& [k, s] : series) plot.series.push_back(s);
    plot.y_reference = 1e-10;
    std::ofstream(out_dir + "/pareto.svg") << svg::line_plot(plot) << "\n";
    // Markdown summary (the README's performance section is made from it).
    std::ostringstream md;
    md << "Machine: " << report["machine"]["cpu"].get<std::string>() << ", " << max_threads << " cores; " << date << "; hairlut " << kVersion
       << ".\nCommand: `build/release/tools/bench-hair-luts/" << report["command"].get<std::string>() << "`\n\n";
    md << "| method | setting | time per entry (1 thread) | max error / peak (β ≥ 0.5°) | p99 (all) | energy error |\n|---|---|---|---|---|---|\n";
    for (const json& r : report["methods"])
      md << "| " << r["method"].get<std::string>() << " | " << r["setting"].get<std::string>() << " | " << fmt(r["time_per_entry_ns"].get<double>())
         << " ns | " << fmt(r["max_rel_target_domain"].get<double>()) << " | " << fmt(r["p99_rel"].get<double>()) << " | "
         << fmt(r["max_energy_rel"].get<double>()) << " |\n";
    if (report.contains("same_accuracy")) md << "\nSame accuracy: `" << report["same_accuracy"].dump() << "`\n";
    if (report.contains("generic_table")) md << "\nGeneric table: `" << report["generic_table"].dump() << "`\n";
    md << "\nPer material (per-material.md):\n\n" << std::ifstream(out_dir + "/per-material.md").rdbuf();
    md << "\nEnd to end (end-to-end.md):\n\n" << std::ifstream(out_dir + "/end-to-end.md").rdbuf();
    md << "\npbrt-v4 HairBxDF::f (pbrt-hair.md):\n\n" << std::ifstream(out_dir + "/pbrt-hair.md").rdbuf();
    md << "\nLookups and S from tables (lookup.md):\n\n" << std::ifstream(out_dir + "/lookup.md").rdbuf();
    md << "\nImportance sampling (sampling.md):\n\n" << std::ifstream(out_dir + "/sampling.md").rdbuf();
    md << "\nRenderer runtime against pbrt-v4 (runtime.md):\n\n" << std::ifstream(out_dir + "/runtime.md").rdbuf();
    md << "\nResolution: `" << report["resolution"]["axes"].dump() << "`\n";
    md << "\nScaling (scaling.md):\n\n" << std::ifstream(out_dir + "/scaling.md").rdbuf();
    md << "\nExport presets:\n\n" << std::ifstream(out_dir + "/presets.md").rdbuf();
    std::ofstream(out_dir + "/bench.md") << md.str();
    if (!quiet) std::printf("%s\nwrote %s/bench.json, bench.csv, bench.md, pareto.svg\n", md.str().c_str(), out_dir.c_str());
  }
  return 0;
}

int main(int argc, char** argv) {
  // A section that throws is a failed run (exit 1, one line), not an abort.
  try {
    return bench_main(argc, argv);
  } catch (const hairlut::BakeCancelled&) {
    std::fprintf(stderr, "\nbench-hair-luts: interrupted\n");
    return hairlut_tools::cancel_exit_code();
  } catch (const std::exception& e) {
    hairlut::tools::print_error("bench-hair-luts", e.what());
    return 1;
  }
}
