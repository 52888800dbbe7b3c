// validate-hair-luts: check a baked hairlut table file (HDF5 or OpenEXR), or the tables of a
// config, and write report.html, report.json and report.md. Exit status 0 when every check
// passes, 1 when a check fails, 2 for bad input. Thin: the checks live in hairlut/report/validate.hpp.
#include <malloc.h>
#include <unistd.h>

#include "common/cli.hpp"
#include "common/progress.hpp"
#include <atomic>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/util/error.hpp>
#include <hairlut/report/report.hpp>
#include <hairlut/report/validate_engine.hpp>
#include <hairlut/bake/outputs.hpp>
#include <hairlut/io/table_io.hpp>
#include <hairlut/report/validate.hpp>
#include <string>
#include <vector>

#include "../common/cancel.hpp"

int main(int argc, char** argv) {
  // Tables of a set validated in parts are allocated and freed part after part. glibc's dynamic
  // mmap threshold rises to the size of the first freed table and puts the next ones on the heap,
  // which keeps what it frees: a fixed threshold returns them (peak RSS with parts of 36 MiB:
  // 128 MiB, 72 MiB with it), so that --memory-budget holds.
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  hairlut_tools::install_cancel_handlers("validate-hair-luts");
  CLI::App app{"validate-hair-luts: energy-conservation and accuracy report of hairlut tables"};
  app.footer(R"(Examples:
  validate-hair-luts tables/default/hairlut-default.h5 --out report/
  validate-hair-luts tables/default/hairlut-default.exr --threshold accuracy_max_rel=0.1
  validate-hair-luts --config tables/configs/default.json --out report/

Writes report.html (open it in a browser), report.json and report.md into --out. Thresholds
(name=value): furnace_direct, furnace_table, longitudinal_deon, mp_table_energy,
accuracy_max_rel, accuracy_p99_rel (N_p), accuracy_energy_max_rel, accuracy_mp_max_rel,
accuracy_melanin_max_rel, accuracy_ds_max_rel, energy_consistency, and for mean-energy and dual-scattering
tables ds_consistency, ds_furnace, ds_accuracy; a config's "validate.thresholds" sets them too, and a
file is judged by the thresholds of the config it was baked with (stored in it); --threshold wins.
Exit status: 0 all checks pass, 1 a check fails (or an I/O failure), 2 bad input or command
line (one line "validate-hair-luts: error: ..." on stderr), 130/143/129 interrupted by SIGINT/SIGTERM/SIGHUP.)");
  std::string file, config_path, out_dir = "hairlut-report";
  std::vector<std::string> thresholds;
  bool quiet = false;
  int threads = 0;
  std::size_t max_points = hairlut::kSampledErrorPoints;
  app.add_option("file", file, "table file written by bake-hair-luts (.h5 or .exr)");
  app.add_option("--config", config_path, "validate the tables of this config (its outputs if up to date, else baked in memory)");
  app.add_option("--out", out_dir, "report directory")->capture_default_str();
  app.add_option("--threshold", thresholds, "override a threshold, name=value (repeatable)");
  app.add_option("--threads", threads, "OpenMP threads for direct evaluation (default: all cores)")->check(CLI::Range(0, 4096));
  app.add_option("--max-points", max_points, "random points per table where the accuracy is measured (the work grows with it)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000000}))
      ->capture_default_str();
  std::uint64_t seed = 0;
  bool no_search = false;
  auto* seed_option = app.add_option("--seed", seed, "seed of the accuracy measure's points (default: drawn afresh each run and recorded in "
                                                      "report.json's accuracy_search.seed; give it to repeat a run exactly)");
  app.add_flag("--no-search", no_search, "judge accuracy on the random points only, without the worst-point search (faster, finds less)");
  double budget_mib = 0.0;
  app.add_option("--memory-budget", budget_mib,
                 "memory to stay within, in MiB (default: half of the machine's memory); an HDF5 set whose values need more is "
                 "validated in parts: its N_p tables over beta a run of beta rows at a time")
      ->check(CLI::Range(64.0, 1e12));
  app.add_flag("--quiet,-q", quiet, "print nothing but errors");
  if (const auto rc = hairlut::tools::parse_command_line(app, "validate-hair-luts", argc, argv)) return *rc;
  if (file.empty() == config_path.empty()) {
    std::fprintf(stderr, "validate-hair-luts: error: give either a table file or --config (see --help)\n");
    return 2;
  }
  if (max_points < 2) {
    std::fprintf(stderr, "validate-hair-luts: error: --max-points must be at least 2 (got %zu)\n", max_points);
    return 2;
  }

  // Before the work: a report that cannot be written would otherwise fail only after every check.
  if (const auto why = hairlut::tools::unwritable_directory(out_dir)) {
    hairlut::tools::print_error("validate-hair-luts", "--out " + *why);
    return 1;
  }

  hairlut::ValidationOptions options;
  options.threads = threads;
  options.max_points = max_points;
  if (seed_option->count() > 0) options.seed = seed;
  options.search = !no_search;
  options.cancel = hairlut_tools::cancel_pointer();
  hairlut_tools::register_temp_dir(out_dir);
  const auto physical = static_cast<std::uint64_t>(::sysconf(_SC_PHYS_PAGES)) * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
  if (budget_mib * 1048576.0 > static_cast<double>(physical)) {
    std::fprintf(stderr, "validate-hair-luts: error: --memory-budget %.0f MiB is more than this machine's memory (%.0f MiB) (see --help)\n", budget_mib,
                 static_cast<double>(physical) / 1048576.0);
    return 2;
  }
  const std::uint64_t budget = budget_mib > 0.0 ? static_cast<std::uint64_t>(budget_mib * 1048576.0) : physical / 2;
  // The thresholds a set was baked with travel in the config stored in its metadata.
  auto stored_thresholds = [&](const nlohmann::ordered_json& metadata) {
    if (!metadata.contains("config") || !metadata["config"].is_string()) return;
    const auto stored = nlohmann::json::parse(metadata["config"].get<std::string>(), nullptr, false);
    if (stored.is_object() && stored.contains("validate") && stored["validate"].contains("thresholds"))
      for (const auto& [k, v] : stored["validate"]["thresholds"].items()) options.thresholds.set(k, v.get<double>());
  };
  hairlut::TableSet set;
  std::string source;
  std::string in_parts;  // an HDF5 file larger than the budget: validated in parts
  try {
    // Clear the previous report first: a failed run must not leave one behind as if it were new.
    std::error_code ignored;
    for (const char* name : {"report.html", "report.json", "report.md"}) std::filesystem::remove(std::filesystem::path(out_dir) / name, ignored);
    if (!config_path.empty()) {
      const hairlut::BakeConfig config = hairlut::load_config(config_path);
      if (config.validate_thresholds.is_object())
        for (const auto& [k, v] : config.validate_thresholds.items()) options.thresholds.set(k, v.get<double>());
      const auto paths = hairlut::output_paths(config);
      if (hairlut::outputs_up_to_date(config)) {
        source = (config.output.hdf5 ? paths.hdf5 : paths.exr).string();
        if (config.output.hdf5 && hairlut::hdf5_values_bytes(source).value_or(0) > budget) in_parts = source;
        else set = hairlut::load_tables(source);
      } else {
        source = config_path + " (baked in memory; outputs missing or out of date)";
        hairlut::BakeOptions bo;
        bo.threads = threads;
        bo.cancel = hairlut_tools::cancel_pointer();
        set = hairlut::bake(config, bo);
      }
    } else if (hairlut::is_engine_texture(file)) {
      // An engine texture (tables.engine): checked against its preset's definition.
      const auto report = hairlut::validate_engine_texture(file, options);
      hairlut::write_engine_report(report, out_dir);
      if (!quiet) std::printf("%s\nwrote %s/report.html, report.json, report.md\n", hairlut::render_engine_report_markdown(report).c_str(), out_dir.c_str());
      return report["summary"]["status"] == "pass" ? 0 : 1;
    } else {
      source = file;
      if (hairlut::hdf5_values_bytes(file).value_or(0) > budget) {
        in_parts = file;
        stored_thresholds(hairlut::read_hdf5_outline(file, false).metadata);
      } else {
        set = hairlut::load_tables(file);
        stored_thresholds(set.metadata);
      }
    }
    for (const std::string& t : thresholds) {
      const auto eq = t.find('=');
      if (eq == std::string::npos) throw hairlut::DomainError("--threshold must be name=value (got \"" + t + "\")");
      std::size_t used = 0;
      double value = 0.0;
      try {
        value = std::stod(t.substr(eq + 1), &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != t.size() - eq - 1) throw hairlut::DomainError("--threshold " + t.substr(0, eq) + " must be a number (got \"" + t.substr(eq + 1) + "\")");
      options.thresholds.set(t.substr(0, eq), value);
    }
  } catch (const hairlut::ConfigError& e) {
    std::fprintf(stderr, "validate-hair-luts: error: %s\n", e.what());
    return 2;
  } catch (const hairlut::IoError& e) {
    std::fprintf(stderr, "validate-hair-luts: error: %s\n", e.what());
    return 2;
  } catch (const hairlut::DomainError& e) {
    std::fprintf(stderr, "validate-hair-luts: error: %s\n", e.what());
    return 2;
  } catch (const hairlut::BakeCancelled&) {
    std::fprintf(stderr, "validate-hair-luts: interrupted; no report written\n");
    return hairlut_tools::cancel_exit_code();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "validate-hair-luts: error: %s\n", e.what());
    return 2;
  }

  hairlut::tools::Progress progress(!quiet && ::isatty(STDERR_FILENO));
  options.progress = [&progress](std::string_view stage, std::size_t done, std::size_t total) { progress.update(stage, done, total); };
  try {
    const auto report = in_parts.empty() ? hairlut::validate_tables(set, source, options)
                                         : hairlut::validate_tables_in_parts(in_parts, source, budget, options);
    progress.stage("writing", out_dir + "/report.html, .json, .md");
    hairlut::write_report(report, out_dir);
    progress.finish();
    if (!quiet) {
      std::printf("%s", hairlut::render_report_markdown(report).c_str());
      std::printf("\nwrote %s/report.html, report.json, report.md\n", out_dir.c_str());
    }
    return report["summary"]["status"] == "pass" ? 0 : 1;
  } catch (const hairlut::BakeCancelled&) {
    std::fprintf(stderr, "\nvalidate-hair-luts: interrupted; no report written\n");
    return hairlut_tools::cancel_exit_code();
  } catch (const hairlut::DomainError& e) {
    std::fprintf(stderr, "validate-hair-luts: error: %s\n", e.what());
    return 2;
  } catch (const hairlut::IoError& e) {  // a set validated in parts is read here, as it goes
    std::fprintf(stderr, "validate-hair-luts: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "validate-hair-luts: error: %s\n", e.what());
    return 1;
  }
}
