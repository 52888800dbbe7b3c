// Files and leftovers turned against the baker and the loaders: temporaries planted at the
// baker's names (a symbolic link, a leftover of an earlier process with the same pid), user files
// that look like temporaries, outputs changed in place after a bake, and HDF5 files whose data
// live outside the file.
#include <hdf5.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/io/hdf5_io.hpp>
#include <hairlut/io/table_io.hpp>
#include <sstream>

#include "catch.hpp"

using namespace hairlut;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hairlut-hostile-" + std::to_string(::getpid()) + "-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

json tiny_config(bool exr = true) {
  json j = json::parse(R"({
    "name": "hostile",
    "lobes": { "explicit": ["R", "TT", "TRT"], "residual": true },
    "quadrature": { "method": "gauss-legendre", "order": 32 },
    "tables": {
      "np": { "axes": {
        "theta_d": { "count": 3, "range_deg": [0, 80] },
        "phi": { "count": 5, "symmetry": "even" },
        "sigma_a": { "count": 2, "range": [0, 2] },
        "beta": { "count": 2, "range_deg": [8, 30] } } },
      "mp": { "axes": {
        "theta_i": { "count": 3, "range_deg": [-80, 80] },
        "theta_r": { "count": 3, "range_deg": [-80, 80] },
        "beta": { "count": 2, "range_deg": [5, 20] } } }
    },
    "output": { "basename": "s", "formats": ["hdf5", "exr"] }
  })");
  if (!exr) j["output"]["formats"] = {"hdf5"};
  return j;
}

BakeConfig config_in(const fs::path& dir, const json& j = tiny_config()) { return parse_config(j, "hostile.json", dir); }

std::string file_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary);
  out << bytes;
}

bool loads(const fs::path& p) {
  try {
    load_tables(p);
    return true;
  } catch (const IoError&) {
    return false;
  }
}

std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST_CASE("A leftover at a temporary name of this pid neither corrupts nor blocks the bake", "[io][hostile]") {
  const fs::path dir = temp_dir("pid-reuse");
  const BakeConfig c = config_in(dir);
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  // A killed earlier process with this pid left a large file at the name the baker used to pick.
  const std::string pid = std::to_string(::getpid());
  write_bytes(dir / ("s.h5.tmp-" + pid), std::string(3 << 20, '\x5a'));
  write_bytes(dir / ("s.json.tmp-" + pid), "{ not a sidecar");
  write_outputs(set, c, report);
  CHECK(loads(output_paths(c).hdf5));
  CHECK(loads(output_paths(c).exr));
  CHECK(outputs_up_to_date(c));
}

TEST_CASE("write_hdf5 over an existing larger file writes only the new file", "[io][hostile]") {
  const fs::path dir = temp_dir("overwrite");
  const BakeConfig c = config_in(dir);
  const TableSet set = bake(c, {});
  const fs::path p = dir / "t.h5";
  write_bytes(p, std::string(4 << 20, '\x11'));
  write_hdf5(set, p);
  const TableSet back = read_hdf5(p);
  REQUIRE(back.tables.size() == set.tables.size());
  CHECK(back.tables[0].f32 == set.tables[0].f32);
  CHECK(fs::file_size(p) < (std::uintmax_t{1} << 20));
}

TEST_CASE("Temporaries are never written through a symbolic link planted at a name", "[io][hostile]") {
  const fs::path dir = temp_dir("symlink");
  const BakeConfig c = config_in(dir);
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  const fs::path victim = dir / "victim.txt";
  write_bytes(victim, "precious\n");
  const std::string pid = std::to_string(::getpid());
  for (const char* ext : {"h5", "exr", "json"}) fs::create_symlink(victim, dir / ("s." + std::string(ext) + ".tmp-" + pid));
  write_outputs(set, c, report);
  CHECK(file_bytes(victim) == "precious\n");
  CHECK(loads(output_paths(c).hdf5));
  // write_hdf5 itself refuses to write through a link.
  fs::create_symlink(victim, dir / "link.h5");
  CHECK_THROWS_AS(write_hdf5(set, dir / "link.h5"), IoError);
  CHECK(file_bytes(victim) == "precious\n");
}

TEST_CASE("The stale-temporary cleanup removes what a killed bake left and nothing of the user's", "[io][hostile]") {
  const fs::path dir = temp_dir("cleanup");
  const BakeConfig c = config_in(dir, tiny_config(false));
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  // Files of the user's that merely look like temporaries of this basename.
  const std::vector<std::string> user = {"s.h5.tmp-keep", "s-draft.tmp-x", "s.h5.tmp-1", "s.h5.0123456789abcdef.tmp-1",
                                         "s.json.tmp-999999999", "s.h5.tmp-"};
  for (const std::string& n : user) write_bytes(dir / n, "user data\n");
  // A bake killed while writing (here by a file-size limit, as a hard stop would) leaves its
  // temporary behind.
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    const rlimit core{0, 0}, size{4096, 4096};
    ::setrlimit(RLIMIT_CORE, &core);
    ::setrlimit(RLIMIT_FSIZE, &size);
    ::signal(SIGXFSZ, SIG_DFL);
    try {
      write_outputs(set, c, report);
    } catch (...) {
    }
    ::_exit(0);
  }
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  REQUIRE(WIFSIGNALED(status));
  const std::string tail = ".tmp-" + std::to_string(child);
  std::size_t left = 0;
  for (const std::string& n : names_in(dir)) left += n.size() > tail.size() && n.compare(n.size() - tail.size(), tail.size(), tail) == 0;
  CHECK(left == 1);
  remove_stale_temporaries(c);
  std::vector<std::string> expected = user;
  std::sort(expected.begin(), expected.end());
  CHECK(names_in(dir) == expected);
  for (const std::string& n : user) CHECK(file_bytes(dir / n) == "user data\n");
  // A bake after it leaves the user's files alone too.
  write_outputs(set, c, report);
  for (const std::string& n : user) CHECK(file_bytes(dir / n) == "user data\n");
}

TEST_CASE("Up to date means the contents match, not only the sizes", "[io][hostile]") {
  const fs::path dir = temp_dir("uptodate");
  const BakeConfig c = config_in(dir);
  BakeReport report;
  write_outputs(bake(c, {}, &report), c, report);
  REQUIRE(outputs_up_to_date(c));
  const fs::path h5 = output_paths(c).hdf5, exr = output_paths(c).exr;
  const std::string h5_bytes = file_bytes(h5), exr_bytes = file_bytes(exr);
  std::string flipped = h5_bytes;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 0x01);
  write_bytes(h5, flipped);
  CHECK_FALSE(outputs_up_to_date(c));
  write_bytes(h5, h5_bytes);
  CHECK(outputs_up_to_date(c));
  write_bytes(exr, std::string(exr_bytes.size(), '\0'));
  CHECK_FALSE(outputs_up_to_date(c));
  // A FIFO at an output's name is not up to date (and is not read: the check would block).
  write_bytes(exr, exr_bytes);
  fs::remove(h5);
  REQUIRE(::mkfifo(h5.c_str(), 0644) == 0);
  CHECK_FALSE(outputs_up_to_date(c));
}
