#include "hairlut/bake/config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/hair_model.hpp"
#include "hairlut/bake/json_schema.hpp"
#include "hairlut/bake/engine_preset.hpp"
#include "hairlut/bake/model_kind.hpp"
#include "hairlut/util/version.hpp"
#include "config_parse.hpp"

namespace hairlut {
namespace detail {
extern const char* const config_schema_json;  // lib/src/bake/config.schema.json, embedded by the build
}

nlohmann::ordered_json config_schema() {
  nlohmann::ordered_json s = nlohmann::ordered_json::parse(detail::config_schema_json);
  // The models: their names in `model`'s enum (full names, then short ones), their settings keys,
  // their rules; the default stays the base schema's. A reference into an ordered_json object does
  // not survive an insertion into it, so each is taken after the models' keys are in.
  nlohmann::ordered_json names = nlohmann::ordered_json::array();
  std::string described, shorts;
  for (const ModelKind* m : model_kinds()) {
    const nlohmann::ordered_json f = nlohmann::ordered_json::parse(m->schema());
    names.push_back(std::string(m->name()));
    described += (described.empty() ? "" : " or ") + f.at("description").get<std::string>();
    shorts += (shorts.empty() ? "\"" : ", \"") + std::string(m->short_name()) + "\"";
    if (f.contains("properties"))
      for (const auto& [key, value] : f.at("properties").items()) {
        if (s.at("properties").contains(key)) throw std::logic_error("model " + std::string(m->name()) + ": key " + key + " is also in the config schema");
        s.at("properties")[key] = value;
      }
    if (f.contains("allOf"))
      for (const auto& rule : f.at("allOf")) s.at("allOf").push_back(rule);
  }
  for (const ModelKind* m : model_kinds()) names.push_back(std::string(m->short_name()));
  nlohmann::ordered_json& model = s.at("properties").at("model");
  model["enum"] = names;
  model["description"] = "Scattering model: " + described + ". " + shorts + " are accepted as short names and recorded as the full ones.";
  // The engine presets: their names in tables.engine.preset's enum, their textures' names, their
  // own keys of tables.engine and their rules.
  {
    nlohmann::ordered_json preset_names = nlohmann::ordered_json::array(), texture_names = nlohmann::ordered_json::array();
    std::string presets_described;
    nlohmann::ordered_json engine = s.at("properties").at("tables").at("properties").at("engine");
    for (const EnginePreset* p : engine_presets()) {
      const nlohmann::ordered_json f = nlohmann::ordered_json::parse(p->schema());
      preset_names.push_back(std::string(p->name()));
      presets_described += (presets_described.empty() ? "" : "; ") + f.at("description").get<std::string>();
      for (const std::string& t : p->texture_names())
        if (std::find(texture_names.begin(), texture_names.end(), t) == texture_names.end()) texture_names.push_back(t);
      if (f.contains("properties"))
        for (const auto& [key, value] : f.at("properties").items()) {
          if (engine.at("properties").contains(key)) throw std::logic_error("preset " + std::string(p->name()) + ": key " + key + " is also in the config schema");
          engine.at("properties")[key] = value;
        }
      if (f.contains("allOf"))
        for (const auto& rule : f.at("allOf")) engine["allOf"].push_back(rule);
    }
    engine.at("properties").at("preset")["enum"] = preset_names;
    engine.at("properties").at("preset")["description"] = "The preset: " + presets_described + ".";
    engine.at("properties").at("textures").at("items")["enum"] = texture_names;
    s.at("properties").at("tables").at("properties")["engine"] = engine;
  }
  nlohmann::ordered_json& tables = s.at("properties").at("tables").at("properties");
  nlohmann::ordered_json& thresholds = s.at("properties").at("validate").at("properties").at("thresholds").at("properties");
  for (const TableKind* k : table_kinds()) {
    const TableKind::Threshold th = k->threshold();
    if (tables.contains(k->name()) || thresholds.contains(th.name))
      throw std::logic_error("table kind " + std::string(k->name()) + " is also in the config schema");
    tables[std::string(k->name())] = nlohmann::ordered_json::parse(k->schema());
    thresholds[std::string(th.name)] = {{"type", "number"}, {"exclusiveMinimum", 0}, {"default", th.value}, {"description", th.description}};
  }
  return s;
}

void config_error(const std::string& path, const std::string& reason) { detail::config_parse::fail(path, reason); }

GridAxis config_value_axis(const nlohmann::json& j, const std::string& path, const std::string& name, double domain_lo, double domain_hi,
                           const std::string& units, const std::string& long_name) {
  return detail::config_parse::make_axis(j, path, name, false, domain_lo, domain_hi, units, long_name);
}

nlohmann::json config_axes_json(const std::vector<GridAxis>& axes) { return detail::config_parse::axes_json(axes); }

GridAxis config_angle_axis(const nlohmann::json& j, const std::string& path, const std::string& name, double domain_lo, double domain_hi,
                           const std::string& long_name) {
  return detail::config_parse::make_axis(j, path, name, true, domain_lo, domain_hi, "rad", long_name);
}

int config_lobe_index(const std::string& name, int lobe_count, const std::string& path) {
  return detail::config_parse::lobe_index(name, lobe_count, path);
}

void config_per_lobe_values(const nlohmann::json& j, const std::string& path, int lobe_count, double scale, std::vector<double>& out,
                            double& residual_out) {
  detail::config_parse::per_lobe_values(j, path, lobe_count, scale, out, residual_out);
}


const ModelKind* find_model_kind(std::string_view name) {
  for (const ModelKind* m : model_kinds())
    if (m->name() == name || m->short_name() == name) return m;
  return nullptr;
}

const ModelKind& BakeConfig::model_kind() const {
  const ModelKind* m = find_model_kind(model);
  if (!m) throw DomainError("model " + model + ": not a model of this build");
  return *m;
}

std::string_view to_string(NpQuadratureConfig::Method method) {
  switch (method) {
    case NpQuadratureConfig::Method::adaptive: return "adaptive";
    case NpQuadratureConfig::Method::gauss_legendre: return "gauss-legendre";
    default: return "fourier";
  }
}

std::string_view to_string(NpRepresentation r) { return r == NpRepresentation::fourier ? "fourier" : "tensor"; }

namespace {

using namespace detail::config_parse;

BakeConfig parse_checked(const nlohmann::json& doc, const std::filesystem::path& base_dir) {
  BakeConfig c;
  c.name = doc.at("name").get<std::string>();
  c.description = doc.value("description", std::string());
  // The schema's enum holds the models' names and short names; the full one is recorded.
  const ModelKind* model = find_model_kind(doc.value("model", std::string("deon2011")));
  if (!model) fail("model", "is not a model of this build");
  c.model = model->name();

  const nlohmann::json fiber = doc.value("fiber", nlohmann::json::object());
  c.eta = get_number(fiber, "eta", 1.55);
  c.path = parse_absorption_path(fiber.value("absorption_path", std::string("chord")), "fiber.absorption_path");

  const nlohmann::json lobes = doc.value("lobes", nlohmann::json::object());
  const auto names = lobes.value("explicit", model->default_lobes());
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string path = "lobes.explicit[" + std::to_string(i) + "]";
    int p = -1;
    checked([&] { p = parse_lobe(names[i], path); });
    if (p != static_cast<int>(i))
      fail(path, "must be \"" + lobe_name(static_cast<int>(i)) + "\": list the lobes R, TT, TRT, ... in order without gaps (got \"" +
                     names[i] + "\")");
  }
  c.lobe_count = static_cast<int>(names.size());
  // What a model refuses (another model's settings and keys): its rules in the schema's allOf.
  c.model_settings = model->parse(doc, c);
  c.residual = model->has_residual() ? lobes.value("residual", true) : false;
  c.fold_below = get_number(lobes, "fold_below", 0.0);
  c.tilt.assign(static_cast<std::size_t>(c.lobe_count), 0.0);
  if (lobes.contains("tilt_deg")) {
    for (const auto& [key, value] : lobes.at("tilt_deg").items()) {
      const int p = lobe_index(key, c.lobe_count, "lobes.tilt_deg." + key);
      if (p < 0) c.residual_tilt = radians(value.get<double>());
      else c.tilt[static_cast<std::size_t>(p)] = radians(value.get<double>());
    }
  }

  const nlohmann::json q = doc.value("quadrature", nlohmann::json::object());
  const std::string method = q.value("method", std::string("fourier"));
  c.quadrature.method = method == "adaptive"         ? NpQuadratureConfig::Method::adaptive
                        : method == "gauss-legendre" ? NpQuadratureConfig::Method::gauss_legendre
                                                     : NpQuadratureConfig::Method::fourier;
  c.quadrature.order = q.value("order", 256);
  c.quadrature.variable = parse_integration_variable(q.value("variable", std::string("gamma")), "quadrature.variable");
  c.quadrature.tolerance = get_number(q, "tolerance", 1e-12);
  c.quadrature.energy_order = q.value("energy_order", 128);

  const nlohmann::json tables = doc.value("tables", nlohmann::json::object());
  if (tables.contains("np")) parse_np_tables(doc, tables, c);
  if (tables.contains("mp")) parse_mp_tables(doc, tables, c);
  for (const TableKind* k : table_kinds())
    if (const std::string name(k->name()); tables.contains(name)) c.kinds.push_back({k, k->parse(tables.at(name))});

  if (tables.contains("dual_scattering")) c.dual_scattering = parse_dual_scattering(tables.at("dual_scattering"), c.lobe_count, c.residual);
  if (tables.contains("engine")) c.engine = parse_engine(tables.at("engine"), names);

  if (doc.contains("scene")) parse_scene(doc, c);
  if (!c.np_axes && !c.np_fourier && !c.mp_axes && c.kinds.empty() && !c.dual_scattering && !c.engine) {
    std::string known = "np, mp, dual_scattering, engine";
    for (const TableKind* k : table_kinds()) known += ", " + std::string(k->name());
    fail("tables", "must ask for at least one table (" + known + ")");
  }

  model->check(c);
  if (c.engine) engine_preset(c.engine->preset).check(c);

  if (doc.contains("validate")) c.validate_thresholds = doc.at("validate").value("thresholds", nlohmann::json::object());
  // A bake for a target error is judged by that target unless the config says otherwise: the
  // validator's accuracy_max_rel for the N_p tables is the target (target_error accepts the
  // bake by the validator's measure).
  if (c.np_target_error && !c.validate_thresholds.contains("accuracy_max_rel")) c.validate_thresholds["accuracy_max_rel"] = *c.np_target_error;
  const nlohmann::json& out = doc.at("output");
  std::filesystem::path dir = out.value("directory", std::string("."));
  c.output.directory = dir.is_absolute() ? dir : (base_dir / dir).lexically_normal();
  c.output.basename = out.at("basename").get<std::string>();
  for (const auto& f : out.at("formats")) (f == "hdf5" ? c.output.hdf5 : c.output.exr) = true;
  const nlohmann::json h5 = out.value("hdf5", nlohmann::json::object());
  c.output.hdf5_double = h5.value("precision", std::string("float32")) == "float64";
  c.output.hdf5_deflate = h5.value("compression", 6);
  const nlohmann::json exr = out.value("exr", nlohmann::json::object());
  c.output.exr_half = exr.value("precision", std::string("float")) == "half";
  c.output.exr_compression = exr.value("compression", std::string("zip"));
  if (c.np_fourier && c.output.exr)
    fail("output.formats", "exr: the Fourier N_p tables (tables.np.representation fourier) are written to HDF5 only (OpenEXR has no "
                           "layout for them); remove \"exr\"");
  if (out.contains("sampling_data")) {
    if (!out.at("sampling_data").is_boolean()) fail("output.sampling_data", "must be true or false");
    c.output.sampling_data = out.at("sampling_data").get<bool>();
  }

  // Normalized form: every default filled in, angles in radians, keys sorted (nlohmann::json).
  nlohmann::json n;
  n["name"] = c.name;
  n["description"] = c.description;
  n["model"] = c.model;
  n["fiber"] = {{"eta", c.eta}, {"absorption_path", to_string(c.path)}};
  model->normalize(c, n);
  nlohmann::json t = nlohmann::json::object();
  if (c.np_fourier) {
    const FourierNpConfig& f = *c.np_fourier;
    t["np"] = {{"representation", "fourier"},
               {"axes", axes_json(f.axes)},
               {"fourier", {{"beta_range", {f.beta_lo, f.beta_hi}}, {"tolerance", f.tolerance}}}};
    if (c.np_target_error) t["np"]["target_error"] = *c.np_target_error;
    if (c.np_target_points) t["np"]["target_points"] = *c.np_target_points;
    if (c.np_energy_axes) t["np"]["energy_axes"] = axes_json(*c.np_energy_axes);
  }
  if (c.np_axes) {
    t["np"] = {{"axes", axes_json(*c.np_axes)}};
    // Recorded only when given, so that configs without it keep their hash.
    if (c.np_representation) t["np"]["representation"] = to_string(*c.np_representation);
    if (c.np_target_error) t["np"]["target_error"] = *c.np_target_error;
    if (c.np_target_points) t["np"]["target_points"] = *c.np_target_points;
    if (c.np_normalize_energy) t["np"]["normalize"] = "energy";
    if (c.np_energy_axes) t["np"]["energy_axes"] = axes_json(*c.np_energy_axes);
    if (!c.np_beta_bands.empty()) t["np"]["beta_bands"] = beta_bands_json(c.np_beta_bands);
  }
  if (c.mp_axes) t["mp"] = {{"axes", axes_json(*c.mp_axes)}};
  for (const TableKindRequest& k : c.kinds) t[std::string(k.kind->name())] = k.kind->normalized(*k.settings);
  if (c.dual_scattering) t["dual_scattering"] = dual_scattering_json(*c.dual_scattering);
  if (c.engine) t["engine"] = engine_json(*c.engine);
  n["tables"] = t;
  if (c.scene) {
    nlohmann::json mats = nlohmann::json::array();
    for (const MaterialConfig& m : c.scene->materials) {
      nlohmann::json mj = {{"name", m.name}, {"sigma_a", m.sigma_a}, {"beta_m", m.beta_m}, {"beta_n", m.beta_n},
                 {"residual_beta_m", m.residual_beta_m}, {"residual_beta_n", m.residual_beta_n}};
      if (m.melanin) mj["melanin"] = {{"eumelanin", (*m.melanin)[0]}, {"pheomelanin", (*m.melanin)[1]}, {"model", m.melanin_model}};
      mats.push_back(mj);
    }
    n["scene"] = {{"mode", c.scene->mode == SceneConfig::Mode::per_material ? "per-material" : "restrict-generic"},
                  {"materials", mats}};
  }
  nlohmann::json formats = nlohmann::json::array();
  if (c.output.hdf5) formats.push_back("hdf5");
  if (c.output.exr) formats.push_back("exr");
  n["output"] = {{"basename", c.output.basename},
                 {"formats", formats},
                 {"hdf5", {{"precision", c.output.hdf5_double ? "float64" : "float32"}, {"compression", c.output.hdf5_deflate}}},
                 {"exr", {{"precision", c.output.exr_half ? "half" : "float"}, {"compression", c.output.exr_compression}}}};
  if (!c.output.sampling_data) n["output"]["sampling_data"] = false;  // absent when true: earlier configs keep their hash
  // The validation thresholds travel with the tables (the stored config), so that a file is judged
  // by the thresholds it was baked with.
  if (c.validate_thresholds.is_object() && !c.validate_thresholds.empty()) n["validate"] = {{"thresholds", c.validate_thresholds}};
  c.normalized = n;
  c.hash = fnv1a64_hex(n.dump() + "\nhairlut " + kVersion);
  return c;
}


}  // namespace

BakeConfig parse_config(const nlohmann::json& document, const std::string& source, const std::filesystem::path& base_dir) {
  static_assert(sizeof(char) == 1);
  const JsonSchema schema(config_schema());
  const auto violations = schema.validate(document, 1);
  if (!violations.empty()) throw ConfigError(source + ": " + violations.front().message);
  try {
    return parse_checked(document, base_dir);
  } catch (const KeyError& e) {
    throw ConfigError(source + ": " + e.path + ": " + e.reason);
  } catch (const DomainError& e) {
    throw ConfigError(source + ": " + e.what());
  } catch (const nlohmann::json::exception& e) {
    // The schema should make this unreachable; keep the message one line anyway.
    throw ConfigError(source + ": " + e.what());
  }
}

BakeConfig load_config(const std::filesystem::path& file) {
  const std::string source = file.string();
  // A config is a small file: refuse directories and devices (/dev/zero never ends), and stop
  // reading past kMaxConfigBytes (a pipe is read up to that bound).
  constexpr std::uintmax_t kMaxConfigBytes = std::uintmax_t{16} << 20;
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (status.type() == std::filesystem::file_type::directory) throw ConfigError(source + ": is a directory, not a config file");
  if (!ec && status.type() != std::filesystem::file_type::regular && status.type() != std::filesystem::file_type::fifo &&
      status.type() != std::filesystem::file_type::not_found)
    throw ConfigError(source + ": not a regular file or pipe (a config is a JSON file)");
  if (const auto bytes = std::filesystem::file_size(file, ec); !ec && bytes > kMaxConfigBytes)
    throw ConfigError(source + ": config file too large (" + std::to_string(bytes) + " bytes; at most 16 MiB)");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ConfigError(source + ": cannot open config file (" + std::string(std::strerror(errno)) + ")");
  std::string text;
  std::vector<char> block(1 << 16);
  while (in) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    text.append(block.data(), static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxConfigBytes) throw ConfigError(source + ": config file too large (more than 16 MiB)");
  }
  if (in.bad()) throw ConfigError(source + ": cannot read config file");
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::out_of_range& e) {
    throw ConfigError(source + ": invalid JSON: a number is out of range (" + std::string(e.what()) + ")");
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is the offset of the error; turn it into line:column.
    const std::string& s = text;
    std::size_t line = 1, col = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < s.size(); ++i) {
      if (s[i] == '\n') ++line, col = 1;
      else ++col;
    }
    std::string what = e.what();
    const auto pos = what.find("syntax error");
    if (pos != std::string::npos) what = what.substr(pos);
    throw ConfigError(source + ":" + std::to_string(line) + ":" + std::to_string(col) + ": invalid JSON: " + what);
  }
  std::filesystem::path base = file.parent_path();
  if (base.empty()) base = ".";
  return parse_config(doc, source, base);
}

}  // namespace hairlut
