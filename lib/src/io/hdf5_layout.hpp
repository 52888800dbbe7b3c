// Storage layout of the datasets write_hdf5 creates whole (not slab by slab), chosen for the
// cost of writing many small tables (a show's per-material files hold about ten datasets per
// material, most of them a few hundred bytes):
//
// - compact (the values inside the dataset's object header): every dataset of at most
//   kCompactSmallBytes, whatever the deflate level (deflate gains nothing there). The object
//   header is checksummed (format ≥ 1.8 headers), so the values keep a checksum without Fletcher-32;
// - contiguous, no filters: larger datasets when deflate is 0 (the values carry no HDF5
//   checksum; hairlut_checksum covers them, and every hairlut reader checks it). Not compact: a
//   table of tens of KiB inside its object header is copied with the header's messages and
//   checksummed with them at every flush;
// - chunked with shuffle, deflate and Fletcher-32 otherwise (unchanged).
//
// Attributes stay in the object header (compact attribute storage) up to kCompactAttributes per
// object instead of HDF5's default of 8, past which HDF5 moves them to a fractal heap and a B-tree
// (dense storage) that cost more to build and to search than the handful of attributes they hold.
//
// None of this changes what a reader sees: the same datasets, shapes, types, values and attributes.
#pragma once

#include <hdf5.h>

#include <cstddef>

namespace hairlut::detail {

inline constexpr std::size_t kCompactSmallBytes = 4096;
inline constexpr unsigned kCompactAttributes = 64;

enum class Hdf5Layout { compact, contiguous, chunked };

/// The layout of a dataset of `bytes` bytes written whole, stored with deflate level `deflate`.
Hdf5Layout whole_dataset_layout(std::size_t bytes, int deflate);

/// Sets `layout` on a dataset creation property list (compact or contiguous; chunked is left to
/// the caller, which sets the chunk shape and filters). Returns HDF5's status.
herr_t set_unfiltered_layout(hid_t dcpl, Hdf5Layout layout);

/// Keeps up to kCompactAttributes attributes in the object header of objects created with
/// `ocpl` (a dataset or group creation property list). Returns HDF5's status.
herr_t keep_attributes_compact(hid_t ocpl);

}  // namespace hairlut::detail

