// HDF5 files at the byte level, below the HDF5 library: screening the global heap before HDF5
// reads it, fixing the superblock checksum of an in-memory image, writing an image to disk.
//
// global_heap_problem: a guard run before HDF5 reads the variable-length strings of a file: HDF5 1.10 parses a global
// heap collection ("GCOL") with a loop that never ends when an object record has size 0, and the
// collection carries no checksum. This scan finds every collection in the file's bytes and refuses
// one whose records would not advance that loop or would run past the collection's end. Bytes of
// table data that happen to spell "GCOL" are recognised only with version 1, zero reserved bytes
// and a size that fits the file, and even then are refused only for a record HDF5 itself could not
// walk; a file HDF5 wrote passes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "hairlut/io/hdf5_io.hpp"
#include "hairlut/util/hash.hpp"

namespace hairlut::detail {

/// Empty when every global heap collection in the bytes is walkable, else a one-phrase reason.
/// `scanned`, when given, hears now and then that no byte below its argument will be read again.
std::string global_heap_problem(const unsigned char* data, std::size_t size, const std::function<void(std::size_t)>& scanned = {});

/// The same for a file, mapped read-only, the pages behind the scan released as it goes (no copy,
/// and a file larger than memory never resident whole).
std::string global_heap_problem(const std::filesystem::path& file);

/// HDF5 1.10's H5Fget_file_image clears the superblock's "open for writing" flags in the image but
/// leaves the checksum computed with them set: recompute it (superblock versions 2 and 3).
void fix_superblock_checksum(std::span<char> image);

/// Writes `bytes` to `path` (created or truncated; never through a symbolic link) and syncs it; every system error (disk full, a
/// file-size limit, I/O) becomes an IoError naming the file and the reason.
void write_file_bytes(const std::filesystem::path& path, std::span<const char> bytes);

/// What the sidecar records of a written file: its size and hash (16 hex digits; empty: not known).
struct FileDigest {
  std::uintmax_t bytes = 0;
  HashAlgorithm algorithm = kFileHash;
  std::string hash;
};

/// write_hdf5 that also returns the digest of the bytes it wrote, hashed from the in-memory image
/// (the writer of a bake's files needs it for the sidecar; reading the file back costs a second
/// pass over the disk cache and a buffer).
FileDigest write_hdf5_digest(const TableSet& set, const std::filesystem::path& path, const Hdf5WriteOptions& options);

// Flushes a written file to disk (fsync); throws IoError("<file>: cannot write (<reason>)").
void sync_file(const std::filesystem::path& path);

}  // namespace hairlut::detail
