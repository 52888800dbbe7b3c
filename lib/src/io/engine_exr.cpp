#include "hairlut/io/engine_exr.hpp"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <algorithm>
#include <cmath>

#include "hairlut/io/hdf5_io.hpp"  // IoError
#include "hairlut/util/version.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;
constexpr const char* kChannels[4] = {"R", "G", "B", "A"};

std::string axis_text(const GridAxis& a, char letter) {
  return std::string(1, letter) + " = " + a.name + " (" + std::to_string(a.count) + " texels, " + std::string(to_string(a.placement)) + "): " + a.long_name;
}

}  // namespace

void write_engine_texture(const TableSet& set, const EngineTexture& t, const std::filesystem::path& file) {
  const std::string name = file.string();
  auto fail = [&](const std::string& what) { throw IoError(name + ": " + what); };
  // The source tables and their shared axes.
  const Table* tables[4] = {};
  const Table* first = nullptr;
  for (int c = 0; c < 4; ++c) {
    if (t.channels[c].table.empty()) continue;
    tables[c] = set.find(t.channels[c].table);
    if (!tables[c]) fail("table " + t.channels[c].table + " of texture " + t.name + " was not baked");
    if (!first) first = tables[c];
    if (tables[c]->axes.size() != 3) fail(t.channels[c].table + ": an engine texture needs three axes");
    for (std::size_t k = 0; k < 3; ++k)
      if (tables[c]->axes[k].to_json() != first->axes[k].to_json()) fail("the tables of texture " + t.name + " do not share their axes");
  }
  if (!first) fail("texture " + t.name + " has no table");
  const int Z = first->axes[0].count, Y = first->axes[1].count, X = first->axes[2].count;
  const int rows = (Z + t.tiles_per_row - 1) / t.tiles_per_row;
  const long width = static_cast<long>(X) * std::min(Z, t.tiles_per_row), height = static_cast<long>(Y) * rows;
  if (width > 65536 || height > 65536) fail("texture too large for one image");
  const int nch = t.channel_count;
  if (nch < 1 || nch > 4) fail("texture " + t.name + ": channel count must lie in [1, 4]");
  std::array<std::vector<half>, 4> px;
  for (auto& v : px) v.assign(static_cast<std::size_t>(width * height), half(0.0f));
  for (int c = 0; c < nch; ++c) {
    const EngineChannel& ch = t.channels[c];
    for (int z = 0; z < Z; ++z)
      for (int y = 0; y < Y; ++y)
        for (int x = 0; x < X; ++x) {
          double v = ch.constant;
          if (tables[c]) {
            const std::size_t index = (static_cast<std::size_t>(z) * Y + static_cast<std::size_t>(y)) * X + static_cast<std::size_t>(x);
            v = ch.scale * tables[c]->get(index);
            if (ch.saturate) v = std::clamp(v, 0.0, 1.0);
          }
          if (!std::isfinite(v) || std::abs(v) > 65504.0)
            fail(ch.table + ": value " + std::to_string(v) + " at texel (" + std::to_string(x) + ", " + std::to_string(y) + ", " +
                 std::to_string(z) + ") does not fit a half float");
          const auto [col, row] = engine_pixel(t, X, Y, x, y, z);
          px[static_cast<std::size_t>(c)][static_cast<std::size_t>(row * width + col)] = half(static_cast<float>(v));
        }
  }
  // Header: the layout in words and as JSON.
  const std::string tile = std::to_string(X) + " x " + std::to_string(Y);
  std::string layout = "texel (x, y, z) of the " + std::to_string(X) + " x " + std::to_string(Y) + " x " + std::to_string(Z) +
                       " texture is pixel (x + " + std::to_string(X) + " (z mod " + std::to_string(t.tiles_per_row) + "), " +
                       (t.flip_y ? std::to_string(Y - 1) + " - y" : std::string("y")) + " + " + std::to_string(Y) + " floor(z / " +
                       std::to_string(t.tiles_per_row) + ")): " + std::to_string(Z) + " tiles of " + tile + ", " +
                       std::to_string(std::min(Z, t.tiles_per_row)) + " per row" +
                       (t.flip_y ? "; rows flipped within each tile (texel y = 0 at the bottom, the engine's texture origin)" : "");
  json desc = t.describe();
  desc["layout"] = layout;
  desc["size"] = {X, Y, Z};
  desc["axes"] = {{"X", first->axes[2].to_json()}, {"Y", first->axes[1].to_json()}, {"Z", first->axes[0].to_json()}};
  desc["hairlut_version"] = kVersion;
  desc["config_hash"] = set.metadata.value("config_hash", std::string());
  Imf::Header h(static_cast<int>(width), static_cast<int>(height));
  h.compression() = Imf::ZIP_COMPRESSION;
  for (int c = 0; c < nch; ++c) h.channels().insert(kChannels[c], Imf::Channel(Imf::HALF));
  h.insert("hairlut.engine", Imf::StringAttribute(desc.dump()));
  h.insert("hairlut.engine.layout", Imf::StringAttribute(layout));
  std::string channels;
  for (int c = 0; c < nch; ++c) {
    const EngineChannel& ch = t.channels[c];
    channels += std::string(c ? " " : "") + kChannels[c] + "=";
    if (ch.table.empty()) channels += std::to_string(ch.constant).substr(0, 3);
    else channels += (ch.scale != 1.0 ? std::to_string(ch.scale) + "*" : std::string()) + ch.table + (ch.saturate ? " (saturated)" : "");
  }
  h.insert("hairlut.engine.channels", Imf::StringAttribute(channels));
  h.insert("hairlut.engine.axes", Imf::StringAttribute(axis_text(first->axes[2], 'X') + "; " + axis_text(first->axes[1], 'Y') + "; " +
                                                      axis_text(first->axes[0], 'Z')));
  h.insert("hairlut.engine.format", Imf::StringAttribute(t.engine_format));
  h.insert("hairlut.version", Imf::StringAttribute(kVersion));
  h.insert("hairlut.format_version", Imf::StringAttribute(format_version_text(TableSet())));  // a texture stores no E / g
  try {
    Imf::OutputFile out(name.c_str(), h);
    Imf::FrameBuffer fb;
    for (int c = 0; c < nch; ++c)
      fb.insert(kChannels[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(px[static_cast<std::size_t>(c)].data()), sizeof(half),
                                         sizeof(half) * static_cast<std::size_t>(width)));
    out.setFrameBuffer(fb);
    out.writePixels(static_cast<int>(height));
  } catch (const std::exception& e) {
    fail(std::string("cannot write OpenEXR file: ") + e.what());
  }
}

float EngineImage::texel(const EngineTexture& t, int X, int Y, int x, int y, int z, int c) const {
  const auto [col, row] = engine_pixel(t, X, Y, x, y, z);
  return channels[static_cast<std::size_t>(c)][static_cast<std::size_t>(row * width + col)];
}

EngineImage read_engine_texture(const std::filesystem::path& file) {
  const std::string name = file.string();
  EngineImage img;
  try {
    Imf::InputFile in(name.c_str());
    const auto* attr = in.header().findTypedAttribute<Imf::StringAttribute>("hairlut.engine");
    if (!attr) throw IoError(name + ": missing header attribute hairlut.engine (not a hairlut engine texture?)");
    const auto* version = in.header().findTypedAttribute<Imf::StringAttribute>("hairlut.format_version");
    if (!version) throw IoError(name + ": missing header attribute hairlut.format_version (written before the format was versioned?)");
    check_format_version(version->value(), name);
    img.description = nlohmann::json::parse(attr->value());
    const Imath::Box2i dw = in.header().dataWindow();
    img.width = dw.max.x - dw.min.x + 1;
    img.height = dw.max.y - dw.min.y + 1;
    if (img.width <= 0 || img.height <= 0 || static_cast<long>(img.width) * img.height > (1L << 26)) throw IoError(name + ": bad image size");
    for (int c = 0; c < 4; ++c)
      if (in.header().channels().findChannel(kChannels[c])) img.channel_count = c + 1;
    Imf::FrameBuffer fb;
    for (int c = 0; c < 4; ++c) {
      auto& v = img.channels[static_cast<std::size_t>(c)];
      v.assign(static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height), 0.0f);
      char* base = reinterpret_cast<char*>(v.data()) -
                   (static_cast<std::ptrdiff_t>(dw.min.x) + static_cast<std::ptrdiff_t>(dw.min.y) * img.width) * static_cast<std::ptrdiff_t>(sizeof(float));
      fb.insert(kChannels[c], Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * static_cast<std::size_t>(img.width)));
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
  } catch (const IoError&) {
    throw;
  } catch (const std::exception& e) {
    throw IoError(name + ": cannot read engine texture (" + std::string(e.what()) + ")");
  }
  return img;
}

bool is_engine_texture(const std::filesystem::path& file) {
  try {
    if (!std::filesystem::is_regular_file(file)) return false;
    Imf::InputFile in(file.string().c_str());
    return in.header().findTypedAttribute<Imf::StringAttribute>("hairlut.engine") != nullptr;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace hairlut
