// FNV-1a 64-bit hashing for change detection and corruption checks (not for security).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace hairlut {

/// Incremental FNV-1a 64: h = (h XOR byte) · 1099511628211 over every byte, from 14695981039346656037.
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
  std::string hex() const {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h_));
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

}  // namespace hairlut
