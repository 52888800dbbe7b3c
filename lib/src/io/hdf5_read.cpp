// Reading a table set from HDF5 (hdf5_io.hpp): the file screened first (signature, global heap,
// format version), then every table checked against the checksummed metadata.
#include "hairlut/io/hdf5_io.hpp"

#include <hdf5.h>
#include <hdf5_hl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <set>

#include "hairlut/util/error.hpp"
#include "hairlut/util/hash.hpp"
#include "hdf5_bytes.hpp"
#include "hdf5_objects.hpp"
#include "table_semantics.hpp"

namespace hairlut {

using namespace detail::h5;

namespace {
// What read_open_file reads: every table whole (the default), the outline (no values; the content
// checksum streamed when verify), or the rows a Hdf5Rows names.
struct ReadPlan {
  enum class Kind { whole, outline, rows } kind = Kind::whole;
  bool verify = true;
  std::size_t run_bytes = 0;
  const Hdf5RunVisitor* visit = nullptr;
  const Hdf5Rows* rows = nullptr;
};
TableSet read_open_file(const File& f, hid_t file_id, const ReadPlan& plan = {});

Handle open_file(File& f, const std::filesystem::path& path, bool screen_heap = true) {
  // A FIFO or device would block or never end; only a regular file (or a link to one) is read.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) f.fail("cannot open file (" + std::string(std::strerror(errno)) + ")");
  if (!S_ISREG(st.st_mode)) f.fail("not a regular file");
  f.bytes = static_cast<std::uint64_t>(st.st_size);
  check_signature(f, path);
  if (screen_heap)
    if (const std::string why = detail::global_heap_problem(path); !why.empty()) f.fail(why);
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG);  // closing the file closes whatever a failed read left open
  Handle file(quiet([&] { return H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()); }), H5Fclose);
  f.check(file.get(), "cannot open as HDF5 (truncated or corrupted file)");
  return file;
}
}  // namespace

TableSet read_hdf5(const std::filesystem::path& path) {
  const ErrorSilencer silence;
  File f{path.string()};
  const Handle file = open_file(f, path);
  return read_open_file(f, file.get());
}

TableSet read_hdf5_outline(const std::filesystem::path& path, bool verify, std::size_t run_bytes, const Hdf5RunVisitor& visit) {
  const ErrorSilencer silence;
  File f{path.string()};
  const Handle file = open_file(f, path);
  ReadPlan plan;
  plan.kind = ReadPlan::Kind::outline;
  plan.verify = verify;
  plan.run_bytes = std::max<std::size_t>(run_bytes, 1);
  plan.visit = visit ? &visit : nullptr;
  return read_open_file(f, file.get(), plan);
}

TableSet read_hdf5_rows(const std::filesystem::path& path, const Hdf5Rows& rows, bool screened) {
  const ErrorSilencer silence;
  File f{path.string()};
  const Handle file = open_file(f, path, !screened);
  ReadPlan plan;
  plan.kind = ReadPlan::Kind::rows;
  plan.rows = &rows;
  return read_open_file(f, file.get(), plan);
}

TableSet read_hdf5_memory(const char* data, std::size_t size, const std::string& name) {
  const ErrorSilencer silence;
  File f{name};
  f.bytes = size;
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
TableSet read_open_file(const File& f, hid_t file_id, const ReadPlan& plan) {
  Handle root(quiet([&] { return H5Gopen2(file_id, "/", H5P_DEFAULT); }), H5Gclose);
  f.check(root.get(), "cannot open the root group");
  check_links(f, root.get());
  // The values read are held at once (every table, or a part of the large ones): what the tables
  // claim is bounded by the stored bytes (kMaxCompressionRatio), and what is held by the machine's
  // memory before each table is allocated.
  const std::uint64_t physical = static_cast<std::uint64_t>(::sysconf(_SC_PHYS_PAGES)) * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
  std::uint64_t total_raw = 0, total_stored = 0, total_held = 0;

  if (quiet([&] { return H5Aexists(root.get(), "hairlut_format_version"); }) <= 0) {
    (void)read_string_attr(f, root.get(), "hairlut_metadata", "/");  // no hairlut metadata at all: says so
    f.fail("missing attribute hairlut_format_version (written before the table format was versioned; bake the tables again)");
  }
  const int major = check_format_version(read_string_attr(f, root.get(), "hairlut_format_version", "/"), f.name);
  // The content checksum's algorithm: named from format 2.0 on; files of format 1.x use FNV-1a 64.
  HashAlgorithm algorithm = HashAlgorithm::fnv1a64;
  if (major >= 2 || quiet([&] { return H5Aexists(root.get(), "hairlut_checksum_algorithm"); }) > 0) {
    const std::string name = read_string_attr(f, root.get(), "hairlut_checksum_algorithm", "/");
    const std::optional<HashAlgorithm> known = hash_algorithm_from_name(name);
    if (!known) f.fail("unknown checksum algorithm \"" + name.substr(0, 40) + "\" (root attribute hairlut_checksum_algorithm)");
    algorithm = *known;
  }

  TableSet set;
  json index;
  try {
    set.metadata = json::parse(read_string_attr(f, root.get(), "hairlut_metadata", "/"));
    index = json::parse(read_string_attr(f, root.get(), "hairlut_tables", "/"));
  } catch (const json::exception&) {
    f.fail("malformed hairlut metadata (JSON) on the root group");
  }
  if (!set.metadata.is_object() || !index.is_array()) f.fail("malformed hairlut metadata on the root group");
  // The outline's content checksum, streamed in the order content_checksum hashes.
  std::optional<Hasher> hasher;
  if (plan.kind == ReadPlan::Kind::outline && plan.verify) hasher.emplace(algorithm), hasher->update(set.metadata.dump());
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
    check_dataset_storage(f, ds.get(), tpath, 0);
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
    const std::uint64_t raw = static_cast<std::uint64_t>(n) * bytes;
    total_stored += check_dataset_storage(f, ds.get(), tpath, raw);
    total_raw += raw;
    if (f.bytes > 0 && total_stored > f.bytes) f.fail(tpath + ": the tables claim more stored bytes than the file has");
    if (f.bytes > 0 && total_raw / kMaxCompressionRatio > f.bytes)
      f.fail(tpath + ": the tables' values (" + std::to_string(total_raw) + " bytes) exceed what a file of " + std::to_string(f.bytes) +
             " bytes can hold compressed");
    // The leading-axis rows read: all, none (the outline), or the part plan.rows names.
    const std::size_t rows_total = static_cast<std::size_t>(t.axes.empty() ? 1 : t.axes[0].count);
    const std::size_t row_values = t.axes.empty() ? 1 : n / std::max<std::size_t>(rows_total, 1);
    const bool part = plan.kind == ReadPlan::Kind::rows && !t.axes.empty() && t.group == plan.rows->group && t.axes[0].name == plan.rows->axis;
    if (part && (plan.rows->first < 0 || plan.rows->count < 1 || static_cast<std::size_t>(plan.rows->first) + static_cast<std::size_t>(plan.rows->count) > rows_total))
      f.fail(tpath + ": rows " + std::to_string(plan.rows->first) + " to " + std::to_string(plan.rows->first + plan.rows->count - 1) +
             " asked of a " + t.axes[0].name + " axis of " + std::to_string(rows_total));
    const std::uint64_t held = plan.kind == ReadPlan::Kind::outline ? 0 : part ? static_cast<std::uint64_t>(plan.rows->count) * row_values * bytes : raw;
    total_held += held;
    if (physical > 0 && total_held > physical)
      f.fail(tpath + ": the tables' values (" + std::to_string(total_held >> 20) + " MiB) exceed this machine's memory");
    const Precision precision = bytes == 8 ? Precision::float64 : Precision::float32;
    // Rows [r0, r0 + count) of the dataset into `data` (a hyperslab of the leading axis).
    auto read_rows = [&](std::size_t r0, std::size_t count, void* data) {
      herr_t status = -1;
      if (r0 == 0 && count == rows_total) {
        status = quiet([&] { return H5Dread(ds.get(), bytes == 8 ? H5T_NATIVE_DOUBLE : H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, data); });
      } else {
        std::vector<hsize_t> start(dims.size(), 0), extent = dims;
        start[0] = r0, extent[0] = count;
        Handle file_space(quiet([&] { return H5Dget_space(ds.get()); }), H5Sclose);
        Handle memory_space(quiet([&] { return H5Screate_simple(rank, extent.data(), nullptr); }), H5Sclose);
        if (file_space.valid() && memory_space.valid() &&
            quiet([&] { return H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr, extent.data(), nullptr); }) >= 0)
          status = quiet([&] {
            return H5Dread(ds.get(), bytes == 8 ? H5T_NATIVE_DOUBLE : H5T_NATIVE_FLOAT, memory_space.get(), file_space.get(), H5P_DEFAULT, data);
          });
      }
      if (status < 0) f.fail(tpath + ": cannot read the values (data corrupted: checksum or decompression failed)");
    };
    if (plan.kind == ReadPlan::Kind::outline) {
      // No values kept: each run of rows is hashed (and shown to the visitor) and dropped.
      if (plan.verify) {
        hasher->update(t.describe().dump());
        const std::size_t step = std::max<std::size_t>(1, plan.run_bytes / std::max<std::size_t>(row_values * bytes, 1));
        std::vector<float> f32;
        std::vector<double> f64;
        for (std::size_t r0 = 0; r0 < rows_total; r0 += step) {
          const std::size_t count = std::min(step, rows_total - r0), values = count * row_values;
          if (bytes == 8) f64.resize(values);
          else f32.resize(values);
          read_rows(r0, count, bytes == 8 ? static_cast<void*>(f64.data()) : static_cast<void*>(f32.data()));
          hasher->update(bytes == 8 ? static_cast<const void*>(f64.data()) : static_cast<const void*>(f32.data()), values * bytes);
          if (plan.visit) (*plan.visit)(Hdf5Run{t, r0 * row_values, values, bytes == 8 ? nullptr : f32.data(), bytes == 8 ? f64.data() : nullptr});
        }
      }
      t.precision = precision;
    } else if (part) {
      t.precision = precision;
      const std::size_t values = static_cast<std::size_t>(plan.rows->count) * row_values;
      if (bytes == 8) t.f64.resize(values);
      else t.f32.resize(values);
      read_rows(static_cast<std::size_t>(plan.rows->first), static_cast<std::size_t>(plan.rows->count),
                bytes == 8 ? static_cast<void*>(t.f64.data()) : static_cast<void*>(t.f32.data()));
    } else {
      t.allocate(precision);
      read_rows(0, rows_total, bytes == 8 ? static_cast<void*>(t.f64.data()) : static_cast<void*>(t.f32.data()));
    }
    // Each axis must be attached as a dimension scale whose values are the axis's nodes.
    Handle group(quiet([&] { return H5Gopen2(root.get(), t.group.c_str(), H5P_DEFAULT); }), H5Gclose);
    f.check(group.get(), tpath + ": cannot open group " + t.group);
    for (std::size_t k = 0; k < t.axes.size(); ++k) {
      const GridAxis& a = t.axes[k];
      const std::string scale_name = scale_names.of(t.group, a);
      Handle scale(quiet([&] { return H5Dopen2(group.get(), scale_name.c_str(), H5P_DEFAULT); }), H5Dclose);
      if (!scale.valid()) f.fail(tpath + ": missing dimension scale " + t.group + "/" + scale_name);
      check_dataset_storage(f, scale.get(), t.group + "/" + scale_name, 0);
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
  // The content checksum covers everything read above; HDF5 checksums only part of it. A part of
  // the tables cannot be checked against it: the outline of the same file (verify) checks it.
  if (plan.kind == ReadPlan::Kind::whole || hasher) {
    const std::string sum = hasher ? hasher->hex() : content_checksum(set, ChecksumRounding::as_stored, algorithm);
    if (read_string_attr(f, root.get(), "hairlut_checksum", "/") != sum) f.fail("content checksum mismatch: the file is corrupted");
  }
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
  if (plan.kind == ReadPlan::Kind::outline) return set;
  if (plan.kind == ReadPlan::Kind::rows)
    for (Table& t : set.tables)
      if (!t.axes.empty() && t.group == plan.rows->group && t.axes[0].name == plan.rows->axis) {
        try {
          t.axes[0] = narrowed_axis(t.axes[0], plan.rows->first, plan.rows->count, t.path() + "." + t.axes[0].name);
        } catch (const DomainError& e) {
          f.fail(e.what());
        }
      }
  detail::check_table_semantics(set, f.name);
  return set;
}
}  // namespace


}  // namespace hairlut
