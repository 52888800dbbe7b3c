// A config's outputs: the config read into the set's file description (io/table_io.hpp) and the
// bake's report into its sidecar's.
#include "hairlut/bake/outputs.hpp"

#include "hairlut/bake/engine_presets.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;
namespace fs = std::filesystem;

SidecarSource sidecar_source(const BakeConfig& c, const BakeReport& report) {
  json folded = json::array();
  for (const auto& f : report.folded) folded.push_back({{"lobe", f.lobe}, {"max_energy", f.max_energy}});
  SidecarSource s{c.name, c.model, c.hash, json()};
  s.report = {{"explicit_lobes", report.explicit_lobes}, {"folded_lobes", folded}, {"notes", report.notes}, {"entries", report.entries}};
  return s;
}

}  // namespace

OutputPaths output_paths(const BakeConfig& c) { return set_paths(c.output.directory, c.output.basename); }

std::vector<EngineOutput> engine_outputs(const BakeConfig& c) {
  std::vector<EngineOutput> out;
  if (!c.engine) return out;
  for (const EngineTexture& t : engine_preset_textures(*c.engine))
    out.push_back({t, engine_texture_path(c.output.directory, c.output.basename, t)});
  return out;
}

SetFiles output_files(const BakeConfig& c, int threads) {
  SetFiles f;
  f.directory = c.output.directory;
  f.basename = c.output.basename;
  f.hdf5 = c.output.hdf5;
  f.exr = c.output.exr;
  f.hdf5_options = {c.output.hdf5_deflate, threads};
  f.hdf5_double = c.output.hdf5_double;
  f.exr_options = {c.output.exr_half, c.output.exr_compression};
  f.engine = engine_outputs(c);
  return f;
}

bool outputs_up_to_date(const BakeConfig& c) { return table_set_up_to_date(output_files(c), c.hash); }

json sidecar_json(const TableSet& set, const BakeConfig& c, const BakeReport& report, const std::vector<std::pair<std::string, fs::path>>& files) {
  return sidecar_json(set, output_files(c, report.threads), sidecar_source(c, report), files);
}

std::vector<fs::path> write_outputs(const TableSet& set, const BakeConfig& c, const BakeReport& report, const std::atomic<bool>* cancel,
                                    const SlabbedTables* slabbed, const LockWait& wait) {
  if (slabbed && !slabbed->empty() && c.output.exr)
    throw DomainError("output.exr: tables larger than the memory budget are baked slab by slab into HDF5 only (EXR files hold "
                      "engine-sized textures); set output.exr to false or raise --memory-budget");
  return write_table_set(set, output_files(c, report.threads), sidecar_source(c, report), cancel, slabbed, wait);
}

void remove_stale_temporaries(const BakeConfig& c, const LockWait& wait) {
  remove_stale_temporaries(c.output.directory, c.output.basename, wait);
}

}  // namespace hairlut
