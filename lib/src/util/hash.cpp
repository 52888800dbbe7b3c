// Hasher (hash.hpp): XXH3-64 from xxHash, compiled into this file (header-only use, so that the
// library gains no link dependency), or FNV-1a 64.
#include "hairlut/util/hash.hpp"

#define XXH_INLINE_ALL
#include <xxhash.h>

namespace hairlut {

struct Hasher::Xxh3State {
  XXH3_state_t state;
};

const char* hash_algorithm_name(HashAlgorithm a) { return a == HashAlgorithm::xxh3_64 ? "xxh3-64" : "fnv1a-64"; }

std::optional<HashAlgorithm> hash_algorithm_from_name(std::string_view name) {
  if (name == "xxh3-64") return HashAlgorithm::xxh3_64;
  if (name == "fnv1a-64") return HashAlgorithm::fnv1a64;
  return std::nullopt;
}

const char* hash_sidecar_key(HashAlgorithm a) { return a == HashAlgorithm::xxh3_64 ? "xxh3_64" : "fnv1a64"; }

Hasher::Hasher(HashAlgorithm a) : algorithm_(a) {
  if (a == HashAlgorithm::xxh3_64) {
    xxh3_ = std::make_unique<Xxh3State>();
    XXH3_INITSTATE(&xxh3_->state);
    XXH3_64bits_reset(&xxh3_->state);
  }
}

Hasher::~Hasher() = default;

void Hasher::update(const void* data, std::size_t size) {
  if (size == 0) return;
  if (xxh3_) XXH3_64bits_update(&xxh3_->state, data, size);
  else fnv_.update(data, size);
}

std::uint64_t Hasher::value() const { return xxh3_ ? XXH3_64bits_digest(&xxh3_->state) : fnv_.value(); }

}  // namespace hairlut
