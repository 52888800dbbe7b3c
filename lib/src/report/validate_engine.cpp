#include "hairlut/report/validate_engine.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "hairlut/util/angles.hpp"
#include "hairlut/bake/bake.hpp"
#include "hairlut/physics/dual_scattering.hpp"
#include "hairlut/io/engine_exr.hpp"
#include "hairlut/bake/engine_presets.hpp"
#include "hairlut/report/engine_preset_report.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/io/hdf5_io.hpp"  // IoError
#include "hairlut/report/report.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;

json check(const std::string& id, const std::string& title, bool pass, const json& value, const json& threshold, const std::string& comparison,
           const std::string& detail) {
  return {{"id", id}, {"title", title}, {"status", pass ? "pass" : "fail"}, {"value", value}, {"threshold", threshold},
          {"comparison", comparison}, {"detail", detail}};
}

// Half of the spacing of half floats at |v| (subnormals: 2^-24).
double half_ulp(double v) {
  const double a = std::abs(v);
  if (a < std::ldexp(1.0, -14)) return std::ldexp(1.0, -25);
  return std::ldexp(1.0, std::ilogb(a) - 11);
}

void check_cancel(const ValidationOptions& o) {
  if (o.cancel && o.cancel->load()) throw BakeCancelled();
}

}  // namespace

namespace detail::validation {

// Texel indices to recompute along an axis of n texels: all, or k evenly spread including both ends.
std::vector<int> texel_spread(int n, int k) {
  std::vector<int> out;
  if (k >= n) {
    for (int i = 0; i < n; ++i) out.push_back(i);
    return out;
  }
  for (int i = 0; i < k; ++i) out.push_back(static_cast<int>(std::lround(static_cast<double>(i) * (n - 1) / (k - 1))));
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace detail::validation

json validate_engine_texture(const std::filesystem::path& file, const ValidationOptions& opt) {
  const EngineImage img = read_engine_texture(file);
  const json& d = img.description;
  std::string preset, name;
  try {
    preset = d.at("preset").get<std::string>();
    name = d.at("texture").get<std::string>();
  } catch (const nlohmann::json::exception&) {
    throw DomainError(file.string() + ": header hairlut.engine names no preset or texture");
  }
  EngineConfig ec;
  ec.preset = preset;
  ec.textures = {name};
  const std::vector<EngineTexture> defs = engine_preset_textures(ec);  // throws DomainError for unknown names
  const EngineTexture& t = defs.at(0);
  const EngineTableSpec* spec = nullptr;
  const std::vector<EngineTableSpec> specs = engine_preset_tables(ec, true);
  for (const EngineTableSpec& s : specs)
    if (s.group == t.group) spec = &s;
  if (!spec) throw DomainError(file.string() + ": no table group " + t.group + " in preset " + preset);

  std::vector<json> checks;
  // Layout: the header against the preset's definition of the texture.
  json expected = t.describe();
  json got = json::object();
  for (const auto& [k, v] : expected.items())
    if (d.contains(k)) got[k] = d.at(k);
  const bool layout_ok = nlohmann::json(got) == nlohmann::json(expected);  // key order aside
  checks.push_back(check("engine_layout", "header describes the preset's texture (format, channels, tiles, flip)", layout_ok,
                         layout_ok ? 0 : 1, 0, "==", layout_ok ? t.engine_format : "header " + got.dump() + " differs from " + expected.dump()));
  const int Z = spec->axes[0].count, Y = spec->axes[1].count, X = spec->axes[2].count;
  const int rows = (Z + t.tiles_per_row - 1) / t.tiles_per_row;
  const int W = X * std::min(Z, t.tiles_per_row), H = Y * rows;
  const bool size_ok = img.width == W && img.height == H && img.channel_count == t.channel_count;
  checks.push_back(check("engine_size", "image size and channel count", size_ok, json::array({img.width, img.height, img.channel_count}),
                         json::array({W, H, t.channel_count}), "==",
                         std::to_string(X) + " x " + std::to_string(Y) + " x " + std::to_string(Z) + " texels, " + std::to_string(t.tiles_per_row) +
                             " tiles per row"));
  bool axes_ok = d.contains("axes");
  if (axes_ok) {
    const json& a = d.at("axes");
    auto same = [&](const char* k, const GridAxis& g) { return a.contains(k) && nlohmann::json(a.at(k)) == nlohmann::json(g.to_json()); };
    axes_ok = same("X", spec->axes[2]) && same("Y", spec->axes[1]) && same("Z", spec->axes[0]);
  }
  checks.push_back(check("engine_axes", "axes (names, ranges, spacing, texel placement) are the preset's", axes_ok, axes_ok ? 0 : 1, 0, "==",
                         spec->axes[2].name + ", " + spec->axes[1].name + ", " + spec->axes[0].name));
  json report;
  report["source"] = file.string();
  report["validator"] = "validate-hair-luts (engine texture)";
  report["texture"] = d;
  if (!size_ok) {  // texel positions are meaningless on a wrong-sized image
    report["summary"] = {{"status", "fail"}, {"passed", 0}, {"failed", 1}, {"skipped", 0}};
    report["checks"] = checks;
    return report;
  }
  auto texel = [&](int x, int y, int z, int c) { return static_cast<double>(img.texel(t, X, Y, x, y, z, c)); };

  // Constant channels.
  double worst_const = 0.0;
  for (int c = 0; c < t.channel_count; ++c) {
    if (!t.channels[c].table.empty()) continue;
    for (int z = 0; z < Z; ++z)
      for (int y = 0; y < Y; ++y)
        for (int x = 0; x < X; ++x) worst_const = std::max(worst_const, std::abs(texel(x, y, z, c) - t.channels[c].constant));
  }
  checks.push_back(check("engine_constants", "constant channels hold their constant at every texel", worst_const == 0.0, worst_const, 0, "==",
                         "max |texel - constant|"));

  // Values recomputed from the definition: |texel − v| ≤ ½ ulp_half(v) + (2^-24 + tol)|v| (+ abs_tol).
  struct Worst {
    double ratio = 0.0;
    std::string where;
    long count = 0;
  } w;
  auto compare = [&](int x, int y, int z, int c, double v, double tol, double abs_tol) {
    const double allowed = half_ulp(v) + (std::ldexp(1.0, -24) + tol) * std::abs(v) + abs_tol;
    const double r = std::abs(texel(x, y, z, c) - v) / allowed;
    ++w.count;
    if (r > w.ratio) {
      w.ratio = r;
      w.where = "texel (" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) + ") channel " + std::string(1, "RGBA"[c]) +
                ": " + std::to_string(texel(x, y, z, c)) + " vs " + std::to_string(v);
    }
  };
  const std::size_t budget = std::max<std::size_t>(opt.max_points / 8, 8);
  const int per_axis = std::max(2, static_cast<int>(std::cbrt(static_cast<double>(budget))));
  const EnginePresetReport* preset_report = nullptr;
  for (const EnginePresetReport* r : engine_preset_reports())  // lib/presets/
    if (r->name() == preset) preset_report = r;
  if (!preset_report) throw DomainError(file.string() + ": preset " + preset + " has no definition of its texels to check");
  check_cancel(opt);
  const std::string definition = preset_report->recompute(t, *spec, per_axis, opt, compare);
  checks.push_back(check("engine_values", "texels against their definition (half rounding allowed)", w.ratio <= 1.0, w.ratio, 1.0, "<=",
                         definition + "; " + std::to_string(w.count) + " values; worst " + w.where));
  int passed = 0, failed = 0;
  for (const json& c : checks) (c["status"] == "pass" ? passed : failed)++;
  report["summary"] = {{"status", failed == 0 ? "pass" : "fail"}, {"passed", passed}, {"failed", failed}, {"skipped", 0}};
  report["checks"] = checks;
  return report;
}

std::string render_engine_report_markdown(const json& r) {
  std::ostringstream o;
  const json& s = r["summary"];
  o << "# hairlut validation report (engine texture)\n\n";
  o << "**" << s["status"].get<std::string>() << "**: " << s["passed"] << " passed, " << s["failed"] << " failed\n\n";
  o << "Source: `" << r["source"].get<std::string>() << "`  \n";
  if (r.contains("texture")) o << "Texture: " << r["texture"].value("preset", std::string("?")) << " / " << r["texture"].value("texture", std::string("?")) << "\n\n";
  o << "| check | status | value | threshold | detail |\n|---|---|---|---|---|\n";
  for (const json& c : r["checks"])
    o << "| " << c["id"].get<std::string>() << " | " << c["status"].get<std::string>() << " | " << c["value"].dump() << " | "
      << c["comparison"].get<std::string>() << ' ' << c["threshold"].dump() << " | " << c["detail"].get<std::string>() << " |\n";
  return o.str();
}

void write_engine_report(const json& r, const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const std::string md = render_engine_report_markdown(r);
  std::string body = "<pre>";
  for (char c : md) body += c == '<' ? std::string("&lt;") : c == '>' ? std::string("&gt;") : c == '&' ? std::string("&amp;") : std::string(1, c);
  body += "</pre>";
  const std::pair<const char*, std::string> files[] = {
      {"report.json", r.dump(2) + "\n"}, {"report.md", md}, {"report.html", html_page("hairlut validation: " + r["source"].get<std::string>(), body)}};
  for (const auto& [name, text] : files) {
    const std::filesystem::path p = dir / name;
    std::ofstream f(p, std::ios::binary | std::ios::trunc);
    f << text;
    if (!f) throw IoError(p.string() + ": cannot write");
  }
}

}  // namespace hairlut
