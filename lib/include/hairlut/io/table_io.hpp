// The files of one table set: HDF5 and/or OpenEXR tables and engine textures plus a JSON sidecar
// that describes every table (schemas/hairlut-tables.schema.json); which files a bake config
// writes is bake/outputs.hpp's. Files are written to temporary names in the output directory and
// renamed into place only when complete, so an interrupted writer never leaves a partial file at
// the destination. The sidecar, renamed last, is the set's manifest: it records each file's size
// and hash (XXH3-64; FNV-1a 64 in sets of format 1.x), which load_tables checks. A writer holds an
// exclusive lock (flock) on the output directory while it writes and commits, so two bakes never
// interleave their files.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hairlut/io/engine_exr.hpp"
#include "hairlut/io/exr_io.hpp"
#include "hairlut/io/hdf5_io.hpp"
#include "hairlut/tables/slab_stream.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// The files of one table set, named by its directory and base name: <basename>.h5, <basename>.exr
/// and the sidecar <basename>.json (load_tables finds a file's sidecar by this rule); an engine
/// texture goes to <basename>-<suffix>.exr (engine_texture_path).
struct OutputPaths {
  std::filesystem::path hdf5, exr, sidecar;
};
OutputPaths set_paths(const std::filesystem::path& directory, const std::string& basename);
std::filesystem::path engine_texture_path(const std::filesystem::path& directory, const std::string& basename, const EngineTexture& texture);

/// What a table set is written as: which files, in which encodings.
struct SetFiles {
  std::filesystem::path directory;   ///< holds every file: created if missing, locked while the set is written
  std::string basename;              ///< names the files (set_paths) and the temporaries a stopped writer left
  bool hdf5 = false, exr = false;    ///< whole-set files written
  Hdf5WriteOptions hdf5_options;
  bool hdf5_double = false;          ///< the tables are float64 (the sidecar records the HDF5 file's precision)
  ExrWriteOptions exr_options;
  std::vector<EngineOutput> engine;  ///< engine textures, each to its own file
};

/// Where a set came from, as its sidecar records it beside what the writer knows (the files, the
/// tables, the set's metadata). `config_hash` is what table_set_up_to_date compares.
struct SidecarSource {
  std::string name, model, config_hash;
  nlohmann::ordered_json report;  ///< the sidecar's "report": what the producer decided and measured
};

/// True when the sidecar records `config_hash` and this library's version and lists exactly the
/// files `files` asks for, each a regular file with the recorded size and content hash: writing the
/// set again would change nothing.
bool table_set_up_to_date(const SetFiles& files, const std::string& config_hash);

/// The sidecar document for a table set written to the given files (format, path).
nlohmann::ordered_json sidecar_json(const TableSet& set, const SetFiles& files, const SidecarSource& source,
                                    const std::vector<std::pair<std::string, std::filesystem::path>>& written);

/// How a writer waits for the output directory's lock while another process (a bake committing
/// there) holds it: `notice` (optional) hears once that it waits and who holds the lock ("pid N
/// (name)" when the system says); after `timeout_s` seconds (negative: no limit) the wait ends in
/// an IoError naming the holder. The writer's `cancel` flag ends the wait too (BakeCancelled).
struct LockWait {
  double timeout_s = -1.0;
  std::function<void(const std::string&)> notice;
};

/// Writes every file `files` asks for and the sidecar (temporary names, then rename). Before each
/// rename it checks `cancel`; if raised, it removes the temporaries and throws BakeCancelled.
/// Returns the final paths written. Throws IoError (also for Fourier N_p tables or `slabbed`
/// tables in an EXR file, which has no layout for them). With `slabbed`, the HDF5 file is written
/// slab by slab (write_hdf5_slabbed), and the producers' exceptions (BakeCancelled) pass through.
/// The output directory's lock is waited for as `wait` says.
std::vector<std::filesystem::path> write_table_set(const TableSet& set, const SetFiles& files, const SidecarSource& source,
                                                   const std::atomic<bool>* cancel = nullptr, const SlabbedTables* slabbed = nullptr,
                                                   const LockWait& wait = {});

/// Removes temporary files a killed writer may have left in `directory` (under the directory's
/// lock, waited for as `wait` says): only regular files of this user whose names write_table_set
/// made (a keyed hash in the name), for the files of `basename`, of processes no longer running
/// (or of an earlier process with this pid).
void remove_stale_temporaries(const std::filesystem::path& directory, const std::string& basename, const LockWait& wait = {});

/// Loads a table file written by hairlut, choosing the reader by the file's magic bytes
/// (HDF5 or OpenEXR). When the file's set has a sidecar beside it that lists the file, the file
/// must have the size and content hash recorded there (a set is read whole, never mixed with
/// another bake's files); the directory is read under a shared lock, so a bake committing there
/// is waited for. Throws IoError.
TableSet load_tables(const std::filesystem::path& file);

/// A set's HDF5 file read in parts, for a set larger than memory (validate-hair-luts
/// --memory-budget). While it lives it holds the directory's shared lock, so no bake commits there
/// between two parts. On construction it checks the file as load_tables does (its sidecar's size
/// and hash) and reads its outline (read_hdf5_outline): every table's description, and the content
/// checksum verified by streaming the values in runs of at most `run_bytes`, shown to `visit`.
/// Throws IoError (also for a file that is not HDF5).
class TableSetParts {
 public:
  TableSetParts(const std::filesystem::path& file, std::size_t run_bytes, const Hdf5RunVisitor& visit = {});
  ~TableSetParts();
  TableSetParts(const TableSetParts&) = delete;
  TableSetParts& operator=(const TableSetParts&) = delete;
  /// Every table without values.
  const TableSet& outline() const { return outline_; }
  /// The set with the tables `rows` names read in part (read_hdf5_rows). Throws IoError when the
  /// file is no longer the one whose checksum the outline verified (device, inode, size or
  /// modification time changed).
  TableSet rows(const Hdf5Rows& rows) const;

 private:
  struct Lock;
  std::unique_ptr<Lock> lock_;
  std::filesystem::path file_;
  TableSet outline_;
  std::string identity_;  // the file's device, inode, size and modification time when verified
};
/// The file alone, without the directory lock and the sidecar check. Throws IoError.
TableSet load_table_file(const std::filesystem::path& file);

}  // namespace hairlut
