// Validation reports: report.json (every figure), report.md (the summary, for terminals and CI
// logs) and report.html (one self-contained page: summary, then inline SVG plots).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace hairlut {

/// The Markdown summary of validate_tables()'s document.
std::string render_report_markdown(const nlohmann::ordered_json& report);

/// The self-contained HTML page (no scripts, no external resources) of the same document.
std::string render_report_html(const nlohmann::ordered_json& report);

/// Writes report.json, report.md and report.html into `directory` (created if needed): each under
/// a temporary name, renamed into place only when all three are complete. Throws IoError.
void write_report(const nlohmann::ordered_json& report, const std::filesystem::path& directory);

}  // namespace hairlut
