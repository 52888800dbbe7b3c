// The files of one bake: HDF5 and/or OpenEXR tables plus a JSON sidecar that describes every
// table (schemas/hairlut-tables.schema.json). Files are written to temporary names in the output
// directory and renamed into place only when complete, so an interrupted bake never leaves a
// partial file at the destination. The sidecar, renamed last, is the set's manifest: it records
// each file's size and hash (XXH3-64; FNV-1a 64 in sets of format 1.x), which load_tables checks. A bake holds an exclusive lock (flock)
// on the output directory while it writes and commits, so two bakes never interleave their files.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hairlut/bake/bake.hpp"
#include "hairlut/bake/config.hpp"
#include "hairlut/io/exr_io.hpp"
#include "hairlut/io/hdf5_io.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// Where a config's outputs go.
struct OutputPaths {
  std::filesystem::path hdf5, exr, sidecar;
};
OutputPaths output_paths(const BakeConfig& config);

/// True when the sidecar records this config's hash and library version and every file it lists
/// exists as a regular file with the recorded size and content hash: re-baking would change nothing.
bool outputs_up_to_date(const BakeConfig& config);

/// The sidecar document for a table set written to the given files.
nlohmann::ordered_json sidecar_json(const TableSet& set, const BakeConfig& config, const BakeReport& report,
                                    const std::vector<std::pair<std::string, std::filesystem::path>>& files);

/// How a writer waits for the output directory's lock while another process (a bake committing
/// there) holds it: `notice` (optional) hears once that it waits and who holds the lock ("pid N
/// (name)" when the system says); after `timeout_s` seconds (negative: no limit) the wait ends in
/// an IoError naming the holder. The writer's `cancel` flag ends the wait too (BakeCancelled).
struct LockWait {
  double timeout_s = -1.0;
  std::function<void(const std::string&)> notice;
};

/// Writes every requested format and the sidecar (temporary names, then rename). Before each
/// rename it checks `cancel`; if raised, it removes the temporaries and throws BakeCancelled.
/// Returns the final paths written. Throws IoError. With `slabbed` (bake's slabbed tables), the
/// HDF5 file is baked and written slab by slab (write_hdf5_slabbed); EXR output is refused then
/// (DomainError), and the producers' exceptions (BakeCancelled) pass through. The output directory's
/// lock is waited for as `wait` says.
std::vector<std::filesystem::path> write_outputs(const TableSet& set, const BakeConfig& config, const BakeReport& report,
                                                 const std::atomic<bool>* cancel = nullptr, const SlabbedTables* slabbed = nullptr,
                                                 const LockWait& wait = {});

/// Removes temporary files a killed bake of this config may have left in the output directory
/// (under the directory's lock, waited for as `wait` says):
/// only regular files of this user whose names write_outputs made (a keyed hash in the name), for
/// this config's outputs, of processes no longer running (or of an earlier process with this pid).
void remove_stale_temporaries(const BakeConfig& config, const LockWait& wait = {});

/// Loads a table file written by hairlut, choosing the reader by the file's magic bytes
/// (HDF5 or OpenEXR). When the file's set has a sidecar beside it that lists the file, the file
/// must have the size and content hash recorded there (a set is read whole, never mixed with
/// another bake's files); the directory is read under a shared lock, so a bake committing there
/// is waited for. Throws IoError.
TableSet load_tables(const std::filesystem::path& file);

/// The file alone, without the directory lock and the sidecar check. Throws IoError.
TableSet load_table_file(const std::filesystem::path& file);

}  // namespace hairlut
