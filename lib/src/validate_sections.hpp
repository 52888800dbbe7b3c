// Validator and report sections that live in their own files (internal to the library).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hairlut/tables.hpp"
#include "hairlut/validate.hpp"

namespace hairlut::detail {

/// Mean-energy and dual-scattering tables (tables.dual_scattering, tables.engine): the consistency
/// a_f + a_b = Σ_p E_p between the two tables, the white furnace of the mean-energy table where it
/// has σa = 0 and d'Eon's uniform setting, the tables against dual_scattering() (no interpolation)
/// at sampled nodes, and the curves for the plots. Appends its checks; returns report["dual_scattering"].
nlohmann::ordered_json dual_scattering_section(const TableSet& set, const ValidationOptions& options,
                                               std::vector<nlohmann::ordered_json>& checks);

/// The HTML (inline SVG plots) and Markdown of that section; empty when the set has no such tables.
std::string render_dual_scattering_html(const nlohmann::ordered_json& report);
std::string render_dual_scattering_markdown(const nlohmann::ordered_json& report);

}  // namespace hairlut::detail
