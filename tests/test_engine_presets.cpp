// Export presets: the engine textures hold exactly the baked tables, in the engine's atlas layout,
// encoding and texel placement; the presets' configs are checked; the files take part in the
// up-to-date check; the generic dual-scattering tables are bit-identical for any thread count.
#include <Imath/half.h>

#include <cmath>
#include <filesystem>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/bake/engine_preset.hpp>
#include <hairlut/report/engine_preset_report.hpp>
#include <hairlut/physics/dual_scattering.hpp>
#include <hairlut/bake/outputs.hpp>
#include <hairlut/io/engine_exr.hpp>
#include <hairlut/physics/longitudinal_mp.hpp>
#include <hairlut/io/table_io.hpp>
#include <numbers>
#include <set>
#include <unistd.h>

#include "catch.hpp"

using namespace hairlut;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr double pi = std::numbers::pi;

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hairlut-test-" + std::to_string(::getpid()) + "-" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

BakeConfig shipped(const std::string& name, const fs::path& out) {
  BakeConfig c = load_config(fs::path(HAIRLUT_SOURCE_DIR) / "tables" / "configs" / (name + ".json"));
  c.output.directory = out;
  return c;
}

float as_half(double v) { return static_cast<float>(half(static_cast<float>(v))); }

std::string config_error(const std::string& text) {
  try {
    parse_config(json::parse(text), "engine.json", ".");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(accepted)";
}

// Every texel of every channel of a texture against its tables, through the engine's layout formula.
void check_texture(const TableSet& set, const EngineTexture& t, const EngineImage& img, int X, int Y, int Z) {
  long mismatches = 0;
  for (int c = 0; c < 4; ++c) {
    const EngineChannel& ch = t.channels[c];
    const Table* tb = ch.table.empty() ? nullptr : set.find(ch.table);
    if (!ch.table.empty()) REQUIRE(tb != nullptr);
    for (int z = 0; z < Z; ++z)
      for (int y = 0; y < Y; ++y)
        for (int x = 0; x < X; ++x) {
          double v = ch.constant;
          if (tb) {
            v = ch.scale * tb->get((static_cast<std::size_t>(z) * Y + static_cast<std::size_t>(y)) * X + static_cast<std::size_t>(x));
            if (ch.saturate) v = std::clamp(v, 0.0, 1.0);
          }
          if (img.texel(t, X, Y, x, y, z, c) != as_half(v)) ++mismatches;
        }
  }
  CHECK(mismatches == 0);
}

}  // namespace

TEST_CASE("Unreal preset: 64 x 64 x 16 dual-scattering and mean-energy textures in Unreal's 4 x 4 atlas", "[presets][unreal]") {
  const fs::path dir = temp_dir("unreal");
  const BakeConfig c = shipped("unreal-hair-strands", dir);
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  const auto files = write_outputs(set, c, report);
  CHECK(files.size() == 4);  // HDF5, two textures, sidecar
  CHECK(outputs_up_to_date(c));
  const auto outputs = engine_outputs(c);
  REQUIRE(outputs.size() == 2);
  for (const EngineOutput& o : outputs) {
    const EngineImage img = read_engine_texture(o.path);
    CHECK(img.width == 256);
    CHECK(img.height == 256);
    CHECK(img.description["preset"] == "unreal-hair-strands");
    CHECK(img.description["size"] == json::array({64, 64, 16}));
    check_texture(set, o.texture, img, 64, 64, 16);
    // The preset's atlas: slice z is tile (z mod 4, z / 4) of 64 x 64 texels, no flip.
    CHECK(img.texel(o.texture, 64, 64, 5, 7, 6, 3) == 1.0f);
    const auto px = engine_pixel(o.texture, 64, 64, 5, 7, 6);
    CHECK(px[0] == 5 + 64 * 2);
    CHECK(px[1] == 7 + 64 * 1);
  }
  // The tables against the point evaluation at a node: sin θ = 40.5/64, roughness 20.5/64, √c = 10.5/16.
  const Table* af = set.find("unreal/dual_scattering/a_f");
  const Table* e = set.find("unreal/mean_energy/E_total");
  REQUIRE(af);
  REQUIRE(e);
  const double r = 20.5 / 64, b = r * r, color = std::pow(10.5 / 16, 2);
  HairModel m;
  m.sigma_a = -0.25 * std::log(color);
  m.lobes = {{b, b, -0.07}, {b / 2, b / 2, 0.035}, {2 * b, 2 * b, 0.14}};
  m.residual = LobeParams{2 * b, 2 * b, 0.14};
  const DualScatteringPoint p = dual_scattering(m, std::asin(40.5 / 64));
  const std::size_t i = (10 * 64 + 20) * 64 + 40;
  CHECK(af->get(i) == Approx(p.a_f).margin(1e-6));
  CHECK(e->get(i) == Approx(p.energy_total).margin(1e-6));
  // The sidecar lists the textures; removing one makes the outputs stale.
  fs::remove(outputs[1].path);
  CHECK_FALSE(outputs_up_to_date(c));
  fs::remove_all(dir);
}

TEST_CASE("Unity preset: 64^3 attenuation (RG), azimuthal and longitudinal (RGBA) textures as 8 x 8 flipbooks with a bottom-left origin",
          "[presets][unity]") {
  const fs::path dir = temp_dir("unity");
  const BakeConfig c = shipped("unity-hdrp-hair", dir);
  BakeReport report;
  const TableSet set = bake(c, {}, &report);
  write_outputs(set, c, report);
  const auto outputs = engine_outputs(c);
  REQUIRE(outputs.size() == 3);
  for (const EngineOutput& o : outputs) {
    const EngineImage img = read_engine_texture(o.path);
    CHECK(img.width == 512);  // within Unity's 2048 import limit for 3D textures
    CHECK(img.height == 512);
    CHECK(img.channel_count == (o.texture.name == "attenuation" ? 2 : 4));  // R16G16_SFloat, R16G16B16A16_SFloat
    check_texture(set, o.texture, img, 64, 64, 64);
    const auto px = engine_pixel(o.texture, 64, 64, 3, 0, 10);
    CHECK(px[0] == 3 + 64 * 2);  // slice 10 is cell (10 mod 8, 10 / 8)
    CHECK(px[1] == 63 + 64);     // texel row 0 is the bottom row of its cell
  }
  // HDRP's constants are fixed by its kernels: the preset refuses others, naming its block.
  CHECK_THAT(config_error(R"({ "name": "t", "lobes": { "explicit": ["R", "TT", "TRT"] }, "tables": { "engine": { "preset": "unity-hdrp-hair", "unity": { "radial_smoothness": 0.5 } } }, "output": { "basename": "t", "formats": ["hdf5"] } })"),
             Catch::Matchers::Contains("tables.engine.unity: unity-hdrp-hair reproduces HDRP's kernels"));
  CHECK_THAT(config_error(R"({ "name": "t", "fiber": { "eta": 1.6 }, "lobes": { "explicit": ["R", "TT", "TRT"] }, "tables": { "engine": { "preset": "unity-hdrp-hair-deon" } }, "output": { "basename": "t", "formats": ["hdf5"] } })"),
             Catch::Matchers::Contains("fiber.eta: unity-hdrp-hair-deon reproduces HDRP's kernels, which fix eta = 1.55"));
  // Azimuthal: N is 2π-periodic and even (x + 32 is φ + 2π; 63 − x is −φ), computed independently at
  // each node, and integrates to 1 over a period (the trimmed logistic does). The wrapped logistic has
  // kinks at ±π, so the 32-point rectangle rule errs by about h²/12 times the jump of N' (at most the
  // jump 2|l'(π)|/mass of one wrapped logistic of scale s, N being an average of shifted copies);
  // the check allows twice that.
  const Table* n = set.find("unity/azimuthal/N_TRT");
  REQUIRE(n);
  double worst_period = 0.0, worst_norm = 0.0;
  const double h = 4 * pi / 64;
  for (int z : {0, 20, 40, 63})
    for (int y : {0, 30, 63}) {
      auto at = [&](int x) { return n->get((static_cast<std::size_t>(z) * 64 + static_cast<std::size_t>(y)) * 64 + static_cast<std::size_t>(x)); };
      double sum = 0.0;
      for (int x = 0; x < 32; ++x) {
        const double scale = std::max(1.0, at(x));
        worst_period = std::max({worst_period, std::abs(at(x) - at(x + 32)) / scale, std::abs(at(x) - at(63 - x)) / scale});
        sum += at(x) * (4 * pi / 64);
      }
      if (z >= 40) {
        const double b = (z + 0.5) / 64, sc = std::sqrt(pi / 8) * (0.265 * b + 1.194 * b * b + 5.372 * std::pow(b, 22));
        const double e = std::exp(-pi / sc), l = e / (sc * (1 + e) * (1 + e)), mass = 1 / (1 + e) - e / (1 + e);
        const double jump = 2 * l * std::tanh(pi / (2 * sc)) / sc / mass;
        worst_norm = std::max(worst_norm, std::abs(sum - 1.0) / (2 * h * h / 12 * jump + 1e-12));
      }
    }
  CHECK(worst_period < 1e-6);
  CHECK(worst_norm < 1.0);
  WARN("HDRP azimuthal table: periodicity/evenness max relative difference " << worst_period << ", |integral - 1| / allowance " << worst_norm);
  // Longitudinal and attenuation: test_hdrp_kernels compares every texel with HDRP's kernels.
  fs::remove_all(dir);
}

TEST_CASE("Generic dual-scattering tables are bit-identical for any thread count", "[presets][determinism]") {
  const fs::path dir = temp_dir("ds-threads");
  const BakeConfig c = shipped("dual-scattering", dir);
  BakeOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const TableSet a = bake(c, one), b = bake(c, two);
  CHECK(content_checksum(a) == content_checksum(b));
  // White furnace of the mean-energy table at σa = 0 (the config's first σa node).
  const Table* e = a.find("mean_energy/E_total");
  REQUIRE(e);
  double worst = 0.0;
  for (std::size_t i = 0; i < 16 * 32; ++i) worst = std::max(worst, std::abs(e->get(i) - 1.0));
  CHECK(worst < 1e-6);
  fs::remove_all(dir);
}

TEST_CASE("Engine configs: one-line errors naming the key", "[presets][config]") {
  const std::string out = R"(, "output": { "basename": "t", "formats": ["hdf5"] } })";
  CHECK_THAT(config_error(R"({ "name": "t", "tables": { "engine": { "preset": "unreal-hair-strands" } })" + out),
             Catch::Matchers::Contains("lobes.explicit: must be [\"R\", \"TT\", \"TRT\"] for tables.engine"));
  CHECK_THAT(config_error(R"({ "name": "t", "lobes": { "explicit": ["R", "TT", "TRT"] }, "tables": { "engine": { "preset": "unreal-hair-strands", "textures": ["attenuation"] } })" + out),
             Catch::Matchers::Contains("tables.engine.textures: \"attenuation\" is not a texture of unreal-hair-strands"));
  CHECK_THAT(config_error(R"({ "name": "t", "lobes": { "explicit": ["R", "TT", "TRT"] }, "tables": { "engine": { "preset": "unreal-hair-strands", "unity": { "cuticle_angle_deg": 2 } } })" + out),
             Catch::Matchers::Contains("tables.engine.unity: must not be given with another preset (applies to the unity-hdrp-hair preset only)"));
  CHECK_THAT(config_error(R"({ "name": "t", "lobes": { "explicit": ["R", "TT", "TRT"] }, "tables": { "engine": { "preset": "godot" } })" + out),
             Catch::Matchers::Contains("tables.engine.preset"));
  CHECK_THAT(config_error(R"({ "name": "t", "lobes": { "explicit": ["R", "TT"], "residual": false }, "tables": { "dual_scattering": { "axes": { "theta_i": { "count": 3, "range_deg": [0, 90] }, "beta": { "count": 2, "range_deg": [2, 10] }, "sigma_a": { "count": 2, "range": [0, 1] } }, "lobe_scale": { "residual": 2 } } })" + out),
             Catch::Matchers::Contains("tables.dual_scattering.lobe_scale.residual: is given but lobes.residual is false"));
  CHECK_THAT(config_error(R"({ "name": "t", "tables": { "dual_scattering": { "axes": { "theta_i": { "count": 3, "range_deg": [0, 100] }, "beta": { "count": 2, "range_deg": [2, 10] }, "sigma_a": { "count": 2, "range": [0, 1] } } } })" + out),
             Catch::Matchers::Contains("tables.dual_scattering.axes.theta_i.range_deg: must lie within [-90, 90] degrees"));
}

// The contract every preset of lib/presets/ keeps (hairlut/bake/engine_preset.hpp,
// hairlut/report/engine_preset_report.hpp), for each preset the build found: the config schema
// carries its name, textures, keys and rules; its textures read tables of its own groups; the
// validator knows how to recompute its texels; its settings are what the normalized config records.
TEST_CASE("presets: every preset folder joins the config schema and keeps the contract", "[presets][config]") {
  const nlohmann::ordered_json schema = config_schema();
  const auto& engine = schema["properties"]["tables"]["properties"]["engine"];
  REQUIRE(engine_presets().size() >= 3);
  std::set<std::string> names;
  for (const EnginePreset* p : engine_presets()) {
    const std::string name(p->name());
    INFO("preset " << name);
    CHECK(names.insert(name).second);
    CHECK(&engine_preset(name) == p);
    const auto& presets = engine["properties"]["preset"]["enum"];
    CHECK(std::find(presets.begin(), presets.end(), name) != presets.end());
    const json fragment = json::parse(p->schema());
    CHECK(engine["properties"]["preset"]["description"].get<std::string>().find(fragment.at("description").get<std::string>()) != std::string::npos);
    if (fragment.contains("properties"))
      for (const auto& [key, value] : fragment["properties"].items()) CHECK(engine["properties"].contains(key));
    // Textures: the names it lists, each reading tables of one of its groups.
    const std::vector<std::string> texture_names = p->texture_names();
    const auto& allowed = engine["properties"]["textures"]["items"]["enum"];
    std::vector<std::string> listed;
    for (const EngineTexture& t : p->textures()) {
      listed.push_back(t.name);
      CHECK(t.preset == name);
      CHECK(std::find(allowed.begin(), allowed.end(), t.name) != allowed.end());
      bool group_found = false;
      for (const EngineTableSpec& g : p->tables(true)) group_found = group_found || g.group == t.group;
      CHECK(group_found);
      for (int c = 0; c < t.channel_count; ++c)
        if (!t.channels[c].table.empty()) CHECK(t.channels[c].table.rfind(t.group + "/", 0) == 0);
    }
    CHECK(listed == texture_names);
    // The validator's side.
    bool reported = false;
    for (const EnginePresetReport* r : engine_preset_reports()) reported = reported || r->name() == name;
    CHECK(reported);
    // Its settings with every default are what the normalized config records.
    const std::string out = R"(, "output": { "basename": "t", "formats": ["hdf5"] } })";
    const BakeConfig c = parse_config(json::parse(R"({ "name": "t", "lobes": { "explicit": ["R", "TT", "TRT"] }, "tables": { "engine": { "preset": ")" + name + "\" } }" + out),
                                      "preset.json", std::filesystem::temp_directory_path());
    for (const auto& [key, value] : c.engine->settings.items()) CHECK(c.normalized["tables"]["engine"][key] == value);
  }
  for (const EnginePresetReport* r : engine_preset_reports()) CHECK_NOTHROW(engine_preset(r->name()));
  CHECK_THROWS_WITH(engine_preset("godot"), Catch::Matchers::Contains("tables.engine.preset must be one of"));
}
