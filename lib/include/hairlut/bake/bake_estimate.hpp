// Size of a bake before it starts: how many values its tables hold, and from that the memory and
// disk it needs, so that the baker can refuse a config that cannot fit instead of failing with
// std::bad_alloc after minutes of work, and can decide to bake its large tables slab by slab.
#pragma once

#include <cstdint>
#include <string>

#include "hairlut/bake/config.hpp"

namespace hairlut {

struct BakeEstimate {
  /// Table values the config asks for, estimated from its grids: N_p and the lobe energies per
  /// lobe, M_p per lobe, melanin, one dual-scattering table. An estimate (lobes folded at bake
  /// time, scene materials and engine textures are not modelled); saturates at UINT64_MAX.
  std::uint64_t values = 0;
  /// Of those, the values of the tables bake() can produce slab by slab (SlabbedTables): the
  /// generic N_p over (β, σa, θd, φ) and the generic M_p over (β, θi, θr) of a d'Eon config.
  std::uint64_t slabbable_values = 0;
  /// Values of the largest leading-axis row (one β) of those tables: the smallest slab possible.
  std::uint64_t slabbable_row_values = 0;
  /// Bytes per stored value (4 for float32 HDF5, 8 for float64).
  std::uint64_t value_bytes = 4;
  /// Bytes of memory at the peak when everything is held whole: the tables at their stored
  /// precision, plus one in-memory file image (HDF5 is written from memory) at most as large.
  /// An estimate, not a bound.
  std::uint64_t memory_bytes = 0;
  /// Bytes on disk before compression: every requested file at its precision (compression
  /// usually makes the files smaller, never larger by more than a few percent).
  std::uint64_t disk_bytes = 0;
};

/// The estimate for a validated config (never throws).
BakeEstimate estimate_bake(const BakeConfig& config);

/// Memory a bake takes beyond its tables, slabs and file image: the program, HDF5's caches and
/// one deflated chunk (≤ 4 MiB) per buffer, the threads' scratch. A fixed allowance.
inline constexpr std::uint64_t kBakeOverheadBytes = std::uint64_t{48} << 20;

/// How a bake stays within a memory budget.
struct MemoryPlan {
  bool slabbed = false;          ///< bake and write the slabbable tables slab by slab
  std::uint64_t slab_bytes = 0;  ///< largest slab when slabbed (two are in memory at once)
  std::uint64_t peak_bytes = 0;  ///< estimated peak: tables held whole (+ image, or + two slabs) + kBakeOverheadBytes
  std::string refused;           ///< non-empty: the bake cannot stay within the budget, and why (one phrase)
  std::uint64_t minimum_bytes = 0;  ///< when refused: the smallest budget the bake could stay within
};

/// The plan for a budget in bytes (0: no budget, everything held whole). Held whole when the
/// whole estimate fits; else slabbed with the largest slabs the rest of the budget allows
/// (at least 4 MiB, one HDF5 chunk, and at least one β row of the slabbed tables; at most 256 MiB,
/// beyond which larger slabs gain nothing).
MemoryPlan plan_memory(const BakeEstimate& estimate, std::uint64_t budget_bytes);

}  // namespace hairlut
