#include "hairlut/io/gpu_export.hpp"

#include <unistd.h>

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>

#include "hairlut/io/hdf5_io.hpp"  // IoError
#include "hairlut/tables/hair_views.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/util/version.hpp"

namespace hairlut {
// Named, not anonymous: the unity build compiles this file with exr_io.cpp's and engine_exr.cpp's
// helpers of the same names.
namespace detail::gpu_files {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;
constexpr const char* kRgba[4] = {"R", "G", "B", "A"};
constexpr int kFormatVersion = 1;
// Bounds on what a description may ask a reader to allocate (hostile files): textures of at most
// 16384 × 16384 × 2048 texels are beyond every GPU's limits anyway.
constexpr long long kMaxExtent = 16384, kMaxLayers = 2048, kMaxFloats = 1LL << 32;

static_assert(std::endian::native == std::endian::little, "the export's binary files are little-endian, as this host");

// A file of the export, written to a temporary name; renamed into place by commit().
struct Pending {
  fs::path final_path, tmp;
};

fs::path temporary(const fs::path& p) { return fs::path(p.string() + ".tmp-" + std::to_string(::getpid())); }

void write_bytes(const fs::path& file, const void* data, std::size_t bytes) {
  std::ofstream f(file, std::ios::binary | std::ios::trunc);
  if (!f) throw IoError(file.string() + ": cannot create the file");
  f.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  f.close();
  if (!f) throw IoError(file.string() + ": write failed");
}

// An RGBA 2D array texture (layers stacked along y) as one OpenEXR image.
void write_texture(const fs::path& file, const std::vector<float>& texels, int width, int height, int layers, bool half, const json& desc) {
  const int rows = height * layers;
  Imf::Header h(width, rows);
  h.compression() = Imf::ZIP_COMPRESSION;
  for (const char* c : kRgba) h.channels().insert(c, Imf::Channel(half ? Imf::HALF : Imf::FLOAT));
  h.insert("hairlut.gpu", Imf::StringAttribute(desc.dump()));
  Imf::FrameBuffer fb;
  std::vector<Imath::half> hv;
  if (half) {
    hv.resize(texels.size());
    for (std::size_t i = 0; i < texels.size(); ++i) hv[i] = Imath::half(texels[i]);
    for (int c = 0; c < 4; ++c)
      fb.insert(kRgba[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(hv.data() + c), 4 * sizeof(Imath::half), 4 * sizeof(Imath::half) * width));
  } else {
    for (int c = 0; c < 4; ++c)
      fb.insert(kRgba[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(texels.data()) + c), 4 * sizeof(float),
                                         4 * sizeof(float) * static_cast<std::size_t>(width)));
  }
  try {
    Imf::OutputFile out(file.c_str(), h);
    out.setFrameBuffer(fb);
    out.writePixels(rows);
  } catch (const std::exception& e) {
    throw IoError(file.string() + ": " + e.what());
  }
}

std::vector<float> read_texture(const fs::path& file, int width, int height, int layers) {
  std::vector<float> texels(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * static_cast<std::size_t>(layers) * 4);
  try {
    Imf::InputFile in(file.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    if (dw.max.x - dw.min.x + 1 != width || dw.max.y - dw.min.y + 1 != height * layers)
      throw IoError(file.string() + ": the image is not " + std::to_string(width) + " x " + std::to_string(height * layers) + " pixels");
    for (const char* c : kRgba)
      if (!in.header().channels().findChannel(c)) throw IoError(file.string() + ": channel " + c + " missing");
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(texels.data()) - (static_cast<std::ptrdiff_t>(dw.min.y) * width + dw.min.x) * 16;
    for (int c = 0; c < 4; ++c) fb.insert(kRgba[c], Imf::Slice(Imf::FLOAT, base + 4 * c, 16, 16 * static_cast<std::size_t>(width)));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
  } catch (const IoError&) {
    throw;
  } catch (const std::exception& e) {
    throw IoError(file.string() + ": " + e.what());
  }
  for (float& v : texels)
    if (!std::isfinite(v) || v < 0.0f) v = 0.0f;  // as the writer stores them: the shaders read no other
  return texels;
}

std::vector<char> read_bytes(const fs::path& file, std::size_t bytes) {
  std::ifstream f(file, std::ios::binary | std::ios::ate);
  if (!f) throw IoError(file.string() + ": cannot open the file");
  if (static_cast<std::size_t>(f.tellg()) != bytes)
    throw IoError(file.string() + ": " + std::to_string(static_cast<long long>(f.tellg())) + " bytes where the description says " + std::to_string(bytes));
  std::vector<char> data(bytes);
  f.seekg(0);
  f.read(data.data(), static_cast<std::streamsize>(bytes));
  if (!f) throw IoError(file.string() + ": read failed");
  return data;
}

// A description's field, checked (hostile files): its type and range, named in the error.
long long integer(const json& j, const char* key, long long lo, long long hi, const fs::path& file) {
  if (!j.is_object() || !j.contains(key) || !j[key].is_number_integer()) throw IoError(file.string() + ": " + key + " must be an integer");
  const long long v = j[key].get<long long>();
  if (v < lo || v > hi) throw IoError(file.string() + ": " + key + " must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}
fs::path beside(const json& j, const fs::path& description) {
  if (!j.is_object() || !j.contains("file") || !j["file"].is_string()) throw IoError(description.string() + ": a file entry needs a name");
  const std::string name = j["file"].get<std::string>();
  if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..")
    throw IoError(description.string() + ": file " + name + " must be a plain name beside the description");
  return description.parent_path() / name;
}

// Every table the generic set names lies within the values (the shader reads what the set says).
void check_generic(const gpu::GpuGenericSet& s, std::size_t floats, const fs::path& file) {
  auto fail = [&](const std::string& why) { throw IoError(file.string() + ": " + why); };
  if (s.lobes[0] < 1 || s.lobes[0] > 8 || s.lobes[1] < 0 || s.lobes[1] > 1) fail("lobes out of range");
  auto table = [&](int index, bool needed) {
    if (index < 0) {
      if (needed) fail("a lobe's table is missing");
      return;
    }
    if (index >= gpu::kGenericMaxTables) fail("table index " + std::to_string(index) + " out of range");
    const gpu::GpuTable& t = s.tables[index];
    if (t.head[2] < 1 || t.head[2] > 4 || t.head[1] < 0 || t.head[1] + t.head[2] > gpu::kGenericMaxAxes || t.head[0] < 0 || t.head[3] < 0 || t.head[3] > 2)
      fail("table " + std::to_string(index) + " is malformed");
    long long last = t.head[0];
    for (int d = 0; d < t.head[2]; ++d) {
      const gpu::GpuAxis& a = s.axes[t.head[1] + d];
      if (a.mode[0] < 1 || a.mode[0] > 1 << 20 || a.mode[3] < 1 || a.mode[1] < 0 || a.mode[1] > 4) fail("table " + std::to_string(index) + ": an axis is malformed");
      last += static_cast<long long>(a.mode[0] - 1) * a.mode[3];
    }
    if (last >= static_cast<long long>(floats)) fail("table " + std::to_string(index) + " reaches beyond the values");
  };
  for (int p = 0; p < s.lobes[0]; ++p) table(s.np[p], true), table(s.energy[p], false), table(s.mp[p], true);
  if (s.lobes[1]) table(s.residual[0], true), table(s.residual[1], false), table(s.residual[2], true);
}

}  // namespace detail::gpu_files

GpuLayout gpu_layout(const TableSet& set) {
  using namespace detail::gpu_files;
  GpuLayout g;
  g.materials = hairlut::material_groups(set);
  try {
    if (!g.materials.empty()) {
      g.kind = "materials";
      for (const std::string& m : g.materials) g.textures.add(material_tables<float>(set, m));
    } else {
      g.kind = "generic";
      g.generic.emplace(hair_tables<float, double>(set));
    }
  } catch (const std::invalid_argument& e) {
    throw DomainError(std::string("GPU export: ") + e.what());
  }
  return g;
}

std::vector<std::filesystem::path> write_gpu_export(const TableSet& set, const std::filesystem::path& base, const GpuExportOptions& options) {
  using namespace detail::gpu_files;
  const GpuLayout g = gpu_layout(set);
  const std::string stem = base.filename().string();
  const fs::path dir = base.parent_path();
  std::vector<Pending> files;
  json desc = {{"format", "hairlut-gpu"},
               {"version", kFormatVersion},
               {"kind", g.kind},
               {"shader", g.kind == "materials" ? "hairlut.glsl" : "hairlut_generic.glsl"},
               {"byte_order", "little-endian"},
               {"hairlut_version", kVersion},
               {"config_hash", set.metadata.value("config_hash", std::string())}};
  auto add = [&](const std::string& suffix) {
    files.push_back({dir / (stem + suffix), temporary(dir / (stem + suffix))});
    return files.back();
  };
  try {
    if (g.kind == "materials") {
      const gpu::MaterialTextures& t = g.textures;
      desc["materials"] = g.materials;
      const char* texel = options.half ? "RGBA half" : "RGBA float32";
      const Pending np = add(".np.exr"), mp = add(".mp.exr"), blocks = add(".materials.bin"), rows = add(".rows.bin");
      desc["np"] = {{"file", np.final_path.filename().string()}, {"width", t.np_width}, {"height", t.np_height}, {"layers", t.np_layers}, {"texel", texel},
                    {"layout", "x = phi node, y = theta_d node; layer l in image rows l*height to (l+1)*height-1"}};
      desc["mp"] = {{"file", mp.final_path.filename().string()}, {"width", t.mp_width}, {"height", t.mp_height}, {"layers", t.mp_layers}, {"texel", texel},
                    {"layout", "x = theta_r node, y = theta_i node; layer l in image rows l*height to (l+1)*height-1"}};
      desc["blocks"] = {{"file", blocks.final_path.filename().string()}, {"struct", "HairlutMaterial (std140)"}, {"count", t.materials.size()},
                        {"bytes", t.materials.size() * sizeof(gpu::GpuMaterial)}};
      desc["rows"] = {{"file", rows.final_path.filename().string()}, {"floats", t.rows.size()}};
      write_texture(np.tmp, t.np, t.np_width, t.np_height, t.np_layers, options.half, desc["np"]);
      write_texture(mp.tmp, t.mp, t.mp_width, t.mp_height, t.mp_layers, options.half, desc["mp"]);
      write_bytes(blocks.tmp, t.materials.data(), t.materials.size() * sizeof(gpu::GpuMaterial));
      write_bytes(rows.tmp, t.rows.data(), t.rows.size() * sizeof(float));
    } else {
      const gpu::GenericBuffers& b = *g.generic;
      const Pending s = add(".generic-set.bin"), d = add(".generic-data.bin");
      desc["set"] = {{"file", s.final_path.filename().string()}, {"struct", "HairlutGenericSet (std140)"}, {"bytes", sizeof b.set}};
      desc["data"] = {{"file", d.final_path.filename().string()}, {"floats", b.data.size()}};
      write_bytes(s.tmp, &b.set, sizeof b.set);
      write_bytes(d.tmp, b.data.data(), b.data.size() * sizeof(float));
    }
    const Pending description = add(".gpu.json");
    const std::string text = desc.dump(2) + "\n";
    write_bytes(description.tmp, text.data(), text.size());
    for (const Pending& f : files) fs::rename(f.tmp, f.final_path);
  } catch (...) {
    std::error_code ec;
    for (const Pending& f : files) fs::remove(f.tmp, ec);
    throw;
  }
  std::vector<std::filesystem::path> out;
  for (const Pending& f : files) out.push_back(f.final_path);
  return out;
}

GpuLayout read_gpu_export(const std::filesystem::path& description) {
  using namespace detail::gpu_files;
  json d;
  {
    std::ifstream f(description);
    if (!f) throw IoError(description.string() + ": cannot open the file");
    d = json::parse(f, nullptr, false);
  }
  if (d.is_discarded() || !d.is_object() || d.value("format", std::string()) != "hairlut-gpu")
    throw IoError(description.string() + ": not a hairlut GPU export description");
  if (integer(d, "version", kFormatVersion, kFormatVersion, description) != kFormatVersion) throw IoError(description.string() + ": unknown version");
  GpuLayout g;
  g.kind = d.value("kind", std::string());
  if (g.kind == "materials") {
    gpu::MaterialTextures& t = g.textures;
    const json& np = d["np"];
    const json& mp = d["mp"];
    t.np_width = static_cast<int>(integer(np, "width", 2, kMaxExtent, description));
    t.np_height = static_cast<int>(integer(np, "height", 2, kMaxExtent, description));
    t.np_layers = static_cast<int>(integer(np, "layers", 1, kMaxLayers, description));
    t.mp_width = static_cast<int>(integer(mp, "width", 2, kMaxExtent, description));
    t.mp_height = static_cast<int>(integer(mp, "height", 2, kMaxExtent, description));
    t.mp_layers = static_cast<int>(integer(mp, "layers", 1, kMaxLayers, description));
    const long long count = integer(d["blocks"], "count", 1, 4096, description);
    const long long floats = integer(d["rows"], "floats", 0, kMaxFloats, description);
    if (integer(d["blocks"], "bytes", 0, kMaxFloats, description) != count * static_cast<long long>(sizeof(gpu::GpuMaterial)))
      throw IoError(description.string() + ": blocks.bytes is not count x " + std::to_string(sizeof(gpu::GpuMaterial)));
    if (!d["materials"].is_array() || static_cast<long long>(d["materials"].size()) != count)
      throw IoError(description.string() + ": materials must list one name per block");
    for (const json& m : d["materials"]) {
      if (!m.is_string()) throw IoError(description.string() + ": a material name must be a string");
      g.materials.push_back(m.get<std::string>());
    }
    t.np = read_texture(beside(np, description), t.np_width, t.np_height, t.np_layers);
    t.mp = read_texture(beside(mp, description), t.mp_width, t.mp_height, t.mp_layers);
    const std::vector<char> blocks = read_bytes(beside(d["blocks"], description), static_cast<std::size_t>(count) * sizeof(gpu::GpuMaterial));
    t.materials.resize(static_cast<std::size_t>(count));
    std::memcpy(t.materials.data(), blocks.data(), blocks.size());
    const std::vector<char> rows = read_bytes(beside(d["rows"], description), static_cast<std::size_t>(floats) * sizeof(float));
    t.rows.resize(static_cast<std::size_t>(floats));
    std::memcpy(t.rows.data(), rows.data(), rows.size());
    // What the shader indexes with lies within what was read.
    for (const gpu::GpuMaterial& m : t.materials) {
      const int lobes = m.lobes[0] + m.lobes[1];
      if (m.lobes[0] < 1 || m.lobes[0] > 7 || m.lobes[1] < 0 || m.lobes[1] > 1 || m.lobes[2] < 0 || m.lobes[2] + lobes > t.np_layers ||
          m.lobes[3] < 0 || m.lobes[3] + (lobes + 3) / 4 > t.mp_layers)
        throw IoError(description.string() + ": a material's lobes or layers lie outside the textures");
      for (const std::int32_t o : {m.rows0[0], m.rows0[1], m.rows0[2], m.rows0[3], m.rows1[0], m.rows1[1], m.rows1[2]})
        if (o < 0 || o > floats) throw IoError(description.string() + ": a material's sampling rows lie outside the rows");
    }
    t.explicit_lobes = t.materials[0].lobes[0], t.residual = t.materials[0].lobes[1] != 0;
  } else if (g.kind == "generic") {
    gpu::GenericBuffers b;
    if (integer(d["set"], "bytes", 0, kMaxFloats, description) != static_cast<long long>(sizeof b.set))
      throw IoError(description.string() + ": set.bytes is not " + std::to_string(sizeof b.set));
    const long long floats = integer(d["data"], "floats", 1, kMaxFloats, description);
    const std::vector<char> s = read_bytes(beside(d["set"], description), sizeof b.set);
    std::memcpy(&b.set, s.data(), sizeof b.set);
    const std::vector<char> v = read_bytes(beside(d["data"], description), static_cast<std::size_t>(floats) * sizeof(float));
    b.data.resize(static_cast<std::size_t>(floats));
    std::memcpy(b.data.data(), v.data(), v.size());
    check_generic(b.set, b.data.size(), description);
    g.generic = std::move(b);
  } else {
    throw IoError(description.string() + ": kind must be materials or generic");
  }
  return g;
}

}  // namespace hairlut
