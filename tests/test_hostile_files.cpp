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
#include <hairlut/bake/outputs.hpp>
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

// The loader's refusal of `p`, or "" when it loads.
std::string load_refusal(const fs::path& p) {
  try {
    load_tables(p);
    return "";
  } catch (const IoError& e) {
    return e.what();
  }
}

TEST_CASE("Sidecars are read for the fields the loader uses, and large, deep or long-listed ones are refused naming the file", "[io][hostile]") {
  const fs::path dir = temp_dir("sidecar");
  const BakeConfig c = config_in(dir);
  BakeReport report;
  write_outputs(bake(c, {}, &report), c, report);
  const fs::path h5 = output_paths(c).hdf5, side = output_paths(c).sidecar;
  const std::string text = file_bytes(side);
  const json doc = json::parse(text);
  REQUIRE(load_refusal(h5).empty());
  // A field the loader does not use, of 4 MB of nested objects: read, and the kept fields still
  // decide (the set is up to date; a wrong recorded size is refused).
  std::string unit;
  for (int i = 0; i < 20; ++i) unit += "{\"a\":";
  unit += "0" + std::string(20, '}');
  std::string padding = "[";
  while (padding.size() < (std::size_t{4} << 20)) padding += unit + ",";
  padding.back() = ']';
  write_bytes(side, text.substr(0, text.rfind('}')) + ", \"padding\": " + padding + "}");
  CHECK(load_refusal(h5).empty());
  CHECK(outputs_up_to_date(c));
  json wrong = doc;
  for (json& f : wrong["files"]) f["bytes"] = f["bytes"].get<std::uint64_t>() + 1;
  std::string wrong_text = wrong.dump();
  write_bytes(side, wrong_text.substr(0, wrong_text.rfind('}')) + ", \"padding\": " + padding + "}");
  CHECK(load_refusal(h5).find("does not match its set's sidecar") != std::string::npos);
  CHECK_FALSE(outputs_up_to_date(c));
  // Nested too deeply, a "files" list too long, over the size cap (a sparse file: the size is
  // refused before anything is read): one line naming the sidecar, and not up to date.
  json long_list = doc;
  for (int i = 0; i < 20000; ++i) long_list["files"].push_back({{"path", "x" + std::to_string(i)}});
  const std::string deep = text.substr(0, text.rfind('}')) + ", \"x\": " + std::string(5000, '[') + std::string(5000, ']') + "}";
  for (const auto& [contents, phrase] : {std::pair<std::string, std::string>{deep, "nests deeper than 24 levels"},
                                         {long_list.dump(), "holds more than 65536 values"}, {"", "is 257.0 MiB, more than the 256 MiB"}}) {
    write_bytes(side, contents);
    if (contents.empty()) fs::resize_file(side, std::uintmax_t{257} << 20);
    const std::string why = load_refusal(h5);
    CHECK(why.rfind(side.string() + ": the set's sidecar ", 0) == 0);
    CHECK(why.find(phrase) != std::string::npos);
    CHECK(why.find('\n') == std::string::npos);
    CHECK_FALSE(outputs_up_to_date(c));
  }
  fs::remove_all(dir);
}

namespace {

// The message of read_hdf5 on `set` written with a valid checksum (the writer computes it), or
// "(loaded)".
std::string refusal(const TableSet& set, const fs::path& p) {
  write_hdf5(set, p);
  try {
    read_hdf5(p);
  } catch (const IoError& e) {
    return e.what();
  }
  return "(loaded)";
}

// Checks that `text` contains `part`, showing the text when it does not.
#define CHECK_CONTAINS(text, part)                          \
  do {                                                      \
    const std::string checked_text = (text);                \
    INFO(checked_text);                                     \
    CHECK(checked_text.find(part) != std::string::npos);    \
  } while (false)

Table& table(TableSet& set, const std::string& path) {
  for (Table& t : set.tables)
    if (t.path() == path) return t;
  FAIL("no table " << path);
  throw;
}

}  // namespace

TEST_CASE("Contents that make no sense are refused even with a valid checksum", "[io][hostile]") {
  const fs::path dir = temp_dir("semantics");
  const TableSet good = bake(config_in(dir, tiny_config(false)), {});
  const fs::path p = dir / "t.h5";
  REQUIRE(refusal(good, p) == "(loaded)");
  SECTION("a table relabelled with another quantity") {
    TableSet s = good;
    table(s, "np/TT").quantity = "M_p";
    CHECK_CONTAINS(refusal(s, p), "quantity");
  }
  SECTION("a slice's mass far from its prefix masses") {
    TableSet s = good;
    table(s, "sampling/np/TT_mass").set(0, 1e300);
    CHECK_CONTAINS(refusal(s, p), "TT_mass");
  }
  SECTION("NaN in a stored CDF") {
    TableSet s = good;
    Table& cdf = table(s, "sampling/np/TT_cdf");
    cdf.set(cdf.size() / 2, std::nan(""));
    CHECK_CONTAINS(refusal(s, p), "TT_cdf");
  }
  SECTION("a negative clamp bound") {
    TableSet s = good;
    table(s, "sampling/mp/R_clamp_bound").set(0, -1.0);
    CHECK_CONTAINS(refusal(s, p), "R_clamp_bound");
  }
}

TEST_CASE("Grazing-factor attributes beyond what a bake writes are refused", "[io][hostile]") {
  // A lookup raises cos θd to cos_theta_d_power: 1e9 would be a loop of 1e9 steps per lookup.
  const fs::path dir = temp_dir("grazing");
  json j = tiny_config(false);
  j["tables"]["np"]["axes"]["theta_d"]["range_deg"] = {0, 90};
  const TableSet good = bake(config_in(dir, j), {});
  const fs::path p = dir / "t.h5";
  REQUIRE(refusal(good, p) == "(loaded)");
  REQUIRE(good.find("np/energy_TT"));
  REQUIRE(good.find("np/energy_TT")->attributes.value("cos_theta_d_power", 0) == 2);
  for (const json& bad : {json(1000000000), json(-1), json(3), json(1.5), json("2")}) {
    TableSet s = good;
    table(s, "np/energy_TT").attributes["cos_theta_d_power"] = bad;
    CHECK_CONTAINS(refusal(s, p), "cos_theta_d_power");
  }
  for (const char* key : {"x_scale", "tau", "d"})
    for (const json& bad : {json(-1.0), json(1e300), json(nullptr)}) {
      TableSet s = good;
      table(s, "np/residual").attributes["grazing_absorption"][key] = bad;
      CHECK_CONTAINS(refusal(s, p), std::string("grazing_absorption.") + key);
    }
}

TEST_CASE("Beta bands that overlap, leave gaps or disagree with their tables are refused", "[io][hostile]") {
  const fs::path dir = temp_dir("bands");
  json j = tiny_config(false);
  j["tables"].erase("mp");
  j["tables"]["np"]["axes"]["beta"] = {{"count", 2}, {"range_deg", {2, 20}}, {"spacing", "log"}};
  j["tables"]["np"]["beta_bands"] = json::parse(R"([{"beta": {"count": 2, "range_deg": [2, 6]}}, {"beta": {"count": 2, "range_deg": [6, 20]}}])");
  const TableSet good = bake(config_in(dir, j), {});
  const fs::path p = dir / "t.h5";
  REQUIRE(refusal(good, p) == "(loaded)");
  REQUIRE(good.metadata.contains("np_beta_bands"));
  auto edited = [&](double lo1, double hi1) {
    TableSet s = good;
    s.metadata["np_beta_bands"][1]["range"] = {lo1, hi1};
    return refusal(s, p);
  };
  const double lo1 = good.metadata["np_beta_bands"][1]["range"][0].get<double>();
  const double hi1 = good.metadata["np_beta_bands"][1]["range"][1].get<double>();
  CHECK_CONTAINS(edited(lo1 * 0.9, hi1), "np_beta_bands");  // overlaps band 0
  CHECK_CONTAINS(edited(lo1 * 1.1, hi1), "np_beta_bands");  // leaves a gap
  CHECK_CONTAINS(edited(lo1, lo1 * 0.5), "np_beta_bands");  // reversed
  CHECK_CONTAINS(edited(lo1, hi1 * 2.0), "beta axis");      // not the tables' range
  TableSet s = good;
  table(s, "np/TT_band1").attributes["beta_band"]["index"] = 0;
  CHECK_CONTAINS(refusal(s, p), "beta_band");
}

TEST_CASE("Fourier tables with parameters beyond a config's ranges are refused", "[io][hostile]") {
  const fs::path dir = temp_dir("fourier");
  const json j = json::parse(R"({
    "name": "f", "lobes": { "explicit": ["R", "TT"], "residual": true },
    "quadrature": { "method": "fourier", "tolerance": 1e-6 },
    "tables": { "np": { "representation": "fourier",
      "axes": { "beta": { "range_deg": [5, 20] }, "sigma_a": { "count": 3, "range": [0, 2] }, "theta_d": { "count": 4, "range_deg": [0, 60] } },
      "fourier": { "tolerance": 1e-3 } } },
    "output": { "basename": "s", "formats": ["hdf5"] } })");
  const TableSet good = bake(config_in(dir, j), {});
  const fs::path p = dir / "t.h5";
  REQUIRE(refusal(good, p) == "(loaded)");
  for (const auto& [key, value] : std::vector<std::pair<std::string, double>>{
           {"beta_min", 1e-15}, {"beta_min", 0.0}, {"beta_max", 1e300}, {"eta", 1e300}, {"eta", 1.0}, {"tolerance", 0.5}}) {
    TableSet s = good;
    for (Table& t : s.tables)
      if (t.group == "np_fourier") t.attributes[key] = value;
    CHECK_CONTAINS(refusal(s, p), key);
  }
}
