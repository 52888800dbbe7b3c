// A table set laid out for hairlut's GLSL runtime (docs/gpu.md), as files an engine loads without
// hairlut: what gpu_textures.hpp and gpu_buffers.hpp build in memory, written once.
//   - A per-material set (scene.mode per-material): for lib/shaders/hairlut.glsl, the N_p and M_p
//     2D array textures as OpenEXR images (RGBA, float32 or half; layer l is rows l·height to
//     (l + 1)·height − 1, so that the image is the array's texels in upload order), the
//     HairlutMaterial blocks (std140 bytes) and the sampling rows (float32).
//   - A generic set: for lib/shaders/hairlut_generic.glsl, the HairlutGenericSet block (std140
//     bytes) and every table's values (float32).
// Binary files are little-endian. <base>.gpu.json describes them (kind, shader, each file's name,
// size and element count, the materials in block order) and is written last: every file goes to a
// temporary name first and is renamed into place when all are complete.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "hairlut/sampler/gpu_buffers.hpp"
#include "hairlut/sampler/gpu_textures.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

struct GpuExportOptions {
  bool half = false;  ///< textures as RGBA16F (half) instead of RGBA32F; buffers stay float32
};

/// A set as the GLSL runtime reads it: the textures of every material, or the generic buffers.
struct GpuLayout {
  std::string kind;                          ///< "materials" or "generic"
  std::vector<std::string> materials;        ///< the material groups, in block order
  gpu::MaterialTextures textures;            ///< kind "materials"
  std::optional<gpu::GenericBuffers> generic;  ///< kind "generic"
};

/// Lays out `set`: every "materials/<name>" group when it has one, else its generic d'Eon tables.
/// Throws DomainError naming what the shaders cannot read (a Fourier set, β bands, axes).
GpuLayout gpu_layout(const TableSet& set);

/// Writes `set`'s layout as <base>.gpu.json and the files it names beside it; returns their paths,
/// the description last. Throws DomainError as gpu_layout, IoError when a file cannot be written
/// (no file of the export is then left in place).
std::vector<std::filesystem::path> write_gpu_export(const TableSet& set, const std::filesystem::path& base, const GpuExportOptions& options = {});

/// Reads an export back from its description (a C++ engine's loader, and the tests): the same
/// layout, with half textures as the float values they hold. Treats the files as hostile: throws
/// IoError naming the file and the reason for a missing file, a malformed description, or a size
/// or count that does not match it.
GpuLayout read_gpu_export(const std::filesystem::path& description);

}  // namespace hairlut
