// bake-hair-luts: bake the tables a config asks for into HDF5 / OpenEXR files with a JSON sidecar.
// Thin: parsing, baking and writing live in the hairlut library; this file handles the command
// line, progress display, signals and exit codes.
#include <sys/statvfs.h>
#include <unistd.h>

#include "common/cli.hpp"
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/bake_estimate.hpp>
#include <hairlut/util/error.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/bake/outputs.hpp>
#include <hairlut/io/table_io.hpp>
#include <optional>
#include <string>
#include <system_error>

#include "../common/cancel.hpp"
#include "../common/progress.hpp"

namespace {

// Bytes free for this user on the file system of `dir` (or of its nearest existing parent).
std::optional<std::uint64_t> free_disk_bytes(std::filesystem::path dir) {
  std::error_code ec;
  dir = std::filesystem::absolute(dir.empty() ? "." : dir, ec);
  while (!dir.empty() && !std::filesystem::exists(dir, ec) && dir != dir.parent_path()) dir = dir.parent_path();
  struct statvfs fs {};
  if (::statvfs(dir.c_str(), &fs) != 0) return std::nullopt;
  return static_cast<std::uint64_t>(fs.f_bavail) * static_cast<std::uint64_t>(fs.f_frsize);
}

// Why the tool could not write into `dir`, or nothing: `dir` (or, when missing, its nearest
// existing parent, where it would be created) must be a directory this user may write into.
// Nothing is created: --check reports it without side effects, and the bake before its work.
std::optional<std::string> output_directory_problem(std::filesystem::path dir) {
  std::error_code ec;
  dir = std::filesystem::absolute(dir.empty() ? "." : dir, ec);
  std::filesystem::path existing = dir;
  while (!existing.empty() && !std::filesystem::exists(existing, ec) && existing != existing.parent_path()) existing = existing.parent_path();
  if (!std::filesystem::is_directory(existing, ec))
    return dir.string() + ": cannot create the output directory (" + existing.string() + " is not a directory)";
  // A file system without storage (procfs, sysfs: statvfs reports no blocks) takes no new
  // directory or file, whatever access() says for root.
  struct statvfs fs {};
  if (::statvfs(existing.c_str(), &fs) == 0 && fs.f_blocks == 0)
    return dir.string() + ": cannot write files there (" + existing.string() + " is on a file system without storage)";
  if (::access(existing.c_str(), W_OK | X_OK) != 0)
    return dir.string() + ": cannot write into " + (existing == dir ? std::string("the output directory") : existing.string()) + " (" +
           std::generic_category().message(errno) + ")";
  return std::nullopt;
}

}  // namespace

int main(int argc, char** argv) {
  hairlut_tools::install_cancel_handlers("bake-hair-luts");
  CLI::App app{"bake-hair-luts: bake hair scattering lookup tables (d'Eon 2011 M_p and N_p, melanin absorption) "
               "into HDF5 and OpenEXR files described by a JSON sidecar"};
  app.footer(R"(Examples:
  bake-hair-luts --config tables/configs/default.json
  bake-hair-luts --config show.json --threads 8 --force
  bake-hair-luts --config engine.json --output-dir /tmp/luts --quiet
  bake-hair-luts --config scene.json --check

The config format is schemas/hairlut-config.schema.json. An unchanged config with up-to-date
outputs is not baked again (use --force). Exit codes: 0 done or up to date, 1 bake or I/O
failure, 2 bad config or command line (one line "bake-hair-luts: error: ..." on stderr),
130/143/129 interrupted by SIGINT/SIGTERM/SIGHUP (no partial output is left).)");
  std::string config_path, output_dir;
  bool force = false, quiet = false, check = false;
  int threads = 0;
  double budget_mib = 0.0;
  app.add_option("--config", config_path, "bake configuration (JSON)")->required();
  app.add_option("--output-dir", output_dir, "write here instead of the config's output.directory");
  app.add_option("--threads", threads, "OpenMP threads (default: all cores)")->check(CLI::Range(0, 4096));
  app.add_option("--memory-budget", budget_mib,
                 "memory to stay within, in MiB (default: half of the machine's memory); larger generic N_p and M_p "
                 "tables are baked and written slab by slab")
      ->check(CLI::Range(64.0, 1e12));
  double lock_timeout = -1.0;
  app.add_option("--lock-timeout", lock_timeout,
                 "seconds to wait for the output directory while another bake writes there (default: as long as it takes)")
      ->check(CLI::Range(0.0, 1e9));
  app.add_flag("--force", force, "bake even if the outputs are up to date");
  app.add_flag("--quiet,-q", quiet, "no progress display and no summary");
  app.add_flag("--check", check, "validate the config and exit");
  if (const auto rc = hairlut::tools::parse_command_line(app, "bake-hair-luts", argc, argv)) return *rc;

  hairlut::BakeConfig config;
  try {
    config = hairlut::load_config(config_path);
  } catch (const hairlut::ConfigError& e) {
    std::fprintf(stderr, "bake-hair-luts: error: %s\n", e.what());
    return 2;
  }
  if (!output_dir.empty()) config.output.directory = output_dir;
  // The bake writes there at its end: an unwritable place is refused before the work (and --check
  // says valid only for what the bake accepts).
  if (const auto why = output_directory_problem(config.output.directory)) {
    std::fprintf(stderr, "bake-hair-luts: error: %s\n", why->c_str());
    return 1;
  }
  // Size up front: refuse what cannot fit in memory or on disk before any work; tables over the
  // memory budget are baked slab by slab.
  const int bake_threads = threads > 0 ? threads : static_cast<int>(std::max(1L, ::sysconf(_SC_NPROCESSORS_ONLN)));
  const hairlut::BakeEstimate size = hairlut::estimate_bake(config, bake_threads);
  const double mib = 1024.0 * 1024.0;
  const auto physical = static_cast<std::uint64_t>(::sysconf(_SC_PHYS_PAGES)) * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
  // A budget cannot exceed the machine: it bounds what the plan may hold in memory at once, and
  // a larger one would let a plan past the physical-memory guard.
  if (budget_mib * mib > static_cast<double>(physical)) {
    std::fprintf(stderr, "bake-hair-luts: error: --memory-budget %.0f MiB is more than this machine's memory (%.0f MiB) (see --help)\n",
                 budget_mib, static_cast<double>(physical) / mib);
    return 2;
  }
  const std::uint64_t budget = budget_mib > 0.0 ? static_cast<std::uint64_t>(budget_mib * mib) : physical / 2;
  const hairlut::MemoryPlan plan = hairlut::plan_memory(size, budget);
  if (!plan.refused.empty()) {
    const std::string way = plan.minimum_bytes > physical
                                ? "it needs at least " + std::to_string(plan.minimum_bytes >> 20) + " MiB, more than this machine has"
                                : "raise --memory-budget to at least " + std::to_string((plan.minimum_bytes >> 20) + 1);
    std::fprintf(stderr, "bake-hair-luts: error: %s: %s (%llu values); %s\n", config_path.c_str(), plan.refused.c_str(),
                 static_cast<unsigned long long>(size.values), way.c_str());
    return 1;
  }
  if (const auto free_bytes = free_disk_bytes(config.output.directory); free_bytes && size.disk_bytes > *free_bytes) {
    std::fprintf(stderr, "bake-hair-luts: error: %s: the files need up to %.1f MiB on disk before compression (%llu values), more than this machine has free in %s (%.1f MiB)\n",
                 config_path.c_str(), static_cast<double>(size.disk_bytes) / mib, static_cast<unsigned long long>(size.values),
                 config.output.directory.string().c_str(), static_cast<double>(*free_bytes) / mib);
    return 1;
  }
  // What the bake refuses for slabs (sampling data, target_error, ...) is refused here too, before
  // the work and by --check.
  if (plan.slabbed) {
    try {
      hairlut::check_slab_by_slab(config);
    } catch (const hairlut::DomainError& e) {
      std::fprintf(stderr, "bake-hair-luts: error: %s: %s\n", config_path.c_str(), e.what());
      return 1;
    }
  }
  if (plan.slabbed && config.output.exr) {
    std::fprintf(stderr, "bake-hair-luts: error: %s: output.exr: the tables exceed the memory budget of %.0f MiB and are baked slab by slab "
                 "into HDF5 only (EXR files hold engine-sized textures); set output.exr to false or raise --memory-budget\n",
                 config_path.c_str(), static_cast<double>(budget) / mib);
    return 1;
  }
  if (check) {
    if (!quiet) {
      std::printf("%s: valid (config hash %s)\n", config_path.c_str(), config.hash.c_str());
      std::printf("estimate: %llu values; disk about %.1f MiB (at most %.1f MiB before compression)\n",
                  static_cast<unsigned long long>(size.values), static_cast<double>(size.disk_expected_bytes) / mib,
                  static_cast<double>(size.disk_bytes) / mib);
      if (plan.slabbed)
        std::printf("memory: peak about %.1f MiB within the budget of %.0f MiB: generic N_p and M_p baked and written slab by slab "
                    "(slabs of at most %.1f MiB, two in memory)\n",
                    static_cast<double>(plan.peak_bytes) / mib, static_cast<double>(budget) / mib, static_cast<double>(plan.slab_bytes) / mib);
      else
        std::printf("memory: peak about %.1f MiB (tables held whole; budget %.0f MiB)\n", static_cast<double>(plan.peak_bytes) / mib,
                    static_cast<double>(budget) / mib);
    }
    return 0;
  }
  if (!force && hairlut::outputs_up_to_date(config)) {
    if (!quiet) std::printf("up to date: %s (config hash %s); use --force to bake again\n",
                            hairlut::output_paths(config).sidecar.string().c_str(), config.hash.c_str());
    return 0;
  }

  hairlut_tools::register_temp_dir(config.output.directory);
  hairlut::tools::Progress bar(!quiet && ::isatty(STDERR_FILENO));
  hairlut::BakeOptions options;
  options.threads = threads;
  options.cancel = hairlut_tools::cancel_pointer();
  options.progress = [&](std::string_view stage, std::size_t done, std::size_t total) { bar.update(stage, done, total); };
  // Another bake writing into the directory holds its lock: say who, and give up after --lock-timeout.
  hairlut::LockWait lock_wait;
  lock_wait.timeout_s = lock_timeout;
  lock_wait.notice = [&](const std::string& what) {
    if (!quiet) std::fprintf(stderr, "bake-hair-luts: %s%s\n", what.c_str(), lock_timeout >= 0.0 ? " (--lock-timeout set)" : "");
  };
  try {
    hairlut::remove_stale_temporaries(config, lock_wait);
    hairlut::BakeReport report;
    hairlut::SlabbedTables slabbed;
    slabbed.slab_bytes = plan.slab_bytes;
    const auto start = std::chrono::steady_clock::now();
    const hairlut::TableSet set = hairlut::bake(config, options, &report, plan.slabbed ? &slabbed : nullptr);
    bar.stage("writing", hairlut::output_paths(config).sidecar.parent_path().string());
    const auto files =
        hairlut::write_outputs(set, config, report, hairlut_tools::cancel_pointer(), plan.slabbed ? &slabbed : nullptr, lock_wait);
    bar.finish();
    if (plan.slabbed) report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!quiet) {
      for (const auto& f : report.folded)
        std::printf("folded lobe %s into the residual (largest energy %.3g < fold_below %.3g)\n", f.lobe.c_str(), f.max_energy,
                    config.fold_below);
      for (const auto& n : report.notes) std::printf("note: %s\n", n.c_str());
      std::printf("baked %zu values in %zu tables in %.2f s%s (config hash %s)\n", report.entries, set.tables.size(), report.seconds,
                  plan.slabbed ? " slab by slab" : "", config.hash.c_str());
      for (const auto& f : files) std::printf("wrote %s\n", f.string().c_str());
    }
  } catch (const hairlut::BakeCancelled&) {
    std::fprintf(stderr, "\nbake-hair-luts: interrupted; no output was written or replaced\n");
    return hairlut_tools::cancel_exit_code();
  } catch (const hairlut::IoError& e) {
    std::fprintf(stderr, "bake-hair-luts: error: %s\n", e.what());
    return 1;
  } catch (const hairlut::DomainError& e) {
    std::fprintf(stderr, "bake-hair-luts: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bake-hair-luts: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
