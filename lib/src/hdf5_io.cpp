#include "hairlut/hdf5_io.hpp"

#include <hdf5.h>
#include <hdf5_hl.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "hairlut/error.hpp"
#include "hairlut/hash.hpp"
#include "hdf5_bytes.hpp"
#include "hdf5_layout.hpp"
#include "axis_identity.hpp"
#include "table_checksum.hpp"
#include "slab_queue.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;

// Owns an HDF5 identifier and closes it with the matching H5?close.
class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  Handle& operator=(Handle&& o) noexcept {
    std::swap(id_, o.id_);
    std::swap(close_, o.close_);
    return *this;
  }
  ~Handle() {
    if (id_ >= 0 && close_) {
      H5E_BEGIN_TRY { close_(id_); }
      H5E_END_TRY;
    }
  }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Closes now and returns HDF5's status (the destructor, which cannot report, ignores it).
  herr_t close_now() {
    herr_t status = 0;
    if (id_ >= 0 && close_) status = close_(id_);
    id_ = -1;
    return status;
  }

 private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

// While alive, HDF5's automatic error-stack printing is off (restored afterwards), so a failure
// reaches the user only as the one-line IoError built from the stack (hdf5_reason).
class ErrorSilencer {
 public:
  ErrorSilencer() {
    // HDF5 1.10 cannot close a file whose corrupted object header failed to load (no identifier
    // stays open, but its shutdown loops and prints "infinite loop closing library" at exit).
    // hairlut never leaves data to flush at exit (files are written from memory images and closed
    // explicitly, reads are read-only), so the library's exit handler is skipped; this only takes
    // effect if it runs before HDF5's first use in the process.
    static const bool no_exit_handler = [] { return H5dont_atexit() >= 0; }();
    (void)no_exit_handler;
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ErrorSilencer(const ErrorSilencer&) = delete;
  ErrorSilencer& operator=(const ErrorSilencer&) = delete;
  ~ErrorSilencer() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// The innermost message of HDF5's current error stack as a short phrase (the system's reason,
// e.g. "No space left on device", when HDF5 recorded one); empty when the stack is empty. Clears
// the stack.
std::string hdf5_reason() {
  std::string innermost;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned n, const H5E_error2_t* e, void* out) -> herr_t {
        if (n == 0 && e && e->desc) *static_cast<std::string*>(out) = e->desc;
        return 0;
      },
      &innermost);
  H5Eclear2(H5E_DEFAULT);
  if (const auto at = innermost.find("error message = '"); at != std::string::npos) {
    const auto start = at + 17, end = innermost.find('\'', start);
    return innermost.substr(start, end == std::string::npos ? std::string::npos : end - start);
  }
  if (innermost.size() > 120) innermost = innermost.substr(0, 117) + "...";
  return innermost;
}

// Context for one file: turns HDF5 failures into one-line IoErrors naming the file and, when HDF5
// gives one, its innermost reason.
struct File {
  std::string name;

  [[noreturn]] void fail(const std::string& what) const {
    const std::string reason = hdf5_reason();
    throw IoError(name + ": " + what + (reason.empty() ? std::string() : " (HDF5: " + reason + ")"));
  }

  hid_t check(hid_t id, const std::string& what) const {
    if (id < 0) fail(what);
    return id;
  }
  void check_status(herr_t status, const std::string& what) const {
    if (status < 0) fail(what);
  }
};

template <class F>
auto quiet(F&& f) {
  decltype(f()) r{};
  H5E_BEGIN_TRY { r = f(); }
  H5E_END_TRY;
  return r;
}

Handle string_type() {
  Handle t(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(t.get(), H5T_VARIABLE);
  H5Tset_cset(t.get(), H5T_CSET_UTF8);
  return t;
}

void write_string_attr(const File& f, hid_t obj, const std::string& key, const std::string& value) {
  Handle type = string_type();
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(quiet([&] { return H5Acreate2(obj, key.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT); }), H5Aclose);
  f.check(attr.get(), "cannot create attribute " + key);
  const char* p = value.c_str();
  f.check_status(quiet([&] { return H5Awrite(attr.get(), type.get(), &p); }), "cannot write attribute " + key);
}

// A fixed-length string attribute, stored inside the (checksummed) object header: hairlut's own
// metadata use these so that the loader never reads HDF5's global heap, which has no checksums
// (a corrupted global heap can send HDF5 1.10 into an endless loop).
void write_fixed_string_attr(const File& f, hid_t obj, const std::string& key, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), std::max<std::size_t>(value.size(), 1));
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(quiet([&] { return H5Acreate2(obj, key.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT); }), H5Aclose);
  f.check(attr.get(), "cannot create attribute " + key);
  std::string padded = value;
  if (padded.empty()) padded.push_back('\0');
  f.check_status(quiet([&] { return H5Awrite(attr.get(), type.get(), padded.data()); }), "cannot write attribute " + key);
}

void write_doubles_attr(const File& f, hid_t obj, const std::string& key, const std::vector<double>& v) {
  const hsize_t n = v.size();
  Handle space(v.size() == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose);
  Handle attr(quiet([&] { return H5Acreate2(obj, key.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT); }), H5Aclose);
  f.check(attr.get(), "cannot create attribute " + key);
  f.check_status(quiet([&] { return H5Awrite(attr.get(), H5T_NATIVE_DOUBLE, v.data()); }), "cannot write attribute " + key);
}

void write_int_attr(const File& f, hid_t obj, const std::string& key, long long v) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(quiet([&] { return H5Acreate2(obj, key.c_str(), H5T_STD_I64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT); }), H5Aclose);
  f.check(attr.get(), "cannot create attribute " + key);
  f.check_status(quiet([&] { return H5Awrite(attr.get(), H5T_NATIVE_LLONG, &v); }), "cannot write attribute " + key);
}

// JSON values as natural HDF5 attributes (strings, numbers, number arrays); anything else as JSON text.
void write_json_attrs(const File& f, hid_t obj, const json& attrs) {
  for (const auto& [key, value] : attrs.items()) {
    if (value.is_string()) write_string_attr(f, obj, key, value.get<std::string>());
    else if (value.is_number_integer() || value.is_boolean()) write_int_attr(f, obj, key, value.is_boolean() ? value.get<bool>() : value.get<long long>());
    else if (value.is_number()) write_doubles_attr(f, obj, key, {value.get<double>()});
    else if (value.is_array() && !value.empty() && std::all_of(value.begin(), value.end(), [](const json& x) { return x.is_number(); }))
      write_doubles_attr(f, obj, key, value.get<std::vector<double>>());
    else write_string_attr(f, obj, key, value.dump());
  }
}

// Reads one of hairlut's fixed-length string attributes (see write_fixed_string_attr).
std::string read_string_attr(const File& f, hid_t obj, const std::string& key, const std::string& where) {
  if (quiet([&] { return H5Aexists(obj, key.c_str()); }) <= 0) f.fail(where + ": missing attribute " + key + " (not a hairlut table file?)");
  Handle attr(quiet([&] { return H5Aopen(obj, key.c_str(), H5P_DEFAULT); }), H5Aclose);
  f.check(attr.get(), where + ": cannot open attribute " + key);
  Handle ftype(quiet([&] { return H5Aget_type(attr.get()); }), H5Tclose);
  if (!ftype.valid() || H5Tget_class(ftype.get()) != H5T_STRING || H5Tis_variable_str(ftype.get()) != 0)
    f.fail(where + ": attribute " + key + " is not a fixed-length string");
  Handle space(quiet([&] { return H5Aget_space(attr.get()); }), H5Sclose);
  if (!space.valid() || H5Sget_simple_extent_npoints(space.get()) != 1) f.fail(where + ": attribute " + key + " is not a scalar");
  const std::size_t n = H5Tget_size(ftype.get());
  if (n == 0 || n > (std::size_t{1} << 30)) f.fail(where + ": attribute " + key + " has an implausible size");
  Handle mtype(H5Tcopy(ftype.get()), H5Tclose);  // same size, padding and character set: no conversion
  std::string s(n, '\0');
  f.check_status(quiet([&] { return H5Aread(attr.get(), mtype.get(), s.data()); }), where + ": cannot read attribute " + key);
  s.resize(std::strlen(s.c_str()));
  return s;
}

// Creates the groups of a path such as "materials/blonde"; returns the innermost.
Handle open_or_create_group(const File& f, hid_t root, const std::string& path) {
  Handle gcpl(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
  H5Pset_obj_track_times(gcpl.get(), 0);
  Handle current(H5Gopen2(root, "/", H5P_DEFAULT), H5Gclose);
  std::size_t start = 0;
  while (start < path.size()) {
    const std::size_t end = std::min(path.find('/', start), path.size());
    const std::string part = path.substr(start, end - start);
    hid_t g;
    if (quiet([&] { return H5Lexists(current.get(), part.c_str(), H5P_DEFAULT); }) > 0)
      g = quiet([&] { return H5Gopen2(current.get(), part.c_str(), H5P_DEFAULT); });
    else
      g = quiet([&] { return H5Gcreate2(current.get(), part.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT); });
    f.check(g, "cannot create group " + path);
    current = Handle(g, H5Gclose);
    start = end + 1;
  }
  return current;
}

// Chunks: whole trailing planes (the sampler's inner axes), leading axes one at a time; a chunk
// stays under 4 MiB by splitting the outermost axis it reaches if needed.
std::vector<hsize_t> chunk_dims(const std::vector<hsize_t>& dims, std::size_t element) {
  std::vector<hsize_t> chunk(dims.size(), 1);
  std::size_t bytes = element;
  for (std::size_t k = dims.size(); k-- > 0;) {
    const hsize_t want = std::max<hsize_t>(dims[k], 1);
    if (bytes * want <= (std::size_t{4} << 20)) {
      chunk[k] = want;
      bytes *= want;
    } else {
      chunk[k] = std::max<hsize_t>(1, (std::size_t{4} << 20) / bytes);
      break;
    }
  }
  return chunk;
}

Handle dataset_create_plist(const File& f, const std::vector<hsize_t>& dims, std::size_t element, int deflate, bool whole = true) {
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_obj_track_times(dcpl.get(), 0);
  // Datasets written whole: compact or contiguous when small or unfiltered (hdf5_layout.hpp).
  f.check_status(detail::keep_attributes_compact(dcpl.get()), "cannot set attribute storage");
  std::size_t bytes = element;
  for (const hsize_t d : dims) bytes *= static_cast<std::size_t>(d);
  if (const detail::Hdf5Layout layout = detail::whole_dataset_layout(bytes, deflate); whole && layout != detail::Hdf5Layout::chunked) {
    f.check_status(detail::set_unfiltered_layout(dcpl.get(), layout), "cannot set the dataset layout");
    return dcpl;
  }
  std::vector<hsize_t> chunk = chunk_dims(dims, element);
  f.check_status(H5Pset_chunk(dcpl.get(), static_cast<int>(dims.size()), chunk.data()), "cannot set chunking");
  H5Pset_fletcher32(dcpl.get());
  H5Pset_shuffle(dcpl.get());
  if (deflate > 0) H5Pset_deflate(dcpl.get(), static_cast<unsigned>(deflate));
  return dcpl;
}

void write_scale(const File& f, hid_t group, const GridAxis& a, const std::string& name, int deflate) {
  const std::vector<double> nodes = a.nodes();
  const std::vector<hsize_t> dims = {static_cast<hsize_t>(nodes.size())};
  Handle space(H5Screate_simple(1, dims.data(), nullptr), H5Sclose);
  Handle dcpl = dataset_create_plist(f, dims, sizeof(double), deflate);
  Handle ds(quiet([&] { return H5Dcreate2(group, name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT); }),
            H5Dclose);
  f.check(ds.get(), "cannot create axis " + a.name);
  f.check_status(H5Dwrite(ds.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, nodes.data()), "cannot write axis " + a.name);
  f.check_status(H5DSset_scale(ds.get(), a.name.c_str()), "cannot make " + a.name + " a dimension scale");
  write_string_attr(f, ds.get(), "units", a.units);
  write_string_attr(f, ds.get(), "long_name", a.long_name);
  write_string_attr(f, ds.get(), "spacing", std::string(to_string(a.spacing)));
  write_string_attr(f, ds.get(), "placement", std::string(to_string(a.placement)));
  write_string_attr(f, ds.get(), "wrap", std::string(to_string(a.wrap)));
  write_doubles_attr(f, ds.get(), "range", {a.lo, a.hi});
  if (!a.labels.empty()) {
    std::string joined;
    for (const auto& l : a.labels) joined += (joined.empty() ? "" : ",") + l;
    write_string_attr(f, ds.get(), "labels", joined);
  }
}

// --- The attributes h5py users read (written by write_json_attrs / write_string_attr) must say
// what the checksummed metadata say: a reader refuses a file whose visible metadata were altered,
// naming the attribute. Numbers live in the (checksummed) object header; string values live in
// the global heap, which read_hdf5 screens first (hdf5_heap_check.hpp).

std::string read_vlen_string_attr(const File& f, hid_t attr, const std::string& where) {
  Handle type = string_type();
  char* value = nullptr;
  f.check_status(quiet([&] { return H5Aread(attr, type.get(), &value); }), where + ": cannot read the value");
  std::string s = value ? value : "";
  if (value) H5free_memory(value);
  return s;
}

// Fails naming `where` (object path and attribute) unless the attribute holds `want` as
// write_json_attrs would have written it.
void verify_attr(const File& f, hid_t obj, const std::string& key, const json& want, const std::string& object) {
  const std::string where = object + " attribute " + key;
  if (quiet([&] { return H5Aexists(obj, key.c_str()); }) <= 0) f.fail(where + " is missing (metadata altered)");
  Handle attr(quiet([&] { return H5Aopen(obj, key.c_str(), H5P_DEFAULT); }), H5Aclose);
  f.check(attr.get(), "cannot open " + where);
  Handle type(quiet([&] { return H5Aget_type(attr.get()); }), H5Tclose);
  Handle space(quiet([&] { return H5Aget_space(attr.get()); }), H5Sclose);
  if (!type.valid() || !space.valid()) f.fail("cannot read " + where);
  const H5T_class_t cls = H5Tget_class(type.get());
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  const bool numbers = want.is_array() && !want.empty() && std::all_of(want.begin(), want.end(), [](const json& x) { return x.is_number(); });
  bool same = false;
  if (want.is_number_integer() || want.is_boolean()) {
    long long v = 0;
    same = cls == H5T_INTEGER && n == 1 && quiet([&] { return H5Aread(attr.get(), H5T_NATIVE_LLONG, &v); }) >= 0 &&
           v == (want.is_boolean() ? static_cast<long long>(want.get<bool>()) : want.get<long long>());
  } else if (want.is_number() || numbers) {
    const std::vector<double> w = numbers ? want.get<std::vector<double>>() : std::vector<double>{want.get<double>()};
    std::vector<double> v(w.size());
    same = cls == H5T_FLOAT && n == static_cast<hssize_t>(w.size()) &&
           quiet([&] { return H5Aread(attr.get(), H5T_NATIVE_DOUBLE, v.data()); }) >= 0 && v == w;
  } else {
    const std::string w = want.is_string() ? want.get<std::string>() : want.dump();
    same = cls == H5T_STRING && H5Tis_variable_str(type.get()) > 0 && n == 1 && read_vlen_string_attr(f, attr.get(), "cannot read " + where) == w;
  }
  if (!same) f.fail(where + " disagrees with the checksummed metadata (metadata altered)");
}

void verify_json_attrs(const File& f, hid_t obj, const json& attrs, const std::string& object) {
  for (const auto& [key, value] : attrs.items()) verify_attr(f, obj, key, value, object);
}

void verify_scale_attrs(const File& f, hid_t scale, const GridAxis& a, const std::string& object) {
  verify_attr(f, scale, "units", a.units, object);
  verify_attr(f, scale, "long_name", a.long_name, object);
  verify_attr(f, scale, "spacing", std::string(to_string(a.spacing)), object);
  verify_attr(f, scale, "placement", std::string(to_string(a.placement)), object);
  verify_attr(f, scale, "wrap", std::string(to_string(a.wrap)), object);
  verify_attr(f, scale, "range", json::array({a.lo, a.hi}), object);
  if (!a.labels.empty()) {
    std::string joined;
    for (const auto& l : a.labels) joined += (joined.empty() ? "" : ",") + l;
    verify_attr(f, scale, "labels", joined, object);
  }
  if (quiet([&] { return H5DSis_scale(scale); }) <= 0) f.fail(object + " is no longer a dimension scale (metadata altered)");
}

// DIMENSION_LIST (which axis scale each dimension uses) must be present with one entry per
// dimension; its references live in the global heap and are not followed here.
void verify_dimension_list(const File& f, hid_t ds, std::size_t rank, const std::string& object) {
  const std::string where = object + " attribute DIMENSION_LIST";
  if (quiet([&] { return H5Aexists(ds, "DIMENSION_LIST"); }) <= 0) f.fail(where + " is missing (metadata altered)");
  Handle attr(quiet([&] { return H5Aopen(ds, "DIMENSION_LIST", H5P_DEFAULT); }), H5Aclose);
  Handle type(attr.valid() ? quiet([&] { return H5Aget_type(attr.get()); }) : -1, H5Tclose);
  Handle space(attr.valid() ? quiet([&] { return H5Aget_space(attr.get()); }) : -1, H5Sclose);
  if (!type.valid() || !space.valid() || H5Tget_class(type.get()) != H5T_VLEN ||
      H5Sget_simple_extent_npoints(space.get()) != static_cast<hssize_t>(rank))
    f.fail(where + " does not list one scale per dimension (metadata altered)");
}

bool same_axis(const GridAxis& a, const GridAxis& b) { return detail::identical_axes(a, b) || a.to_json() == b.to_json(); }  // quick test first

// The dataset name of an axis's dimension scale in its group: the axis's name, or name_2, name_3,
// ... for further, different axes of the same name in the group (the energy tables of a
// normalized N_p may use denser sigma_a and theta_d than N_p's), numbered in table order so that
// the writer and the loader agree.
class ScaleNames {
 public:
  std::string of(const std::string& group, const GridAxis& a) {
    std::vector<GridAxis>& variants = seen_[group][a.name];
    std::size_t i = 0;
    while (i < variants.size() && !same_axis(variants[i], a)) ++i;
    if (i == variants.size()) variants.push_back(a);
    return i == 0 ? a.name : a.name + "_" + std::to_string(i + 1);
  }

 private:
  std::map<std::string, std::map<std::string, std::vector<GridAxis>>> seen_;
};

// The superblock version byte that follows the signature at offset 0; hairlut writes ≥ 2.
void check_signature_bytes(const File& f, const unsigned char* head, std::size_t size) {
  static constexpr unsigned char sig[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
  if (size < 9 || std::memcmp(head, sig, 8) != 0) f.fail("not an HDF5 file (no HDF5 signature at offset 0)");
  if (head[8] < 2)
    f.fail("not a hairlut table file: HDF5 superblock version " + std::to_string(head[8]) +
           " (hairlut writes version 2 or later, whose metadata are checksummed)");
}

void check_signature(const File& f, const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) f.fail("cannot open file (" + std::string(std::strerror(errno)) + ")");
  std::array<unsigned char, 9> head{};
  in.read(reinterpret_cast<char*>(head.data()), head.size());
  check_signature_bytes(f, head.data(), static_cast<std::size_t>(in.gcount()));
}

}  // namespace

std::string format_version_text() { return std::to_string(kFormatVersionMajor) + "." + std::to_string(kFormatVersionMinor); }

void check_format_version(const std::string& text, const std::string& name) {
  const auto dot = text.find('.');
  auto digits = [](const std::string& d) {
    return !d.empty() && d.size() <= 6 && std::all_of(d.begin(), d.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (dot == std::string::npos || !digits(text.substr(0, dot)) || !digits(text.substr(dot + 1)))
    throw IoError(name + ": malformed format version \"" + text.substr(0, 40) + "\" (expected MAJOR.MINOR)");
  const int major = std::stoi(text.substr(0, dot));
  if (major > kFormatVersionMajor)
    throw IoError(name + ": written in table format " + text + ", newer than this hairlut reads (format " + format_version_text() +
                  ", major version " + std::to_string(kFormatVersionMajor) + "); use a newer hairlut");
  if (major < kFormatVersionMajor)
    throw IoError(name + ": written in table format " + text + ", older than this hairlut reads (major version " +
                  std::to_string(kFormatVersionMajor) + "); bake the tables again");
}

namespace {

// Leading-axis row ranges [row0, row0 + rows) of each slabbed table (empty for tables held whole).
using SlabRanges = std::vector<std::vector<std::pair<std::size_t, std::size_t>>>;

struct SlabFeed {
  const SlabRanges* ranges;
  detail::SlabQueue* queue;
};

struct WriterStopped {};  // the baking side stopped: unwind the writer quietly

// Everything write_hdf5 stores, into an open file. With a feed, the values of slabbed tables
// arrive slab by slab and the content checksum is computed while writing, over the same bytes in
// the same order as content_checksum (the metadata, then each table's description and values),
// and stored last; without one it is computed first from the tables in memory.
void write_contents(const File& f, hid_t file, const TableSet& set, const Hdf5WriteOptions& options, SlabFeed* feed) {
  Handle root(H5Gopen2(file, "/", H5P_DEFAULT), H5Gclose);
  write_fixed_string_attr(f, root.get(), "hairlut_format_version", format_version_text());
  // Provenance on the root, both as individual attributes and as one JSON text.
  write_json_attrs(f, root.get(), set.metadata);
  write_fixed_string_attr(f, root.get(), "hairlut_metadata", set.metadata.dump());
  json index = json::array();
  for (const Table& t : set.tables) index.push_back(t.path());
  write_fixed_string_attr(f, root.get(), "hairlut_tables", index.dump());
  Fnv1a64 hash;
  // Each table's description, dumped once for the checksum and its hairlut_table attribute.
  std::vector<std::string> described;
  for (const Table& t : set.tables) described.push_back(t.describe().dump());
  if (!feed) write_fixed_string_attr(f, root.get(), "hairlut_checksum", detail::content_checksum_of(set, described));
  else hash.update(set.metadata.dump());

  // Dimension scales per group, then the tables.
  ScaleNames names;
  std::map<std::string, std::map<std::string, GridAxis>> scales;
  for (const Table& t : set.tables)
    for (const GridAxis& a : t.axes) scales[t.group].emplace(names.of(t.group, a), a);
  for (const auto& [group, axes] : scales) {
    Handle g = open_or_create_group(f, file, group);
    for (const auto& [name, axis] : axes) write_scale(f, g.get(), axis, name, options.deflate);
  }
  for (std::size_t i = 0; i < set.tables.size(); ++i) {
    const Table& t = set.tables[i];
    const bool slabbed = feed && !(*feed->ranges)[i].empty();
    Handle g = open_or_create_group(f, file, t.group);
    std::vector<hsize_t> dims;
    for (const GridAxis& a : t.axes) dims.push_back(static_cast<hsize_t>(a.count));
    if (!slabbed && grid_size(t.axes) != t.size())
      f.fail("table " + t.path() + " holds " + std::to_string(t.size()) + " values for its axes' grid");
    const bool dbl = t.precision == Precision::float64;
    const hid_t mem_type = dbl ? H5T_NATIVE_DOUBLE : H5T_NATIVE_FLOAT;
    Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
    Handle dcpl = dataset_create_plist(f, dims, dbl ? 8 : 4, options.deflate, !slabbed);
    Handle ds(quiet([&] {
                return H5Dcreate2(g.get(), t.name.c_str(), dbl ? H5T_IEEE_F64LE : H5T_IEEE_F32LE, space.get(), H5P_DEFAULT,
                                  dcpl.get(), H5P_DEFAULT);
              }),
              H5Dclose);
    f.check(ds.get(), "cannot create dataset " + t.path());
    if (feed) hash.update(described[i]);
    if (!slabbed) {
      const void* data = dbl ? static_cast<const void*>(t.f64.data()) : static_cast<const void*>(t.f32.data());
      f.check_status(H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "cannot write dataset " + t.path());
      if (feed) hash.update(data, t.size() * (dbl ? 8 : 4));
    } else {
      // Each slab as a hyperslab of whole leading-axis rows (chunk-aligned by SlabRanges).
      for (const auto& [row0, rows] : (*feed->ranges)[i]) {
        detail::SlabQueue::Item item;
        if (!feed->queue->take_full(item)) throw WriterStopped{};
        if (item.row0 != row0 || item.rows != rows) f.fail("internal: slab of " + t.path() + " out of order");
        const Table& v = *item.values;
        std::vector<hsize_t> start(dims.size(), 0), count = dims;
        start[0] = row0, count[0] = rows;
        f.check_status(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr),
                       "cannot select rows of " + t.path());
        const hsize_t n = v.size();
        Handle mem(H5Screate_simple(1, &n, nullptr), H5Sclose);
        const void* data = dbl ? static_cast<const void*>(v.f64.data()) : static_cast<const void*>(v.f32.data());
        f.check_status(quiet([&] { return H5Dwrite(ds.get(), mem_type, mem.get(), space.get(), H5P_DEFAULT, data); }),
                       "cannot write rows " + std::to_string(row0) + "-" + std::to_string(row0 + rows - 1) + " of dataset " + t.path());
        hash.update(data, v.size() * (dbl ? 8 : 4));
        feed->queue->put_empty(item.values);
      }
    }
    for (std::size_t k = 0; k < t.axes.size(); ++k) {
      Handle scale(H5Dopen2(g.get(), names.of(t.group, t.axes[k]).c_str(), H5P_DEFAULT), H5Dclose);
      f.check_status(H5DSattach_scale(ds.get(), scale.get(), static_cast<unsigned>(k)), "cannot attach axis " + t.axes[k].name);
    }
    write_string_attr(f, ds.get(), "quantity", t.quantity);
    write_string_attr(f, ds.get(), "units", t.units);
    write_string_attr(f, ds.get(), "long_name", t.long_name);
    write_json_attrs(f, ds.get(), t.attributes);
    write_fixed_string_attr(f, ds.get(), "hairlut_table", described[i]);
  }
  if (feed) write_fixed_string_attr(f, root.get(), "hairlut_checksum", hash.hex());
}

// The whole HDF5 file, built in memory (HDF5's core driver without a backing store): HDF5 never
// writes to disk, so a full disk or a file-size limit cannot leave HDF5 with a file it fails to
// close (HDF5 1.10 then crashes when the library shuts down); write_file_bytes reports it instead.
// (Slabbed tables cannot be held in memory: write_slabbed_file writes them to disk directly.)
std::vector<char> hdf5_image(const TableSet& set, const File& f, const Hdf5WriteOptions& options) {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG);  // on an error path, closing the file closes every object in it
  H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V110, H5F_LIBVER_LATEST);  // 1.10 format: compact chunk indexes
  f.check_status(H5Pset_fapl_core(fapl.get(), std::size_t{1} << 20, 0), "cannot set up an in-memory HDF5 file");
  Handle fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  H5Pset_obj_track_times(fcpl.get(), 0);
  Handle file(quiet([&] { return H5Fcreate(f.name.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()); }), H5Fclose);
  f.check(file.get(), "cannot create HDF5 file");
  write_contents(f, file.get(), set, options, nullptr);
  f.check_status(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), "cannot flush HDF5 file");
  const ssize_t size = H5Fget_file_image(file.get(), nullptr, 0);
  if (size <= 0) f.fail("cannot take the HDF5 file image");
  std::vector<char> image(static_cast<std::size_t>(size));
  if (H5Fget_file_image(file.get(), image.data(), image.size()) != size) f.fail("cannot take the HDF5 file image");
  detail::fix_superblock_checksum(image);
  f.check_status(file.close_now(), "cannot close HDF5 file");
  return image;
}

// The slabbed file, written straight to disk (HDF5's default driver) from the writer thread.
void write_slabbed_file(const TableSet& set, const std::filesystem::path& path, const Hdf5WriteOptions& options, SlabFeed& feed) {
  const ErrorSilencer silence;
  const File f{path.string()};
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG);
  H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V110, H5F_LIBVER_LATEST);
  Handle fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  H5Pset_obj_track_times(fcpl.get(), 0);
  Handle file(quiet([&] { return H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()); }), H5Fclose);
  f.check(file.get(), "cannot create HDF5 file");
  write_contents(f, file.get(), set, options, &feed);
  f.check_status(quiet([&] { return file.close_now(); }), "cannot close HDF5 file");
  detail::sync_file(path);
}

}  // namespace

void write_hdf5_slabbed(const TableSet& set, const SlabbedTables& slabbed, const std::filesystem::path& path,
                        const Hdf5WriteOptions& options) {
  if (slabbed.empty()) return write_hdf5(set, path, options);
  // Slabs: whole multiples of the chunk's leading extent, as many as fit in slab_bytes.
  SlabRanges ranges(set.tables.size());
  std::vector<const SlabbedTable*> order;
  for (const SlabbedTable& st : slabbed.tables) {
    const Table& t = set.tables.at(st.table);
    std::vector<hsize_t> dims;
    for (const GridAxis& a : t.axes) dims.push_back(static_cast<hsize_t>(a.count));
    const std::size_t element = t.precision == Precision::float64 ? 8 : 4;
    const std::vector<hsize_t> chunk = chunk_dims(dims, element);
    std::uint64_t row_bytes = element;
    for (std::size_t k = 1; k < dims.size(); ++k) row_bytes *= dims[k];
    const std::uint64_t step = std::max<hsize_t>(chunk[0], 1);
    if (row_bytes * step > slabbed.slab_bytes)
      throw DomainError("table " + t.path() + ": one row of its leading axis " + t.axes[0].name + " takes " +
                        std::to_string(row_bytes * step >> 20) + " MiB, more than a slab of the memory budget (" +
                        std::to_string(slabbed.slab_bytes >> 20) + " MiB); raise --memory-budget or use fewer nodes on the other axes");
    const std::size_t per = static_cast<std::size_t>(slabbed.slab_bytes / (row_bytes * step) * step);
    for (std::size_t row0 = 0; row0 < dims[0]; row0 += per) ranges[st.table].emplace_back(row0, std::min<std::size_t>(per, dims[0] - row0));
    order.push_back(&st);
  }
  std::sort(order.begin(), order.end(), [](const SlabbedTable* a, const SlabbedTable* b) { return a->table < b->table; });

  detail::SlabQueue queue;
  SlabFeed feed{&ranges, &queue};
  std::exception_ptr writer_error;
  std::thread writer([&] {
    try {
      write_slabbed_file(set, path, options, feed);
    } catch (const WriterStopped&) {
    } catch (...) {
      writer_error = std::current_exception();
    }
    queue.close();
  });
  std::exception_ptr baker_error;
  try {
    for (const SlabbedTable* st : order) {
      const Table& t = set.tables[st->table];
      const std::size_t row_values = grid_size(t.axes) / static_cast<std::size_t>(std::max(t.axes[0].count, 1));
      for (const auto& [row0, rows] : ranges[st->table]) {
        Table* buffer = queue.take_empty();
        if (!buffer) break;
        buffer->precision = t.precision;
        if (t.precision == Precision::float64) buffer->f64.resize(rows * row_values);
        else buffer->f32.resize(rows * row_values);
        st->fill(row0, rows, *buffer);
        queue.put_full({buffer, row0, rows});
      }
    }
  } catch (...) {
    baker_error = std::current_exception();
    queue.close();
  }
  writer.join();
  if (baker_error) std::rethrow_exception(baker_error);
  if (writer_error) std::rethrow_exception(writer_error);
}

void write_hdf5(const TableSet& set, const std::filesystem::path& path, const Hdf5WriteOptions& options) {
  const ErrorSilencer silence;
  const File f{path.string()};
  const std::vector<char> image = hdf5_image(set, f, options);
  detail::write_file_bytes(path, image);
}

namespace {
TableSet read_open_file(const File& f, hid_t file_id);
}

TableSet read_hdf5(const std::filesystem::path& path) {
  const ErrorSilencer silence;
  const File f{path.string()};
  check_signature(f, path);
  if (const std::string why = detail::global_heap_problem(path); !why.empty()) f.fail(why);
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG);  // closing the file closes whatever a failed read left open
  Handle file(quiet([&] { return H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()); }), H5Fclose);
  f.check(file.get(), "cannot open as HDF5 (truncated or corrupted file)");
  return read_open_file(f, file.get());
}

TableSet read_hdf5_memory(const char* data, std::size_t size, const std::string& name) {
  const ErrorSilencer silence;
  const File f{name};
  check_signature_bytes(f, reinterpret_cast<const unsigned char*>(data), size);
  if (const std::string why = detail::global_heap_problem(reinterpret_cast<const unsigned char*>(data), size); !why.empty()) f.fail(why);
  // An in-memory file image (core driver, no backing store): HDF5 reads from a private copy.
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG);
  f.check_status(H5Pset_fapl_core(fapl.get(), 1 << 16, 0), "cannot set up an in-memory HDF5 file");
  f.check_status(quiet([&] { return H5Pset_file_image(fapl.get(), const_cast<char*>(data), size); }), "cannot load the HDF5 file image");
  Handle file(quiet([&] { return H5Fopen("hairlut-memory-image.h5", H5F_ACC_RDONLY, fapl.get()); }), H5Fclose);
  f.check(file.get(), "cannot open as HDF5 (truncated or corrupted file)");
  return read_open_file(f, file.get());
}

namespace {
TableSet read_open_file(const File& f, hid_t file_id) {
  Handle root(quiet([&] { return H5Gopen2(file_id, "/", H5P_DEFAULT); }), H5Gclose);
  f.check(root.get(), "cannot open the root group");

  if (quiet([&] { return H5Aexists(root.get(), "hairlut_format_version"); }) <= 0) {
    (void)read_string_attr(f, root.get(), "hairlut_metadata", "/");  // no hairlut metadata at all: says so
    f.fail("missing attribute hairlut_format_version (written before the table format was versioned; bake the tables again)");
  }
  check_format_version(read_string_attr(f, root.get(), "hairlut_format_version", "/"), f.name);

  TableSet set;
  json index;
  try {
    set.metadata = json::parse(read_string_attr(f, root.get(), "hairlut_metadata", "/"));
    index = json::parse(read_string_attr(f, root.get(), "hairlut_tables", "/"));
  } catch (const json::exception&) {
    f.fail("malformed hairlut metadata (JSON) on the root group");
  }
  if (!set.metadata.is_object() || !index.is_array()) f.fail("malformed hairlut metadata on the root group");
  std::set<std::string> seen;
  ScaleNames scale_names;
  for (const json& entry : index) {
    if (!entry.is_string()) f.fail("malformed table index");
    const std::string tpath = entry.get<std::string>();
    if (!seen.insert(tpath).second) f.fail("table " + tpath + " listed twice");
    const auto slash = tpath.rfind('/');
    if (slash == std::string::npos || slash == 0) f.fail("malformed table path " + tpath);
    if (quiet([&] { return H5Lexists(root.get(), tpath.c_str(), H5P_DEFAULT); }) <= 0 &&
        quiet([&] { return H5Oexists_by_name(root.get(), tpath.c_str(), H5P_DEFAULT); }) <= 0)
      f.fail("table " + tpath + " is listed but missing");
    Handle ds(quiet([&] { return H5Dopen2(root.get(), tpath.c_str(), H5P_DEFAULT); }), H5Dclose);
    f.check(ds.get(), "cannot open table " + tpath + " (missing or corrupted)");
    json desc;
    try {
      desc = json::parse(read_string_attr(f, ds.get(), "hairlut_table", tpath));
    } catch (const json::exception&) {
      f.fail(tpath + ": malformed hairlut_table attribute");
    }
    Table t;
    try {
      t.group = desc.at("group").get<std::string>();
      t.name = desc.at("name").get<std::string>();
      t.quantity = desc.at("quantity").get<std::string>();
      t.units = desc.at("units").get<std::string>();
      t.long_name = desc.value("long_name", std::string());
      t.attributes = desc.value("attributes", json::object());
      const json& axes = desc.at("axes");
      if (!axes.is_array() || axes.size() > 8) f.fail(tpath + ": malformed axes");
      for (std::size_t k = 0; k < axes.size(); ++k) t.axes.push_back(GridAxis::from_json(axes[k], tpath + ".axes[" + std::to_string(k) + "]"));
    } catch (const json::exception& e) {
      f.fail(tpath + ": malformed hairlut_table attribute (" + std::string(e.what()) + ")");
    } catch (const DomainError& e) {
      f.fail(e.what());
    }
    if (t.path() != tpath) f.fail(tpath + ": hairlut_table names a different path (" + t.path() + ")");
    // The stored shape must be the axes' shape.
    Handle space(quiet([&] { return H5Dget_space(ds.get()); }), H5Sclose);
    f.check(space.get(), tpath + ": cannot read the dataspace");
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank != static_cast<int>(t.axes.size())) f.fail(tpath + ": has rank " + std::to_string(rank) + " but " + std::to_string(t.axes.size()) + " axes");
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
    H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
    for (int k = 0; k < rank; ++k)
      if (dims[static_cast<std::size_t>(k)] != static_cast<hsize_t>(t.axes[static_cast<std::size_t>(k)].count))
        f.fail(tpath + ": dimension " + std::to_string(k) + " has " + std::to_string(dims[static_cast<std::size_t>(k)]) +
               " entries but axis " + t.axes[static_cast<std::size_t>(k)].name + " has " +
               std::to_string(t.axes[static_cast<std::size_t>(k)].count));
    std::size_t n = 0;
    try {
      n = grid_size(t.axes);
    } catch (const DomainError&) {
      f.fail(tpath + ": too large");
    }
    if (n > (std::size_t{1} << 32)) f.fail(tpath + ": too large (" + std::to_string(n) + " values)");
    Handle ftype(quiet([&] { return H5Dget_type(ds.get()); }), H5Tclose);
    if (!ftype.valid() || H5Tget_class(ftype.get()) != H5T_FLOAT) f.fail(tpath + ": values are not floating point");
    const std::size_t bytes = H5Tget_size(ftype.get());
    if (bytes != 4 && bytes != 8) f.fail(tpath + ": values are neither float32 nor float64");
    t.allocate(bytes == 8 ? Precision::float64 : Precision::float32);
    void* data = bytes == 8 ? static_cast<void*>(t.f64.data()) : static_cast<void*>(t.f32.data());
    const herr_t status = quiet([&] {
      return H5Dread(ds.get(), bytes == 8 ? H5T_NATIVE_DOUBLE : H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    });
    if (status < 0) f.fail(tpath + ": cannot read the values (data corrupted: checksum or decompression failed)");
    // Each axis must be attached as a dimension scale whose values are the axis's nodes.
    Handle group(quiet([&] { return H5Gopen2(root.get(), t.group.c_str(), H5P_DEFAULT); }), H5Gclose);
    f.check(group.get(), tpath + ": cannot open group " + t.group);
    for (std::size_t k = 0; k < t.axes.size(); ++k) {
      const GridAxis& a = t.axes[k];
      const std::string scale_name = scale_names.of(t.group, a);
      Handle scale(quiet([&] { return H5Dopen2(group.get(), scale_name.c_str(), H5P_DEFAULT); }), H5Dclose);
      if (!scale.valid()) f.fail(tpath + ": missing dimension scale " + t.group + "/" + scale_name);
      // The attachment itself (DIMENSION_LIST) lives in the unchecksummed global heap, so it is
      // not read here; tests check it with h5py.
      Handle sspace(quiet([&] { return H5Dget_space(scale.get()); }), H5Sclose);
      if (!sspace.valid() || H5Sget_simple_extent_npoints(sspace.get()) != a.count)
        f.fail(tpath + ": dimension scale " + a.name + " has the wrong length");
      std::vector<double> values(static_cast<std::size_t>(a.count));
      if (quiet([&] { return H5Dread(scale.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()); }) < 0)
        f.fail(tpath + ": cannot read dimension scale " + a.name + " (corrupted)");
      if (values != a.nodes()) f.fail(tpath + ": dimension scale " + a.name + " disagrees with the axis metadata");
    }
    set.tables.push_back(std::move(t));
  }
  // The content checksum covers everything read above; HDF5 checksums only part of it.
  if (read_string_attr(f, root.get(), "hairlut_checksum", "/") != content_checksum(set))
    f.fail("content checksum mismatch: the file is corrupted");
  // The visible copies of the metadata (what h5py shows) must agree with the checksummed ones.
  verify_json_attrs(f, root.get(), set.metadata, "/");
  ScaleNames visible_scales;
  for (const Table& t : set.tables) {
    const std::string object = "/" + t.path();
    Handle ds(quiet([&] { return H5Dopen2(root.get(), t.path().c_str(), H5P_DEFAULT); }), H5Dclose);
    f.check(ds.get(), "cannot open table " + object);
    verify_attr(f, ds.get(), "quantity", t.quantity, object);
    verify_attr(f, ds.get(), "units", t.units, object);
    verify_attr(f, ds.get(), "long_name", t.long_name, object);
    verify_json_attrs(f, ds.get(), t.attributes, object);
    verify_dimension_list(f, ds.get(), t.axes.size(), object);
    for (const GridAxis& a : t.axes) {
      const std::string scale_path = t.group + "/" + visible_scales.of(t.group, a);
      Handle scale(quiet([&] { return H5Dopen2(root.get(), scale_path.c_str(), H5P_DEFAULT); }), H5Dclose);
      f.check(scale.get(), "cannot open dimension scale /" + scale_path);
      verify_scale_attrs(f, scale.get(), a, "/" + scale_path);
    }
  }
  return set;
}
}  // namespace

}  // namespace hairlut
