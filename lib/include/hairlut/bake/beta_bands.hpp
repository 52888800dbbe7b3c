// β bands of a config and their bake (tables/beta_bands.hpp describes the bands and their
// tables): tables.np.beta_bands parsed and recorded, the tables of bands 1 … n − 1 baked.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hairlut/tables/beta_bands.hpp"
#include "hairlut/tables/grid.hpp"

namespace hairlut {

struct BakeConfig;
struct BakeOptions;
struct BakeReport;
struct TableSet;
enum class Precision;

/// tables.np.beta_bands of a config: each element's axes are `np_axes_json` (tables.np.axes)
/// with the element's keys (beta, sigma_a, theta_d, phi) merged in key by key (JSON merge patch),
/// turned into axes by `make_axes` (the config's own axis parser). Checks: at least one band,
/// β edge-placed in each band, bands contiguous and increasing (band k's lo is band k − 1's hi),
/// and every band's σa and θd ranges equal to tables.np.axes's (the energy tables are shared).
/// Throws DomainError("tables.np.beta_bands[k].<field> <reason>").
std::vector<BetaBand> parse_beta_bands(const nlohmann::json& bands, const nlohmann::json& np_axes_json,
                                       const std::function<std::vector<GridAxis>(const nlohmann::json&, const std::string&)>& make_axes);

/// The bands as the normalized config records them.
nlohmann::json beta_bands_json(const std::vector<BetaBand>& bands);

/// After the generic N_p tables of band 0 (np/<lobe>, p < lobes) are in `set`: tags them with
/// their band, bakes bands 1 … n − 1 as np/<lobe>_band<k> (same quadrature, same energy
/// normalization: factor np/energy_<lobe>) and records `np_beta_bands` in the set's metadata.
void append_beta_band_tables(const BakeConfig& c, const std::vector<BetaBand>& bands, int lobes, bool normalize_energy, Precision precision,
                             const BakeOptions& opt, TableSet& set, BakeReport& report);

}  // namespace hairlut
