#include "hdf5_bytes.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

#include "hairlut/io/hdf5_io.hpp"  // IoError

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
// Returns "" when it is not a collection (HDF5 could not load it as one) or is walkable. Each
// record walked takes one of `steps`; none left: the walk stops (the caller reports it).
std::string walk_collection(const unsigned char* c, std::size_t available, std::uint64_t offset, std::uint64_t& steps) {
  if (available < kHeader || c[4] != 1 || c[5] != 0 || c[6] != 0 || c[7] != 0) return "";
  const std::uint64_t size = le64(c + 8);
  if (size < kHeader || size > available) return "";
  const unsigned char* p = c + kHeader;
  const unsigned char* end = c + size;
  while (p < end) {
    if (steps == 0) return "";
    --steps;
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

// Bob Jenkins' lookup3 hash ("hashlittle", byte-wise), which HDF5 uses for its metadata checksums.
std::uint32_t lookup3(const unsigned char* k, std::size_t length) {
  auto rot = [](std::uint32_t x, int r) { return (x << r) | (x >> (32 - r)); };
  std::uint32_t a, b, c;
  a = b = c = 0xdeadbeefu + static_cast<std::uint32_t>(length);
  auto word = [&](const unsigned char* p, std::size_t n) {  // n (<= 4) little-endian bytes
    std::uint32_t w = 0;
    for (std::size_t i = 0; i < n; ++i) w |= static_cast<std::uint32_t>(p[i]) << (8 * i);
    return w;
  };
  while (length > 12) {
    a += word(k, 4), b += word(k + 4, 4), c += word(k + 8, 4);
    a -= c, a ^= rot(c, 4), c += b;
    b -= a, b ^= rot(a, 6), a += c;
    c -= b, c ^= rot(b, 8), b += a;
    a -= c, a ^= rot(c, 16), c += b;
    b -= a, b ^= rot(a, 19), a += c;
    c -= b, c ^= rot(b, 4), b += a;
    length -= 12, k += 12;
  }
  if (length == 0) return c;
  a += word(k, std::min<std::size_t>(length, 4));
  if (length > 4) b += word(k + 4, std::min<std::size_t>(length - 4, 4));
  if (length > 8) c += word(k + 8, length - 8);
  c ^= b, c -= rot(b, 14);
  a ^= c, a -= rot(c, 11);
  b ^= a, b -= rot(a, 25);
  c ^= b, c -= rot(b, 16);
  a ^= c, a -= rot(c, 4);
  b ^= a, b -= rot(a, 14);
  c ^= b, c -= rot(b, 24);
  return c;
}

}  // namespace

void write_file_bytes(const std::filesystem::path& path, std::span<const char> bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) throw IoError(path.string() + ": cannot create file (" + std::strerror(errno) + ")");
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = n < 0 ? errno : ENOSPC;
      ::close(fd);
      throw IoError(path.string() + ": cannot write (" + std::strerror(err) + ")");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
    const int err = errno;
    ::close(fd);
    throw IoError(path.string() + ": cannot write (" + std::strerror(err) + ")");
  }
  if (::close(fd) != 0) throw IoError(path.string() + ": cannot write (" + std::strerror(errno) + ")");
}

void sync_file(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError(path.string() + ": cannot write (" + std::strerror(errno) + ")");
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
    const int err = errno;
    ::close(fd);
    throw IoError(path.string() + ": cannot write (" + std::strerror(err) + ")");
  }
  ::close(fd);
}

// Superblock versions 2 and 3: 12 bytes, four addresses, then the lookup3 checksum.
void fix_superblock_checksum(std::span<char> image) {
  auto* b = reinterpret_cast<unsigned char*>(image.data());
  if (image.size() < 12 || b[8] < 2) return;
  const std::size_t n = 12 + 4 * static_cast<std::size_t>(b[9]);
  if (image.size() < n + 4) return;
  b[11] = 0;  // file consistency flags: closed
  const std::uint32_t sum = lookup3(b, n);
  for (int i = 0; i < 4; ++i) b[n + static_cast<std::size_t>(i)] = static_cast<unsigned char>(sum >> (8 * i));
}

std::string global_heap_problem(const unsigned char* data, std::size_t size, const std::function<void(std::size_t)>& scanned) {
  // Candidates may overlap (a collection's bytes can spell "GCOL" again, every 4 bytes): the
  // records walked over all of them are bounded by a multiple of the file's size, so the scan
  // stays linear. A file HDF5 wrote walks each real collection once, its records at least 16
  // bytes long, well within the bound.
  std::uint64_t steps = 4 * static_cast<std::uint64_t>(size) + (std::uint64_t{1} << 16);
  constexpr std::size_t kReport = std::size_t{64} << 20;
  std::size_t reported = 0;
  for (std::size_t i = 0; i + 4 <= size; ++i) {
    const void* hit = std::memchr(data + i, 'G', size - i);
    if (!hit) break;
    i = static_cast<std::size_t>(static_cast<const unsigned char*>(hit) - data);
    if (scanned && i >= reported + kReport) scanned(reported = i);  // the walk goes forward from i
    if (i + 4 <= size && std::memcmp(data + i, "GCOL", 4) == 0) {
      if (std::string why = walk_collection(data + i, size - i, i, steps); !why.empty()) return why;
      if (steps == 0) return "global heap collections overlap beyond any HDF5 file's (corrupted or hostile file)";
    }
  }
  return "";
}

std::string global_heap_problem(const std::filesystem::path& file) {
  // The file mapped read-only: each candidate collection is walked in place, with no copy.
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return "";  // the open that follows reports it
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size <= 0) {
    ::close(fd);
    return "";
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  void* map = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
  ::close(fd);
  if (map == MAP_FAILED) return "cannot map the file to screen it (" + std::string(std::strerror(errno)) + ")";
  ::madvise(map, size, MADV_SEQUENTIAL);
  // The pages behind the scan leave this process (the page cache keeps them): the mapped file
  // would otherwise count whole in its resident memory, a set larger than memory included.
  const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  std::size_t released = 0;
  std::string why = global_heap_problem(static_cast<const unsigned char*>(map), size, [&](std::size_t below) {
    const std::size_t upto = below / page * page;
    ::madvise(static_cast<unsigned char*>(map) + released, upto - released, MADV_DONTNEED);
    released = upto;
  });
  ::munmap(map, size);
  return why;
}

}  // namespace hairlut::detail
