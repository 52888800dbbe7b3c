// bench-hair-luts, section "representations": entries against worst and p99 sampled error and
// lookup cost per table representation (generic N_p domain; engine-preset budgets).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace bench {

/// Bakes each representation in memory and measures it (quick: fewer cases and points).
nlohmann::ordered_json bench_representations(bool quick, bool quiet);
/// Writes representations.json, .csv, .md and .svg (Pareto plot) into out_dir.
void write_representations(const nlohmann::ordered_json& rows, const nlohmann::ordered_json& machine, const std::string& out_dir);

}  // namespace bench
