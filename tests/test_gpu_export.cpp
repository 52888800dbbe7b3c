// The GPU export (hairlut/io/gpu_export.hpp): a per-material and a generic set written and read
// back hold the layout built in memory, value for value; and a reader given hostile files (a name
// that leaves the directory, a truncated file, indices that reach beyond the values, an absurd
// count) refuses each with one line naming the file, allocating nothing the files did not justify.
// The shaders reading these layouts are tested through Vulkan in tests/gpu/.
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/io/gpu_export.hpp>
#include <hairlut/io/hdf5_io.hpp>
#include <hairlut/io/table_io.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <nlohmann/json.hpp>

#include "catch.hpp"

#ifndef HAIRLUT_SOURCE_DIR
#error "HAIRLUT_SOURCE_DIR must name the source tree"
#endif

using namespace hairlut;
namespace fs = std::filesystem;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hairlut-test-gpu-export-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read_error(const fs::path& description) {
  try {
    read_gpu_export(description);
  } catch (const IoError& e) {
    return e.what();
  }
  return "(read)";
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream f(p);
  return nlohmann::json::parse(f);
}
void write_json(const fs::path& p, const nlohmann::json& j) { std::ofstream(p) << j.dump(2); }

TableSet per_material_set() {
  std::ifstream f(fs::path(HAIRLUT_SOURCE_DIR) / "tests" / "configs" / "valid" / "gpu-material.json");
  return bake(parse_config(nlohmann::json::parse(f), "gpu-material.json", fs::temp_directory_path()));
}

}  // namespace

TEST_CASE("gpu export: a per-material set read back holds the textures, blocks and rows built in memory", "[gpu]") {
  const TableSet set = per_material_set();
  const GpuLayout built = gpu_layout(set);
  REQUIRE(built.kind == "materials");
  REQUIRE(built.materials.size() == 2);
  const fs::path dir = fresh_dir("materials");
  const std::vector<fs::path> files = write_gpu_export(set, dir / "m");
  REQUIRE(files.size() == 5);
  CHECK(files.back() == dir / "m.gpu.json");
  for (const auto& e : fs::directory_iterator(dir)) CHECK(e.path().string().find(".tmp-") == std::string::npos);
  const GpuLayout read = read_gpu_export(dir / "m.gpu.json");
  CHECK(read.materials == built.materials);
  CHECK(read.textures.np == built.textures.np);
  CHECK(read.textures.mp == built.textures.mp);
  CHECK(read.textures.rows == built.textures.rows);
  REQUIRE(read.textures.materials.size() == built.textures.materials.size());
  CHECK(std::memcmp(read.textures.materials.data(), built.textures.materials.data(), built.textures.materials.size() * sizeof(gpu::GpuMaterial)) == 0);

  SECTION("half textures hold the values rounded to binary16") {
    GpuExportOptions half;
    half.half = true;
    write_gpu_export(set, dir / "h", half);
    const GpuLayout h = read_gpu_export(dir / "h.gpu.json");
    std::size_t differ = 0, rounded = 0;
    for (std::size_t i = 0; i < built.textures.np.size(); ++i) {
      differ += h.textures.np[i] != gpu::from_half(gpu::to_half(built.textures.np[i]));
      rounded += h.textures.np[i] != built.textures.np[i];
    }
    CHECK(differ == 0);
    CHECK(rounded > 0);  // the file is half, not float32
  }
  SECTION("a texture of other dimensions than its description is refused") {
    nlohmann::json d = read_json(dir / "m.gpu.json");
    d["np"]["layers"] = d["np"]["layers"].get<int>() + 1;
    write_json(dir / "m.gpu.json", d);
    CHECK_THAT(read_error(dir / "m.gpu.json"), Catch::Matchers::Contains("m.np.exr") && Catch::Matchers::Contains("pixels"));
  }
  SECTION("a block whose layers lie outside the textures is refused") {
    std::vector<gpu::GpuMaterial> blocks = built.textures.materials;
    blocks[1].lobes[2] = 1000;
    std::ofstream(dir / "m.materials.bin", std::ios::binary).write(reinterpret_cast<const char*>(blocks.data()), static_cast<std::streamsize>(blocks.size() * sizeof blocks[0]));
    CHECK_THAT(read_error(dir / "m.gpu.json"), Catch::Matchers::Contains("outside the textures"));
  }
  fs::remove_all(dir);
}

TEST_CASE("gpu export: the default generic set read back holds the buffers built in memory, and hostile descriptions are refused", "[gpu]") {
  const TableSet set = load_tables(fs::path(HAIRLUT_SOURCE_DIR) / "tables" / "default" / "hairlut-default.h5");
  const gpu::GenericBuffers built(hair_tables<float, double>(set));
  const fs::path dir = fresh_dir("generic");
  REQUIRE(write_gpu_export(set, dir / "g").size() == 3);
  const fs::path desc = dir / "g.gpu.json";
  {
    const GpuLayout read = read_gpu_export(desc);
    REQUIRE(read.kind == "generic");
    REQUIRE(read.generic);
    CHECK(std::memcmp(&read.generic->set, &built.set, sizeof built.set) == 0);
    CHECK(read.generic->data == built.data);
  }
  const nlohmann::json good = read_json(desc);
  SECTION("a file name that leaves the directory") {
    nlohmann::json d = good;
    d["data"]["file"] = "../g.generic-data.bin";
    write_json(desc, d);
    CHECK_THAT(read_error(desc), Catch::Matchers::Contains("plain name"));
  }
  SECTION("a count far beyond the file: refused by its size, before anything is allocated for it") {
    nlohmann::json d = good;
    d["data"]["floats"] = 1LL << 40;
    write_json(desc, d);
    CHECK_THAT(read_error(desc), Catch::Matchers::Contains("floats must lie in"));
    d["data"]["floats"] = good["data"]["floats"].get<long long>() + 1;
    write_json(desc, d);
    CHECK_THAT(read_error(desc), Catch::Matchers::Contains("bytes where the description says"));
  }
  SECTION("a truncated values file") {
    fs::resize_file(dir / "g.generic-data.bin", 1000);
    CHECK_THAT(read_error(desc), Catch::Matchers::Contains("g.generic-data.bin"));
  }
  SECTION("a table index or offset beyond the values") {
    gpu::GpuGenericSet s = built.set;
    s.np[0] = 40;
    std::ofstream(dir / "g.generic-set.bin", std::ios::binary).write(reinterpret_cast<const char*>(&s), sizeof s);
    CHECK_THAT(read_error(desc), Catch::Matchers::Contains("out of range"));
    s = built.set;
    s.tables[s.mp[0]].head[0] = static_cast<std::int32_t>(built.data.size()) - 10;
    std::ofstream(dir / "g.generic-set.bin", std::ios::binary).write(reinterpret_cast<const char*>(&s), sizeof s);
    CHECK_THAT(read_error(desc), Catch::Matchers::Contains("reaches beyond the values"));
  }
  SECTION("not a description, or another version") {
    std::ofstream(desc) << "{\"format\": \"hairlut-gpu\", \"version\": 2}";
    CHECK_THAT(read_error(desc), Catch::Matchers::Contains("version"));
    std::ofstream(desc) << "not json";
    CHECK_THAT(read_error(desc), Catch::Matchers::Contains("not a hairlut GPU export"));
  }
  fs::remove_all(dir);
}

TEST_CASE("gpu export: a directory that cannot be written leaves no file of the export", "[gpu]") {
  const TableSet set = per_material_set();
  const fs::path dir = fresh_dir("unwritable");
  fs::create_directories(dir / ("m.rows.bin.tmp-" + std::to_string(::getpid())));  // the rows' temporary name is taken by a directory
  CHECK_THROWS_AS(write_gpu_export(set, dir / "m"), IoError);
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  CHECK(files == 0);
  fs::remove_all(dir);
}
