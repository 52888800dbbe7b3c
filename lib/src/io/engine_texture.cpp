// An engine texture's layout (engine_texture.hpp): its description, as the file's header and the
// set's sidecar record it, and texel placement; no OpenEXR here.
#include "hairlut/io/engine_texture.hpp"

namespace hairlut {
namespace {
using json = nlohmann::ordered_json;
}  // namespace

json EngineTexture::describe() const {
  json j;
  j["preset"] = preset;
  j["texture"] = name;
  j["engine_format"] = engine_format;
  j["channel_count"] = channel_count;
  j["tiles_per_row"] = tiles_per_row;
  j["flip_y"] = flip_y;
  json ch = json::object();
  const char* names[4] = {"R", "G", "B", "A"};
  for (int c = 0; c < channel_count; ++c) {
    const EngineChannel& e = channels[c];
    if (e.table.empty()) ch[names[c]] = {{"constant", e.constant}};
    else ch[names[c]] = {{"table", e.table}, {"scale", e.scale}, {"saturate", e.saturate}};
  }
  j["channels"] = ch;
  j["description"] = description;
  return j;
}

std::array<long, 2> engine_pixel(const EngineTexture& t, int X, int Y, int x, int y, int z) {
  const long col = static_cast<long>(x) + static_cast<long>(X) * (z % t.tiles_per_row);
  const long row = static_cast<long>(t.flip_y ? Y - 1 - y : y) + static_cast<long>(Y) * (z / t.tiles_per_row);
  return {col, row};
}

}  // namespace hairlut
