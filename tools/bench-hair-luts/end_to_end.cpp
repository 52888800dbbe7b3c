// Section "end to end": a show's per-material config of Tungsten's shape (N materials, 64 cos θd ×
// 64 φ over [−π, π] with both ends, R, TT, TRT, RGB, β = 2°, float32 HDF5) through
// `bake-hair-luts --threads 1`, CPU time of the child process, against N of the baseline's
// precomputes (baseline_tungsten.cpp) in this process; plus where the tool's time goes.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <hairlut/util/angles.hpp>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/physics/melanin.hpp>
#include <hairlut/bake/outputs.hpp>
#include <hairlut/io/table_io.hpp>
#include <sstream>

#include "baseline_tungsten.hpp"
#include "bench_common.hpp"

namespace bench {

using namespace hairlut;

namespace {

// Melanin concentrations of material i of a show (deterministic, spread over blond to black).
std::pair<double, double> melanin_of(int i) { return {0.05 + 0.25 * i, 0.1 + 0.05 * (i % 5)}; }

}  // namespace

// β of material i: beta_deg for every material, or beta_deg + i · beta_step_deg (each its own).
static double beta_of(int i, double beta_deg, double beta_step_deg) { return beta_deg + i * beta_step_deg; }

std::string tungsten_shape_config(int materials, double beta_deg, int compression, double beta_step_deg) {
  json mats = json::array();
  for (int i = 0; i < materials; ++i) {
    const auto [e, p] = melanin_of(i);
    const double b = beta_of(i, beta_deg, beta_step_deg);
    char name[16];
    std::snprintf(name, sizeof name, "m%02d", i);
    mats.push_back({{"name", name}, {"melanin", {{"eumelanin", e}, {"pheomelanin", p}}}, {"beta_deg", {{"R", b}, {"TT", b}, {"TRT", b}}}});
  }
  const json c = {{"name", "tungsten-shape"},
                  {"description", "per-material tables of Tungsten's shape (bench-hair-luts end-to-end section)"},
                  {"model", "deon2011"},
                  {"fiber", {{"eta", 1.55}, {"absorption_path", "chord"}}},
                  {"lobes", {{"explicit", {"R", "TT", "TRT"}}, {"residual", false}}},
                  {"quadrature", {{"method", "fourier"}, {"tolerance", 1e-10}}},
                  {"tables", {{"np", {{"axes", {{"theta_d", {{"count", 64}, {"range_deg", {0, 90}}, {"spacing", "cos"}}},
                                                  {"phi", {{"count", 64}, {"symmetry", "full"}}}}}}}}},
                  {"scene", {{"mode", "per-material"}, {"materials", mats}}},
                  {"output", {{"directory", "."}, {"basename", "tungsten-shape"}, {"formats", {"hdf5"}}}}};
  json out = c;
  if (compression >= 0) out["output"]["hdf5"] = {{"compression", compression}};
  return out.dump(2) + "\n";
}

json bench_end_to_end(const Settings& st) {
  const int runs = st.quick ? 2 : 15;
  const std::string dir = (std::filesystem::temp_directory_path() / ("hairlut-bench-e2e-" + std::to_string(::getpid()))).string();
  std::filesystem::create_directories(dir);
  json rows = json::array();
  std::ostringstream md, csv;
  csv << "materials,beta,hdf5_compression,tool_cpu_ms_min,tool_cpu_ms_median,tool_wall_ms_min,baseline_cpu_ms_min,ratio,process_start_cpu_ms\n";
  md << "| materials | β | HDF5 deflate | bake-hair-luts --threads 1 (CPU, minimum of the runs) | baseline precomputes (CPU) | ratio | of which process start and config check |\n|---|---|---|---|---|---|---|\n";
  // The fixed cost of running the tool at all: start, read and check the config, exit.
  const std::string one = dir + "/one.json";
  std::ofstream(one) << tungsten_shape_config(1, 2.0, -1, 0.0);
  std::vector<double> check_cpu;
  for (int i = 0; i < runs; ++i) check_cpu.push_back(run_child({st.bake_tool, "--config", one, "--check", "--quiet"}).cpu_seconds);
  // The shape asked for (every material at β = 2°, so materials share their node factors and
  // windows: material_np.hpp), and 16 materials each of its own β (2° to 3.5° in steps of 0.1°),
  // which share nothing but the rule's nodes.
  struct Case {
    int materials, compression;
    double beta_step;
  };
  const std::vector<Case> cases = {{1, -1, 0.0}, {16, -1, 0.0}, {1, 0, 0.0}, {16, 0, 0.0}, {16, 0, 0.1}};
  auto config_of = [&](std::size_t k) { return dir + "/case-" + std::to_string(k) + ".json"; };
  for (std::size_t k = 0; k < cases.size(); ++k) std::ofstream(config_of(k)) << tungsten_shape_config(cases[k].materials, 2.0, cases[k].compression, cases[k].beta_step);
  // Each run times every case once, tool and baseline side by side, so that a slow spell of the
  // machine (a shared host) falls on all cases rather than on all runs of one.
  std::vector<std::vector<double>> cpus(cases.size()), walls(cases.size()), bases(cases.size());
  std::vector<int> statuses(cases.size(), 0);
  log(st.quiet, "end to end: %d runs of %zu cases ...\n", runs, cases.size());
  for (int r = 0; r < runs; ++r)
    for (std::size_t k = 0; k < cases.size(); ++k) {
      const auto& [materials, compression, beta_step] = cases[k];
      // Each case into its own directory: a run replaces what the same case wrote before (a show re-baked).
      const ChildResult c = run_child({st.bake_tool, "--config", config_of(k), "--output-dir", dir + "/out-" + std::to_string(k), "--force", "--quiet", "--threads", "1"});
      statuses[k] = c.status;
      cpus[k].push_back(c.cpu_seconds);
      walls[k].push_back(c.seconds);
      TungstenTables t;
      const double c0 = thread_cpu_seconds();
      for (int i = 0; i < materials; ++i) {
        const auto [e, p] = melanin_of(i);
        const Rgb s = melanin_sigma_a_rgb(e, p);
        const double b = beta_of(i, 2.0, beta_step);
        tungsten_precompute({1.55f, {static_cast<float>(s.r), static_cast<float>(s.g), static_cast<float>(s.b)}, static_cast<float>(radians(b))}, t);
      }
      bases[k].push_back(thread_cpu_seconds() - c0);
    }
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const auto& [materials, compression, beta_step] = cases[k];
    const std::string cfg = config_of(k);
    const std::vector<double>&cpu = cpus[k], &wall = walls[k], &base = bases[k];
    const int status = statuses[k];
    // Where the time goes, in this process (one thread): config, bake, files (minimum of the runs).
    double t_config = INFINITY, t_bake = INFINITY, t_write = INFINITY;
    for (int r = 0; r < runs; ++r) {
      double t0 = thread_cpu_seconds();
      const BakeConfig c = load_config(cfg);
      t_config = std::min(t_config, thread_cpu_seconds() - t0);
      BakeOptions o;
      o.threads = 1;
      BakeReport report;
      t0 = thread_cpu_seconds();
      const TableSet set = bake(c, o, &report);
      t_bake = std::min(t_bake, thread_cpu_seconds() - t0);
      BakeConfig cw = c;
      cw.output.directory = dir + "/out-inproc";
      std::filesystem::create_directories(cw.output.directory);
      t0 = thread_cpu_seconds();
      write_outputs(set, cw, report);
      t_write = std::min(t_write, thread_cpu_seconds() - t0);
    }
    const double ratio = minimum(cpu) / minimum(base);
    const std::string beta_text = beta_step > 0 ? "each its own beta (2 to " + fmt(beta_of(materials - 1, 2.0, beta_step)) + " deg)" : "beta 2 deg";
    json row = {{"materials", materials},
                {"hdf5_compression", compression < 0 ? json("default (deflate 6)") : json(compression)},
                {"beta", beta_text},
                {"config", "generated by bench-hair-luts (tungsten_shape_config): 64 cos(theta_d) edges over [0, 90] deg x 64 phi over [-180, 180] "
                           "deg edges, R/TT/TRT, RGB melanin, " + beta_text + ", tolerance 1e-10, float32 HDF5"},
                {"tool_exit_status", status},
                {"tool_cpu_ms_min", minimum(cpu) * 1e3},
                {"tool_cpu_ms_median", median(cpu) * 1e3},
                {"tool_wall_ms_min", minimum(wall) * 1e3},
                {"baseline_cpu_ms_min", minimum(base) * 1e3},
                {"baseline_cpu_ms_median", median(base) * 1e3},
                {"ratio", ratio},
                {"ratio_of_medians", median(cpu) / median(base)},
                {"process_start_and_check_cpu_ms_min", minimum(check_cpu) * 1e3},
                {"in_process_ms", {{"load_config", t_config * 1e3}, {"bake", t_bake * 1e3}, {"write_outputs", t_write * 1e3}}}};
    rows.push_back(row);
    csv << materials << ",\"" << beta_text << "\"," << (compression < 0 ? 6 : compression) << ',' << minimum(cpu) * 1e3 << ',' << median(cpu) * 1e3 << ',' << minimum(wall) * 1e3 << ',' << minimum(base) * 1e3 << ',' << ratio << ','
        << minimum(check_cpu) * 1e3 << "\n";
    md << "| " << materials << " | " << beta_text << " | " << (compression < 0 ? 6 : compression) << " | " << fmt(minimum(cpu) * 1e3) << " ms (median " << fmt(median(cpu) * 1e3)
       << ") | " << fmt(minimum(base) * 1e3) << " ms | " << fmt(ratio) << " (medians " << fmt(median(cpu) / median(base)) << ") | "
       << fmt(minimum(check_cpu) * 1e3) << " ms (in process: config " << fmt(t_config * 1e3) << " ms, bake " << fmt(t_bake * 1e3) << " ms, files "
       << fmt(t_write * 1e3) << " ms) |\n";
  }
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  json result = {{"machine", st.machine},
                 {"tool", "bake-hair-luts --threads 1 --force --quiet, CPU time (user + system) of the child, minimum of " + std::to_string(runs) + " runs"},
                 {"baseline", "the same number of Tungsten precomputes (re-implementation, tools/bench-hair-luts/baseline_tungsten.cpp), CPU time of this thread; "
                  "in-process breakdown (config, bake with one thread, files) also in thread CPU time"},
                 {"rows", rows}};
  write_file(st, "end-to-end.json", result.dump(2) + "\n");
  write_file(st, "end-to-end.csv", csv.str());
  write_file(st, "end-to-end.md", md.str());
  return result;
}

}  // namespace bench
