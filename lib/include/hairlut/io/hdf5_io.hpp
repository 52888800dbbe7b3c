// HDF5 files of hairlut tables.
//
// Layout: one group per table group ("np", "mp", "melanin", "materials/<name>"); in each group one
// dataset per table and one dimension scale (H5DS) per axis, named like the axis ("theta_d",
// "phi", "sigma_a", "beta", ...) with `units` and `long_name` attributes, so that h5py, xarray and
// netCDF tools see real coordinates. Datasets of at most 4 KiB (axes, energies, M_p of a
// material) are compact (stored in their checksummed object header, unfiltered); larger ones are
// chunked with shuffle + deflate and a Fletcher-32 checksum, or, with deflate 0, contiguous
// (unfiltered; hairlut_checksum covers their values). The file uses the HDF5 1.10 format (superblock v3, checksummed metadata, compact chunk indexes) and records no
// time stamps, so the same tables give the same bytes. The root carries the provenance
// (version, model, eta, lobes, quadrature, config text and hash) as attributes.
#pragma once

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>

#include "hairlut/util/error.hpp"
#include "hairlut/tables/slab_stream.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// A file that cannot be written or read as hairlut tables. what() is one line: "<file>: <reason>".
class IoError : public std::runtime_error {
 public:
  explicit IoError(const std::string& message) : std::runtime_error(one_line(message)) {}
};

/// Version of the table file format, "MAJOR.MINOR", written into every file (HDF5 root attribute
/// `hairlut_format_version`, EXR header attribute `hairlut.format_version`). A minor change only
/// adds (attributes, tables, optional keys) and older readers of the same major version read the
/// file; a major change may alter or remove what a reader relies on, and readers refuse a newer
/// major version (docs/table-format.md, "Format version and compatibility").
/// Format 2.0 changed the checksums (content checksum and the sidecar's file digests) from FNV-1a
/// 64 to XXH3-64 and names the algorithm in each file, and reads every 1.x file (1.1, and 1.2
/// with N_p in the Fourier representation), verifying FNV-1a there. Format 3.0 lets energy and
/// residual tables whose θd axis reaches 90° store E / g with the attributes cos_theta_d_power and
/// grazing_absorption (Table::grazing_factor), which a 2.x reader would read wrong: a file holding
/// such a table records 3.0, so that a 2.x reader refuses it; any other file records 2.0, whose
/// content it is (a file records the lowest version whose content it holds, as 1.x files did).
/// Files that recorded 2.1 (the same attributes, an earlier hairlut) are read as 3.0's.
inline constexpr int kFormatVersionMajor = 3;
inline constexpr int kFormatVersionMajorOldest = 1;  ///< the oldest major version this hairlut reads
inline constexpr int kFormatVersionMinor = 0;        ///< the newest minor version of kFormatVersionMajor this hairlut writes (it reads any)
/// "MAJOR.MINOR": the newest format this hairlut writes.
std::string format_version_text();
/// The format version a file of `set` records: "3.0" when a table stores its values over a grazing
/// factor, "2.0" otherwise (see kFormatVersionMajor).
std::string format_version_text(const TableSet& set);
/// The major version of format_version_text(set).
int format_major_of(const TableSet& set);

/// Returns MAJOR when `text` is "MAJOR.MINOR" (decimal) with kFormatVersionMajorOldest ≤ MAJOR ≤
/// kFormatVersionMajor; otherwise throws IoError("<name>: ..."), saying whether the file is newer
/// or older than this hairlut reads.
int check_format_version(const std::string& text, const std::string& name);

struct Hdf5WriteOptions {
  int deflate = 6;  ///< 0 … 9; 0 stores unfiltered (compact or contiguous; tables written slab by slab stay chunked with shuffle and Fletcher-32)
  /// Threads that filter (checksum, shuffle, deflate) the chunks of tables written whole, at most
  /// four (bounded scratch memory); 0: the OpenMP default. The file's bytes do not depend on it.
  int threads = 0;
};

/// Writes the tables to `file` (created or truncated). Throws IoError.
void write_hdf5(const TableSet& set, const std::filesystem::path& file, const Hdf5WriteOptions& options = {});

/// The same for a set whose `slabbed` tables hold no values: their producers are called on this
/// thread for chunk-aligned ranges of leading-axis rows (at most slabbed.slab_bytes each), while
/// one writer thread writes the previous slab as an HDF5 hyperslab, so at most two slabs are in
/// memory. The file is written to disk directly (not from a memory image). Values and checksum
/// equal those write_hdf5 stores for the same tables held whole; the file's bytes differ only in
/// layout (the checksum attribute is written last). Throws IoError, DomainError (a leading-axis
/// row larger than a slab) or what a producer throws (BakeCancelled).
void write_hdf5_slabbed(const TableSet& set, const SlabbedTables& slabbed, const std::filesystem::path& file,
                        const Hdf5WriteOptions& options = {});

/// Reads a file written by write_hdf5 back into memory, exactly as stored. Rejects files that are
/// not hairlut tables, are truncated or corrupted, or lack metadata, with an IoError.
TableSet read_hdf5(const std::filesystem::path& file);

/// Reading a set larger than memory in parts (validate-hair-luts --memory-budget): the tables of
/// `group` whose leading axis is named `axis` (the N_p tables of a generic set, over β) hold only
/// that axis's rows [first, first + count), the axis narrowed to them (narrowed_axis); every other
/// table is read whole.
struct Hdf5Rows {
  std::string group = "np", axis = "beta";
  int first = 0, count = 0;
};
/// One run of a table's values as read_hdf5_outline streams them: `count` values from row-major
/// index `offset`, as stored (f32 or f64 set, the other null).
struct Hdf5Run {
  const Table& table;
  std::size_t offset, count;
  const float* f32;
  const double* f64;
};
using Hdf5RunVisitor = std::function<void(const Hdf5Run&)>;
/// Every table's description and axes without values (size() == 0), after the screening read_hdf5
/// does. With `verify`, every value is read in runs of leading-axis rows of at most `run_bytes`
/// (one row at least), shown to `visit` and hashed: the content checksum is verified without the
/// set in memory. Throws IoError.
TableSet read_hdf5_outline(const std::filesystem::path& file, bool verify, std::size_t run_bytes = std::size_t{64} << 20,
                           const Hdf5RunVisitor& visit = {});
/// The set with the tables `rows` names read in part (the others whole), checked as read_hdf5
/// checks a file except for the content checksum, which a part cannot show: read_hdf5_outline
/// verifies it. Throws IoError, also for rows outside a table's axis. `screened`: the file is the
/// one (same inode, size and time) whose global heap an outline read screened, which a caller
/// holding its identity (TableSetParts) may skip: the screen reads the whole file.
TableSet read_hdf5_rows(const std::filesystem::path& file, const Hdf5Rows& rows, bool screened = false);
/// The same from a file image in memory (`name` is used in error messages).
TableSet read_hdf5_memory(const char* data, std::size_t size, const std::string& name);

}  // namespace hairlut
