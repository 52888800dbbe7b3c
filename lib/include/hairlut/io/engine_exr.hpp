// OpenEXR files of engine textures (their layout: engine_texture.hpp): one single-part half-float
// image per texture with the engine's channel count (RG or RGBA), the 3D texture's Z slices laid
// out as tiles of X × Y texels the way the engine lays them out or imports them (Unreal's 4 × 4
// atlas; HDRP's 64 slices as an 8 × 8 flipbook for Unity's 3D-texture import, bottom-left origin in
// each cell). The header states the layout, each axis and each channel (`hairlut.engine.*`, all of
// it as JSON in `hairlut.engine`); `exrheader FILE` prints them.
#pragma once

#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hairlut/io/engine_texture.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// An engine texture and the file it goes to (bake/outputs.hpp: engine_outputs names a config's).
struct EngineOutput {
  EngineTexture texture;
  std::filesystem::path path;
};

/// Writes the texture from the set's tables (all of the texture's tables share three axes: Z, Y, X
/// in storage order). Writes the texture's first channel_count channels. Values are scaled and
/// clamped as the channel says and stored as half; a value
/// that is not finite or beyond the half range is refused. Throws IoError.
void write_engine_texture(const TableSet& set, const EngineTexture& texture, const std::filesystem::path& file);

/// An engine texture read back: the image in row-major order per channel and the header's JSON.
struct EngineImage {
  int width = 0, height = 0;
  int channel_count = 0;                       ///< channels in the file (R, G, B, A in that order)
  std::array<std::vector<float>, 4> channels;  ///< R, G, B, A (those not in the file read as 0)
  nlohmann::json description;                  ///< the `hairlut.engine` header attribute
  /// The value of texel (x, y, z) in channel c.
  float texel(const EngineTexture& texture, int X, int Y, int x, int y, int z, int c) const;
};
/// Reads a file written by write_engine_texture. Throws IoError.
EngineImage read_engine_texture(const std::filesystem::path& file);

/// True when `file` is an OpenEXR file with a `hairlut.engine` header (an engine texture). Never throws.
bool is_engine_texture(const std::filesystem::path& file);

}  // namespace hairlut
