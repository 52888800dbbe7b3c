// Model "kajiya1989": Kajiya and Kay 1989 in the factored form of the hair-shading survey
// (physics/kajiya_kay.hpp), M_KK = K_d + k_s cos^n(θr + θi)/cos θi with N_KK = 1, tabulated over
// (β, θi, θr) with n = 1/(4β²) (KajiyaKayParams::exponent_for_width): the lobe an engine that
// still shades with Kajiya–Kay reads, on the same axes and in the same files as the other models'
// M_p. It has no azimuthal structure, so it bakes no N_p tables, and it is not energy conserving.
#include <chrono>
#include <cmath>

#include "bake/bake_internal.hpp"
#include "hairlut/bake/model_kind.hpp"
#include "hairlut/bake/table_truth.hpp"
#include "hairlut/physics/hair_model.hpp"
#include "hairlut/physics/kajiya_kay.hpp"
#include "hairlut/tables/table_sampling.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/util/version.hpp"

namespace hairlut::models::kajiya1989 {
extern const char* const schema_json;  // schema.json, embedded by the build

namespace {

using json = nlohmann::ordered_json;

struct Settings final : ModelSettings {
  double kd = 0.0, ks = 1.0;
  nlohmann::json json() const override { return {{"kd", kd}, {"ks", ks}}; }
};

const Settings& settings_of(const BakeConfig& c) {
  const auto* s = dynamic_cast<const Settings*>(c.model_settings.get());
  if (!s) throw DomainError("model kajiya1989: the config has no kajiya_kay settings (not read by parse_config?)");
  return *s;
}

KajiyaKayParams params_at(const Settings& s, double beta) {
  KajiyaKayParams p;
  p.kd = s.kd;
  p.ks = s.ks;
  p.exponent = KajiyaKayParams::exponent_for_width(beta);
  return p;
}

TableSet bake_tables(const BakeConfig& c, const Settings& s, const BakeOptions& opt, BakeReport* report_out) {
  const auto t0 = std::chrono::steady_clock::now();
  BakeReport report;
  TableSet set;
  const Precision precision = c.output.hdf5_double ? Precision::float64 : Precision::float32;
  report.explicit_lobes = 1;
  detail::open_set_description(
      c,
      "Kajiya and Kay 1989 in the survey's factored form with hairlut's angles (docs/conventions.md): S = M_KK N_KK with "
      "M_KK = K_d + k_s max(0, cos(theta_r + theta_i))^n / cos(theta_i), n = 1/(4 beta^2), N_KK = 1; energy measure cos^2(theta_r) dtheta_r dphi",
      set);
  set.metadata["lobes"] = json::array({"R"});
  set.metadata["residual"] = false;
  set.metadata["folded_lobes"] = json::array();
  set.metadata["quadrature"] = {{"method", "closed form (no quadrature)"}};
  set.metadata["kajiya_kay"] = s.json();
  detail::close_set_description(c, precision, set);

  if (c.mp_axes) {
    const std::vector<double> betas = detail::axis_named(*c.mp_axes, "beta").nodes();
    const std::vector<double> tis = detail::axis_named(*c.mp_axes, "theta_i").nodes(), trs = detail::axis_named(*c.mp_axes, "theta_r").nodes();
    Table t = detail::make_table("mp", "R", "M_p", "1/rad",
                                 "Kajiya-Kay longitudinal function K_d + k_s cos^n(theta_r + theta_i)/cos(theta_i), n = 1/(4 beta^2)", *c.mp_axes,
                                 precision);
    t.attributes = {{"lobe", "R"}, {"p", 0}, {"model", "kajiya1989"}, {"function", "kajiya_kay"}, {"kd", s.kd}, {"ks", s.ks}};
    set.tables.push_back(std::move(t));
    Table& table = set.tables.back();
    const std::size_t ni = tis.size(), nr = trs.size();
    detail::parallel_for(betas.size() * ni, opt, "M_KK", nr, [&](std::size_t k) {
      const std::size_t ib = k / ni, ii = k % ni;
      const KajiyaKayParams p = params_at(s, betas[ib]);
      for (std::size_t ir = 0; ir < nr; ++ir) table.set(k * nr + ir, kajiya_kay_longitudinal(p, tis[ii], trs[ir]));
    });
    report.entries += betas.size() * ni * nr;
  }
  return detail::finish_model_bake(c, opt, t0, precision, std::move(set), report, report_out);
}

class Model final : public ModelKind {
 public:
  std::string_view name() const override { return "kajiya1989"; }
  std::string_view short_name() const override { return "kajiya-kay"; }
  std::string_view schema() const override { return schema_json; }

  // One lobe, no residual, tilts, fold_below, quadrature, N_p, scene, dual scattering or presets:
  // the schema's rules of this model (its allOf).
  std::vector<std::string> default_lobes() const override { return {"R"}; }
  bool has_residual() const override { return false; }
  std::shared_ptr<const ModelSettings> parse(const nlohmann::json& doc, const BakeConfig&) const override {
    const nlohmann::json k = doc.value("kajiya_kay", nlohmann::json::object());
    auto s = std::make_shared<Settings>();
    s->kd = k.value("kd", 0.0);  // [0, 1] and [0, 100]: the schema's bounds
    s->ks = k.value("ks", 1.0);
    return s;
  }
  void normalize(const BakeConfig& c, nlohmann::json& n) const override {
    n["lobes"] = {{"explicit", {"R"}}, {"residual", false}};
    n["kajiya_kay"] = settings_of(c).json();
  }
  // The specular term divides by cos θi, so the table's θi range (where the validator looks, and
  // the sampler interpolates) stays off the poles; beyond it the sampler holds the end values.
  void check(const BakeConfig& c) const override {
    if (!c.mp_axes) return;
    const GridAxis& ti = detail::axis_named(*c.mp_axes, "theta_i");
    if (!(std::abs(ti.lo) < kHalfPi - 1e-9 && std::abs(ti.hi) < kHalfPi - 1e-9))
      config_error("tables.mp.axes.theta_i", "must lie inside (-90, 90) degrees for model kajiya1989 (M_KK diverges at grazing incidence "
                                             "as 1/cos theta_i), for example range_deg [-85, 85]");
  }
  std::vector<GridAxis> np_axes(const nlohmann::json&, const std::string& path, const SharedNpAxes&, const BakeConfig&) const override {
    config_error(path.substr(0, path.find('.', path.find('.') + 1)), "model kajiya1989 has no N_p tables");  // the schema refuses it first
  }
  std::string mp_beta_meaning() const override { return "width beta of the specular lobe: exponent n = 1/(4 beta^2)"; }
  void material_roughness(const nlohmann::json&, const std::string& path, const BakeConfig&, MaterialConfig&) const override {
    config_error(path, "model kajiya1989 has no per-material tables");  // the schema refuses a scene first
  }

  bool slab_by_slab() const override { return false; }
  std::vector<PlannedTable> own_np_tables(const BakeConfig&) const override { return {}; }
  TableSet bake(const BakeConfig& c, const BakeOptions& opt, BakeReport* report, SlabbedTables*) const override {
    return bake_tables(c, settings_of(c), opt, report);
  }

  std::shared_ptr<const ModelSettings> from_metadata(const nlohmann::json& metadata, double, AbsorptionPath) const override {
    if (!metadata.contains("kajiya_kay")) throw DomainError("table metadata: model kajiya1989 without its \"kajiya_kay\" settings");
    auto s = std::make_shared<Settings>();
    try {
      s->kd = metadata.at("kajiya_kay").at("kd").get<double>();
      s->ks = metadata.at("kajiya_kay").at("ks").get<double>();
    } catch (const nlohmann::json::exception& e) {
      throw DomainError(std::string("table metadata: kajiya_kay settings malformed (") + e.what() + ")");
    }
    if (!(s->kd >= 0.0 && s->kd <= 1.0)) throw DomainError("table metadata: kajiya_kay.kd must lie in [0, 1]");
    if (!(s->ks >= 0.0 && s->ks <= 100.0)) throw DomainError("table metadata: kajiya_kay.ks must lie in [0, 100]");
    return s;
  }
  // M_KK itself at the point (one pow and one cos: the search may sweep whole cells).
  std::optional<TableTruth> truth(const Table& t, const ModelSettings& base) const override {
    if (t.attributes.value("function", std::string()) != "kajiya_kay" || t.axes.size() != 3 || t.axes[0].name != "beta") return std::nullopt;
    const Settings s = dynamic_cast<const Settings&>(base);
    TableTruth tr = with_mp_denominator({}, 2);
    tr.sweep_cells = true;
    tr.make = [s](const std::vector<double>&) {
      return PointFunction([s](const std::vector<double>& y) { return kajiya_kay_longitudinal(params_at(s, y[0]), y[1], y[2]); });
    };
    tr.features = [](const std::vector<double>& y) { return std::vector<double>{-y[1]}; };  // the mirror cone
    return tr;
  }
};

}  // namespace

const ModelKind& model_kind() {
  static const Model model;
  return model;
}

}  // namespace hairlut::models::kajiya1989
