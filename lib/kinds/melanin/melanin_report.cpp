// The validator's section of the melanin tables: their accuracy check (against melanin_bake.cpp's
// references) and colour swatches of the light through one fiber per concentration.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "hairlut/report/svg_plot.hpp"
#include "hairlut/report/table_kind_report.hpp"

namespace hairlut::kinds::melanin {
namespace {

using json = nlohmann::ordered_json;

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::string triple(const json& j) {
  std::string s = "(";
  for (std::size_t i = 0; i < j.size(); ++i) s += (i ? ", " : "") + fmt(j[i].get<double>());
  return s + ")";
}

class Report final : public TableKindReport {
 public:
  std::string_view name() const override { return "melanin"; }
  bool owns(const Table& t) const override { return t.group == "melanin" && (t.quantity == "sigma_a" || t.quantity == "transmittance"); }
  std::string_view accuracy_check() const override { return "accuracy_melanin_max_rel"; }
  std::string_view accuracy_title() const override {
    return "Melanin tables (sigma_a, spectral transmittance): worst relative error found (random points, then the search)";
  }

  // The colour of light through one fiber diameter per concentration: exp(−2 σa), or the
  // tabulated transmittance over its path (2 radii by default) clamped to [0, 1] out of gamut.
  json section(const TableSet& set) const override {
    json swatches = json::array();
    for (const char* path : {"melanin/sigma_a_deon", "melanin/transmittance_spectral"}) {
      const Table* m = set.find(path);
      if (!m || m->axes.size() != 3) continue;
      const auto ce = m->axes[0].nodes(), cp = m->axes[1].nodes();
      const bool transmittance = m->quantity == "transmittance";
      auto colour = [&](std::size_t o) { return transmittance ? std::clamp(m->get(o), 0.0, 1.0) : std::exp(-2.0 * m->get(o)); };
      json rows = json::array();
      for (std::size_t i = 0; i < ce.size(); ++i)
        for (std::size_t j = 0; j < cp.size(); ++j) {
          const std::size_t o = (i * cp.size() + j) * 3;
          rows.push_back({{"eumelanin", ce[i]}, {"pheomelanin", cp[j]}, {"rgb", {colour(o), colour(o + 1), colour(o + 2)}}});
        }
      swatches.push_back({{"table", path}, {"swatches", rows}, {"attributes", m->attributes}});
    }
    return swatches.empty() ? json() : swatches;
  }

  std::string html(const json& section) const override {
    std::string o;
    for (const json& mel : section) {
      std::vector<svg::Swatch> sw;
      std::vector<std::string> rows, cols;
      double last_e = -1;
      for (const json& x : mel["swatches"]) {
        const double ce = x["eumelanin"].get<double>(), cp = x["pheomelanin"].get<double>();
        const json& rgb = x["rgb"];
        sw.push_back({rgb[0].get<double>(), rgb[1].get<double>(), rgb[2].get<double>(), "eumelanin " + fmt(ce) + ", pheomelanin " + fmt(cp)});
        if (ce != last_e) rows.push_back(fmt(ce)), last_e = ce;
        if (rows.size() == 1) cols.push_back(fmt(cp));
      }
      const std::string table = mel["table"].get<std::string>();
      o += "<h2>Melanin: fiber colour (" + svg::escape(table) +
           ")</h2><p>Transmittance through one fiber diameter, exp(&minus;2 &sigma;<sub>a</sub>), per concentration.";
      const json& a = mel["attributes"];
      if (a.contains("fitted_eumelanin_cross_section"))
        o += " Fitted RGB cross-sections: eumelanin " + triple(a["fitted_eumelanin_cross_section"]) + ", pheomelanin " +
             triple(a["fitted_pheomelanin_cross_section"]) + " (d'Eon: (0.419, 0.697, 1.37), (0.187, 0.4, 1.05)).";
      o += "</p>\n" + svg::swatch_grid(table, sw, static_cast<int>(cols.size()), rows, cols, "eumelanin", "pheomelanin") + "\n";
    }
    return o;
  }
};

}  // namespace

const TableKindReport& report() {
  static const Report r;
  return r;
}

}  // namespace hairlut::kinds::melanin
