// Model "marschner2003": Marschner et al. 2003's N_R, N_TT, N_TRT (smooth fiber, exact or cubic
// paths, caustic replacement, eccentricity) and Gaussian M_p tables, in the same layout
// conventions as the d'Eon tables: its config keys (the "marschner" settings, N_p over σa, θd, an
// eccentric TRT's φh and φ, Table 1's roughness per material), its baker and its tables' references.
//
// Exact and approximate: every N_p value is eq. 8 / §5.2.2 evaluated at the node (roots to
// rounding, no quadrature); lobe energies are adaptive Gauss–Kronrod integrals in γ to 1e−11.
// The M_p values are the closed-form Gaussians.
#include <chrono>
#include <cmath>

#include "bake/bake_internal.hpp"
#include "hairlut/bake/model_kind.hpp"
#include "hairlut/bake/table_truth.hpp"
#include "hairlut/tables/table_sampling.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/physics/hair_model.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"
#include "hairlut/physics/marschner.hpp"
#include "hairlut/util/version.hpp"

namespace hairlut::models::marschner2003 {
extern const char* const schema_json;  // schema.json, embedded by the build

namespace {

using json = nlohmann::ordered_json;
using detail::axis_named;
using detail::make_table;
using detail::parallel_for;

std::string argument_name(GaussianArgument a) { return a == GaussianArgument::theta_h ? "theta-h" : "2theta-h"; }

// Table attributes of Marschner's M_p of lobe p with Gaussian width ratio·β (or β itself).
json mp_attributes(const MarschnerConfig& m, int p, const MarschnerLobes& lobes, bool per_material) {
  json a = {{"lobe", lobe_name(p)}, {"p", p}, {"model", "marschner2003"}, {"function", "gaussian"},
            {"argument", argument_name(m.argument)}, {"alpha_theta_h", lobes.alpha[p]}};
  if (per_material) a["beta"] = lobes.beta[p];
  else a["beta_ratio"] = lobes.beta[p] / lobes.beta[0];
  return a;
}

// The N_p tables of one σa list (generic axis or a material's RGB) over θd (, φh), φ, plus the lobe
// energies; writes through index(p, k, t, h, j) and energy_index(p, k, t, h).
struct NpTarget {
  std::vector<std::size_t> np, energy;  // table index per lobe
};

void bake_np(const MarschnerParams& params, const std::vector<double>& sigmas, const std::vector<double>& thetas, const std::vector<double>& phi_hs,
             const std::vector<double>& phis, int lobes, const NpTarget& target, const BakeOptions& opt, const std::string& stage, TableSet& set) {
  const std::size_t ns = sigmas.size(), nt = thetas.size(), nh = phi_hs.size(), nphi = phis.size();
  // One work item per (θd, φh); R and TT do not depend on φh and are baked in the items with h = 0.
  parallel_for(nt * nh, opt, stage, ns * nphi * static_cast<std::size_t>(lobes), [&](std::size_t item) {
    const std::size_t t = item / nh, h = item % nh;
    const MarschnerAzimuthal az(params, thetas[t], phi_hs[h]);
    std::vector<double> row(ns), e(ns);
    for (int p = 0; p < lobes; ++p) {
      const bool trt = p == 2;
      if (!trt && h != 0) continue;
      Table& np = set.tables[target.np[static_cast<std::size_t>(p)]];
      Table& en = set.tables[target.energy[static_cast<std::size_t>(p)]];
      const std::size_t hh = trt ? h : 0, nhh = trt ? nh : 1;
      for (std::size_t j = 0; j < nphi; ++j) {
        az.np(p, sigmas, phis[j], row);
        for (std::size_t k = 0; k < ns; ++k) np.set(((k * nt + t) * nhh + hh) * nphi + j, row[k]);
      }
      az.energy(p, sigmas, e);
      for (std::size_t k = 0; k < ns; ++k) en.set((k * nt + t) * nhh + hh, e[k]);
    }
  });
}

TableSet bake_tables(const BakeConfig& c, const MarschnerConfig& m, const BakeOptions& opt, BakeReport* report_out) {
  const auto t0 = std::chrono::steady_clock::now();
  BakeReport report;
  TableSet set;
  const Precision precision = c.output.hdf5_double ? Precision::float64 : Precision::float32;
  const bool per_material = c.scene && c.scene->mode == SceneConfig::Mode::per_material;
  const int lobes = c.lobe_count;
  report.explicit_lobes = lobes;

  detail::open_set_description(
      c,
      "Marschner et al. 2003 with hairlut's angles (docs/conventions.md): S = sum_p M_p N_p with M_p = g(beta_p; theta_h - alpha_p)/cos^2(theta_d) "
      "(alpha shifts theta_h, Marschner's Table 1 sign), energy measure cos^2(theta_r) dtheta_r dphi; N_p = sum over paths A(p,h)/|2 dPhi/dh| with "
      "Phi(p,h) = 2p gamma_t - 2 gamma_i + p pi, A with the Bravais eta', eta'' Fresnel factors; TRT with the caustic replacement of sec. 5.2.2 "
      "and eta*(phi_h) of sec. 5.2.3; sigma_a per unit fiber radius",
      set);
  set.metadata["lobes"] = json::array();
  for (int p = 0; p < lobes; ++p) set.metadata["lobes"].push_back(lobe_name(p));
  set.metadata["residual"] = false;
  set.metadata["folded_lobes"] = json::array();
  set.metadata["quadrature"] = {{"method", "smooth-fiber paths (no quadrature)"},
                                {"roots", to_string(m.params.roots)},
                                {"energy_method", "adaptive gauss-kronrod in gamma, rel 1e-11"}};
  set.metadata["marschner"] = marschner_json(m);
  detail::close_set_description(c, precision, set);

  const bool eccentric = m.params.eccentricity != 1.0;
  // ---- N_p and lobe energies.
  if (c.np_axes) {
    std::vector<GridAxis> np_axes = restricted_np_axes(c, &report.notes);
    const GridAxis theta_axis = axis_named(np_axes, "theta_d"), phi_axis = axis_named(np_axes, "phi");
    std::vector<double> phi_hs = {0.0};
    std::vector<GridAxis> h_axes;  // the φh axis of an eccentric TRT, if any
    if (eccentric) {
      h_axes.push_back(axis_named(np_axes, "phi_h"));
      phi_hs = h_axes.front().nodes();
    }
    auto axes_for = [&](int p, std::vector<GridAxis> lead, bool with_phi) {
      lead.push_back(theta_axis);
      if (p == 2) lead.insert(lead.end(), h_axes.begin(), h_axes.end());
      if (with_phi) lead.push_back(phi_axis);
      return lead;
    };
    auto add_np_tables = [&](const std::string& group, const std::string& prefix, const GridAxis& lead, const json& extra) {
      NpTarget target;
      for (int p = 0; p < lobes; ++p) {
        Table t = make_table(group, prefix + lobe_name(p), "N_p", "1/rad",
                             "Marschner 2003 azimuthal scattering function N_p of lobe " + lobe_name(p) +
                                 (p == 2 ? " (caustic replacement" + std::string(eccentric ? ", eta*(phi_h))" : ")") : ""),
                             axes_for(p, {lead}, true), precision);
        t.attributes = {{"lobe", lobe_name(p)}, {"p", p}, {"model", "marschner2003"}};
        t.attributes.update(extra);
        target.np.push_back(set.tables.size());
        set.tables.push_back(std::move(t));
      }
      for (int p = 0; p < lobes; ++p) {
        Table t = make_table(group, "energy_" + lobe_name(p), "energy", "1",
                             "energy int N_p dphi of Marschner's lobe " + lobe_name(p), axes_for(p, {lead}, false), precision);
        t.attributes = {{"lobe", lobe_name(p)}, {"p", p}, {"model", "marschner2003"}};
        t.attributes.update(extra);
        target.energy.push_back(set.tables.size());
        set.tables.push_back(std::move(t));
      }
      return target;
    };
    const std::vector<double> thetas = theta_axis.nodes(), phis = phi_axis.nodes();
    if (!per_material) {
      const GridAxis sigma_axis = axis_named(np_axes, "sigma_a");
      const NpTarget target = add_np_tables("np", "", sigma_axis, json::object());
      bake_np(m.params, sigma_axis.nodes(), thetas, phi_hs, phis, lobes, target, opt, "N_p", set);
      report.entries += sigma_axis.nodes().size() * thetas.size() * (phis.size() + 1) * static_cast<std::size_t>(lobes);
    } else {
      const GridAxis channel = channel_axis({"R", "G", "B"}, "colour channel (linear sRGB primaries)");
      for (const MaterialConfig& mat : c.scene->materials) {
        const NpTarget target = add_np_tables("materials/" + mat.name, "np_", channel, {{"material", mat.name}, {"sigma_a", mat.sigma_a}});
        const std::vector<double> sigmas(mat.sigma_a.begin(), mat.sigma_a.end());
        bake_np(m.params, sigmas, thetas, phi_hs, phis, lobes, target, opt, "N_p " + mat.name, set);
        report.entries += 3 * thetas.size() * (phis.size() + 1) * static_cast<std::size_t>(lobes);
      }
    }
  }

  // ---- Gaussian M_p: generic over (β_R, θi, θr) per lobe with Table 1's ratios; per material over (θi, θr).
  if (c.mp_axes) {
    const GridAxis ti_axis = axis_named(*c.mp_axes, "theta_i"), tr_axis = axis_named(*c.mp_axes, "theta_r");
    const std::vector<double> tis = ti_axis.nodes(), trs = tr_axis.nodes();
    const std::size_t ni = tis.size(), nr = trs.size();
    auto fill = [&](std::size_t first, const std::vector<MarschnerLobes>& per_beta, const std::string& stage) {
      const std::size_t nb = per_beta.size();
      parallel_for(nb * ni, opt, stage, nr * static_cast<std::size_t>(lobes), [&](std::size_t k) {
        const std::size_t ib = k / ni, ii = k % ni;
        const MarschnerLobes& l = per_beta[ib];
        for (int p = 0; p < lobes; ++p) {
          Table& t = set.tables[first + static_cast<std::size_t>(p)];
          for (std::size_t ir = 0; ir < nr; ++ir)
            t.set((ib * ni + ii) * nr + ir, longitudinal_gaussian(l.beta[p], l.alpha[p], tis[ii], trs[ir], m.argument));
        }
      });
      report.entries += nb * ni * nr * static_cast<std::size_t>(lobes);
    };
    if (!per_material) {
      const std::vector<double> betas = axis_named(*c.mp_axes, "beta").nodes();
      const std::size_t first = set.tables.size();
      const MarschnerLobes unit = m.lobes(1.0);
      for (int p = 0; p < lobes; ++p) {
        Table t = make_table("mp", lobe_name(p), "M_p", "1/rad",
                             "Marschner Gaussian longitudinal function g(beta_p; theta_h - alpha_p)/cos^2(theta_d) of lobe " + lobe_name(p) +
                                 ", beta_p = beta_ratio * beta (beta = beta_R)",
                             *c.mp_axes, precision);
        t.attributes = mp_attributes(m, p, unit, false);
        set.tables.push_back(std::move(t));
      }
      std::vector<MarschnerLobes> per_beta;
      for (double b : betas) per_beta.push_back(m.lobes(b));
      fill(first, per_beta, "M_p");
    } else {
      for (const MaterialConfig& mat : c.scene->materials) {
        MarschnerLobes l = m.lobes(mat.beta_m[0]);
        for (int p = 0; p < lobes; ++p) l.beta[p] = mat.beta_m[static_cast<std::size_t>(p)];
        const std::size_t first = set.tables.size();
        for (int p = 0; p < lobes; ++p) {
          Table t = make_table("materials/" + mat.name, "mp_" + lobe_name(p), "M_p", "1/rad",
                               "Marschner Gaussian M_p of lobe " + lobe_name(p) + " for material " + mat.name, {ti_axis, tr_axis}, precision);
          t.attributes = mp_attributes(m, p, l, true);
          t.attributes["material"] = mat.name;
          set.tables.push_back(std::move(t));
        }
        fill(first, {l}, "M_p " + mat.name);
      }
    }
  }

  return detail::finish_model_bake(c, opt, t0, precision, std::move(set), report, report_out);
}

double number(const nlohmann::json& j, const char* key, double fallback) { return j.contains(key) ? j.at(key).get<double>() : fallback; }

// The settings of the config's "marschner" key.
MarschnerConfig parse_settings(const nlohmann::json& doc, const BakeConfig& c) {
  // At most R, TT and TRT, no residual, tilts, fold_below or quadrature: the schema's rules of model
  // marschner2003 (its allOf), applied before this runs.
  const nlohmann::json mj = doc.value("marschner", nlohmann::json::object());
  MarschnerConfig m;
  m.params.eta = c.eta;
  m.params.path = c.path;
  m.params.roots = parse_marschner_roots(mj.value("roots", std::string("exact")), "marschner.roots");
  const nlohmann::json k = mj.value("caustic", nlohmann::json::object());
  m.params.caustic.k_G = number(k, "k_G", 0.5);
  // At least 0.5 degrees by the schema: a narrower caustic is finer than any table's phi spacing,
  // and the validator's integration over it grows without bound as it narrows (1e-10 degrees:
  // over ten minutes).
  m.params.caustic.w_c = radians(number(k, "w_c_deg", 15.0));
  m.params.caustic.delta_eta_prime = number(k, "delta_eta_prime", 0.3);
  m.params.caustic.delta_h_max = number(k, "delta_h_max", 0.5);
  m.params.eccentricity = number(mj, "eccentricity", 1.0);
  m.params.eccentric_fresnel = parse_eccentric_fresnel(mj.value("eccentric_fresnel", std::string("eta")), "marschner.eccentric_fresnel");
  const nlohmann::json l = mj.value("longitudinal", nlohmann::json::object());
  m.alpha_r = radians(number(l, "alpha_R_deg", -5.0));
  m.argument = l.value("argument", std::string("theta-h")) == "2theta-h" ? GaussianArgument::two_theta_h : GaussianArgument::theta_h;
  try {
    m.params.validate();
  } catch (const DomainError& e) {
    // "<field> <reason>" → "marschner.<field>: <reason>", as the config parser reports a key.
    const std::string what = e.what();
    const auto space = what.find(' ');
    config_error("marschner." + what.substr(0, space), space == std::string::npos ? what : what.substr(space + 1));
  }
  return m;
}

// Marschner 2003 tables: N_p and energies over (σa or channel, θd, [φh,] φ) evaluated directly
// (no quadrature in N_p; the energies by adaptive quadrature), M_p the closed-form Gaussian.
std::optional<TableTruth> marschner_truth(const Table& t, const MarschnerConfig& m) {
  std::vector<std::string> dims;
  for (const GridAxis& a : t.axes) dims.push_back(a.name);
  const int p = t.attributes.value("p", -1);
  if (dims.size() < 2 || p < 0 || p > 2) return std::nullopt;
  if (t.quantity == "M_p" && t.attributes.value("function", std::string()) == "gaussian") {
    const double alpha = t.attributes.value("alpha_theta_h", 0.0);
    const GaussianArgument arg = t.attributes.value("argument", std::string("theta-h")) == "2theta-h" ? GaussianArgument::two_theta_h : GaussianArgument::theta_h;
    if (dims == std::vector<std::string>{"beta", "theta_i", "theta_r"}) {
      const double ratio = t.attributes.value("beta_ratio", 1.0);
      TableTruth tr = with_mp_denominator({}, 2);
      tr.make = [=](const std::vector<double>&) {
        return PointFunction([=](const std::vector<double>& y) { return longitudinal_gaussian(ratio * y[0], alpha, y[1], y[2], arg); });
      };
      return tr;
    }
    if (dims == std::vector<std::string>{"theta_i", "theta_r"}) {
      const double beta = t.attributes.value("beta", 0.1);
      TableTruth tr = with_mp_denominator({}, 1);
      tr.make = [=](const std::vector<double>&) {
        return PointFunction([=](const std::vector<double>& y) { return longitudinal_gaussian(beta, alpha, y[0], y[1], arg); });
      };
      return tr;
    }
    return std::nullopt;
  }
  if (dims[0] != "sigma_a" && dims[0] != "channel") return std::nullopt;
  if (dims[1] != "theta_d") return std::nullopt;
  const bool with_h = dims.size() > 2 && dims[2] == "phi_h";
  std::vector<double> channel_sigmas;
  if (dims[0] == "channel") {
    if (!t.attributes.contains("sigma_a")) return std::nullopt;
    channel_sigmas = t.attributes["sigma_a"].get<std::vector<double>>();
  }
  auto sigma_of = [channel_sigmas](double x) {
    return channel_sigmas.empty() ? x : channel_sigmas[static_cast<std::size_t>(std::clamp<long>(std::lround(x), 0, static_cast<long>(channel_sigmas.size()) - 1))];
  };
  const std::vector<int> slab = with_h ? std::vector<int>{1, 2} : std::vector<int>{1};
  const MarschnerParams params = m.params;
  const bool np = t.quantity == "N_p" && dims.back() == "phi" && dims.size() == (with_h ? 4u : 3u);
  const bool energy = t.quantity == "energy" && dims.size() == (with_h ? 3u : 2u);
  if (!np && !energy) return std::nullopt;
  auto build = [=](bool white) {
    return [=](const std::vector<double>& x) {
      auto az = std::make_shared<MarschnerAzimuthal>(params, x[1], with_h ? x[2] : 0.0);
      return PointFunction([=](const std::vector<double>& y) {
        const double sig = white ? 0.0 : sigma_of(y[0]);
        if (np) return az->np(p, sig, y.back());
        double e = 0.0;
        az->energy(p, std::span<const double>(&sig, 1), std::span<double>(&e, 1));
        return e;
      });
    };
  };
  TableTruth tr;
  tr.slab_axes = slab;
  tr.make = build(false);
  tr.make_white = build(true);
  return np ? with_np_denominator(std::move(tr), static_cast<int>(dims.size()) - 1) : with_energy_denominator(std::move(tr));
}

struct Settings final : ModelSettings {
  MarschnerConfig m;
  nlohmann::json json() const override { return marschner_json(m); }
};

const MarschnerConfig& settings_of(const BakeConfig& c) {
  const auto* s = dynamic_cast<const Settings*>(c.model_settings.get());
  if (!s) throw DomainError("model marschner2003: the config has no marschner settings (not read by parse_config?)");
  return s->m;
}

class Model final : public ModelKind {
 public:
  std::string_view name() const override { return "marschner2003"; }
  std::string_view short_name() const override { return "marschner"; }
  std::string_view schema() const override { return schema_json; }

  // At most R, TT and TRT, no residual, tilts, fold_below or quadrature: the schema's rules of this
  // model (its allOf), applied before these run.
  std::vector<std::string> default_lobes() const override { return {"R", "TT", "TRT"}; }
  bool has_residual() const override { return false; }
  std::shared_ptr<const ModelSettings> parse(const nlohmann::json& doc, const BakeConfig& c) const override {
    auto s = std::make_shared<Settings>();
    s->m = parse_settings(doc, c);
    return s;
  }
  void normalize(const BakeConfig& c, nlohmann::json& n) const override {
    std::vector<std::string> names;
    for (int p = 0; p < c.lobe_count; ++p) names.push_back(lobe_name(p));
    n["lobes"] = {{"explicit", names}, {"residual", false}};
    n["marschner"] = marschner_json(settings_of(c));
  }
  // N_R, N_TT over (σa, θd, φ); an eccentric TRT also over φh (before φ). No β: the schema refuses it.
  std::vector<GridAxis> np_axes(const nlohmann::json& ax, const std::string& p, const SharedNpAxes& shared,
                                const BakeConfig& c) const override {
    std::vector<GridAxis> axes{shared.sigma_a, shared.theta_d, shared.phi};
    const bool eccentric = settings_of(c).params.eccentricity != 1.0;
    if (ax.contains("phi_h") && !eccentric) config_error(p + "phi_h", "applies to an eccentric fiber only (marschner.eccentricity is 1)");
    if (eccentric) {
      const nlohmann::json def = {{"count", 9}, {"range_deg", {0, 90}}};
      GridAxis ph = config_angle_axis(ax.contains("phi_h") ? ax.at("phi_h") : def, p + "phi_h", "phi_h", 0.0, kHalfPi,
                                      "azimuthal half angle phi_h = (phi_i + phi_r)/2 from the axis where eta* = eta1* (period pi, even)");
      ph.wrap = Wrap::reflect;
      if (ph.lo != 0.0 || std::abs(ph.hi - kHalfPi) > 1e-12)
        config_error(p + "phi_h", "must cover [0, 90] degrees (eta* is even in phi_h with period 180 degrees; the sampler folds phi_h into it)");
      ph.hi = kHalfPi;
      axes.insert(axes.begin() + 2, ph);
    }
    return axes;
  }
  std::string mp_beta_meaning() const override { return "width beta_R of the R lobe's Gaussian (lobe p uses Table 1's beta_p = ratio_p beta_R)"; }
  // Gaussian widths: R given, TT and TRT given or from Table 1 (β_R/2, 2β_R); R present, no
  // residual and no beta_n_deg: the schema's rules.
  void material_roughness(const nlohmann::json& mj, const std::string& path, const BakeConfig& c, MaterialConfig& m) const override {
    const nlohmann::json& b = mj.at("beta_deg");
    for (const auto& [key, value] : b.items()) config_lobe_index(key, c.lobe_count, path + ".beta_deg." + key);
    const MarschnerLobes table1 = settings_of(c).lobes(radians(b.at("R").get<double>()));
    for (int lobe = 0; lobe < c.lobe_count; ++lobe)
      m.beta_m.push_back(b.contains(lobe_name(lobe)) ? radians(b.at(lobe_name(lobe)).get<double>()) : table1.beta[lobe]);
    m.beta_n = m.beta_m;
  }

  void check(const BakeConfig&) const override {}  // its rules are the schema's and the N_p axes'

  bool slab_by_slab() const override { return false; }
  // N_p over (σa, θd, φ) per lobe, TRT of an eccentric fiber over φh too; the energies without φ.
  std::vector<PlannedTable> own_np_tables(const BakeConfig& c) const override {
    std::vector<PlannedTable> out;
    if (!c.np_axes) return out;
    const std::vector<GridAxis>& ax = *c.np_axes;
    for (int p = 0; p < c.lobe_count; ++p) {
      PlannedTable np;
      for (const GridAxis& a : ax)
        if (a.name != "phi_h" || p == 2) np.axes.push_back(a);
      PlannedTable energy{np.axes, false};
      energy.axes.pop_back();  // φ
      out.push_back(std::move(np));
      out.push_back(std::move(energy));
    }
    return out;
  }
  TableSet bake(const BakeConfig& c, const BakeOptions& opt, BakeReport* report, SlabbedTables*) const override {
    return bake_tables(c, settings_of(c), opt, report);
  }

  std::shared_ptr<const ModelSettings> from_metadata(const nlohmann::json& metadata, double eta, AbsorptionPath path) const override {
    if (!metadata.contains("marschner")) throw DomainError("table metadata: model marschner2003 without its \"marschner\" settings");
    auto s = std::make_shared<Settings>();
    s->m = marschner_from_json(metadata.at("marschner"), eta, path);
    return s;
  }
  std::optional<TableTruth> truth(const Table& t, const ModelSettings& s) const override {
    if (t.attributes.value("model", std::string()) != "marschner2003") return std::nullopt;
    return marschner_truth(t, dynamic_cast<const Settings&>(s).m);
  }
};

}  // namespace

const ModelKind& model_kind() {
  static const Model model;
  return model;
}

}  // namespace hairlut::models::marschner2003
