// The layout of an engine texture: which table each channel samples and how it is encoded, and
// where a 3D texture's texels go in the 2D atlas of its file. A file-format description (the
// export presets in bake/engine_presets.hpp fill it in; io/engine_exr.hpp writes and reads it).
#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <string>

namespace hairlut {

/// The sampled quantities of an engine texture channel.
struct EngineChannel {
  std::string table;     ///< table path ("unreal/dual_scattering/a_f"), or empty for a constant
  double constant = 0.0; ///< the value when `table` is empty
  double scale = 1.0;    ///< the texture stores clamp(scale × value) (see saturate)
  bool saturate = false; ///< clamp to [0, 1] as the engine's own bake does
};

/// One engine texture: a 3D texture of X × Y × Z texels written as a 2D atlas of Z tiles of X × Y.
struct EngineTexture {
  int channel_count = 4;    ///< channels written: R, G (2), R, G, B (3) or R, G, B, A (4), the engine's own count
  std::string preset;       ///< "unreal-hair-strands", "unity-hdrp-hair"
  std::string name;         ///< "dual-scattering", "mean-energy", "attenuation", ...
  std::string file_suffix;  ///< appended to the output basename: <basename>-<suffix>.exr
  std::string group;        ///< table group of its sources
  EngineChannel channels[4];  ///< R, G, B, A (those past channel_count are not written)
  int tiles_per_row = 1;    ///< tile of slice z at column z % tiles_per_row, row z / tiles_per_row
  bool flip_y = false;      ///< texel row y at image row Y − 1 − y within its tile (bottom-left origin)
  std::string engine_format;  ///< the engine's texture format, e.g. "PF_FloatRGBA (RGBA16F)"
  std::string description;    ///< which shader reads it and how
  nlohmann::ordered_json describe() const;
};

/// Image position (column, row) of texel (x, y, z) of a texture of X × Y texels per slice.
std::array<long, 2> engine_pixel(const EngineTexture& texture, int X, int Y, int x, int y, int z);

}  // namespace hairlut
