// Validation of the engine textures that bake-hair-luts writes (engine_exr.hpp): the file's layout,
// size, channel count, axes and constant channels against the preset's definition, and texels
// recomputed from the definition of their values (HDRP's kernels for unity-hdrp-hair,
// dual_scattering() for unreal-hair-strands) compared within the half rounding.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "hairlut/io/engine_exr.hpp"  // is_engine_texture
#include "hairlut/report/validate.hpp"

namespace hairlut {

/// Checks an engine texture; returns a report document {"source", "validator", "texture", "summary",
/// "checks": [{id, title, status, value, threshold, comparison, detail}]}. The texels recomputed are
/// all of them for HDRP's longitudinal and attenuation textures and an evenly spread subset of at most
/// options.max_points / 8 otherwise. Throws IoError (unreadable file), DomainError (a header that names
/// no known preset or texture), BakeCancelled.
nlohmann::ordered_json validate_engine_texture(const std::filesystem::path& file, const ValidationOptions& options = {});

/// report.json, report.md and report.html of that report in `directory` (created if needed). Throws IoError.
void write_engine_report(const nlohmann::ordered_json& report, const std::filesystem::path& directory);
/// The Markdown of that report.
std::string render_engine_report_markdown(const nlohmann::ordered_json& report);

}  // namespace hairlut
