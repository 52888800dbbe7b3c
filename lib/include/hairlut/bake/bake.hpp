// The baker: evaluates the tables a BakeConfig asks for, in parallel with OpenMP.
//
// Every entry is computed independently from the config alone, so the result is bit-identical
// for any number of threads. Long bakes report progress through a callback and stop early when
// the caller raises a cancellation flag.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "hairlut/bake/config.hpp"
#include "hairlut/util/error.hpp"  // BakeCancelled
#include "hairlut/util/quadrature.hpp"
#include "hairlut/tables/slab_stream.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

struct BakeOptions {
  int threads = 0;  ///< OpenMP threads; 0 = the OpenMP default (all cores)
  /// Called from one thread at a time with the work done so far and the total (arbitrary units).
  std::function<void(std::string_view stage, std::size_t done, std::size_t total)> progress;
  const std::atomic<bool>* cancel = nullptr;  ///< polled between work items
};

/// What the baker decided and measured, for the tool to print and the metadata to record.
struct BakeReport {
  struct Folded {
    std::string lobe;
    double max_energy;
  };
  std::vector<Folded> folded;           ///< explicit lobes folded into the residual
  int explicit_lobes = 0;               ///< lobes baked explicitly after folding
  std::vector<std::string> notes;       ///< one line each (e.g. restricted ranges of scene mode)
  nlohmann::ordered_json resolution;    ///< counts chosen for tables.np.target_error and the error achieved
  std::size_t entries = 0;              ///< values computed
  double seconds = 0.0;
  int threads = 0;                      ///< threads the bake ran on (the HDF5 writer deflates on as many; 0: OpenMP's default)
};

/// One N_p grid: lobes p = 0 … lobes − 1 over σa_k, θd_t, the lobe's β list and φ_j.
struct NpGridRequest {
  double eta = 1.55;
  AbsorptionPath path = AbsorptionPath::chord;
  NpQuadratureConfig quadrature;
  int lobes = 3;
  std::vector<double> sigmas, thetas, phis;
  std::function<std::vector<double>(int p)> betas_of;
  /// Rules shared across calls (optional; a private cache is used when null).
  std::shared_ptr<GaussLegendreCache> rules;
  /// When set, only lobe `p` at β indices [b0, b1) is evaluated and passed to the output. The
  /// methods and rules are still chosen for the whole grid, so these values are bit-identical to
  /// the same entries of a whole-grid call (what slab-by-slab baking relies on).
  struct Subset {
    int p = 0;
    std::size_t b0 = 0, b1 = 0;
  };
  std::optional<Subset> only;
};
/// Receives every value: out(p, k, t, b, j, N_p). Called concurrently for distinct entries.
using NpGridOutput = std::function<void(int p, std::size_t k, std::size_t t, std::size_t b, std::size_t j, double value)>;

/// Evaluates an N_p grid with the request's method, in parallel (deterministic per entry).
/// Returns how many adaptive entries missed their tolerance (0 for the other methods).
std::size_t bake_np_grid(const NpGridRequest& request, const BakeOptions& options, const std::string& stage, const NpGridOutput& out);

/// Bakes every table of the config, by its model (lib/models/, bake/model_kind.hpp). Throws BakeCancelled or DomainError.
/// With `slabbed`, the generic N_p tables (over β, σa, θd, φ) and the generic M_p tables (over β,
/// θi, θr) of a d'Eon config are left without values and listed there with their producers, for
/// write_hdf5_slabbed to bake and write slab by slab; everything else (metadata and checksummed
/// notes included) is final when bake returns. Refused (DomainError) for what needs those tables
/// whole: the adaptive N_p method, tables.np.target_error and a model that does not bake slab by slab
/// (ModelKind::slab_by_slab: Marschner 2003).
TableSet bake(const BakeConfig& config, const BakeOptions& options = {}, BakeReport* report = nullptr, SlabbedTables* slabbed = nullptr);
/// What bake() refuses when asked for slabs (DomainError, one line): the tool's --check calls it
/// for a slabbed plan, so that it says valid only for what the bake accepts.
void check_slab_by_slab(const BakeConfig& config);

/// The generic N_p axes a scene in restrict-generic mode ends up with: sigma_a and beta ranges
/// narrowed to [min, max] of what its materials use (counts kept; one node if min = max).
std::vector<GridAxis> restricted_np_axes(const BakeConfig& config, std::vector<std::string>* notes = nullptr);

}  // namespace hairlut
