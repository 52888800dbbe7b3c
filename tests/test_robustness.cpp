// Hostile input at the library level: pattern-checked strings of any length, config files that are
// not files, the table format version, metadata altered behind the checksum, and a set whose files
// come from two bakes. The tools' side (signals, disk full, concurrent bakes) is in
// tests/robustness/hostile.py.
#include <hdf5.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/bake/json_schema.hpp>
#include <hairlut/bake/outputs.hpp>
#include <hairlut/io/table_io.hpp>
#include <string>
#include <unistd.h>

#include "catch.hpp"

using namespace hairlut;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hairlut-robust-" + std::to_string(::getpid()) + "-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

json tiny_config(const std::string& name = "robust") {
  json c = json::parse(R"({
    "lobes": { "explicit": ["R", "TT"], "residual": true },
    "quadrature": { "order": 32 },
    "tables": { "np": { "axes": {
      "theta_d": { "count": 3, "range_deg": [0, 60] }, "phi": { "count": 5 },
      "sigma_a": { "count": 2, "range": [0, 1] }, "beta": { "count": 1, "range_deg": [10, 10] } } } },
    "output": { "basename": "t", "formats": ["hdf5", "exr"] }
  })");
  c["name"] = name;
  return c;
}

std::string config_error(const fs::path& p) {
  try {
    (void)load_config(p);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string load_error(const fs::path& p) {
  try {
    (void)load_tables(p);
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("Pattern-checked strings of a million characters are judged, not crashed on", "[robustness]") {
  const JsonSchema schema(json::parse(R"({
    "type": "object",
    "properties": {
      "name": { "type": "string", "pattern": "^[A-Za-z0-9][A-Za-z0-9_.-]*$", "maxLength": 64 },
      "free": { "type": "string", "pattern": "^[A-Za-z0-9][A-Za-z0-9_.-]*$" },
      "lobe": { "type": "string", "pattern": "^(R|TR*T|p[0-9]{1,2})$" },
      "tilt": { "type": "object", "propertyNames": { "pattern": "^(R|TR*T|p[0-9]{1,2}|residual)$" } }
    }
  })"));
  for (const std::size_t n : {std::size_t{30000}, std::size_t{1000000}}) {
    const std::string a(n, 'a'), trt = "T" + std::string(n, 'R') + "T";
    // Too long: one reason (the length), the pattern is not tried.
    auto v = schema.validate({{"name", a}});
    REQUIRE(v.size() == 1);
    CHECK(v[0].message.find("at most 64 characters") != std::string::npos);
    // No maxLength: the pattern decides, in linear time and bounded stack.
    CHECK(schema.validate({{"free", a}}).empty());
    CHECK(schema.validate({{"free", a + "!"}}).size() == 1);
    CHECK(schema.validate({{"lobe", trt}}).empty());
    CHECK(schema.validate({{"lobe", trt + "R"}}).size() == 1);
    CHECK(schema.validate({{"tilt", {{trt, 1}}}}).empty());
    CHECK(schema.validate({{"tilt", {{a, 1}}}}).size() == 1);
  }
}

TEST_CASE("Config files that are not small regular files are refused before reading", "[robustness]") {
  const fs::path dir = temp_dir("configs");
  CHECK(config_error(dir).find("is a directory") != std::string::npos);
  CHECK(config_error("/dev/zero").find("not a regular file") != std::string::npos);
  CHECK(config_error(dir / "missing.json").find("cannot open config file") != std::string::npos);
  {
    std::ofstream big(dir / "big.json");
    big << "{\"name\": \"" << std::string((16u << 20) + 10, 'a') << "\"}";
  }
  CHECK(config_error(dir / "big.json").find("too large") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("The format version: this major and any minor are read, other majors are refused", "[robustness]") {
  CHECK(format_version_text() == std::to_string(kFormatVersionMajor) + "." + std::to_string(kFormatVersionMinor));
  CHECK_NOTHROW(check_format_version(format_version_text(), "f"));
  CHECK_NOTHROW(check_format_version(std::to_string(kFormatVersionMajor) + ".99", "f"));
  auto message = [](const std::string& v) {
    try {
      check_format_version(v, "f.h5");
    } catch (const IoError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK(message(std::to_string(kFormatVersionMajor + 1) + ".0").find("newer than this hairlut reads") != std::string::npos);
  CHECK(message("0.9").find("older than this hairlut reads") != std::string::npos);
  for (const char* bad : {"", "1", "1.", ".1", "a.b", "1.0.0", "99999999.0", "-1.0"}) CHECK(message(bad).find("f.h5: ") == 0);
}

TEST_CASE("Written files carry the format version and loaders check it", "[robustness][io]") {
  const fs::path dir = temp_dir("version");
  const BakeConfig c = parse_config(tiny_config(), "t.json", dir);
  BakeReport report;
  write_outputs(bake(c, {}, &report), c, report);
  const fs::path h5 = output_paths(c).hdf5;
  REQUIRE_NOTHROW(load_tables(h5));
  REQUIRE_NOTHROW(load_tables(output_paths(c).exr));
  // Rewrite the root attribute as a newer major version.
  fs::copy_file(h5, dir / "newer.h5");
  {
    const hid_t f = H5Fopen((dir / "newer.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    H5Adelete(f, "hairlut_format_version");
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, 3);
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr = H5Acreate2(f, "hairlut_format_version", type, space, H5P_DEFAULT, H5P_DEFAULT);
    const std::string next = std::to_string(kFormatVersionMajor + 1) + ".0";
    H5Awrite(attr, type, next.c_str());
    H5Aclose(attr);
    H5Sclose(space);
    H5Tclose(type);
    H5Fclose(f);
  }
  CHECK(load_error(dir / "newer.h5").find("newer than this hairlut reads") != std::string::npos);
  fs::remove_all(dir);
}

// The root attribute hairlut_format_version of an HDF5 file.
std::string h5_format_version(const fs::path& p) {
  const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t attr = H5Aopen(f, "hairlut_format_version", H5P_DEFAULT);
  const hid_t type = H5Aget_type(attr);
  std::string v(H5Tget_size(type), '\0');
  H5Aread(attr, type, v.data());
  H5Tclose(type), H5Aclose(attr), H5Fclose(f);
  return v.c_str();
}

TEST_CASE("A file records format 3.0 when a table stores energies over a grazing factor, 2.0 otherwise", "[robustness][io]") {
  // Format 3.0's energy tables (θd up to 90°) store E / g, which a 2.x reader would read as E: the
  // major version makes it refuse them. A set without such tables holds 2.0's content and says so.
  const fs::path dir = temp_dir("version3");
  for (const double end : {60.0, 90.0}) {
    json cfg = tiny_config(end == 90.0 ? "grazing" : "short");
    cfg["tables"]["np"]["normalize"] = "energy";
    cfg["tables"]["np"]["axes"]["theta_d"]["range_deg"] = {0.0, end};
    cfg["output"]["basename"] = end == 90.0 ? "g" : "s";
    const BakeConfig c = parse_config(cfg, "t.json", dir);
    BakeReport report;
    const TableSet set = bake(c, {}, &report);
    const bool over_grazing = std::any_of(set.tables.begin(), set.tables.end(), [](const Table& t) { return t.attributes.contains("cos_theta_d_power"); });
    INFO("theta_d up to " << end << " deg");
    CHECK(over_grazing == (end == 90.0));
    write_outputs(set, c, report);
    const std::string want = end == 90.0 ? "3.0" : "2.0";
    CHECK(format_version_text(set) == want);
    CHECK(h5_format_version(output_paths(c).hdf5) == want);
    std::ifstream sidecar(output_paths(c).sidecar);
    CHECK(json::parse(sidecar)["format_version"] == (end == 90.0 ? 3 : 2));
    const TableSet back = load_tables(output_paths(c).hdf5);
    CHECK(load_tables(output_paths(c).exr).tables.size() == back.tables.size());
    for (const Table& t : set.tables) CHECK(back.find(t.path())->attributes == t.attributes);
  }
  fs::remove_all(dir);
}

TEST_CASE("Files of format 1.x (FNV-1a 64 checksums, no algorithm named) are still read and verified", "[robustness][io]") {
  const fs::path dir = temp_dir("format1");
  const BakeConfig c = parse_config(tiny_config(), "t.json", dir);
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  write_outputs(set, c, report);
  const fs::path h5 = output_paths(c).hdf5;
  // The file as format 1.1 wrote it: version 1.1, FNV-1a 64 content checksum, no algorithm attribute.
  auto set_root_string = [](hid_t f, const char* key, const std::string& value) {
    if (H5Aexists(f, key) > 0) H5Adelete(f, key);
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, value.size());
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr = H5Acreate2(f, key, type, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(attr, type, value.c_str());
    H5Aclose(attr);
    H5Sclose(space);
    H5Tclose(type);
  };
  auto as_format_1 = [&](const fs::path& p, const std::string& checksum) {
    fs::copy_file(h5, p, fs::copy_options::overwrite_existing);
    const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    H5Adelete(f, "hairlut_checksum_algorithm");
    set_root_string(f, "hairlut_format_version", "1.1");
    set_root_string(f, "hairlut_checksum", checksum);
    H5Fclose(f);
  };
  const std::string fnv = content_checksum(set, ChecksumRounding::as_stored, HashAlgorithm::fnv1a64);
  CHECK(fnv != content_checksum(set));
  as_format_1(dir / "old.h5", fnv);
  TableSet got;
  REQUIRE_NOTHROW(got = load_tables(dir / "old.h5"));
  CHECK(content_checksum(got) == content_checksum(set));
  // A format 1.x file is verified with FNV-1a: an XXH3-64 checksum there is a mismatch.
  as_format_1(dir / "mixed.h5", content_checksum(set));
  CHECK(load_error(dir / "mixed.h5").find("content checksum mismatch") != std::string::npos);
  // A format 2.x file must name its algorithm, and a known one.
  fs::copy_file(h5, dir / "unnamed.h5");
  {
    const hid_t f = H5Fopen((dir / "unnamed.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    H5Adelete(f, "hairlut_checksum_algorithm");
    H5Fclose(f);
  }
  CHECK(load_error(dir / "unnamed.h5").find("missing attribute hairlut_checksum_algorithm") != std::string::npos);
  fs::copy_file(h5, dir / "unknown.h5");
  {
    const hid_t f = H5Fopen((dir / "unknown.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    set_root_string(f, "hairlut_checksum_algorithm", "md5");
    H5Fclose(f);
  }
  CHECK(load_error(dir / "unknown.h5").find("unknown checksum algorithm \"md5\"") != std::string::npos);
  // A sidecar of format 1 records FNV-1a 64 under "fnv1a64": the loader checks the file with it.
  {
    std::ifstream in(output_paths(c).sidecar);
    json side = json::parse(in);
    for (json& f : side["files"]) {
      std::ifstream bytes(dir / f["path"].get<std::string>(), std::ios::binary);
      const std::string data((std::istreambuf_iterator<char>(bytes)), std::istreambuf_iterator<char>());
      f.erase("xxh3_64");
      f["fnv1a64"] = fnv1a64_hex(data);
    }
    side["format_version"] = 1;
    std::ofstream(output_paths(c).sidecar) << side.dump(2);
  }
  REQUIRE_NOTHROW(load_tables(h5));
  {
    std::ifstream in(output_paths(c).sidecar);
    json side = json::parse(in);
    for (json& f : side["files"]) f["fnv1a64"] = "0000000000000000";
    std::ofstream(output_paths(c).sidecar) << side.dump(2);
  }
  CHECK(load_error(h5).find("fnv1a-64 differ") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("Visible HDF5 metadata altered behind the checksum is refused, naming the attribute", "[robustness][io]") {
  const fs::path dir = temp_dir("attrs");
  const BakeConfig c = parse_config(tiny_config(), "t.json", dir);
  BakeReport report;
  write_outputs(bake(c, {}, &report), c, report);
  const fs::path h5 = output_paths(c).hdf5;
  auto altered = [&](const std::string& name, auto&& change) {
    const fs::path p = dir / (name + ".h5");
    fs::copy_file(h5, p, fs::copy_options::overwrite_existing);
    const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    change(f);
    H5Fclose(f);
    return load_error(p);
  };
  auto set_double = [](hid_t obj, const char* key, double v) {
    H5Adelete(obj, key);
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr = H5Acreate2(obj, key, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(attr, H5T_NATIVE_DOUBLE, &v);
    H5Aclose(attr);
    H5Sclose(space);
  };
  CHECK(altered("eta", [&](hid_t f) { set_double(f, "eta", 2.0); }).find("/ attribute eta disagrees") != std::string::npos);
  CHECK(altered("model", [](hid_t f) { H5Adelete(f, "model"); }).find("/ attribute model is missing") != std::string::npos);
  CHECK(altered("hash", [](hid_t f) { H5Adelete(f, "config_hash"); }).find("attribute config_hash is missing") != std::string::npos);
  auto on_tt = [](auto&& change) {
    return [change](hid_t f) {
      const hid_t d = H5Dopen2(f, "/np/TT", H5P_DEFAULT);
      change(d);
      H5Dclose(d);
    };
  };
  CHECK(altered("units", on_tt([](hid_t d) { H5Adelete(d, "units"); })).find("/np/TT attribute units is missing") != std::string::npos);
  CHECK(altered("dims", on_tt([](hid_t d) { H5Adelete(d, "DIMENSION_LIST"); })).find("DIMENSION_LIST is missing") != std::string::npos);
  CHECK(altered("p", on_tt([&](hid_t d) {
          H5Adelete(d, "p");
          const long long seven = 7;
          const hid_t space = H5Screate(H5S_SCALAR);
          const hid_t attr = H5Acreate2(d, "p", H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT);
          H5Awrite(attr, H5T_NATIVE_LLONG, &seven);
          H5Aclose(attr);
          H5Sclose(space);
        })).find("/np/TT attribute p disagrees") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("A file of another bake beside a set's sidecar is refused", "[robustness][io]") {
  const fs::path a = temp_dir("set-a"), b = temp_dir("set-b");
  const BakeConfig ca = parse_config(tiny_config("first"), "t.json", a);
  const BakeConfig cb = parse_config(tiny_config("second"), "t.json", b);
  BakeReport report;
  write_outputs(bake(ca, {}, &report), ca, report);
  write_outputs(bake(cb, {}, &report), cb, report);
  REQUIRE_NOTHROW(load_tables(output_paths(ca).hdf5));
  // b's HDF5 file in a's set: whole by itself, but not the file a's manifest lists.
  fs::copy_file(output_paths(cb).hdf5, output_paths(ca).hdf5, fs::copy_options::overwrite_existing);
  CHECK(load_error(output_paths(ca).hdf5).find("does not match its set's sidecar") != std::string::npos);
  // Alone (no sidecar beside it) the file is read.
  fs::remove(output_paths(ca).sidecar);
  CHECK_NOTHROW(load_tables(output_paths(ca).hdf5));
  fs::remove_all(a);
  fs::remove_all(b);
}
