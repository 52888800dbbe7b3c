// Validator section "sampling_data": the sampling data stored next to the N_p and M_p tables
// against what the header-only sampler computes from the stored values (table_sampling.hpp).
#include <algorithm>
#include <cmath>

#include "hairlut/tables/table_sampling.hpp"
#include "validate_sections.hpp"

namespace hairlut::detail::validation {

json sampling_data_section(const TableSet& set, std::vector<json>& checks) {
  // Stored and recomputed data come from the same arithmetic on the same values, so they agree to
  // the last bit unless a file altered them; 1e-12 of a slice's scale leaves room for a reader
  // that converts the values through another type.
  const double tolerance = 1e-12;
  json rows = json::array();
  double worst = 0.0;
  std::size_t mismatches = 0, compared = 0;
  std::string absent;
  for (const SamplingDataCheck& c : check_sampling_data(set)) {
    rows.push_back({{"table", c.table},
                    {"stored", c.present},
                    {"problem", c.problem},
                    {"max_cdf_difference", c.max_cdf_difference},
                    {"max_mass_difference", c.max_mass_difference},
                    {"clamp_bound_mismatches", c.bound_mismatches},
                    {"cells_never_clamped", c.unclamped},
                    {"cells", c.cells}});
    if (!c.problem.empty()) {
      absent += (absent.empty() ? "" : ", ") + c.table;
      continue;
    }
    ++compared;
    // NaN-aware: std::max drops a NaN difference (then reported as 0, a pass); keep it instead.
    for (const double d : {c.max_cdf_difference, c.max_mass_difference})
      if (!(d <= worst)) worst = std::isnan(worst) ? worst : d;
    mismatches += c.bound_mismatches;
  }
  const std::string title = "Stored sampling data equal what the sampler computes from the tables";
  if (compared == 0) {
    checks.push_back(skipped("sampling_data", title, absent.empty() ? "no sampled tables" : "no usable stored sampling data (" + absent + ")"));
  } else {
    const bool pass = worst <= tolerance && mismatches == 0;
    checks.push_back(check("sampling_data", title, pass, worst, tolerance, "<=",
                           std::to_string(compared) + " tables compared, largest prefix difference " + fmt(worst) + " of the slice's scale, " +
                               std::to_string(mismatches) + " clamp bound mismatches" + (absent.empty() ? "" : "; not compared: " + absent)));
  }
  return {{"tolerance", tolerance}, {"tables", rows}};
}

}  // namespace hairlut::detail::validation
