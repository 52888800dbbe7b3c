// Size of a bake before it starts: how many values its tables hold, and from that the memory and
// disk it needs, so that the baker can refuse a config that cannot fit instead of failing with
// std::bad_alloc after minutes of work, and can decide to bake its large tables slab by slab.
#pragma once

#include <cstdint>
#include <string>

#include "hairlut/bake/config.hpp"

namespace hairlut {

struct BakeEstimate {
  /// Table values the config asks for, counted table by table as bake() makes them: generic N_p
  /// per explicit lobe, its energy and residual tables (on the energy axes when given), Fourier
  /// coefficients, M_p per lobe and the residual, the two melanin tables, per-material RGB N_p, M_p
  /// and energies, Marschner N_p (TRT over φh too) and energies, dual-scattering and mean-energy
  /// tables, engine presets' tables. Not modelled: lobes folded at bake time (counted, so the
  /// estimate is high by their share), counts that target_error chooses (the given ones are
  /// counted) and β bands. Saturates at UINT64_MAX.
  std::uint64_t values = 0;
  /// Of those, the values of the tables bake() can produce slab by slab (SlabbedTables): the
  /// generic N_p over (β, σa, θd, φ) and the generic M_p over (β, θi, θr) of a d'Eon config.
  std::uint64_t slabbable_values = 0;
  /// Values of the largest leading-axis row (one β) of those tables: the smallest slab possible.
  std::uint64_t slabbable_row_values = 0;
  /// Bytes per stored value (4 for float32 HDF5, 8 for float64).
  std::uint64_t value_bytes = 4;
  /// Bytes of the tables at their stored precision.
  std::uint64_t table_bytes = 0;
  /// Bytes of the importance sampler's data (output.sampling_data) beside every N_p and M_p table
  /// the sampler supports: per value a float64 prefix integral and a float32 clamp bound (12 bytes,
  /// three times a float32 table), per slice a float64 mass.
  std::uint64_t sampling_bytes = 0;
  /// The largest single table or sampling array, in bytes (what one deflate chunk holds at most).
  std::uint64_t largest_table_bytes = 0;
  /// Bytes of memory at the peak when everything is held whole, without the program itself
  /// (kBakeBaseBytes): the tables and sampling data, then, while the HDF5 file is written, its
  /// in-memory image (the expected deflated size of the values when deflated, plus the one growth step
  /// the writer's core driver holds beyond the file: an eighth of the values) and the deflate
  /// threads' scratch; or, while OpenEXR is written, its frame buffers. Or, when larger, the
  /// tables and the curves over θd that a dual-scattering grid (tables.dual_scattering, an engine
  /// preset's) holds while it runs.
  std::uint64_t memory_bytes = 0;
  /// Bytes on disk before compression: every requested file at its precision, the sidecar and
  /// the engine textures (a bound: compression never makes the files larger by more than a few
  /// percent). What the baker checks the free space against.
  std::uint64_t disk_bytes = 0;
  /// Bytes on disk expected after compression: deflated HDF5 at the config's mean of the deflated
  /// fractions below (each kind of array at its own), float OpenEXR at kDeflatedFraction, half-float
  /// OpenEXR and engine textures at kHalfZipFraction, uncompressed ones at their size. An
  /// estimate, not a bound.
  std::uint64_t disk_expected_bytes = 0;
};

/// The fraction of its bytes that deflate (with the shuffle filter, any level from 1) leaves of
/// hairlut's tables (float32) in HDF5, kind by kind, measured dataset by dataset (h5ls -v) in the
/// shipped configs' files. N_p, energy, Fourier and preset tables: 0.34 to 0.62. Also what
/// OpenEXR's zip leaves of a float file as a whole (0.50 and 0.57 measured for show-example.json
/// and marschner.json).
inline constexpr double kDeflatedFraction = 0.45;
/// M_p tables: 0.54 to 0.67 (one table of show-example.json 0.31).
inline constexpr double kDeflatedMpFraction = 0.6;
/// The sampler's float64 prefix integrals and masses: 0.46 to 0.58 (their low mantissa bytes are
/// noise to deflate).
inline constexpr double kDeflatedPrefixFraction = 0.55;
/// The sampler's float32 clamp bounds of a table with a cubic axis: 0.18 (default.json). Without
/// one, an interpolant of non-negative values never dips below 0, every bound is 0 and deflate
/// leaves nothing (under 0.001 measured).
inline constexpr double kDeflatedClampFraction = 0.2;
/// The fraction that OpenEXR's zip leaves of half-float tables and engine textures: measured
/// 0.14 to 0.21 for the shipped configs' EXR files and textures.
inline constexpr double kHalfZipFraction = 0.2;

/// What deflate leaves of a run of repeated bytes: its longest match, 258 bytes, costs about 3.
inline constexpr double kDeflatedRepeatFraction = 3.0 / 258.0;

/// Memory of the baker without its tables: the program, its libraries, the parsed config and
/// schema (measured: 22 MiB at the peak of a bake whose tables hold 0.5 MiB), and per OpenMP
/// thread its stack and scratch (0.2 MiB measured from 1 to 8 threads).
inline constexpr std::uint64_t kBakeBaseBytes = std::uint64_t{22} << 20;
/// Of that, the program before any table is made or written: its libraries, config and schema
/// (measured: the peak of --check, 14.4 to 15.0 MiB for three shipped configs; a bake's peak while
/// a dual-scattering grid runs, less its tables and curves, 14.8 MiB). The rest is the writer's.
inline constexpr std::uint64_t kBakeProgramBytes = std::uint64_t{15} << 20;
inline constexpr std::uint64_t kBakeThreadBytes = std::uint64_t{1} << 18;

/// The estimate for a validated config (never throws); `threads`: the bake's OpenMP threads
/// (0: one).
BakeEstimate estimate_bake(const BakeConfig& config, int threads = 0);

/// Memory a slab-by-slab bake takes beyond its tables, slabs and file image: the program, HDF5's
/// caches and one deflated chunk (≤ 4 MiB) per buffer, the threads' scratch. A fixed allowance,
/// larger than kBakeBaseBytes plus the deflate threads' scratch, so that slabs stay within the budget.
inline constexpr std::uint64_t kBakeOverheadBytes = std::uint64_t{48} << 20;

/// How a bake stays within a memory budget.
struct MemoryPlan {
  bool slabbed = false;          ///< bake and write the slabbable tables slab by slab
  std::uint64_t slab_bytes = 0;  ///< largest slab when slabbed (two are in memory at once)
  std::uint64_t peak_bytes = 0;  ///< estimated peak: held whole, kBakeBaseBytes + memory_bytes; slabbed, the rest + two slabs + kBakeOverheadBytes
  std::string refused;           ///< non-empty: the bake cannot stay within the budget, and why (one phrase)
  std::uint64_t minimum_bytes = 0;  ///< when refused: the smallest budget the bake could stay within
};

/// The plan for a budget in bytes (0: no budget, everything held whole). Held whole when the
/// whole estimate fits; else slabbed with the largest slabs the rest of the budget allows
/// (at least 4 MiB, one HDF5 chunk, and at least one β row of the slabbed tables; at most 256 MiB,
/// beyond which larger slabs gain nothing).
MemoryPlan plan_memory(const BakeEstimate& estimate, std::uint64_t budget_bytes);

}  // namespace hairlut
