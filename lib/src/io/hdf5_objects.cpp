// HDF5 objects as hairlut uses them (hdf5_objects.hpp).
#include "hdf5_objects.hpp"
#include "hdf5_layout.hpp"

#include <hdf5_hl.h>
#include <algorithm>
#include <cmath>
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

#include <hdf5_hl.h>

namespace hairlut::detail::h5 {

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

Handle string_type() {
  Handle t(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(t.get(), H5T_VARIABLE);
  H5Tset_cset(t.get(), H5T_CSET_UTF8);
  return t;
}

void write_string_attr(const File& f, hid_t obj, const std::string& key, const std::string& value) {
  const hid_t type = f.string_type_id();
  Handle attr(quiet([&] { return H5Acreate2(obj, key.c_str(), type, f.scalar_space_id(), H5P_DEFAULT, H5P_DEFAULT); }), H5Aclose);
  f.check(attr.get(), "cannot create attribute " + key);
  const char* p = value.c_str();
  f.check_status(quiet([&] { return H5Awrite(attr.get(), type, &p); }), "cannot write attribute " + key);
}

// A fixed-length string attribute, stored inside the (checksummed) object header: hairlut's own
// metadata use these so that the loader never reads HDF5's global heap, which has no checksums
// (a corrupted global heap can send HDF5 1.10 into an endless loop).
void write_fixed_string_attr(const File& f, hid_t obj, const std::string& key, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), std::max<std::size_t>(value.size(), 1));
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  Handle attr(quiet([&] { return H5Acreate2(obj, key.c_str(), type.get(), f.scalar_space_id(), H5P_DEFAULT, H5P_DEFAULT); }), H5Aclose);
  f.check(attr.get(), "cannot create attribute " + key);
  std::string padded = value;
  if (padded.empty()) padded.push_back('\0');
  f.check_status(quiet([&] { return H5Awrite(attr.get(), type.get(), padded.data()); }), "cannot write attribute " + key);
}

void write_doubles_attr(const File& f, hid_t obj, const std::string& key, const std::vector<double>& v) {
  const hsize_t n = v.size();
  Handle array(v.size() == 1 ? Handle() : Handle(H5Screate_simple(1, &n, nullptr), H5Sclose));
  const hid_t space = v.size() == 1 ? f.scalar_space_id() : array.get();
  Handle attr(quiet([&] { return H5Acreate2(obj, key.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT); }), H5Aclose);
  f.check(attr.get(), "cannot create attribute " + key);
  f.check_status(quiet([&] { return H5Awrite(attr.get(), H5T_NATIVE_DOUBLE, v.data()); }), "cannot write attribute " + key);
}

void write_int_attr(const File& f, hid_t obj, const std::string& key, long long v) {
  Handle attr(quiet([&] { return H5Acreate2(obj, key.c_str(), H5T_STD_I64LE, f.scalar_space_id(), H5P_DEFAULT, H5P_DEFAULT); }), H5Aclose);
  f.check(attr.get(), "cannot create attribute " + key);
  f.check_status(quiet([&] { return H5Awrite(attr.get(), H5T_NATIVE_LLONG, &v); }), "cannot write attribute " + key);
}

// JSON values as natural HDF5 attributes (strings, numbers, number arrays); anything else as JSON text.
namespace {
// Whether every number in `v` is finite: JSON has no infinity or NaN (they dump as null), so a
// file holding one would not match its own checksummed metadata and its loader would refuse it.
bool all_finite(const json& v) {
  if (v.is_number_float()) return std::isfinite(v.get<double>());
  if (v.is_structured())
    for (const json& x : v)
      if (!all_finite(x)) return false;
  return true;
}
}  // namespace

void write_json_attrs(const File& f, hid_t obj, const json& attrs) {
  for (const auto& [key, value] : attrs.items()) {
    if (!all_finite(value))
      f.fail("attribute " + key + " holds a number that is not finite (" + value.dump().substr(0, 80) +
             "): the settings overflow it; nothing was written");
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
  if (n == 0 || n > (std::size_t{1} << 30) || (f.bytes > 0 && n > f.bytes))
    f.fail(where + ": attribute " + key + " has an implausible size (" + std::to_string(n) + " bytes)");
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
  // Links kept in the group's header up to 64 (HDF5's default moves more than 8, e.g. a
  // material's 9 datasets, to a fractal heap and a B-tree of their own).
  f.check_status(H5Pset_link_phase_change(gcpl.get(), 64, 48), "cannot set link storage");
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

Handle dataset_create_plist(const File& f, const std::vector<hsize_t>& dims, std::size_t element, int deflate, bool whole) {
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

Handle write_scale(const File& f, hid_t group, const GridAxis& a, const std::string& name, int deflate) {
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
  // The reconstruction along the axis, for readers that use only the scales (table-format.md).
  write_string_attr(f, ds.get(), "interpolation", std::string(to_string(a.interpolation)));
  write_string_attr(f, ds.get(), "lo_end", std::string(to_string(a.lo_end)));
  if (!a.labels.empty()) {
    std::string joined;
    for (const auto& l : a.labels) joined += (joined.empty() ? "" : ",") + l;
    write_string_attr(f, ds.get(), "labels", joined);
  }
  return ds;
}

void write_dimension_list(const File& f, hid_t ds, const std::vector<hobj_ref_t>& scales) {
  const hsize_t rank = scales.size();
  Handle space(H5Screate_simple(1, &rank, nullptr), H5Sclose);
  Handle type(H5Tvlen_create(H5T_STD_REF_OBJ), H5Tclose);
  Handle attr(quiet([&] { return H5Acreate2(ds, DIMENSION_LIST, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT); }), H5Aclose);
  f.check(attr.get(), "cannot create attribute " DIMENSION_LIST);
  std::vector<hobj_ref_t> refs = scales;
  std::vector<hvl_t> lists(scales.size());
  for (std::size_t k = 0; k < scales.size(); ++k) lists[k] = {1, &refs[k]};
  f.check_status(quiet([&] { return H5Awrite(attr.get(), type.get(), lists.data()); }), "cannot write attribute " DIMENSION_LIST);
}

void write_reference_list(const File& f, hid_t scale, const std::vector<ScaleUse>& uses) {
  const hsize_t n = uses.size();
  Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose);
  Handle type(H5Tcreate(H5T_COMPOUND, sizeof(ScaleUse)), H5Tclose);
  f.check_status(H5Tinsert(type.get(), "dataset", HOFFSET(ScaleUse, dataset), H5T_STD_REF_OBJ), "cannot build the REFERENCE_LIST type");
  f.check_status(H5Tinsert(type.get(), "dimension", HOFFSET(ScaleUse, dimension), H5T_NATIVE_INT), "cannot build the REFERENCE_LIST type");
  Handle attr(quiet([&] { return H5Acreate2(scale, REFERENCE_LIST, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT); }), H5Aclose);
  f.check(attr.get(), "cannot create attribute " REFERENCE_LIST);
  f.check_status(quiet([&] { return H5Awrite(attr.get(), type.get(), uses.data()); }), "cannot write attribute " REFERENCE_LIST);
}

hobj_ref_t object_reference(const File& f, hid_t loc, const std::string& name) {
  hobj_ref_t ref{};
  f.check_status(H5Rcreate(&ref, loc, name.c_str(), H5R_OBJECT, -1), "cannot reference " + name);
  return ref;
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

namespace {
struct LinkVisit {
  std::string bad;  // the first link that is not a hard link
  std::size_t count = 0;
};
constexpr std::size_t kMaxLinks = std::size_t{1} << 20;
}  // namespace

void check_links(const File& f, hid_t root) {
  LinkVisit visit;
  const herr_t status = quiet([&] {
    return H5Lvisit(
        root, H5_INDEX_NAME, H5_ITER_NATIVE,
        [](hid_t, const char* name, const H5L_info_t* info, void* data) -> herr_t {
          auto* v = static_cast<LinkVisit*>(data);
          if (++v->count > kMaxLinks) return 1;
          if (info->type != H5L_TYPE_HARD) {
            v->bad = std::string(name).substr(0, 200) + (info->type == H5L_TYPE_EXTERNAL ? " is an external link (to another file)"
                                                         : info->type == H5L_TYPE_SOFT   ? " is a soft link"
                                                                                         : " is a user-defined link");
            return 1;
          }
          return 0;
        },
        &visit);
  });
  if (!visit.bad.empty()) f.fail(visit.bad + ": refused (hairlut files hold only their own objects)");
  if (visit.count > kMaxLinks) f.fail("more than " + std::to_string(kMaxLinks) + " links: not a hairlut table file");
  if (status < 0) f.fail("cannot list the file's objects (corrupted file)");
}

std::uint64_t check_dataset_storage(const File& f, hid_t ds, const std::string& object, std::uint64_t raw_bytes) {
  Handle dcpl(quiet([&] { return H5Dget_create_plist(ds); }), H5Pclose);
  f.check(dcpl.get(), object + ": cannot read the storage properties");
  const int external = quiet([&] { return H5Pget_external_count(dcpl.get()); });
  if (external != 0) f.fail(object + ": values stored in external files: refused (hairlut keeps every value in its file)");
  const H5D_layout_t layout = quiet([&] { return H5Pget_layout(dcpl.get()); });
  if (layout == H5D_VIRTUAL) f.fail(object + ": a virtual dataset (values mapped from other files): refused");
  if (layout != H5D_COMPACT && layout != H5D_CONTIGUOUS && layout != H5D_CHUNKED) f.fail(object + ": unknown storage layout");
  const int filters = quiet([&] { return H5Pget_nfilters(dcpl.get()); });
  if (filters < 0 || filters > 8) f.fail(object + ": unreadable filter pipeline");
  for (int i = 0; i < filters; ++i) {
    unsigned flags = 0, config = 0;
    std::size_t nvalues = 0;
    const H5Z_filter_t id = quiet([&] { return H5Pget_filter2(dcpl.get(), static_cast<unsigned>(i), &flags, &nvalues, nullptr, 0, nullptr, &config); });
    if (id != H5Z_FILTER_DEFLATE && id != H5Z_FILTER_SHUFFLE && id != H5Z_FILTER_FLETCHER32)
      f.fail(object + ": uses HDF5 filter " + std::to_string(id) + " (hairlut writes deflate, shuffle and Fletcher-32 only)");
  }
  if (raw_bytes == 0) return 0;
  const std::uint64_t stored = quiet([&] { return H5Dget_storage_size(ds); });
  if (stored == 0) f.fail(object + ": values not stored in the file (a dataset read as fill values)");
  if (f.bytes > 0 && stored > f.bytes) f.fail(object + ": claims " + std::to_string(stored) + " stored bytes, more than the file has");
  if (layout != H5D_CHUNKED && stored < raw_bytes) f.fail(object + ": stores fewer bytes than its values take");
  if (raw_bytes / kMaxCompressionRatio > stored)
    f.fail(object + ": " + std::to_string(raw_bytes) + " bytes of values from " + std::to_string(stored) +
           " stored bytes, more than deflate can expand to (corrupted or hostile file)");
  return stored;
}

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
}  // namespace hairlut::detail::h5
