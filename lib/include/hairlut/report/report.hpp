// Validation reports: report.json (every figure), report.md (the summary, for terminals and CI
// logs) and report.html (one self-contained page: summary, then inline SVG plots).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace hairlut {

/// The Markdown summary of validate_tables()'s document.
std::string render_report_markdown(const nlohmann::ordered_json& report);

/// The self-contained HTML page (no scripts, no external resources) of the same document.
std::string render_report_html(const nlohmann::ordered_json& report);

/// A complete HTML page (shared style of hairlut's reports, no scripts) around `body`.
std::string html_page(const std::string& title, const std::string& body);

/// Writes each (file name, text) into `directory` (created if needed) under a temporary name and
/// renames them into place only when all are complete; removes the temporaries on failure.
/// Throws IoError.
void write_text_files(const std::filesystem::path& directory, const std::vector<std::pair<std::string, std::string>>& files);

/// Writes report.json, report.md and report.html into `directory` (created if needed): each under
/// a temporary name, renamed into place only when all three are complete. Throws IoError.
void write_report(const nlohmann::ordered_json& report, const std::filesystem::path& directory);

}  // namespace hairlut
