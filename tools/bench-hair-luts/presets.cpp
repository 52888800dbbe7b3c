// Section "export presets": time to bake each shipped preset config.
#include <omp.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/bake/outputs.hpp>
#include <hairlut/io/engine_exr.hpp>
#include <sstream>

#include "bench_common.hpp"

namespace bench {

using namespace hairlut;

// Each shipped preset config: the bake in this process (all threads, median of `repeats`) and the
// tool end to end (bake and write HDF5, engine textures and sidecar; wall time and peak memory).
json bench_presets(const Settings& st) {
  json rows = json::array();
  std::vector<const char*> names = {"unreal-hair-strands", "unity-hdrp-hair", "dual-scattering"};
  if (st.quick) names = {"dual-scattering"};  // a smoke run: the smallest config
  for (const char* name : names) {
    const std::string path = st.source_dir + "/tables/configs/" + name + ".json";
    log(st.quiet, "preset %s ...\n", name);
    const BakeConfig c = load_config(path);
    std::vector<double> times;
    BakeReport report;
    std::size_t tables = 0;
    for (int i = 0; i < st.repeats; ++i) {
      const TableSet set = bake(c, {}, &report);
      times.push_back(report.seconds);
      tables = set.tables.size();
    }
    const std::string tmp = (std::filesystem::temp_directory_path() / ("hairlut-bench-preset-" + std::to_string(::getpid()))).string();
    const ChildResult child = run_child({st.bake_tool, "--config", path, "--output-dir", tmp, "--force", "--quiet"});
    json files = json::array();
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(tmp, ec))
      files.push_back({{"file", e.path().filename().string()}, {"bytes", static_cast<double>(std::filesystem::file_size(e.path(), ec))}});
    std::filesystem::remove_all(tmp, ec);
    json textures = json::array();
    BakeConfig named = c;
    named.output.directory = ".";
    for (const EngineOutput& o : engine_outputs(named)) textures.push_back(o.texture.name);
    rows.push_back({{"preset", name},
                    {"config", "tables/configs/" + std::string(name) + ".json"},
                    {"textures", textures},
                    {"tables", tables},
                    {"entries", report.entries},
                    {"threads", omp_get_max_threads()},
                    {"bake_seconds_median", median(times)},
                    {"bake_seconds_runs", times},
                    {"tool_exit_status", child.status},
                    {"tool_wall_seconds", child.seconds},
                    {"tool_peak_rss_bytes", static_cast<double>(child.peak_rss_kb) * 1024.0},
                    {"files", files}});
  }
  return rows;
}

void write_presets(const json& rows, const Settings& st) {
  std::ostringstream csv, md;
  csv << "preset,textures,tables,entries,threads,bake_seconds_median,tool_wall_seconds,tool_peak_rss_bytes\n";
  md << "| preset | textures | values | bake (median, " << rows.front()["threads"] << " threads) | bake-hair-luts end to end | peak memory |\n|---|---|---|---|---|---|\n";
  for (const json& r : rows) {
    std::string tex;
    for (const auto& t : r["textures"]) tex += (tex.empty() ? "" : " ") + t.get<std::string>();
    csv << r["preset"].get<std::string>() << ",\"" << tex << "\"," << r["tables"] << ',' << r["entries"] << ',' << r["threads"] << ','
        << r["bake_seconds_median"] << ',' << r["tool_wall_seconds"] << ',' << r["tool_peak_rss_bytes"] << "\n";
    md << "| " << r["preset"].get<std::string>() << " | " << (tex.empty() ? "(generic tables)" : tex) << " | " << r["entries"] << " | "
       << fmt(r["bake_seconds_median"].get<double>()) << " s | " << fmt(r["tool_wall_seconds"].get<double>()) << " s | "
       << fmt(r["tool_peak_rss_bytes"].get<double>() / 1048576.0) << " MiB |\n";
  }
  write_file(st, "presets.json", json({{"machine", st.machine}, {"presets", rows}}).dump(2) + "\n");
  write_file(st, "presets.csv", csv.str());
  write_file(st, "presets.md", md.str());
}

}  // namespace bench
