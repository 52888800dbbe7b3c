// Writing a table set as HDF5 (hdf5_io.hpp): whole in memory, or slab by slab from a writer thread.
#include "hairlut/io/hdf5_io.hpp"

#include <hdf5.h>
#include <hdf5_hl.h>

#include <omp.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "hairlut/util/error.hpp"
#include "hairlut/util/hash.hpp"
#include "hdf5_bytes.hpp"
#include "hdf5_chunks.hpp"
#include "hdf5_layout.hpp"
#include "hdf5_objects.hpp"
#include "table_checksum.hpp"
#include "table_text.hpp"
#include "slab_queue.hpp"

namespace hairlut {

using namespace detail::h5;

namespace {

// Leading-axis row ranges [row0, row0 + rows) of each slabbed table (empty for tables held whole).
using SlabRanges = std::vector<std::vector<std::pair<std::size_t, std::size_t>>>;

struct SlabFeed {
  const SlabRanges* ranges;
  detail::SlabQueue* queue;
};

struct WriterStopped {};  // the baking side stopped: unwind the writer quietly

// Threads that filter chunks at once, at most: each holds about 8 MiB of scratch (a 4 MiB chunk
// shuffled, and room for it deflated) and its batch's deflated chunks wait to be written, so four
// stay within the bake's fixed allowance for the writer (kBakeOverheadBytes, bake_estimate.hpp).
constexpr int kDeflateThreadsMax = 4;

// A chunked, deflated dataset written whole: its chunks filtered on up to kDeflateThreadsMax of
// options.threads, two per thread at a time, each batch handed to HDF5 in chunk order.
void write_filtered_chunks(const File& f, hid_t ds, const void* data, const std::vector<hsize_t>& dims, std::size_t element,
                           const Hdf5WriteOptions& options, const std::string& path) {
  const std::vector<hsize_t> chunk = chunk_dims(dims, element);
  const std::size_t n = detail::chunk_count(dims, chunk);
  const int threads = std::min(kDeflateThreadsMax, options.threads > 0 ? options.threads : omp_get_max_threads());
  const std::size_t batch = 2 * static_cast<std::size_t>(threads);
  for (std::size_t first = 0; first < n; first += batch) {
    std::vector<detail::FilteredChunk> done;
    try {
      done = detail::filtered_chunks(data, dims, chunk, element, options.deflate, first, std::min(batch, n - first), threads);
    } catch (const std::exception& e) {
      f.fail("cannot deflate dataset " + path + ": " + e.what());
    }
    for (const detail::FilteredChunk& c : done)
      f.check_status(H5Dwrite_chunk(ds, H5P_DEFAULT, c.filter_mask, c.offset.data(), c.bytes.size(), c.bytes.data()),
                     "cannot write a chunk of dataset " + path);
  }
}

// Everything write_hdf5 stores, into an open file. With a feed, the values of slabbed tables
// arrive slab by slab and the content checksum is computed while writing, over the same bytes in
// the same order as content_checksum (the metadata, then each table's description and values),
// and stored last; without one it is computed first from the tables in memory.
void write_contents(const File& f, hid_t file, const TableSet& set, const Hdf5WriteOptions& options, SlabFeed* feed) {
  Handle root(H5Gopen2(file, "/", H5P_DEFAULT), H5Gclose);
  write_fixed_string_attr(f, root.get(), "hairlut_format_version", format_version_text(set));
  // Provenance on the root, both as individual attributes and as one JSON text.
  write_json_attrs(f, root.get(), set.metadata);
  write_fixed_string_attr(f, root.get(), "hairlut_metadata", set.metadata.dump());
  json index = json::array();
  for (const Table& t : set.tables) index.push_back(t.path());
  write_fixed_string_attr(f, root.get(), "hairlut_tables", index.dump());
  // The checksum's algorithm (format 2.0 on; files of format 1.x name none and use FNV-1a 64).
  write_fixed_string_attr(f, root.get(), "hairlut_checksum_algorithm", hash_algorithm_name(kFileHash));
  Hasher hash(kFileHash);
  // Each table's description, dumped once for the checksum and its hairlut_table attribute.
  std::vector<std::string> described;
  detail::TableText text;
  for (const Table& t : set.tables) described.push_back(text.compact(t));
  if (!feed) write_fixed_string_attr(f, root.get(), "hairlut_checksum", detail::content_checksum_of(set, described));
  else hash.update(set.metadata.dump());

  // Dimension scales per group, then the tables.
  ScaleNames names;
  std::map<std::string, std::map<std::string, GridAxis>> scales;
  for (const Table& t : set.tables)
    for (const GridAxis& a : t.axes) scales[t.group].emplace(names.of(t.group, a), a);
  // Each scale's reference (for the tables' DIMENSION_LIST) and its uses (its REFERENCE_LIST,
  // written once every table is attached).
  struct ScaleRefs {
    hobj_ref_t ref;
    std::vector<ScaleUse> uses;
    Handle scale;  // kept open until its REFERENCE_LIST is written
  };
  std::map<std::string, ScaleRefs> scale_objects;  // by the path of the scale's dataset (the first group that shows it)
  std::map<std::string, ScaleRefs*> scale_refs;    // by group/name, for every group that shows it
  // Sibling groups (the materials of a scene: materials/<name>, under a group other than the root)
  // share a scale of the same name and axis: one dataset, hard-linked into each group, so every
  // group still shows its axes by name (readers open group/name as before) and the file holds the
  // values and attributes once. Keyed by the parent, the name and the axis.
  struct Shared {
    GridAxis axis;
    std::string path;
  };
  std::map<std::pair<std::string, std::string>, std::vector<Shared>> siblings;
  for (const auto& [group, axes] : scales) {
    Handle g = open_or_create_group(f, file, group);
    const auto slash = group.rfind('/');
    const std::string parent = slash == std::string::npos ? std::string() : group.substr(0, slash);
    for (const auto& [name, axis] : axes) {
      const std::string path = group + "/" + name;
      std::vector<Shared>* same_name = parent.empty() ? nullptr : &siblings[{parent, name}];
      const Shared* shared = nullptr;
      if (same_name) {
        const auto it = std::find_if(same_name->begin(), same_name->end(), [&axis = axis](const Shared& c) { return same_axis(c.axis, axis); });
        if (it != same_name->end()) shared = &*it;
      }
      if (shared) {
        const std::string& target = shared->path;
        const std::string& link = name;  // clang before 16 cannot capture a structured binding
        f.check_status(quiet([&] { return H5Lcreate_hard(file, target.c_str(), g.get(), link.c_str(), H5P_DEFAULT, H5P_DEFAULT); }),
                       "cannot link dimension scale " + path + " to " + target);
        scale_refs[path] = &scale_objects.at(target);
        continue;
      }
      ScaleRefs& s = scale_objects[path];
      s.scale = write_scale(f, g.get(), axis, name, options.deflate);
      s.ref = object_reference(f, s.scale.get(), ".");
      scale_refs[path] = &s;
      if (same_name) same_name->push_back({axis, path});
    }
  }
  // The group of the tables being written, kept while consecutive tables share the group (a
  // per-material set lists each material's tables together).
  std::string open_group;
  Handle g;
  for (std::size_t i = 0; i < set.tables.size(); ++i) {
    const Table& t = set.tables[i];
    const bool slabbed = feed && !(*feed->ranges)[i].empty();
    if (!g.valid() || t.group != open_group) {
      g = open_or_create_group(f, file, t.group);
      open_group = t.group;
    }
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
      const std::size_t element = dbl ? 8 : 4;
      if (detail::whole_dataset_layout(t.size() * element, options.deflate) == detail::Hdf5Layout::chunked) {
        write_filtered_chunks(f, ds.get(), data, dims, element, options, t.path());
      } else {
        f.check_status(H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "cannot write dataset " + t.path());
      }
      if (feed) hash.update(data, t.size() * element);
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
    std::vector<hobj_ref_t> dims_refs;
    const hobj_ref_t self = object_reference(f, ds.get(), ".");
    for (std::size_t k = 0; k < t.axes.size(); ++k) {
      ScaleRefs& s = *scale_refs.at(t.group + "/" + names.of(t.group, t.axes[k]));
      dims_refs.push_back(s.ref);
      s.uses.push_back({self, static_cast<int>(k)});
    }
    write_dimension_list(f, ds.get(), dims_refs);
    write_string_attr(f, ds.get(), "quantity", t.quantity);
    write_string_attr(f, ds.get(), "units", t.units);
    write_string_attr(f, ds.get(), "long_name", t.long_name);
    write_json_attrs(f, ds.get(), t.attributes);
    write_fixed_string_attr(f, ds.get(), "hairlut_table", described[i]);
  }
  for (auto& entry : scale_objects) {
    write_reference_list(f, entry.second.scale.get(), entry.second.uses);
    f.check_status(entry.second.scale.close_now(), "cannot close dimension scale " + entry.first);
  }
  if (feed) write_fixed_string_attr(f, root.get(), "hairlut_checksum", hash.hex());
}

// The step by which HDF5's core driver grows the in-memory image; it zero-fills each new step
// (and the pages it touches fault in), and growing reallocates the image (a move of pages, not a
// copy, once the image is larger than the heap's mmap threshold). Unfiltered, one step sized for
// the whole file: the values plus 8 KiB per table (its object header with the hairlut_table
// description and attributes, about 5 KiB for a per-material table) and 64 KiB (the root's
// metadata), rounded to 64 KiB; a file that outgrows it takes a second step of the same size.
// Deflated, an eighth of that: how much smaller the file is depends on the values (the generic
// tables with their sampling data: 179 MB of 536 MB), so the image grows in steps, and the driver
// holds (and zero-fills) at most one step more than the file instead of room for every value.
// The file's bytes do not depend on it.
std::size_t core_increment(const TableSet& set, int deflate) {
  std::size_t bytes = std::size_t{64} << 10;
  for (const Table& t : set.tables) bytes += t.size() * (t.precision == Precision::float64 ? 8 : 4) + (std::size_t{8} << 10);
  if (deflate > 0) bytes = std::max<std::size_t>(bytes / 8, std::size_t{64} << 10);
  return (bytes + 0xffff) / 0x10000 * 0x10000;
}

// Superblock versions 2 and 3 (what hairlut writes): 12 bytes, four 8-byte addresses, a checksum.
constexpr std::size_t kSuperblockBytes = 12 + 4 * 8 + 4;

// The core driver's memory, handed over to hdf5_image when the file closes instead of freed (HDF5's
// file image callbacks), so that the finished file is not copied out of HDF5 once more.
struct ImageBuffer {
  void* data = nullptr;    // handed over at close
  void* live = nullptr;    // the driver's memory while the file is open
  std::size_t size = 0;    // the file's bytes (the driver's memory may be longer)
  bool armed = false;      // set once the file being written is open: earlier images are not it
  ImageBuffer() = default;
  ImageBuffer(const ImageBuffer&) = delete;
  ImageBuffer& operator=(const ImageBuffer&) = delete;
  ~ImageBuffer() { std::free(data); }
  std::span<char> bytes() const { return {static_cast<char*>(data), size}; }
};
H5FD_file_image_callbacks_t keep_image_callbacks(ImageBuffer* kept) {
  H5FD_file_image_callbacks_t c{};
  c.image_malloc = [](std::size_t size, H5FD_file_image_op_t, void* udata) { return static_cast<ImageBuffer*>(udata)->live = std::malloc(size); };
  c.image_memcpy = [](void* dest, const void* src, std::size_t size, H5FD_file_image_op_t, void*) { return std::memcpy(dest, src, size); };
  c.image_realloc = [](void* ptr, std::size_t size, H5FD_file_image_op_t, void* udata) {
    return static_cast<ImageBuffer*>(udata)->live = ptr ? std::realloc(ptr, size) : std::malloc(size);
  };
  c.image_free = [](void* ptr, H5FD_file_image_op_t op, void* udata) -> herr_t {
    auto* k = static_cast<ImageBuffer*>(udata);
    if (op == H5FD_FILE_IMAGE_OP_FILE_CLOSE && k && k->armed && !k->data) k->data = ptr;
    else std::free(ptr);
    return 0;
  };
  c.udata_copy = [](void* udata) { return udata; };  // one ImageBuffer, owned by hdf5_image
  c.udata_free = [](void*) -> herr_t { return 0; };
  c.udata = kept;
  return c;
}

// A name under /proc/self, where no file can be created.
constexpr const char* kImageName = "/proc/self/hairlut-in-memory-image.h5";

// The whole HDF5 file, built in memory (HDF5's core driver without a backing store): HDF5 never
// writes to disk, so a full disk or a file-size limit cannot leave HDF5 with a file it fails to
// close (HDF5 1.10 then crashes when the library shuts down); write_file_bytes reports it instead.
// The image is the driver's own memory after the file is closed (closing writes the final
// superblock, as H5Fget_file_image's copy would have it after fix_superblock_checksum).
// (Slabbed tables cannot be held in memory: write_slabbed_file writes them to disk directly.)
void hdf5_image(const TableSet& set, const File& f, const Hdf5WriteOptions& options, ImageBuffer& kept) {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG);  // on an error path, closing the file closes every object in it
  H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V110, H5F_LIBVER_LATEST);  // 1.10 format: compact chunk indexes
  f.check_status(H5Pset_fapl_core(fapl.get(), core_increment(set, options.deflate), 0), "cannot set up an in-memory HDF5 file");
  H5FD_file_image_callbacks_t callbacks = keep_image_callbacks(&kept);
  f.check_status(H5Pset_file_image_callbacks(fapl.get(), &callbacks), "cannot set up an in-memory HDF5 file");
  Handle fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  H5Pset_obj_track_times(fcpl.get(), 0);
  // H5Fcreate first tries to open an existing file of the name (reading it into memory through the
  // callbacks above, a FIFO blocking it): the image is named where no file can be, and only the
  // image of the file created here is kept.
  Handle file(quiet([&] { return H5Fcreate(kImageName, H5F_ACC_TRUNC, fcpl.get(), fapl.get()); }), H5Fclose);
  f.check(file.get(), "cannot create HDF5 file");
  kept.armed = true;
  write_contents(f, file.get(), set, options, nullptr);
  f.check_status(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), "cannot flush HDF5 file");
  const ssize_t size = H5Fget_file_image(file.get(), nullptr, 0);
  if (size <= 0 || !kept.live) f.fail("cannot take the HDF5 file image");
  // Closing rewrites only the superblock (the end-of-file address of the space still in use and
  // the status flags): keep the flushed one, so that the bytes are those of the flushed image.
  std::array<char, kSuperblockBytes> superblock{};
  const std::size_t head = std::min<std::size_t>(superblock.size(), static_cast<std::size_t>(size));
  std::memcpy(superblock.data(), kept.live, head);
  f.check_status(file.close_now(), "cannot close HDF5 file");
  if (!kept.data) f.fail("cannot take the HDF5 file image");
  kept.size = static_cast<std::size_t>(size);
  std::memcpy(kept.data, superblock.data(), head);
  detail::fix_superblock_checksum(kept.bytes());
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
  ImageBuffer image;
  hdf5_image(set, f, options, image);
  detail::write_file_bytes(path, image.bytes());
}

detail::FileDigest detail::write_hdf5_digest(const TableSet& set, const std::filesystem::path& path, const Hdf5WriteOptions& options) {
  const ErrorSilencer silence;
  const File f{path.string()};
  ImageBuffer image;
  hdf5_image(set, f, options, image);
  detail::write_file_bytes(path, image.bytes());
  Hasher h(kFileHash);
  h.update(image.data, image.size);
  return {image.size, kFileHash, h.hex()};
}

}  // namespace hairlut
