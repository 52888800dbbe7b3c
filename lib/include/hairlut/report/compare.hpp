// Side-by-side comparison of hair models for one fiber: d'Eon 2011 (at β → 0 and at the given
// roughness), Marschner 2003 (exact and cubic paths, with its caustic replacement) and
// Kajiya–Kay. The figures (report JSON) show N_p(φ) per lobe at several θd, the total energy per
// θi of each model, where Marschner's cubic approximation departs from the exact roots, and where
// the TRT caustic sits. compare-hair-models writes them as compare.html/json/md; the validator
// adds them to the report of a Marschner table set.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "hairlut/bake/config.hpp"
#include "hairlut/physics/marschner.hpp"
#include "hairlut/physics/kajiya_kay.hpp"

namespace hairlut {

/// The fiber and the models' parameters. Both models see the same fiber (η, σa, absorption path)
/// and the same longitudinal widths: Marschner's Table 1 lobes from β_R and α_R; d'Eon's lobes take
/// those widths as β_m and β_n and the tilts 2α_p (hairlut's convention, see longitudinal_mp.hpp).
struct CompareSettings {
  double eta = 1.55;
  AbsorptionPath path = AbsorptionPath::chord;
  double sigma_a = 0.5;                     ///< absorption per unit radius
  std::string fiber = "";                   ///< how σa was chosen, for titles (e.g. "melanin 0.8, 0.1, channel G")
  double beta_r = radians(5.0);             ///< Marschner's β_R (d'Eon's R lobe roughness too)
  MarschnerConfig marschner;                ///< caustic, eccentricity, α_R, argument (both root finders are shown)
  double phi_h = 0.0;                       ///< azimuthal half angle for an eccentric fiber
  std::vector<double> theta_d = {0.0, radians(20.0), radians(40.0), radians(60.0)};
  std::vector<double> theta_i;              ///< energy curves; empty: −85° … 85° every 10°
  KajiyaKayParams kajiya_kay{0.0, 0.0, 0.0};  ///< exponent 0: n = 1/(4β_R²), k_s such that E_KK(0) = 1
  int phi_samples = 361;                    ///< φ in [0, π]
  bool energies = true;                     ///< compute the (slower) energy-per-θi curves
  std::function<void(std::string_view stage, std::size_t done, std::size_t total)> progress;
  const std::atomic<bool>* cancel = nullptr;
  /// Throws DomainError naming the first bad field.
  void validate() const;
};

/// Computes every figure of the comparison (see the header comment). Throws DomainError, or
/// BakeCancelled when the cancel flag is raised.
nlohmann::ordered_json compare_models(const CompareSettings& settings);

/// The comparison as HTML sections (headings from <h2>, inline SVG, no scripts), for embedding.
std::string render_compare_html_sections(const nlohmann::ordered_json& compare);
/// The comparison as one self-contained HTML page.
std::string render_compare_html(const nlohmann::ordered_json& compare);
/// The key numbers as Markdown.
std::string render_compare_markdown(const nlohmann::ordered_json& compare);
/// Writes compare.json, compare.md and compare.html into `directory` (atomically, as write_report).
void write_compare(const nlohmann::ordered_json& compare, const std::filesystem::path& directory);

}  // namespace hairlut
