// Hashing for change detection and corruption checks (not for security): FNV-1a 64 (configs'
// hashes; the checksums of table files before format 2.0) and XXH3-64 (the checksums of table
// files from format 2.0 on, docs/table-format.md).
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace hairlut {

/// Incremental FNV-1a 64: h = (h XOR byte) · 1099511628211 over every byte, from 14695981039346656037.
/// One dependent multiply per byte (about 4 cycles a byte): fine for short texts, slow for tables.
class Fnv1a64 {
 public:
  void update(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      h_ ^= p[i];
      h_ *= 1099511628211ULL;
    }
  }
  void update(std::string_view s) { update(s.data(), s.size()); }
  std::uint64_t value() const { return h_; }
  /// The hash as 16 lowercase hex digits.
  std::string hex() const { return hex16(h_); }
  static std::string hex16(std::uint64_t v) {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
    return buf;
  }

 private:
  std::uint64_t h_ = 14695981039346656037ULL;
};

/// FNV-1a 64 of a byte string as 16 hex digits.
inline std::string fnv1a64_hex(std::string_view bytes) {
  Fnv1a64 h;
  h.update(bytes);
  return h.hex();
}

/// The checksums a table file may record. Files of format 1.x record FNV-1a 64 (and do not name
/// it); files of format 2.x name theirs (HDF5 `hairlut_checksum_algorithm`, OpenEXR
/// `hairlut.checksum_algorithm`, the sidecar's key `xxh3_64` or `fnv1a64` per file).
enum class HashAlgorithm { fnv1a64, xxh3_64 };

/// What hairlut writes: XXH3-64 (xxHash 0.8, seed 0), about 20 times faster than FNV-1a here.
inline constexpr HashAlgorithm kFileHash = HashAlgorithm::xxh3_64;

/// "fnv1a-64" or "xxh3-64", the names files record.
const char* hash_algorithm_name(HashAlgorithm a);
/// The algorithm of a recorded name; nullopt for a name this hairlut does not know.
std::optional<HashAlgorithm> hash_algorithm_from_name(std::string_view name);
/// The sidecar's key for a file's digest: "fnv1a64" or "xxh3_64".
const char* hash_sidecar_key(HashAlgorithm a);

/// Incremental hash of either algorithm: the same value whatever the pieces the bytes come in.
class Hasher {
 public:
  explicit Hasher(HashAlgorithm a = kFileHash);
  ~Hasher();
  Hasher(const Hasher&) = delete;
  Hasher& operator=(const Hasher&) = delete;
  void update(const void* data, std::size_t size);
  void update(std::string_view s) { update(s.data(), s.size()); }
  std::uint64_t value() const;
  /// The hash as 16 lowercase hex digits.
  std::string hex() const { return Fnv1a64::hex16(value()); }
  HashAlgorithm algorithm() const { return algorithm_; }

 private:
  struct Xxh3State;
  HashAlgorithm algorithm_;
  Fnv1a64 fnv_;
  std::unique_ptr<Xxh3State> xxh3_;
};

}  // namespace hairlut
