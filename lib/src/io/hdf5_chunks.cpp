// Filtered chunks computed on the baker's threads (hdf5_chunks.hpp). Written here rather than
// left to HDF5 because HDF5 runs its filter pipeline on the one thread that calls H5Dwrite (and
// is not thread-safe), which made deflate the serial part of large bakes; the three filters are
// small, fixed algorithms of the HDF5 format, and zlib does the compression.
// Measured: tables/configs/generic.json bakes in 9.4 s of wall time on 2 cores with these chunks,
// 12.9 s with HDF5's own pipeline (15.5 s of CPU time either way; bake-hair-luts --threads 2).
#include "hdf5_chunks.hpp"

#include <omp.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace hairlut::detail {

namespace {

// HDF5's Fletcher-32 (16-bit big-endian words), fed in pieces of whole words: the sums are reduced
// after every 360 words counted from the start (the most whose sums cannot overflow 32 bits), after
// the last partial block, and once more at the end. (HDF5 takes a last odd byte as the high byte of
// a word; a chunk of 4- or 8-byte elements has none.)
struct Fletcher32 {
  std::uint32_t sum1 = 0, sum2 = 0;
  std::size_t in_block = 0;

  void reduce() {
    sum1 = (sum1 & 0xffffu) + (sum1 >> 16);
    sum2 = (sum2 & 0xffffu) + (sum2 >> 16);
  }
  void add(std::uint32_t word) {
    sum1 += word;
    sum2 += sum1;
    if (++in_block == 360) reduce(), in_block = 0;
  }
  void words(const unsigned char* p, std::size_t n) {
    for (std::size_t k = 0; k < n; ++k, p += 2) add((static_cast<std::uint32_t>(p[0]) << 8) | p[1]);
  }
  void zero_words(std::size_t n) {
    for (std::size_t k = 0; k < n; ++k) add(0);
  }
  std::uint32_t finish() {
    if (in_block > 0) reduce();
    reduce();
    return (sum2 << 16) | sum1;
  }
};

}  // namespace

std::size_t chunk_count(const std::vector<hsize_t>& dims, const std::vector<hsize_t>& chunk) {
  std::size_t n = 1;
  for (std::size_t d = 0; d < dims.size(); ++d) n *= static_cast<std::size_t>((dims[d] + chunk[d] - 1) / chunk[d]);
  return n;
}

namespace {

// The shuffle of `m1` elements from `src`, `m2 − m1` elements of zeros and the 4 bytes of
// `tail` (whole elements of it, then its bytes that make no whole element, left at the end):
// byte k of element i to position k · n + i, n the number of whole elements.
void shuffle(const unsigned char* src, std::size_t m1, std::size_t m2, const unsigned char* tail, std::size_t element, unsigned char* dst) {
  const std::size_t tail_elements = 4 / element, n = m2 + tail_elements, left = 4 % element;
  if (element <= 1 || n <= 1) {  // HDF5 leaves such buffers as they are
    std::memcpy(dst, src, m1 * element);
    std::memset(dst + m1 * element, 0, (m2 - m1) * element);
    std::memcpy(dst + m2 * element, tail, 4);
    return;
  }
  for (std::size_t k = 0; k < element; ++k) {
    unsigned char* d = dst + k * n;
    for (std::size_t i = 0; i < m1; ++i) d[i] = src[i * element + k];
    std::memset(d + m1, 0, m2 - m1);
    for (std::size_t i = 0; i < tail_elements; ++i) d[m2 + i] = tail[i * element + k];
  }
  std::memcpy(dst + n * element, tail + tail_elements * element, left);
}

// Chunk c of the row-major order through the pipeline, with `shuffled` and `packed` as scratch.
void filter_chunk(const unsigned char* data, const std::vector<hsize_t>& dims, const std::vector<hsize_t>& chunk, std::size_t element,
                  int deflate, std::size_t c, std::vector<unsigned char>& shuffled, std::vector<unsigned char>& packed, FilteredChunk& out) {
  const std::size_t D = dims.size();
  // The chunk's grid coordinates (row-major, last fastest), its offset and where it starts in the data.
  out.offset.assign(D, 0);
  std::size_t start = 0, stride = 1, rest = c;
  for (std::size_t d = D; d-- > 0;) {
    const std::size_t per = static_cast<std::size_t>((dims[d] + chunk[d] - 1) / chunk[d]);
    out.offset[d] = static_cast<hsize_t>(rest % per) * chunk[d];
    rest /= per;
    start += static_cast<std::size_t>(out.offset[d]) * stride;
    stride *= static_cast<std::size_t>(dims[d]);
  }
  std::size_t whole = 1, have = 1;  // elements of the whole chunk, and of it inside the extent
  for (std::size_t d = 0; d < D; ++d) {
    whole *= static_cast<std::size_t>(chunk[d]);
    have *= static_cast<std::size_t>(std::min<hsize_t>(chunk[d], dims[d] - out.offset[d]));
  }
  const unsigned char* src = data + start * element;
  // Fletcher-32 over the chunk zero-padded past the extent (whole elements: whole words), appended little-endian.
  Fletcher32 f;
  f.words(src, have * element / 2);
  f.zero_words((whole - have) * element / 2);
  const std::uint32_t sum = f.finish();
  const unsigned char tail[4] = {static_cast<unsigned char>(sum), static_cast<unsigned char>(sum >> 8), static_cast<unsigned char>(sum >> 16),
                                 static_cast<unsigned char>(sum >> 24)};
  const std::size_t n = whole * element + 4;
  shuffled.resize(n);
  shuffle(src, have, whole, tail, element, shuffled.data());
  // Deflate into as many bytes as HDF5's filter allows; past them the optional filter is skipped.
  uLongf room = static_cast<uLongf>(std::ceil(static_cast<double>(n) * 1.001) + 12.0);
  packed.resize(room);
  const int status = compress2(packed.data(), &room, shuffled.data(), static_cast<uLong>(n), deflate);
  if (status == Z_OK) {
    out.bytes.assign(packed.begin(), packed.begin() + static_cast<std::ptrdiff_t>(room));
    out.filter_mask = 0;
  } else if (status == Z_BUF_ERROR) {
    out.bytes = shuffled;
    out.filter_mask = 1u << 2;  // the third filter of the pipeline (deflate) skipped
  } else {
    throw std::runtime_error("zlib compress2 failed (" + std::to_string(status) + ")");
  }
}

}  // namespace

std::vector<FilteredChunk> filtered_chunks(const void* data, const std::vector<hsize_t>& dims, const std::vector<hsize_t>& chunk,
                                           std::size_t element, int deflate, std::size_t first, std::size_t count, int threads) {
  std::vector<FilteredChunk> out(count);
  const auto* bytes = static_cast<const unsigned char*>(data);
  const int t = std::max(1, std::min(threads > 0 ? threads : omp_get_max_threads(), static_cast<int>(count)));
  std::vector<std::string> errors(static_cast<std::size_t>(t));
#pragma omp parallel num_threads(t)
  {
    std::vector<unsigned char> shuffled, packed;
    const int me = omp_get_thread_num();
#pragma omp for schedule(dynamic, 1)
    for (std::size_t k = 0; k < count; ++k) {
      try {
        filter_chunk(bytes, dims, chunk, element, deflate, first + k, shuffled, packed, out[k]);
      } catch (const std::exception& e) {  // no exception may leave an OpenMP region
        errors[static_cast<std::size_t>(me)] = e.what();
      }
    }
  }
  for (const std::string& e : errors)
    if (!e.empty()) throw std::runtime_error(e);
  return out;
}

}  // namespace hairlut::detail
