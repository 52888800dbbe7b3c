// The files a bake config writes (output.*, tables.engine) and how a bake writes them: the config's
// side of io/table_io.hpp, which writes, checks and cleans up a table set's files without knowing
// configs.
#pragma once

#include <atomic>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "hairlut/bake/bake.hpp"
#include "hairlut/bake/config.hpp"
#include "hairlut/io/engine_exr.hpp"
#include "hairlut/io/table_io.hpp"
#include "hairlut/tables/slab_stream.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// Where a config's outputs go: output.directory / output.basename with .h5, .exr and .json.
OutputPaths output_paths(const BakeConfig& config);

/// The engine textures a config writes (none without tables.engine), each to
/// <output.directory>/<basename>-<suffix>.exr.
std::vector<EngineOutput> engine_outputs(const BakeConfig& config);

/// The files a config writes and their encodings (HDF5 deflated on `threads` threads, 0: the
/// OpenMP default).
SetFiles output_files(const BakeConfig& config, int threads = 0);

/// True when the sidecar records this config's hash and library version and every file it lists
/// exists as a regular file with the recorded size and content hash: re-baking would change nothing.
bool outputs_up_to_date(const BakeConfig& config);

/// The sidecar document for a table set written to the given files.
nlohmann::ordered_json sidecar_json(const TableSet& set, const BakeConfig& config, const BakeReport& report,
                                    const std::vector<std::pair<std::string, std::filesystem::path>>& files);

/// Writes every requested format and the sidecar (write_table_set: temporary names, then rename).
/// Before each rename it checks `cancel`; if raised, it removes the temporaries and throws
/// BakeCancelled. Returns the final paths written. Throws IoError. With `slabbed` (bake's slabbed
/// tables), the HDF5 file is baked and written slab by slab (write_hdf5_slabbed); EXR output is
/// refused then (DomainError), and the producers' exceptions (BakeCancelled) pass through. The
/// output directory's lock is waited for as `wait` says.
std::vector<std::filesystem::path> write_outputs(const TableSet& set, const BakeConfig& config, const BakeReport& report,
                                                 const std::atomic<bool>* cancel = nullptr, const SlabbedTables* slabbed = nullptr,
                                                 const LockWait& wait = {});

/// Removes temporary files a killed bake of this config may have left in the output directory
/// (remove_stale_temporaries of output.directory and output.basename).
void remove_stale_temporaries(const BakeConfig& config, const LockWait& wait = {});

}  // namespace hairlut
