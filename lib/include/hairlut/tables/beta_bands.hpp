// β bands of the generic N_p tables: the β range split into bands, each baked as an ordinary 4D
// table (β, σa, θd, φ) with node counts of its own. N_p at small β needs many θd and φ nodes (both
// scale as 1/β) and few σa nodes; at large β the reverse holds loosely, so one tensor table pays
// the smallest β's θd × φ density at every β node. Bands let each β range pay only its own.
//
// Tables: band 0 is np/<lobe> (so a reader that knows nothing of bands finds a valid table over
// the first band's β range), band k ≥ 1 is np/<lobe>_band<k>. Each carries the attribute
// `beta_band` = {"index": k, "count": n, "range": [lo, hi]} (radians, the table's β axis range),
// and the set's metadata `np_beta_bands` lists the bands' ranges and table suffixes. Bands tile
// the β range without gaps, each edge-placed on β, so that a shared edge is a node of both bands.
// Lookup rule (beta_band_of): β ≤ hi of band 0 → band 0; else the first band k with β ≤ hi_k; β
// above the last band's hi → the last band (which clamps). A shared edge therefore reads the
// lower band; both store the same exact values on that β node, and differ there only by their
// interpolation over (σa, θd, φ).
//
// Here the bands as tables know them (names, lookup); a config's bands and their bake are in
// bake/beta_bands.hpp.
#pragma once

#include <string>
#include <vector>

#include "hairlut/tables/grid.hpp"

namespace hairlut {

/// One β band: the N_p axes (beta, sigma_a, theta_d, phi) of its table.
struct BetaBand {
  std::vector<GridAxis> axes;
  double lo() const { return axes.front().lo; }
  double hi() const { return axes.front().hi; }
};

/// The name suffix of band k's tables: "" for band 0, "_band<k>" otherwise.
std::string beta_band_suffix(int k);

/// Index of the band that serves β (the rule in the file comment); his: the bands' upper ends.
int beta_band_of(const std::vector<double>& his, double beta);

}  // namespace hairlut
