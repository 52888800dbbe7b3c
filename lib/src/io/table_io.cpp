#include "hairlut/io/table_io.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <random>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string_view>
#include <thread>

#include "hairlut/io/engine_exr.hpp"
#include "hairlut/tables/fourier_tables.hpp"
#include "hdf5_bytes.hpp"
#include "table_text.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/util/hash.hpp"
#include "hairlut/util/version.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;
namespace fs = std::filesystem;

// The hash of a file, read in blocks (no copy of the whole file in memory).
std::string file_hash(const fs::path& p, HashAlgorithm algorithm = kFileHash) {
  std::ifstream in(p, std::ios::binary);
  Hasher h(algorithm);
  std::vector<char> block(1 << 16);
  while (in) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    h.update(block.data(), static_cast<std::size_t>(in.gcount()));
  }
  return h.hex();
}

// Temporary names: "<final name>.<token>.tmp-<pid>", where the token is 8 random hex digits and
// 8 digits of a keyed hash of the final name, the random part and the pid. The token makes the
// name unpredictable (nothing can be planted at it before the file is created) and lets the
// stale-temporary cleanup recognise a name this code made: a user's "s.h5.tmp-keep" or
// "s.h5.0123456789abcdef.tmp-1" does not carry the hash. The ".tmp-<pid>" tail is what the tools'
// signal handlers remove on a hard stop.
std::string temporary_mark(const std::string& final_name, const std::string& random, long pid) {
  Hasher h(HashAlgorithm::xxh3_64);
  h.update("hairlut temporary\n" + final_name + "\n" + random + "\n" + std::to_string(pid));
  return h.hex().substr(0, 8);
}

// The final name of a temporary named by create_temporary, or nothing when `name` is not one.
std::optional<std::pair<std::string, long>> parse_temporary(const std::string& name) {
  const auto tail = name.rfind(".tmp-");
  if (tail == std::string::npos || tail < 18 || name[tail - 17] != '.') return std::nullopt;
  const std::string pid_text = name.substr(tail + 5);
  if (pid_text.empty() || pid_text.size() > 10 || pid_text.find_first_not_of("0123456789") != std::string::npos || pid_text[0] == '0')
    return std::nullopt;
  const std::string token = name.substr(tail - 16, 16);
  if (token.find_first_not_of("0123456789abcdef") != std::string::npos) return std::nullopt;
  const long pid = std::stol(pid_text);
  const std::string final_name = name.substr(0, tail - 17);
  if (temporary_mark(final_name, token.substr(0, 8), pid) != token.substr(8)) return std::nullopt;
  return std::make_pair(final_name, pid);
}

// Removes the listed files when destroyed unless released.
struct TempFiles {
  std::vector<fs::path> paths;
  std::vector<std::pair<dev_t, ino_t>> ids;  // of paths[i], as created
  ~TempFiles() {
    std::error_code ec;
    for (const auto& p : paths) fs::remove(p, ec);
  }
};

// Creates a new, empty temporary file for `final_path` in its directory: exclusively (O_EXCL, so
// never an existing file and never through a symbolic link planted at the name) under a fresh
// unpredictable name, and records it in `temps` for removal on failure.
fs::path create_temporary(const fs::path& final_path, TempFiles& temps) {
  std::random_device random;
  const long pid = static_cast<long>(::getpid());
  const std::string final_name = final_path.filename().string();
  for (int attempt = 0; attempt < 16; ++attempt) {
    char hex[9];
    std::snprintf(hex, sizeof hex, "%08x", static_cast<unsigned>(random()));
    const std::string name = final_name + "." + hex + temporary_mark(final_name, hex, pid) + ".tmp-" + std::to_string(pid);
    const fs::path path = final_path.parent_path() / name;
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0 && errno == EEXIST) continue;
    if (fd < 0) throw IoError(path.string() + ": cannot create a temporary file (" + std::strerror(errno) + ")");
    struct stat st {};
    const int status = ::fstat(fd, &st);
    ::close(fd);
    temps.paths.push_back(path);
    temps.ids.emplace_back(status == 0 ? st.st_dev : 0, status == 0 ? st.st_ino : 0);
    return path;
  }
  throw IoError(final_path.string() + ": cannot create a temporary file (every name tried exists)");
}

// The temporary temps.paths[i] must still be the regular file created there (not replaced by a
// link or another file) before it is renamed into place.
void check_temporary(const TempFiles& temps, const fs::path& path) {
  const auto it = std::find(temps.paths.begin(), temps.paths.end(), path);
  struct stat st {};
  if (it == temps.paths.end() || ::lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode) ||
      std::make_pair(st.st_dev, st.st_ino) != temps.ids[static_cast<std::size_t>(it - temps.paths.begin())])
    throw IoError(path.string() + ": the temporary file was replaced while it was written; nothing was committed");
}

// Who holds a lock on the file open as `fd`: "pid N (name)" from /proc/locks, or a phrase saying
// the system does not tell.
std::string lock_holder(int fd) {
  struct stat st {};
  std::ifstream locks("/proc/locks");
  if (::fstat(fd, &st) != 0 || !locks) return "another process";
  char id[64];
  std::snprintf(id, sizeof id, "%02x:%02x:%llu", major(st.st_dev), minor(st.st_dev), static_cast<unsigned long long>(st.st_ino));
  std::string line;
  while (std::getline(locks, line)) {
    std::istringstream in(line);
    std::string n, kind, mode, access, pid, where;
    if (!(in >> n >> kind >> mode >> access >> pid >> where) || kind != "FLOCK" || where != id || n.find("->") != std::string::npos) continue;
    std::ifstream comm("/proc/" + pid + "/comm");
    std::string name;
    std::getline(comm, name);
    return "pid " + pid + (name.empty() ? std::string() : " (" + name + ")");
  }
  return "another process";
}

// An advisory lock (flock) on a directory, held while alive: exclusive while a bake writes and
// commits its set there, shared while a reader loads a file of a set and checks it against the
// set's sidecar. Without a lock (a directory that cannot be opened, or a file system without
// flock) the work goes on unlocked. A busy lock is waited for as `wait` says (LockWait).
class DirectoryLock {
 public:
  DirectoryLock(const fs::path& dir, bool exclusive, const LockWait& wait = {}, const std::atomic<bool>* cancel = nullptr) {
    fd_ = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd_ < 0) return;
    const int op = exclusive ? LOCK_EX : LOCK_SH;
    if (::flock(fd_, op | LOCK_NB) == 0 || (errno != EWOULDBLOCK && errno != EINTR)) return;
    const std::string who = lock_holder(fd_);
    if (wait.notice) wait.notice((dir.empty() ? std::string(".") : dir.string()) + ": waiting for the directory's lock, held by " + who);
    const auto start = std::chrono::steady_clock::now();
    for (;;) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (::flock(fd_, op | LOCK_NB) == 0) return;
      if (errno != EWOULDBLOCK && errno != EINTR) return;
      if (cancel && cancel->load()) {
        ::close(fd_);
        throw BakeCancelled();
      }
      const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (wait.timeout_s >= 0.0 && waited >= wait.timeout_s) {
        ::close(fd_);
        throw IoError((dir.empty() ? std::string(".") : dir.string()) + ": the directory's lock is still held by " + who + " after " +
                      std::to_string(static_cast<long long>(waited)) + " s; gave up (another bake is writing there)");
      }
    }
  }
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;
  ~DirectoryLock() {
    if (fd_ >= 0) ::close(fd_);  // closing releases the lock
  }

 private:
  int fd_ = -1;
};

// A sidecar is read for a few top-level fields only (`keep`: "format", "files", "config_hash",
// "hairlut_version"); everything else (the tables' descriptions, the config, the report) is parsed
// and dropped, so that memory does not grow with the file (a parsed JSON document takes up to 40
// times its text: a 60 MB sidecar took 2.2 GB). The size cap bounds the time to parse (about 1 s
// per 100 MiB), the depth cap the parser's stack, the cap on kept values what the kept fields hold
// (the "files" list: a few entries per output file). The writer refuses a sidecar over the size cap
// (write_table_set), so that the reader accepts every sidecar hairlut writes.
constexpr std::uintmax_t kMaxSidecarBytes = std::uintmax_t{256} << 20;
constexpr int kMaxSidecarDepth = 24;
constexpr std::size_t kMaxSidecarKeptValues = std::size_t{1} << 16;

// Why a sidecar of `bytes` bytes is not read, or nothing.
std::optional<std::string> sidecar_size_problem(std::uintmax_t bytes) {
  if (bytes <= kMaxSidecarBytes) return std::nullopt;
  char buf[160];
  std::snprintf(buf, sizeof buf, "the set's sidecar is %.1f MiB, more than the %llu MiB a sidecar may be (not read)",
                static_cast<double>(bytes) / 1048576.0, static_cast<unsigned long long>(kMaxSidecarBytes >> 20));
  return std::string(buf);
}

// Thrown by parse_sidecar's callback: why the sidecar is not read (one phrase).
struct SidecarRefused {
  std::string why;
};

json parse_sidecar(std::istream& in, std::initializer_list<std::string_view> keep) {
  bool keeping = false;
  std::size_t kept = 0;
  return json::parse(in, [&](int depth, json::parse_event_t event, json& parsed) {
    if (depth > kMaxSidecarDepth) throw SidecarRefused{"the set's sidecar nests deeper than " + std::to_string(kMaxSidecarDepth) + " levels (not read)"};
    if (depth == 1 && event == json::parse_event_t::key) {
      const std::string& name = parsed.get_ref<const std::string&>();
      keeping = std::find(keep.begin(), keep.end(), name) != keep.end();
      return keeping;
    }
    if (depth >= 1 && !keeping) return false;  // dropped (also every element of a root that is not an object)
    if (depth >= 1 && ++kept > kMaxSidecarKeptValues)
      throw SidecarRefused{"the set's sidecar holds more than " + std::to_string(kMaxSidecarKeptValues) + " values in its top-level fields (not read)"};
    return true;
  });
}

// When `file` is listed in the sidecar of its set (same directory, same base name, ".json"), its
// size and hash must be the recorded ones (XXH3-64 under "xxh3_64"; sidecars of format 1 record
// FNV-1a 64 under "fnv1a64"): a file of another bake, or one replaced after the set was
// committed, is refused.
void check_against_sidecar(const fs::path& file) {
  const fs::path sidecar = fs::path(file).replace_extension(".json");
  std::error_code ec;
  const auto side_bytes = fs::file_size(sidecar, ec);
  if (ec || !fs::is_regular_file(sidecar, ec)) return;
  if (const auto why = sidecar_size_problem(side_bytes)) throw IoError(sidecar.string() + ": " + *why);
  json side;
  try {
    std::ifstream in(sidecar, std::ios::binary);
    side = parse_sidecar(in, {"format", "files"});
  } catch (const SidecarRefused& e) {
    throw IoError(sidecar.string() + ": " + e.why);
  } catch (const json::exception&) {
    throw IoError(sidecar.string() + ": the set's sidecar is not valid JSON (incomplete or corrupted set)");
  }
  if (!side.is_object() || side.value("format", std::string()) != "hairlut-tables" || !side.contains("files") || !side["files"].is_array()) return;
  for (const json& f : side["files"]) {
    if (!f.is_object() || f.value("path", std::string()) != file.filename().string()) continue;
    const std::uintmax_t bytes = fs::file_size(file, ec);
    const HashAlgorithm algorithm = f.contains("xxh3_64") ? HashAlgorithm::xxh3_64 : HashAlgorithm::fnv1a64;
    const json& recorded = f.contains(hash_sidecar_key(algorithm)) ? f[hash_sidecar_key(algorithm)] : json();
    const std::string want = recorded.is_string() ? recorded.get<std::string>() : std::string();
    if (ec || !f.contains("bytes") || !f["bytes"].is_number_unsigned() || f["bytes"].get<std::uintmax_t>() != bytes ||
        want.empty() || file_hash(file, algorithm) != want)
      throw IoError(file.string() + ": does not match its set's sidecar " + sidecar.filename().string() + " (size or " +
                    hash_algorithm_name(algorithm) + " differ): the file belongs to another bake or was changed after the set was written");
    return;
  }
}

}  // namespace

OutputPaths set_paths(const fs::path& directory, const std::string& basename) {
  const fs::path base = directory / basename;
  return {fs::path(base.string() + ".h5"), fs::path(base.string() + ".exr"), fs::path(base.string() + ".json")};
}

fs::path engine_texture_path(const fs::path& directory, const std::string& basename, const EngineTexture& texture) {
  return directory / (basename + "-" + texture.file_suffix + ".exr");
}

bool table_set_up_to_date(const SetFiles& files, const std::string& config_hash) {
  const OutputPaths paths = set_paths(files.directory, files.basename);
  std::error_code ec;
  if (fs::symlink_status(paths.sidecar, ec).type() != fs::file_type::regular || fs::file_size(paths.sidecar, ec) > kMaxSidecarBytes)
    return false;
  std::ifstream in(paths.sidecar);
  if (!in) return false;
  try {
    const json s = parse_sidecar(in, {"config_hash", "hairlut_version", "files"});
    if (s.value("config_hash", std::string()) != config_hash || s.value("hairlut_version", std::string()) != kVersion) return false;
    std::size_t formats = 0;
    for (const json& f : s.at("files")) {
      const fs::path p = files.directory / f.at("path").get<std::string>();
      // The size, then the contents: a file changed in place (a flipped byte, zeroed pixels) is
      // not up to date. Only a regular file is hashed (never a FIFO or a device planted there).
      if (fs::symlink_status(p, ec).type() != fs::file_type::regular || ec) return false;
      if (fs::file_size(p, ec) != f.at("bytes").get<std::uintmax_t>() || ec) return false;
      const HashAlgorithm algorithm = f.contains("xxh3_64") ? HashAlgorithm::xxh3_64 : HashAlgorithm::fnv1a64;
      const json& recorded = f.value(hash_sidecar_key(algorithm), json());
      if (!recorded.is_string() || file_hash(p, algorithm) != recorded.get<std::string>()) return false;
      ++formats;
    }
    return formats == static_cast<std::size_t>(files.hdf5) + static_cast<std::size_t>(files.exr) + files.engine.size();
  } catch (const std::exception&) {
    return false;
  } catch (const SidecarRefused&) {
    return false;
  }
}

namespace {

// The sidecar; `digests[i]`, where given and non-empty, is the digest of files[i] already known
// to the writer (hashed from its bytes in memory); other files are read back and hashed.
// With `text`, each table's axes are placeholders for text->indented (at depth 4: root, "tables",
// the table, "axes").
json sidecar_document(const TableSet& set, const SetFiles& out, const SidecarSource& source,
                      const std::vector<std::pair<std::string, fs::path>>& files, const std::vector<detail::FileDigest>& digests,
                      detail::TableText* text = nullptr) {
  json s;
  s["format"] = "hairlut-tables";
  s["format_version"] = format_major_of(set);
  s["hairlut_version"] = kVersion;
  s["name"] = source.name;
  s["model"] = source.model;
  s["config_hash"] = source.config_hash;
  s["files"] = json::array();
  for (std::size_t i = 0; i < files.size(); ++i) {
    const auto& [format, path] = files[i];
    const bool known = i < digests.size() && !digests[i].hash.empty() && digests[i].algorithm == kFileHash;
    json f = {{"format", format},
              {"path", path.filename().string()},
              {"bytes", known ? digests[i].bytes : fs::file_size(path)},
              {hash_sidecar_key(kFileHash), known ? digests[i].hash : file_hash(path)}};
    if (format == "hdf5") f["precision"] = out.hdf5_double ? "float64" : "float32";
    else if (format == "engine-exr") f["precision"] = "half";  // engine textures are RGBA half
    else f["precision"] = out.exr_options.half ? "half" : "float32";
    s["files"].push_back(f);
  }
  // EXR part and channel of each table.
  std::map<std::string, std::pair<std::string, std::string>> exr_place;
  if (out.exr)
    for (const auto& [part, paths] : exr_part_plan(set))
      for (std::size_t i = 0; i < paths.size(); ++i) exr_place[paths[i]] = {part, paths.size() > 1 ? std::string(1, "RGBA"[i]) : ""};
  s["tables"] = json::array();
  for (const Table& t : set.tables) {
    json d = text ? text->with_placeholders(t) : t.describe();
    if (out.hdf5) d["hdf5"] = {{"dataset", "/" + t.path()}};
    if (out.exr) {
      const auto& [part, channel] = exr_place[t.path()];
      d["exr"] = {{"part", part}};
      if (!channel.empty()) d["exr"]["channel"] = channel;
      else {
        const bool rgb = std::any_of(t.axes.begin(), t.axes.end(), [](const GridAxis& a) { return a.name == "channel"; });
        d["exr"]["channel"] = rgb ? "R,G,B (the channel axis)" : "R";
      }
    }
    s["tables"].push_back(d);
  }
  s["report"] = source.report;
  s["metadata"] = set.metadata;
  // Engine textures: which file holds which texture and how it is laid out.
  if (!out.engine.empty()) {
    s["engine_textures"] = json::array();
    for (const EngineOutput& e : out.engine) {
      json d = e.texture.describe();
      d["path"] = e.path.filename().string();
      s["engine_textures"].push_back(d);
    }
  }
  return s;
}

}  // namespace

json sidecar_json(const TableSet& set, const SetFiles& files, const SidecarSource& source,
                  const std::vector<std::pair<std::string, fs::path>>& written) {
  return sidecar_document(set, files, source, written, {});
}

std::vector<fs::path> write_table_set(const TableSet& set, const SetFiles& out, const SidecarSource& source, const std::atomic<bool>* cancel,
                                      const SlabbedTables* slabbed, const LockWait& wait) {
  const OutputPaths paths = set_paths(out.directory, out.basename);
  if (out.exr && slabbed && !slabbed->empty())
    throw IoError(paths.exr.string() + ": tables baked slab by slab are written to HDF5 only; OpenEXR holds tables whole");
  if (out.exr && has_fourier_np(set))
    throw IoError(paths.exr.string() + ": the Fourier N_p tables (np_fourier) are written to HDF5 only; OpenEXR has no layout for them");
  std::error_code ec;
  fs::create_directories(out.directory, ec);
  if (ec) throw IoError(out.directory.string() + ": cannot create output directory (" + ec.message() + ")");
  // One bake at a time writes and commits into a directory, so that its set is never mixed with
  // another's; readers of the directory wait for the commit (load_tables).
  const DirectoryLock lock(out.directory, true, wait, cancel);
  TempFiles temps;
  std::vector<std::pair<std::string, fs::path>> written;  // format, temporary path
  std::vector<detail::FileDigest> digests;                 // of written[i] where known from memory
  if (out.hdf5) {
    const fs::path t = create_temporary(paths.hdf5, temps);
    if (slabbed) write_hdf5_slabbed(set, *slabbed, t, out.hdf5_options), digests.emplace_back();
    else digests.push_back(detail::write_hdf5_digest(set, t, out.hdf5_options));
    written.emplace_back("hdf5", t);
  }
  if (out.exr) {
    const fs::path t = create_temporary(paths.exr, temps);
    write_exr(set, t, out.exr_options);
    written.emplace_back("exr", t);
  }
  std::vector<fs::path> engine_finals;  // final paths of the engine textures, in `written` order after hdf5/exr
  for (const EngineOutput& e : out.engine) {
    const fs::path t = create_temporary(e.path, temps);
    write_engine_texture(set, e.texture, t);
    written.emplace_back("engine-exr", t);
    engine_finals.push_back(e.path);
  }
  // The sidecar describes the final names.
  detail::TableText text;
  json side = sidecar_document(set, out, source, written, digests, &text);
  for (auto& f : side["files"]) {
    const auto parsed = parse_temporary(f["path"].get<std::string>());
    if (!parsed) throw IoError(out.directory.string() + ": internal: a temporary file name was not recognised");
    f["path"] = parsed->first;
  }
  const fs::path side_tmp = create_temporary(paths.sidecar, temps);
  const std::string side_text = text.indented(side, 4) + "\n";
  if (const auto why = sidecar_size_problem(side_text.size()))
    throw IoError(paths.sidecar.string() + ": " + *why + "; its tables' axes have too many nodes to describe");
  detail::write_file_bytes(side_tmp, side_text);
  std::vector<fs::path> finals;
  auto commit = [&](const fs::path& tmp, const fs::path& final_path) {
    if (cancel && cancel->load()) throw BakeCancelled();
    check_temporary(temps, tmp);
    fs::rename(tmp, final_path, ec);
    if (ec) throw IoError(final_path.string() + ": cannot move the finished file into place (" + ec.message() + ")");
    finals.push_back(final_path);
  };
  std::size_t engine_index = 0;
  for (const auto& [format, tmp] : written)
    commit(tmp, format == "hdf5" ? paths.hdf5 : format == "exr" ? paths.exr : engine_finals[engine_index++]);
  commit(side_tmp, paths.sidecar);  // last: its presence marks a complete, up-to-date output
  temps.paths.clear();
  return finals;
}

void remove_stale_temporaries(const fs::path& directory, const std::string& basename, const LockWait& wait) {
  std::error_code ec;
  if (!fs::is_directory(directory, ec)) return;
  // Under the directory's lock, so that a bake committing there (in this process too) is not
  // robbed of its temporaries.
  const DirectoryLock lock(directory, true, wait);
  const std::string prefix = basename + ".";
  const long self = static_cast<long>(::getpid());
  for (const auto& entry : fs::directory_iterator(directory, ec)) {
    const std::string n = entry.path().filename().string();
    // Only a name create_temporary made, for a file of this set (basename.ext or an engine
    // texture basename-*), ...
    const auto parsed = parse_temporary(n);
    if (!parsed || (parsed->first.rfind(prefix, 0) != 0 && parsed->first.rfind(basename + "-", 0) != 0)) continue;
    // ... a regular file (never a link) owned by this user, ...
    struct stat st {};
    if (::lstat(entry.path().c_str(), &st) != 0 || !S_ISREG(st.st_mode) || st.st_uid != ::geteuid()) continue;
    // ... of a process that no longer runs (a concurrent bake keeps its own; kill(pid, 0) fails
    // with EPERM for a live process of another user: that one is kept too). A name with this
    // process's pid is a leftover of an earlier process that had the same pid: this process has
    // not written any yet.
    const long pid = parsed->second;
    if (pid != self && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM)) continue;
    fs::remove(entry.path(), ec);
  }
}

TableSet load_tables(const fs::path& file) {
  const DirectoryLock lock(file.parent_path(), false);
  TableSet set = load_table_file(file);
  check_against_sidecar(file);
  return set;
}

namespace {
// What tells a file from its replacement: device, inode, size and modification time.
std::string file_identity(const fs::path& file) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) return "missing";
  return std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino) + ":" + std::to_string(st.st_size) + ":" + std::to_string(st.st_mtim.tv_sec) +
         "." + std::to_string(st.st_mtim.tv_nsec);
}
}  // namespace

struct TableSetParts::Lock {
  std::shared_ptr<void> held;  // a DirectoryLock (a type of this file alone)
};

TableSetParts::TableSetParts(const fs::path& file, std::size_t run_bytes, const Hdf5RunVisitor& visit)
    : lock_(new Lock{std::make_shared<DirectoryLock>(file.parent_path(), false)}), file_(file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw IoError(file.string() + ": not a regular file");  // a FIFO would block the read
  std::ifstream in(file, std::ios::binary);
  char head[8] = {};
  if (in) in.read(head, 8);
  if (!in || std::memcmp(head, "\x89HDF\r\n\x1a\n", 8) != 0) throw IoError(file.string() + ": only an HDF5 table file can be read in parts");
  identity_ = file_identity(file);
  outline_ = read_hdf5_outline(file, true, run_bytes, visit);
  check_against_sidecar(file);
  if (file_identity(file) != identity_) throw IoError(file.string() + ": changed while its checksum was verified");
}

TableSet TableSetParts::rows(const Hdf5Rows& rows) const {
  if (file_identity(file_) != identity_) throw IoError(file_.string() + ": changed after its checksum was verified (read in parts)");
  TableSet part = read_hdf5_rows(file_, rows, true);
  if (file_identity(file_) != identity_) throw IoError(file_.string() + ": changed while a part of it was read");
  return part;
}

TableSetParts::~TableSetParts() = default;

TableSet load_table_file(const fs::path& file) {
  // A FIFO or a device would block or never end: only a regular file (or a link to one) is read.
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (!ec && fs::exists(status) && status.type() != fs::file_type::regular) throw IoError(file.string() + ": not a regular file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError(file.string() + ": cannot open file (" + std::string(std::strerror(errno)) + ")");
  char head[8] = {};
  in.read(head, 8);
  if (in.gcount() >= 4 && static_cast<unsigned char>(head[0]) == 0x76 && head[1] == 0x2f && head[2] == 0x31 && head[3] == 0x01)
    return read_exr(file);
  if (in.gcount() == 8 && std::memcmp(head, "\x89HDF\r\n\x1a\n", 8) == 0) return read_hdf5(file);
  throw IoError(file.string() + ": not a hairlut table file (neither HDF5 nor OpenEXR)");
}

}  // namespace hairlut
