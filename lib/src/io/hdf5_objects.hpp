// Internal: HDF5 objects as hairlut's reader and writer use them. Handles that close themselves,
// one-line errors naming the file, hairlut's attributes (fixed-length strings in the checksummed
// object header), chunking, dimension scales and the checks of what h5py users see.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hairlut/io/hdf5_io.hpp"
#include "hairlut/tables/tables.hpp"
#include "hairlut/util/error.hpp"
#include "axis_identity.hpp"

namespace hairlut::detail::h5 {

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
  ~Handle();
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
  /// Whether an ErrorSilencer is alive on this thread (HDF5's automatic printing is per thread).
  static bool active() { return depth_ > 0; }
  ErrorSilencer() {
    ++depth_;
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
  ~ErrorSilencer() {
    H5Eset_auto2(H5E_DEFAULT, func_, data_);
    --depth_;
  }

 private:
  static inline thread_local int depth_ = 0;
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// The innermost message of HDF5's current error stack as a short phrase (the system's reason,
// e.g. "No space left on device", when HDF5 recorded one); empty when the stack is empty. Clears
// the stack.
std::string hdf5_reason();

// A variable-length UTF-8 string type (h5py reads it as str).
Handle string_type();

// Context for one file: turns HDF5 failures into one-line IoErrors naming the file and, when HDF5
// gives one, its innermost reason; and holds what the writer's attributes share (created on first
// use, closed with the File): the variable-length string type and the scalar dataspace. Creating
// and closing them for each of a file's hundreds of attributes was a tenth of the writer's work.
struct File {
  std::string name;
  std::uint64_t bytes = 0;  // the file's size when reading (0: not known); bounds what it may hold
  mutable Handle vlen_string_type{};
  mutable Handle scalar_space{};

  hid_t string_type_id() const {
    if (!vlen_string_type.valid()) vlen_string_type = string_type();
    return vlen_string_type.get();
  }
  hid_t scalar_space_id() const {
    if (!scalar_space.valid()) scalar_space = Handle(H5Screate(H5S_SCALAR), H5Sclose);
    return scalar_space.get();
  }

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

// f() with HDF5's automatic error printing off: inside an ErrorSilencer it already is (and saving
// and restoring it around every call costs more than many of the calls themselves).
template <class F>
auto quiet(F&& f) {
  if (ErrorSilencer::active()) return f();
  decltype(f()) r{};
  H5E_BEGIN_TRY { r = f(); }
  H5E_END_TRY;
  return r;
}

inline Handle::~Handle() {
  if (id_ >= 0 && close_) quiet([&] { return close_(id_); });
}

void write_string_attr(const File& f, hid_t obj, const std::string& key, const std::string& value);

// A fixed-length string attribute, stored inside the (checksummed) object header: hairlut's own
// metadata use these so that the loader never reads HDF5's global heap, which has no checksums
// (a corrupted global heap can send HDF5 1.10 into an endless loop).
void write_fixed_string_attr(const File& f, hid_t obj, const std::string& key, const std::string& value);

void write_doubles_attr(const File& f, hid_t obj, const std::string& key, const std::vector<double>& v);

void write_int_attr(const File& f, hid_t obj, const std::string& key, long long v);

// JSON values as natural HDF5 attributes (strings, numbers, number arrays); anything else as JSON text.
void write_json_attrs(const File& f, hid_t obj, const json& attrs);

// Reads one of hairlut's fixed-length string attributes (see write_fixed_string_attr).
std::string read_string_attr(const File& f, hid_t obj, const std::string& key, const std::string& where);

// Creates the groups of a path such as "materials/blonde"; returns the innermost.
Handle open_or_create_group(const File& f, hid_t root, const std::string& path);

// Chunks: whole trailing planes (the sampler's inner axes), leading axes one at a time; a chunk
// stays under 4 MiB by splitting the outermost axis it reaches if needed.
std::vector<hsize_t> chunk_dims(const std::vector<hsize_t>& dims, std::size_t element);

// Storage of a dataset: chunked with shuffle + deflate + Fletcher-32, or, for a dataset written whole
// (`whole`), compact or contiguous when small or unfiltered (hdf5_layout.hpp).
Handle dataset_create_plist(const File& f, const std::vector<hsize_t>& dims, std::size_t element, int deflate, bool whole = true);

// The axis as a dimension scale named `name` in `group`, left open (the REFERENCE_LIST is written
// once every table is attached).
Handle write_scale(const File& f, hid_t group, const GridAxis& a, const std::string& name, int deflate);

// Dimension-scale attachments as HDF5's Dimension Scales specification stores them (what
// H5DSattach_scale leaves after attaching each scale in turn), each list written once: attaching
// one scale at a time rereads and rewrites the dataset's DIMENSION_LIST and the scale's whole
// REFERENCE_LIST at every attachment.
struct ScaleUse {  // an entry of REFERENCE_LIST: HDF5's ds_list_t
  hobj_ref_t dataset;
  int dimension;
};
// DIMENSION_LIST on a dataset: for dimension k, one object reference, to scales[k].
void write_dimension_list(const File& f, hid_t ds, const std::vector<hobj_ref_t>& scales);
// REFERENCE_LIST on a dimension scale: every (dataset, dimension) that uses it.
void write_reference_list(const File& f, hid_t scale, const std::vector<ScaleUse>& uses);
// An object reference to loc/name.
hobj_ref_t object_reference(const File& f, hid_t loc, const std::string& name);

// --- The attributes h5py users read (written by write_json_attrs / write_string_attr) must say
// what the checksummed metadata say: a reader refuses a file whose visible metadata were altered,
// naming the attribute. Numbers live in the (checksummed) object header; string values live in
// the global heap, which read_hdf5 screens first (hdf5_heap_check.hpp).
std::string read_vlen_string_attr(const File& f, hid_t attr, const std::string& where);

// Fails naming `where` (object path and attribute) unless the attribute holds `want` as
// write_json_attrs would have written it.
void verify_attr(const File& f, hid_t obj, const std::string& key, const json& want, const std::string& object);

void verify_json_attrs(const File& f, hid_t obj, const json& attrs, const std::string& object);

void verify_scale_attrs(const File& f, hid_t scale, const GridAxis& a, const std::string& object);

// DIMENSION_LIST (which axis scale each dimension uses) must be present with one entry per
// dimension; its references live in the global heap and are not followed here.
void verify_dimension_list(const File& f, hid_t ds, std::size_t rank, const std::string& object);

inline bool same_axis(const GridAxis& a, const GridAxis& b) { return detail::identical_axes(a, b) || a.to_json() == b.to_json(); }  // quick test first

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

// --- What a reader refuses before it reads any values: every link in the file must be a hard
// link (an external link opens another file, a soft link names any object), and every dataset
// must keep its values in this file as hairlut stores them (no external storage, which HDF5 reads
// from any named file, device or FIFO; no virtual dataset, which maps other files; only the
// deflate, shuffle and Fletcher-32 filters). Data HDF5 would decompress beyond what deflate can
// reach from the stored bytes, or stored bytes beyond the file, are refused too.
void check_links(const File& f, hid_t root);

// Deflate cannot expand data by more than 1032:1; with Fletcher-32 and chunk overheads the
// stored bytes of a hairlut dataset are never fewer than its values' bytes over this.
inline constexpr std::uint64_t kMaxCompressionRatio = 1100;

// Checks `ds` (described as `object`) as above; `raw_bytes` is what its values take in memory.
// Returns the bytes it occupies in the file.
std::uint64_t check_dataset_storage(const File& f, hid_t ds, const std::string& object, std::uint64_t raw_bytes);

// The superblock version byte that follows the signature at offset 0; hairlut writes ≥ 2.
void check_signature_bytes(const File& f, const unsigned char* head, std::size_t size);

void check_signature(const File& f, const std::filesystem::path& path);

}  // namespace hairlut::detail::h5
