// Size of a bake before it starts: how many values its tables hold, and from that the memory and
// disk it needs, so that the baker can refuse a config that cannot fit instead of failing with
// std::bad_alloc after minutes of work.
#pragma once

#include <cstdint>

#include "hairlut/config.hpp"

namespace hairlut {

struct BakeEstimate {
  /// Table values the config asks for, estimated from its grids: N_p and the lobe energies per
  /// lobe, M_p per lobe, melanin, one dual-scattering table. An estimate (lobes folded at bake
  /// time, scene materials and engine textures are not modelled); saturates at UINT64_MAX.
  std::uint64_t values = 0;
  /// Bytes of memory at the peak: the tables at their stored precision, plus one in-memory file
  /// image (HDF5 is written from memory) at most as large. An estimate, not a bound.
  std::uint64_t memory_bytes = 0;
  /// Bytes on disk before compression: every requested file at its precision (compression
  /// usually makes the files smaller, never larger by more than a few percent).
  std::uint64_t disk_bytes = 0;
};

/// The estimate for a validated config (never throws).
BakeEstimate estimate_bake(const BakeConfig& config);

}  // namespace hairlut
