// The melanin tables: absorption σa over (eumelanin, pheomelanin, channel) by d'Eon 2011's RGB
// cross-sections, and the linear sRGB transmittance of the Donner–Jensen 2006 spectra
// (physics/melanin.hpp). The config's `tables.melanin` (schema.json), its size, its baker and the
// reference the validator judges both tables by.
#include <algorithm>
#include <cmath>

#include "hairlut/bake/bake.hpp"
#include "hairlut/bake/table_kind.hpp"
#include "hairlut/bake/table_truth.hpp"
#include "hairlut/physics/melanin.hpp"

namespace hairlut::kinds::melanin {
extern const char* const schema_json;  // schema.json, embedded by the build

namespace {

struct Settings final : TableKindSettings {
  std::vector<GridAxis> axes;  // eumelanin, pheomelanin
  double path_length = 2.0;
};

const std::vector<std::string> kDims = {"eumelanin", "pheomelanin", "channel"};
constexpr double kSigmaFloor = 1e-2;  // absolute floor of σa (1/radius): exp(−2·0.01) ≈ 0.98 per diameter

// The table's value at y = (eumelanin, pheomelanin, channel) from an RGB function of the two
// concentrations.
template <class F>
PointFunction per_channel(F rgb) {
  return [rgb](const std::vector<double>& y) {
    const Rgb s = rgb(y[0], y[1]);
    const double c[3] = {s.r, s.g, s.b};
    return c[std::clamp<long>(std::lround(y[2]), 0, 2)];
  };
}

std::shared_ptr<const SpectralMelanin> spectral_model(const Table& t) {
  SpectralMelanin::Options so;
  so.path_length = t.attributes.value("path_length", 2.0);
  so.spectral_scale = t.attributes.value("spectral_scale", 0.0);
  return std::make_shared<SpectralMelanin>(SpectralMelanin::builtin(so));
}

class Kind final : public TableKind {
 public:
  std::string_view name() const override { return "melanin"; }
  std::string_view schema() const override { return schema_json; }

  std::shared_ptr<const TableKindSettings> parse(const nlohmann::json& m) const override {
    auto s = std::make_shared<Settings>();
    const std::string p = "tables.melanin.axes.";
    s->axes = {config_value_axis(m.at("axes").at("eumelanin"), p + "eumelanin", "eumelanin", 0.0, 100.0, "1",
                                 "eumelanin concentration (d'Eon 2011 / pbrt units)"),
               config_value_axis(m.at("axes").at("pheomelanin"), p + "pheomelanin", "pheomelanin", 0.0, 100.0, "1",
                                 "pheomelanin concentration (d'Eon 2011 / pbrt units)")};
    // [0.001, 1000] by the schema: outside it the spectral fit's cross sections overflow (a file
    // its loader refuses) or every transmittance rounds to 0 or 1.
    s->path_length = m.value("path_length", 2.0);
    return s;
  }

  nlohmann::json normalized(const TableKindSettings& base) const override {
    const auto& s = static_cast<const Settings&>(base);
    return {{"axes", config_axes_json(s.axes)}, {"path_length", s.path_length}};
  }

  std::vector<TableKindSize> sizes(const TableKindSettings& base) const override {
    const auto& s = static_cast<const Settings&>(base);
    return {{3u * static_cast<std::uint64_t>(s.axes[0].count) * static_cast<std::uint64_t>(s.axes[1].count), 2}};
  }

  void bake(const TableKindSettings& base, Precision precision, TableSet& set, BakeReport& report) const override {
    const auto& s = static_cast<const Settings&>(base);
    std::vector<GridAxis> axes = s.axes;
    axes.push_back(channel_axis({"R", "G", "B"}, "colour channel (linear sRGB primaries)"));
    const std::vector<double> ce = axes[0].nodes(), cp = axes[1].nodes();
    SpectralMelanin::Options so;
    so.path_length = s.path_length;
    const SpectralMelanin spectral = SpectralMelanin::builtin(so);
    const SpectralMelanin::Fit fit = spectral.fit_rgb_cross_sections();
    Table deon = table("sigma_a_deon", "sigma_a", "1/radius", "absorption per unit radius from d'Eon 2011's RGB cross-sections", axes,
                       precision);
    deon.attributes = {{"eumelanin_cross_section", {0.419, 0.697, 1.37}}, {"pheomelanin_cross_section", {0.187, 0.4, 1.05}},
                       {"method", "sigma_a = c_e (0.419, 0.697, 1.37) + c_p (0.187, 0.4, 1.05) (d'Eon 2011 sec. 6.1)"}};
    // The spectral model's colour leaves the sRGB gamut for dark hair (blue T_c ≤ 0), where no RGB
    // absorption reproduces it and −ln T_c has no value: the table stores the transmittance itself,
    // which stays smooth across the gamut boundary, and says how a renderer takes σa from it.
    Table spec = table("transmittance_spectral", "transmittance", "1",
                       "linear sRGB transmittance over path_length radii from the Donner-Jensen 2006 spectra, CIE 1931 2 deg and D65", axes,
                       precision);
    spec.attributes = {{"path_length", s.path_length},
                       {"spectral_scale", spectral.options().spectral_scale},
                       {"fitted_eumelanin_cross_section", {fit.eumelanin.r, fit.eumelanin.g, fit.eumelanin.b}},
                       {"fitted_pheomelanin_cross_section", {fit.pheomelanin.r, fit.pheomelanin.g, fit.pheomelanin.b}},
                       {"fit_rms_relative_error", fit.rms_relative_error},
                       {"method", "T_c = linear sRGB (IEC 61966-2-1, white-balanced to D65) of D65 light through exp(-sigma_a(lambda) L), "
                                  "380-780 nm in 5 nm steps"},
                       {"out_of_gamut", "T_c <= 0 where the transmitted colour lies outside the sRGB gamut (dark hair's blue); "
                                        "a renderer takes sigma_a_c = -ln(max(T_c, 1e-30)) / path_length"}};
    for (std::size_t i = 0; i < ce.size(); ++i)
      for (std::size_t j = 0; j < cp.size(); ++j) {
        const Rgb a = melanin_sigma_a_rgb(ce[i], cp[j]);
        const Rgb b = spectral.transmittance_unclamped(ce[i], cp[j], s.path_length);
        const std::size_t o = (i * cp.size() + j) * 3;
        deon.set(o, a.r), deon.set(o + 1, a.g), deon.set(o + 2, a.b);
        spec.set(o, b.r), spec.set(o + 1, b.g), spec.set(o + 2, b.b);
      }
    set.tables.push_back(std::move(deon));
    set.tables.push_back(std::move(spec));
    report.entries += 2 * ce.size() * cp.size() * 3;
  }

  Threshold threshold() const override {
    return {"accuracy_melanin_max_rel", 1e-2, "max relative error of the melanin sigma_a tables at random points (floor 0.01 per radius)"};
  }

  std::optional<TableTruth> truth(const Table& t) const override {
    if (t.group != "melanin") return std::nullopt;
    std::vector<std::string> dims;
    for (const GridAxis& a : t.axes) dims.push_back(a.name);
    if (dims != kDims) return std::nullopt;
    TableTruth tr;
    if (t.quantity == "sigma_a") {
      tr.absolute_floor = kSigmaFloor;
      tr.denominator = "the exact sigma_a itself (relative error), floored at 0.01 per radius";
      if (t.name == "sigma_a_deon") {
        tr.make = [](const std::vector<double>&) { return per_channel(melanin_sigma_a_rgb); };
      } else {
        tr.make = [model = spectral_model(t)](const std::vector<double>&) {
          return per_channel([model](double ce, double cp) { return model->sigma_a_rgb(ce, cp); });
        };
      }
      return tr;
    }
    if (t.quantity == "transmittance") {
      tr.absolute_floor = 1e-3;
      tr.denominator = "the exact transmittance itself (relative error), floored at 1e-3 (darker than 1e-3 over the path reads as black)";
      const double length = t.attributes.value("path_length", 2.0);
      tr.make = [model = spectral_model(t), length](const std::vector<double>&) {
        return per_channel([model, length](double ce, double cp) { return model->transmittance_unclamped(ce, cp, length); });
      };
      return tr;
    }
    return std::nullopt;
  }

 private:
  static Table table(std::string name, std::string quantity, std::string units, std::string long_name, std::vector<GridAxis> axes,
                     Precision precision) {
    Table t;
    t.group = "melanin";
    t.name = std::move(name);
    t.quantity = std::move(quantity);
    t.units = std::move(units);
    t.long_name = std::move(long_name);
    t.axes = std::move(axes);
    t.allocate(precision);
    return t;
  }
};

}  // namespace

const TableKind& table_kind() {
  static const Kind kind;
  return kind;
}

}  // namespace hairlut::kinds::melanin
