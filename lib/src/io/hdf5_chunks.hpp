// Filtered chunks of a dataset written whole, computed on several threads and handed to HDF5 as
// they are (H5Dwrite_chunk), instead of HDF5 filtering every chunk on the writing thread.
//
// The bytes are those HDF5's own pipeline stores for the dataset creation properties that
// dataset_create_plist sets (hdf5_objects.cpp), in that order: Fletcher-32 (the checksum of the
// chunk appended, little-endian), shuffle (byte k of every element gathered, for the element size
// of the stored type; trailing bytes that make no whole element left in place), deflate (zlib's
// compress2 at the level, into at most ⌈1.001 n⌉ + 12 bytes as HDF5's filter allows it; where that
// fails HDF5 skips the optional filter and so do we, with its bit set in the chunk's filter mask).
// A chunk that reaches past the dataset's extent is padded with zero bytes to the whole chunk, as
// HDF5 pads a chunk it creates without a fill value. Each stored chunk and its filter mask are
// then what HDF5's own pipeline stores for the same values (tested against it with
// H5Dread_chunk), for any number of threads. The file as a whole is not H5Dwrite's byte for
// byte: the chunks and the nodes of the chunk index are allocated in another order.
#pragma once

#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hairlut::detail {

/// One chunk after the pipeline: its offset in elements, the mask of filters skipped, its bytes.
struct FilteredChunk {
  std::vector<hsize_t> offset;
  std::uint32_t filter_mask = 0;
  std::vector<unsigned char> bytes;
};

/// The chunks, in row-major order of their offsets, of a row-major array of `dims` elements of
/// `element` bytes at `data`, cut into chunks of `chunk` (chunk_dims' shape: whole trailing axes,
/// one partial axis, ones before it, so that each chunk is a contiguous run of the array), passed
/// through Fletcher-32, shuffle and deflate at `deflate` (1 … 9). Chunks [first, first + count) of
/// that order, computed on up to `threads` threads (0: the OpenMP default).
std::vector<FilteredChunk> filtered_chunks(const void* data, const std::vector<hsize_t>& dims, const std::vector<hsize_t>& chunk,
                                           std::size_t element, int deflate, std::size_t first, std::size_t count, int threads);

/// The number of chunks of `dims` cut into `chunk`.
std::size_t chunk_count(const std::vector<hsize_t>& dims, const std::vector<hsize_t>& chunk);

}  // namespace hairlut::detail
