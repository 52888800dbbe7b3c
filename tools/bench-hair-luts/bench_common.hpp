// Helpers shared by the sections of bench-hair-luts (timing, statistics, child processes, output).
#pragma once

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace bench {

using json = nlohmann::ordered_json;
using clock_type = std::chrono::steady_clock;

inline double seconds_since(clock_type::time_point t0) { return std::chrono::duration<double>(clock_type::now() - t0).count(); }

/// CPU time (user + system) of this process so far, in seconds.
double process_cpu_seconds();
/// CPU time of the calling thread so far, in seconds: single-threaded timings that do not count
/// the time other processes of a shared machine take from it.
double thread_cpu_seconds();

// Best thread-CPU ns per call of f(), which makes n calls, over `repeats` runs.
template <class F>
double best_ns(std::size_t n, int repeats, F&& f) {
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const double t0 = thread_cpu_seconds();
    f();
    best = std::min(best, (thread_cpu_seconds() - t0) / static_cast<double>(n) * 1e9);
  }
  return best;
}

/// Uniform doubles in [0, 1) from SplitMix64: fixed pseudo-random points, the same on every machine.
struct SplitMix {
  std::uint64_t state;
  double operator()() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1p-53;
  }
};

inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}
inline double minimum(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::min_element(v.begin(), v.end()); }

inline double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

template <class... Args>
void log(bool quiet, const char* fmt, Args... args) {
  if (quiet) return;
  if constexpr (sizeof...(Args) == 0) std::fputs(fmt, stderr);  // a message without arguments is no format
  else std::fprintf(stderr, fmt, args...);
  std::fflush(stderr);
}

std::string fmt(double v, int digits = 3);
std::string cpu_model();
/// The 1-, 5- and 15-minute load averages (/proc/loadavg), or "" where there is none: the machine
/// may be shared, and thread CPU time still grows with what other processes take from the caches.
std::string load_average();

/// A child process's exit status, wall time, CPU time (user + system) and peak resident memory.
struct ChildResult {
  int status = -1;
  double seconds = 0.0, cpu_seconds = 0.0;
  long peak_rss_kb = 0;
};
ChildResult run_child(const std::vector<std::string>& argv);

/// What every section gets from the command line.
struct Settings {
  std::string out_dir, bake_tool;
  std::string source_dir;  ///< holds tables/configs and tables/default: the checkout, or an installed share/hairlut
  bool quick = false, quiet = false;
  int repeats = 3;
  int max_threads = 1;
  json machine;
};

/// Writes text to out_dir/name (creating the directory).
void write_file(const Settings& s, const std::string& name, const std::string& text);

// The sections; each returns its JSON and writes its own files under out_dir.
json bench_presets(const Settings& s);
void write_presets(const json& rows, const Settings& s);
json bench_per_material(const Settings& s);
json bench_end_to_end(const Settings& s);
json bench_scaling(const Settings& s);
json bench_pbrt(const Settings& s);

}  // namespace bench
