#include "hdf5_heap_check.hpp"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

namespace hairlut::detail {
namespace {

constexpr std::size_t kHeader = 16;  // "GCOL", version, 3 reserved bytes, 8-byte collection size
constexpr std::size_t kObjectHeader = 16;  // index (2), reference count (2), reserved (4), size (8)

std::uint64_t le64(const unsigned char* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

// `c` points at a candidate collection with `available` bytes from there to the end of the file.
// Returns "" when it is not a collection (HDF5 could not load it as one) or is walkable.
std::string walk_collection(const unsigned char* c, std::size_t available, std::uint64_t offset) {
  if (available < kHeader || c[4] != 1 || c[5] != 0 || c[6] != 0 || c[7] != 0) return "";
  const std::uint64_t size = le64(c + 8);
  if (size < kHeader || size > available) return "";
  const unsigned char* p = c + kHeader;
  const unsigned char* end = c + size;
  while (p < end) {
    if (static_cast<std::size_t>(end - p) < kObjectHeader) break;  // a tail too small for a record: free space
    const unsigned index = static_cast<unsigned>(p[0]) | (static_cast<unsigned>(p[1]) << 8);
    const std::uint64_t object = le64(p + 8);
    const std::uint64_t need = index > 0 ? kObjectHeader + ((object + 7) & ~std::uint64_t{7}) : object;
    if (need == 0 || object > size || need > static_cast<std::uint64_t>(end - p))
      return "global heap collection at byte " + std::to_string(offset) + " is corrupted (object record at byte " +
             std::to_string(offset + static_cast<std::uint64_t>(p - c)) + ")";
    p += need;
  }
  return "";
}

}  // namespace

std::string global_heap_problem(const unsigned char* data, std::size_t size) {
  for (std::size_t i = 0; i + 4 <= size; ++i) {
    const void* hit = std::memchr(data + i, 'G', size - i);
    if (!hit) break;
    i = static_cast<std::size_t>(static_cast<const unsigned char*>(hit) - data);
    if (i + 4 <= size && std::memcmp(data + i, "GCOL", 4) == 0)
      if (std::string why = walk_collection(data + i, size - i, i); !why.empty()) return why;
  }
  return "";
}

std::string global_heap_problem(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return "";
  std::error_code ec;
  const std::uintmax_t file_size = std::filesystem::file_size(file, ec);
  if (ec) return "";
  constexpr std::size_t kBlock = std::size_t{1} << 20;
  std::vector<unsigned char> block(kBlock + 3);
  std::size_t carried = 0;  // bytes kept from the previous block (a signature may straddle blocks)
  std::uint64_t block_start = 0;  // file offset of block[0]
  while (in) {
    in.read(reinterpret_cast<char*>(block.data() + carried), static_cast<std::streamsize>(kBlock));
    const std::size_t n = carried + static_cast<std::size_t>(in.gcount());
    if (n < 4) break;
    for (std::size_t i = 0; i + 4 <= n; ++i) {
      if (block[i] != 'G' || std::memcmp(block.data() + i, "GCOL", 4) != 0) continue;
      const std::uint64_t offset = block_start + i;
      // Read the candidate collection on its own (a real one is a few KiB; cap the read at 64 MiB).
      std::ifstream col(file, std::ios::binary);
      col.seekg(static_cast<std::streamoff>(offset));
      const std::uint64_t available = file_size - offset;
      unsigned char head[kHeader] = {};
      col.read(reinterpret_cast<char*>(head), kHeader);
      if (col.gcount() != static_cast<std::streamsize>(kHeader)) continue;
      const std::uint64_t size = le64(head + 8);
      if (size < kHeader || size > available || size > (std::uint64_t{64} << 20)) continue;
      std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
      col.seekg(static_cast<std::streamoff>(offset));
      col.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
      if (col.gcount() != static_cast<std::streamsize>(size)) continue;
      if (std::string why = walk_collection(bytes.data(), bytes.size(), offset); !why.empty()) return why;
    }
    carried = std::min<std::size_t>(3, n);
    std::memmove(block.data(), block.data() + n - carried, carried);
    block_start += n - carried;
  }
  return "";
}

}  // namespace hairlut::detail
