// Which engine textures a config writes and where their texels go (engine_exr.hpp): plain
// planning, no OpenEXR, so that a bake can name its files without loading the OpenEXR library.
#include "hairlut/io/engine_exr.hpp"

namespace hairlut {

std::vector<EngineOutput> engine_outputs(const BakeConfig& c) {
  std::vector<EngineOutput> out;
  if (!c.engine) return out;
  for (const EngineTexture& t : engine_preset_textures(*c.engine))
    out.push_back({t, c.output.directory / (c.output.basename + "-" + t.file_suffix + ".exr")});
  return out;
}

std::array<long, 2> engine_pixel(const EngineTexture& t, int X, int Y, int x, int y, int z) {
  const long col = static_cast<long>(x) + static_cast<long>(X) * (z % t.tiles_per_row);
  const long row = static_cast<long>(t.flip_y ? Y - 1 - y : y) + static_cast<long>(Y) * (z / t.tiles_per_row);
  return {col, row};
}

}  // namespace hairlut
