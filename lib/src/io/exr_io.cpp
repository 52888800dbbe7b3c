#include "hairlut/io/exr_io.hpp"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfCompression.h>
#include <OpenEXR/ImfFloatVectorAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "hairlut/util/error.hpp"
#include "hairlut/tables/fourier_tables.hpp"
#include "table_semantics.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;

constexpr const char* kRgba[4] = {"R", "G", "B", "A"};

// Image geometry of a part: which axis indexes x and y, with strides.
struct Layout {
  std::vector<int> image_axes;                 // axes (indices into the table's axes) forming the image
  int channel_axis = -1;                       // index of a "channel" axis, or -1
  std::vector<std::pair<int, long>> x_terms;   // (axis index, stride in x)
  std::vector<std::pair<int, long>> y_terms;   // (axis index, stride in y)
  long width = 1, height = 1;
};

Layout make_layout(const std::vector<GridAxis>& axes) {
  Layout l;
  for (int k = 0; k < static_cast<int>(axes.size()); ++k) {
    if (axes[static_cast<std::size_t>(k)].name == "channel") l.channel_axis = k;
    else l.image_axes.push_back(k);
  }
  // From the last axis backwards, alternate x, y; each new axis is the slower index of its side.
  bool to_x = true;
  for (auto it = l.image_axes.rbegin(); it != l.image_axes.rend(); ++it) {
    const long n = axes[static_cast<std::size_t>(*it)].count;
    if (to_x) {
      l.x_terms.emplace_back(*it, l.width);
      l.width *= n;
    } else {
      l.y_terms.emplace_back(*it, l.height);
      l.height *= n;
    }
    to_x = !to_x;
  }
  return l;
}

std::string describe_layout(const std::vector<GridAxis>& axes, const Layout& l) {
  auto side = [&](const std::vector<std::pair<int, long>>& terms) {
    std::string s;
    for (const auto& [k, stride] : terms) {
      if (!s.empty()) s += " + ";
      s += (stride == 1 ? "" : std::to_string(stride) + "*") + axes[static_cast<std::size_t>(k)].name;
    }
    return s.empty() ? std::string("0") : s;
  };
  return "x = " + side(l.x_terms) + "; y = " + side(l.y_terms) + " (node indices; row-major tables, last axis fastest)";
}

std::string describe_axis(const GridAxis& a) {
  std::ostringstream s;
  s.precision(17);
  s << "count=" << a.count << " range=[" << a.lo << ", " << a.hi << "] units=" << a.units << " spacing=" << to_string(a.spacing)
    << " placement=" << to_string(a.placement) << " wrap=" << to_string(a.wrap) << " (" << a.long_name << ")";
  return s.str();
}

Imf::Compression parse_compression(const std::string& c) {
  if (c == "none") return Imf::NO_COMPRESSION;
  if (c == "zips") return Imf::ZIPS_COMPRESSION;
  if (c == "piz") return Imf::PIZ_COMPRESSION;
  return Imf::ZIP_COMPRESSION;
}

// In-memory input stream for read_exr_memory.
class MemoryStream : public Imf::IStream {
 public:
  MemoryStream(const char* data, std::size_t size, const std::string& name) : Imf::IStream(name.c_str()), data_(data), size_(size) {}
  bool read(char c[], int n) override {
    if (n < 0 || pos_ + static_cast<std::size_t>(n) > size_) throw std::runtime_error("unexpected end of file");
    std::memcpy(c, data_ + pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return pos_ < size_;
  }
  uint64_t tellg() override { return pos_; }
  void seekg(uint64_t pos) override { pos_ = static_cast<std::size_t>(std::min<uint64_t>(pos, size_)); }

 private:
  const char* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

TableSet read_parts(Imf::MultiPartInputFile& in, const std::string& name) {
  auto fail = [&](const std::string& what) -> void { throw IoError(name + ": " + what); };
  TableSet set;
  HashAlgorithm algorithm = HashAlgorithm::fnv1a64;  // files of format 1.x; from 2.0 on the file names it
  const int parts = in.parts();
  if (parts < 1 || parts > 100000) fail("has no image parts");
  for (int p = 0; p < parts; ++p) {
    const Imf::Header& h = in.header(p);
    const std::string pname = h.hasName() ? h.name() : "part " + std::to_string(p);
    const auto* part_attr = h.findTypedAttribute<Imf::StringAttribute>("hairlut.part");
    if (!part_attr) fail(pname + ": missing header attribute hairlut.part (not a hairlut table file?)");
    if (p == 0) {
      const auto* version = h.findTypedAttribute<Imf::StringAttribute>("hairlut.format_version");
      if (!version)
        fail(pname + ": missing header attribute hairlut.format_version (not a hairlut table file, or written before the format was versioned)");
      const int major = check_format_version(version->value(), name);
      const auto* named = h.findTypedAttribute<Imf::StringAttribute>("hairlut.checksum_algorithm");
      if (!named && major >= 2) fail(pname + ": missing header attribute hairlut.checksum_algorithm");
      if (named) {
        const std::optional<HashAlgorithm> known = hash_algorithm_from_name(named->value());
        if (!known) fail(pname + ": unknown checksum algorithm \"" + named->value().substr(0, 40) + "\" (header attribute hairlut.checksum_algorithm)");
        algorithm = *known;
      }
      const auto* meta = h.findTypedAttribute<Imf::StringAttribute>("hairlut.metadata");
      if (!meta) fail(pname + ": missing header attribute hairlut.metadata (not a hairlut table file?)");
      try {
        set.metadata = json::parse(meta->value());
      } catch (const json::exception&) {
        fail(pname + ": malformed hairlut.metadata");
      }
      if (!set.metadata.is_object()) fail(pname + ": malformed hairlut.metadata");
    }
    if (h.type() != Imf::SCANLINEIMAGE) fail(pname + ": is not a scanline image");
    json desc;
    try {
      desc = json::parse(part_attr->value());
    } catch (const json::exception&) {
      fail(pname + ": malformed hairlut.part");
    }
    std::vector<Table> tables;
    std::vector<std::string> channels;
    try {
      for (const json& tj : desc.at("tables")) {
        Table t;
        t.group = tj.at("group").get<std::string>();
        t.name = tj.at("name").get<std::string>();
        t.quantity = tj.at("quantity").get<std::string>();
        t.units = tj.at("units").get<std::string>();
        t.long_name = tj.value("long_name", std::string());
        t.attributes = tj.value("attributes", json::object());
        const json& axes = tj.at("axes");
        if (!axes.is_array() || axes.size() > 8) fail(pname + ": malformed axes");
        for (std::size_t k = 0; k < axes.size(); ++k)
          t.axes.push_back(GridAxis::from_json(axes[k], t.path() + ".axes[" + std::to_string(k) + "]"));
        tables.push_back(std::move(t));
      }
      channels = desc.at("channels").get<std::vector<std::string>>();
    } catch (const json::exception& e) {
      fail(pname + ": malformed hairlut.part (" + std::string(e.what()) + ")");
    } catch (const DomainError& e) {
      fail(pname + ": " + e.what());
    }
    if (tables.empty() || tables.size() > 4) fail(pname + ": must describe 1 to 4 tables");
    const Layout l = make_layout(tables[0].axes);
    for (const Table& t : tables)
      if (t.axes.size() != tables[0].axes.size() ||
          !std::equal(t.axes.begin(), t.axes.end(), tables[0].axes.begin(),
                      [](const GridAxis& a, const GridAxis& b) { return a.name == b.name && a.count == b.count; }))
        fail(pname + ": tables of one part must share their axes");
    const long nch = l.channel_axis >= 0 ? tables[0].axes[static_cast<std::size_t>(l.channel_axis)].count : 1;
    if (l.channel_axis >= 0 && (tables.size() != 1 || nch > 4)) fail(pname + ": a channel-axis part holds one table of <= 4 channels");
    if (channels.size() != (l.channel_axis >= 0 ? static_cast<std::size_t>(nch) : tables.size()))
      fail(pname + ": channel list does not match the tables");
    const Imath::Box2i dw = h.dataWindow();
    const long width = static_cast<long>(dw.max.x) - dw.min.x + 1, height = static_cast<long>(dw.max.y) - dw.min.y + 1;
    if (width != l.width || height != l.height)
      fail(pname + ": image is " + std::to_string(width) + "x" + std::to_string(height) + " but its axes need " +
           std::to_string(l.width) + "x" + std::to_string(l.height));
    if (width <= 0 || height <= 0 || width * height > (1L << 30)) fail(pname + ": image too large");
    for (const std::string& c : channels)
      if (!h.channels().findChannel(c)) fail(pname + ": missing channel " + c);
    // The plain-text header attributes (what exrheader shows and engines read) must say what the
    // checksummed description says; an altered one is named.
    auto expect_text = [&](const std::string& key, const std::string& want) {
      const auto* a = h.findTypedAttribute<Imf::StringAttribute>(key);
      if (!a) fail(pname + ": header attribute " + key + " is missing (metadata altered)");
      if (a->value() != want) fail(pname + ": header attribute " + key + " disagrees with the checksummed description (metadata altered)");
    };
    {
      const Table& first = tables.front();
      expect_text("hairlut.layout", describe_layout(first.axes, l));
      std::string chdesc;
      for (std::size_t c = 0; c < channels.size(); ++c)
        chdesc += (c ? " " : "") + channels[c] + "=" +
                  (l.channel_axis >= 0 ? first.path() + "[channel " + std::to_string(c) + "]" : tables[c].path());
      expect_text("hairlut.channels", chdesc);
      expect_text("hairlut.quantity", first.quantity + " [" + first.units + "]");
      for (const GridAxis& a : first.axes) {
        expect_text("hairlut.axis." + a.name, describe_axis(a));
        const auto* nodes = h.findTypedAttribute<Imf::FloatVectorAttribute>("hairlut.axis." + a.name + ".nodes");
        std::vector<float> want;
        for (double v : a.nodes()) want.push_back(static_cast<float>(v));
        if (!nodes || nodes->value() != want)
          fail(pname + ": header attribute hairlut.axis." + a.name + ".nodes is missing or disagrees with the checksummed description (metadata altered)");
      }
      if (p == 0) expect_text("hairlut.version", set.metadata.value("hairlut_version", std::string("?")));
    }
    // Read every channel as float.
    const std::size_t npix = static_cast<std::size_t>(width * height);
    std::vector<std::vector<float>> pixels(channels.size(), std::vector<float>(npix));
    Imf::FrameBuffer fb;
    for (std::size_t c = 0; c < channels.size(); ++c) {
      char* base = reinterpret_cast<char*>(pixels[c].data()) -
                   (static_cast<std::ptrdiff_t>(dw.min.x) + static_cast<std::ptrdiff_t>(dw.min.y) * width) * static_cast<std::ptrdiff_t>(sizeof(float));
      fb.insert(channels[c], Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * static_cast<std::size_t>(width)));
    }
    Imf::InputPart part(in, p);
    part.setFrameBuffer(fb);
    part.readPixels(dw.min.y, dw.max.y);
    // Scatter the atlas back into row-major tables.
    for (std::size_t ti = 0; ti < tables.size(); ++ti) {
      Table& t = tables[ti];
      t.allocate(Precision::float32);
      const std::size_t n = t.size();
      std::vector<long> idx(t.axes.size(), 0);
      for (std::size_t flat = 0; flat < n; ++flat) {
        long x = 0, y = 0;
        for (const auto& [k, stride] : l.x_terms) x += idx[static_cast<std::size_t>(k)] * stride;
        for (const auto& [k, stride] : l.y_terms) y += idx[static_cast<std::size_t>(k)] * stride;
        const std::size_t ch = l.channel_axis >= 0 ? static_cast<std::size_t>(idx[static_cast<std::size_t>(l.channel_axis)]) : ti;
        t.f32[flat] = pixels[ch][static_cast<std::size_t>(y * width + x)];
        for (std::size_t k = t.axes.size(); k-- > 0;) {  // advance the multi-index, last axis fastest
          if (++idx[k] < t.axes[k].count) break;
          idx[k] = 0;
        }
      }
      set.tables.push_back(std::move(t));
    }
  }
  const auto* sum = in.header(0).findTypedAttribute<Imf::StringAttribute>("hairlut.checksum");
  if (!sum) fail("missing header attribute hairlut.checksum (not a hairlut table file?)");
  if (sum->value() != content_checksum(set, ChecksumRounding::as_stored, algorithm)) fail("content checksum mismatch: the file is corrupted");
  return set;
}

}  // namespace

void write_exr(const TableSet& set, const std::filesystem::path& file, const ExrWriteOptions& options) {
  const std::string fname = file.string();
  auto fail = [&](const std::string& what) { throw IoError(fname + ": " + what); };
  if (set.tables.empty()) fail("no tables to write");
  if (has_fourier_np(set)) fail("the Fourier N_p tables (np_fourier) are written to HDF5 only; OpenEXR has no layout for them");
  const auto plan = exr_part_plan(set);
  // One part per plan entry: its tables, layout and channel names.
  struct Part {
    std::vector<const Table*> tables;
    Layout layout;
    std::vector<std::string> channels;
  };
  std::vector<Part> parts;
  std::vector<Imf::Header> headers;
  for (std::size_t p = 0; p < plan.size(); ++p) {
    Part part;
    for (const std::string& path : plan[p].second) part.tables.push_back(set.find(path));
    const Table& first = *part.tables.front();
    part.layout = make_layout(first.axes);
    const Layout& l = part.layout;
    if (l.width > 65536 || l.height > 65536 || l.width * l.height > (1L << 28))
      fail(first.path() + ": too large for one EXR image (more than 65536 x 65536 or 2^28 pixels)");
    if (l.channel_axis >= 0) {
      const GridAxis& ch = first.axes[static_cast<std::size_t>(l.channel_axis)];
      if (ch.count > 4) fail(first.path() + ": more than 4 channels");
      for (int c = 0; c < ch.count; ++c)
        part.channels.push_back(ch.labels.size() == static_cast<std::size_t>(ch.count) ? ch.labels[static_cast<std::size_t>(c)] : kRgba[c]);
    } else {
      for (std::size_t t = 0; t < part.tables.size(); ++t) part.channels.push_back(kRgba[t]);
    }
    // Every part shares the display window (OpenEXR requires it); its data window is its own.
    Imf::Header h(Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(0, 0)),
                  Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(static_cast<int>(l.width) - 1, static_cast<int>(l.height) - 1)));
    h.setName(plan[p].first);
    h.setType(Imf::SCANLINEIMAGE);
    h.compression() = parse_compression(options.compression);
    for (const std::string& c : part.channels) h.channels().insert(c, Imf::Channel(options.half ? Imf::HALF : Imf::FLOAT));
    json desc;
    desc["tables"] = json::array();
    for (const Table* t : part.tables) desc["tables"].push_back(t->describe());
    desc["channels"] = part.channels;
    desc["layout"] = describe_layout(first.axes, l);
    h.insert("hairlut.part", Imf::StringAttribute(desc.dump()));
    h.insert("hairlut.layout", Imf::StringAttribute(describe_layout(first.axes, l)));
    std::string chdesc;
    for (std::size_t c = 0; c < part.channels.size(); ++c)
      chdesc += (c ? " " : "") + part.channels[c] + "=" +
                (l.channel_axis >= 0 ? first.path() + "[channel " + std::to_string(c) + "]" : part.tables[c]->path());
    h.insert("hairlut.channels", Imf::StringAttribute(chdesc));
    h.insert("hairlut.quantity", Imf::StringAttribute(first.quantity + " [" + first.units + "]"));
    for (const GridAxis& a : first.axes) {
      h.insert("hairlut.axis." + a.name, Imf::StringAttribute(describe_axis(a)));
      std::vector<float> nodes;
      for (double v : a.nodes()) nodes.push_back(static_cast<float>(v));
      h.insert("hairlut.axis." + a.name + ".nodes", Imf::FloatVectorAttribute(nodes));
    }
    if (p == 0) {
      h.insert("hairlut.format_version", Imf::StringAttribute(format_version_text(set)));
      h.insert("hairlut.metadata", Imf::StringAttribute(set.metadata.dump()));
      h.insert("hairlut.version", Imf::StringAttribute(set.metadata.value("hairlut_version", std::string("?"))));
      h.insert("hairlut.checksum_algorithm", Imf::StringAttribute(hash_algorithm_name(kFileHash)));
      h.insert("hairlut.checksum",
               Imf::StringAttribute(content_checksum(set, options.half ? ChecksumRounding::half : ChecksumRounding::float32, kFileHash)));
    }
    headers.push_back(h);
    parts.push_back(std::move(part));
  }
  Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(0, 0));
  for (const Imf::Header& h : headers) display.extendBy(h.dataWindow());
  for (Imf::Header& h : headers) h.displayWindow() = display;
  try {
    Imf::MultiPartOutputFile out(fname.c_str(), headers.data(), static_cast<int>(headers.size()));
    for (std::size_t p = 0; p < parts.size(); ++p) {
      const Part& part = parts[p];
      const Layout& l = part.layout;
      const Table& first = *part.tables.front();
      // Row-major strides of the tables' axes.
      std::vector<long> stride(first.axes.size(), 1);
      for (std::size_t k = first.axes.size(); k-- > 1;) stride[k - 1] = stride[k] * first.axes[k].count;
      // Pixels are filled and written in strips of rows, so memory stays at one strip per part
      // instead of a second copy of the tables.
      const long strip = std::max<long>(1, std::min<long>(l.height, (1L << 20) / std::max<long>(1, l.width)));
      Imf::OutputPart writer(out, static_cast<int>(p));
      std::vector<std::vector<float>> f(part.channels.size());
      std::vector<std::vector<half>> hf(part.channels.size());
      for (long y0 = 0; y0 < l.height; y0 += strip) {
        const long rows = std::min(strip, l.height - y0);
        const std::size_t n = static_cast<std::size_t>(rows * l.width);
        for (auto& v : f) v.assign(n, 0.0f);
        for (long y = y0; y < y0 + rows; ++y)
          for (long x = 0; x < l.width; ++x) {
            // Node indices of the image axes from (x, y): the largest stride first.
            long flat = 0, rx = x, ry = y;
            for (auto it = l.x_terms.rbegin(); it != l.x_terms.rend(); ++it) flat += (rx / it->second) * stride[static_cast<std::size_t>(it->first)], rx %= it->second;
            for (auto it = l.y_terms.rbegin(); it != l.y_terms.rend(); ++it) flat += (ry / it->second) * stride[static_cast<std::size_t>(it->first)], ry %= it->second;
            const std::size_t pix = static_cast<std::size_t>((y - y0) * l.width + x);
            for (std::size_t c = 0; c < part.channels.size(); ++c) {
              const Table& t = l.channel_axis >= 0 ? first : *part.tables[c];
              const long index = flat + (l.channel_axis >= 0 ? static_cast<long>(c) * stride[static_cast<std::size_t>(l.channel_axis)] : 0);
              const double v = t.get(static_cast<std::size_t>(index));
              if (!std::isfinite(v)) fail(t.path() + ": non-finite value at entry " + std::to_string(index));
              if (options.half && std::abs(v) > 65504.0)
                fail(t.path() + ": value " + std::to_string(v) + " exceeds the half-float range; write exr.precision \"float\"");
              f[c][pix] = static_cast<float>(v);
            }
          }
        Imf::FrameBuffer fb;
        for (std::size_t c = 0; c < part.channels.size(); ++c) {
          // The frame buffer's origin is pixel (0, 0): shift the base back by y0 rows.
          const std::ptrdiff_t shift = static_cast<std::ptrdiff_t>(y0 * l.width);
          if (options.half) {
            hf[c].resize(n);
            for (std::size_t i = 0; i < n; ++i) hf[c][i] = half(f[c][i]);
            fb.insert(part.channels[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(hf[c].data() - shift), sizeof(half),
                                                   sizeof(half) * static_cast<std::size_t>(l.width)));
          } else {
            fb.insert(part.channels[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(f[c].data() - shift), sizeof(float),
                                                   sizeof(float) * static_cast<std::size_t>(l.width)));
          }
        }
        writer.setFrameBuffer(fb);
        writer.writePixels(static_cast<int>(rows));
      }
    }
  } catch (const IoError&) {
    throw;
  } catch (const std::exception& e) {
    fail(std::string("cannot write OpenEXR file: ") + e.what());
  }
}

TableSet read_exr(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError(name + ": cannot open file (" + std::string(std::strerror(errno)) + ")");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  const std::string s = bytes.str();
  return read_exr_memory(s.data(), s.size(), name);
}

namespace {

// Reads the data windows of every part from the raw header bytes and rejects sizes that could
// make OpenEXR allocate far more memory than the file could hold (its scanline offset tables and
// our pixel buffers grow with the data window): at most 65536 x 65536 and 2^28 pixels a part, no
// more rows than the offset table in the file can index, and no more pixel bytes than 1100 times
// the file size (deflate, the strongest compression hairlut writes, stays below 1032:1).
void prescan_exr(const unsigned char* d, std::size_t size, const std::string& name) {
  auto fail = [&](const std::string& what) { throw IoError(name + ": truncated or corrupted OpenEXR file (" + what + ")"); };
  auto i32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, d + at, 4);  // little-endian file, little-endian host (x86-64, arm64)
    return static_cast<std::int32_t>(v);
  };
  const std::uint32_t flags = static_cast<std::uint32_t>(i32(4));
  const bool multipart = flags & 0x1000;
  std::size_t pos = 8;
  auto cstring = [&]() {
    std::string s;
    while (pos < size && d[pos] != 0 && s.size() < 256) s += static_cast<char>(d[pos++]);
    if (pos >= size || d[pos] != 0) fail("truncated header");
    ++pos;
    return s;
  };
  double total_pixel_bytes = 0.0;
  for (int part = 0; part < 100000; ++part) {
    bool have_window = false;
    long long w = 0, h = 0;
    int channels = 0;
    for (;;) {
      const std::string attr = cstring();
      if (attr.empty()) break;
      const std::string type = cstring();
      if (pos + 4 > size) fail("truncated header");
      const std::int32_t n = i32(pos);
      pos += 4;
      if (n < 0 || static_cast<std::size_t>(n) > size - pos) fail("attribute " + attr + " runs past the end of the file");
      if (attr == "dataWindow" && type == "box2i" && n == 16) {
        const long long x0 = i32(pos), y0 = i32(pos + 4), x1 = i32(pos + 8), y1 = i32(pos + 12);
        if (x1 < x0 || y1 < y0) fail("empty data window");
        w = x1 - x0 + 1;
        h = y1 - y0 + 1;
        have_window = true;
      }
      if (attr == "channels" && type == "chlist")  // each entry: name\0, int type, 4 bytes, 2 ints
        for (std::size_t q = pos; q < pos + static_cast<std::size_t>(n) && d[q] != 0; ++channels) {
          while (q < pos + static_cast<std::size_t>(n) && d[q] != 0) ++q;
          q += 17;
        }
      pos += static_cast<std::size_t>(n);
    }
    if (!have_window) fail("a part without a data window");
    if (w > 65536 || h > 65536 || w * h > (1LL << 28)) fail("image larger than 65536 x 65536 or 2^28 pixels");
    if (static_cast<double>(h) > 4.0 * static_cast<double>(size) + 64.0) fail("more rows than the file can index");
    total_pixel_bytes += static_cast<double>(w) * static_cast<double>(h) * std::max(channels, 1) * 2.0;
    if (total_pixel_bytes > 1100.0 * static_cast<double>(size) + (1 << 20)) fail("more pixel data than the file can hold");
    if (!multipart) break;
    if (pos >= size) fail("truncated header");
    if (d[pos] == 0) break;  // the empty header that ends a multi-part header list
  }
}

}  // namespace

TableSet read_exr_memory(const char* data, std::size_t size, const std::string& name) {
  static constexpr unsigned char magic[4] = {0x76, 0x2f, 0x31, 0x01};
  if (size < 8 || std::memcmp(data, magic, 4) != 0) throw IoError(name + ": not an OpenEXR file (no EXR magic number)");
  prescan_exr(reinterpret_cast<const unsigned char*>(data), size, name);
  try {
    MemoryStream stream(data, size, name);
    Imf::MultiPartInputFile in(stream);
    TableSet set = read_parts(in, name);
    detail::check_table_semantics(set, name);
    return set;
  } catch (const IoError&) {
    throw;
  } catch (const std::exception& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    throw IoError(name + ": cannot read as OpenEXR (truncated or corrupted): " + what);
  }
}

}  // namespace hairlut
