// The M_p tables: d'Eon's longitudinal function of every lobe (and the residual), generic over
// (β, θi, θr) or per material over (θi, θr) with the material's β; and the melanin → σa tables.
#include <string>
#include <vector>

#include "bake_internal.hpp"
#include "bake_stages.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"
#include "hairlut/physics/melanin.hpp"

namespace hairlut::detail {

void bake_mp_tables(const BakeRun& run, bool per_material, TableSet& set, BakeReport& report) {
  const BakeConfig& c = *run.config;
  const BakeOptions& opt = run.options;
  const Precision precision = run.precision;
  SlabbedTables* const slabbed = run.slabbed;
  const BakeRun& s = run;
  const GridAxis ti_axis = axis_named(*c.mp_axes, "theta_i"), tr_axis = axis_named(*c.mp_axes, "theta_r");
  const std::vector<double> tis = ti_axis.nodes(), trs = tr_axis.nodes();
  const int n_mp = s.lobes + (c.residual ? 1 : 0);
  auto tilt_of = [&](int p) { return p == s.lobes ? c.residual_tilt : c.tilt[static_cast<std::size_t>(p)]; };
  auto lobe_of = [&](int p) { return p == s.lobes ? std::string("residual") : lobe_name(p); };
  const std::size_t ni = tis.size(), nr = trs.size();
  if (!per_material) {
    const std::vector<double> betas = axis_named(*c.mp_axes, "beta").nodes();
    const std::size_t first = set.tables.size();
    for (int p = 0; p < n_mp; ++p) {
      Table t = make_table("mp", lobe_of(p), "M_p", "1/rad",
                           "d'Eon longitudinal function M(beta^2, theta_i, theta_r - alpha) of lobe " + lobe_of(p), *c.mp_axes,
                           precision, !slabbed);
      t.attributes = {{"lobe", lobe_of(p)}, {"p", p}, {"alpha", tilt_of(p)}};
      set.tables.push_back(std::move(t));
    }
    const std::size_t nb = betas.size();
    if (slabbed) {
      for (int p = 0; p < n_mp; ++p)
        slabbed->tables.push_back({first + static_cast<std::size_t>(p), [betas, tis, trs, opt, alpha = tilt_of(p)](std::size_t row0, std::size_t rows, Table& out) {
                                     const std::size_t n_i = tis.size(), n_r = trs.size();
                                     parallel_for(rows * n_i, opt, "M_p slab", n_r, [&](std::size_t k) {
                                       const std::size_t ib = row0 + k / n_i, ii = k % n_i;
                                       for (std::size_t ir = 0; ir < n_r; ++ir)
                                         out.set(k * n_r + ir, longitudinal_deon_tilted(betas[ib] * betas[ib], alpha, tis[ii], trs[ir]));
                                     });
                                   }});
    } else {
      parallel_for(nb * ni, opt, "M_p", nr * static_cast<std::size_t>(n_mp), [&](std::size_t k) {
        const std::size_t ib = k / ni, ii = k % ni;
        const double v = betas[ib] * betas[ib];
        for (int p = 0; p < n_mp; ++p) {
          Table& t = set.tables[first + static_cast<std::size_t>(p)];
          for (std::size_t ir = 0; ir < nr; ++ir)
            t.set((ib * ni + ii) * nr + ir, longitudinal_deon_tilted(v, tilt_of(p), tis[ii], trs[ir]));
        }
      });
    }
    report.entries += nb * ni * nr * static_cast<std::size_t>(n_mp);
  } else {
    for (const MaterialConfig& m : c.scene->materials) {
      const std::string group = "materials/" + m.name;
      const std::size_t first = set.tables.size();
      for (int p = 0; p < n_mp; ++p) {
        const double beta = p == s.lobes ? m.residual_beta_m : m.beta_m[static_cast<std::size_t>(p)];
        Table t = make_table(group, "mp_" + lobe_of(p), "M_p", "1/rad",
                             "M_p of lobe " + lobe_of(p) + " for material " + m.name, {ti_axis, tr_axis}, precision);
        t.attributes = {{"lobe", lobe_of(p)}, {"p", p}, {"material", m.name}, {"beta", beta}, {"alpha", tilt_of(p)}};
        set.tables.push_back(std::move(t));
      }
      std::vector<double> betas;
      for (int p = 0; p < n_mp; ++p) betas.push_back(p == s.lobes ? m.residual_beta_m : m.beta_m[static_cast<std::size_t>(p)]);
      parallel_for(ni, opt, "M_p " + m.name, nr * static_cast<std::size_t>(n_mp), [&](std::size_t ii) {
        for (int p = 0; p < n_mp; ++p) {
          Table& t = set.tables[first + static_cast<std::size_t>(p)];
          const double beta = betas[static_cast<std::size_t>(p)];
          for (std::size_t ir = 0; ir < nr; ++ir)
            t.set(ii * nr + ir, longitudinal_deon_tilted(beta * beta, tilt_of(p), tis[ii], trs[ir]));
        }
      });
      report.entries += ni * nr * static_cast<std::size_t>(n_mp);
    }
  }
}

void append_melanin_tables(const BakeConfig& c, Precision precision, TableSet& set, BakeReport& report) {
  if (!c.melanin_axes) return;
  const GridAxis channel = channel_axis({"R", "G", "B"}, "colour channel (linear sRGB primaries)");
  std::vector<GridAxis> axes = *c.melanin_axes;
  axes.push_back(channel);
  const std::vector<double> ce = axes[0].nodes(), cp = axes[1].nodes();
  SpectralMelanin::Options so;
  so.path_length = c.melanin_path_length;
  const SpectralMelanin spectral = SpectralMelanin::builtin(so);
  const SpectralMelanin::Fit fit = spectral.fit_rgb_cross_sections();
  Table deon = make_table("melanin", "sigma_a_deon", "sigma_a", "1/radius",
                          "absorption per unit radius from d'Eon 2011's RGB cross-sections", axes, precision);
  deon.attributes = {{"eumelanin_cross_section", {0.419, 0.697, 1.37}}, {"pheomelanin_cross_section", {0.187, 0.4, 1.05}},
                     {"method", "sigma_a = c_e (0.419, 0.697, 1.37) + c_p (0.187, 0.4, 1.05) (d'Eon 2011 sec. 6.1)"}};
  // The spectral model's colour leaves the sRGB gamut for dark hair (blue T_c ≤ 0), where no RGB
  // absorption reproduces it and −ln T_c has no value: the table stores the transmittance itself,
  // which stays smooth across the gamut boundary, and says how a renderer takes σa from it.
  Table spec = make_table("melanin", "transmittance_spectral", "transmittance", "1",
                          "linear sRGB transmittance over path_length radii from the Donner-Jensen 2006 spectra, CIE 1931 2 deg and D65",
                          axes, precision);
  spec.attributes = {{"path_length", c.melanin_path_length},
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
      const Rgb b = spectral.transmittance_unclamped(ce[i], cp[j], c.melanin_path_length);
      const std::size_t o = (i * cp.size() + j) * 3;
      deon.set(o, a.r), deon.set(o + 1, a.g), deon.set(o + 2, a.b);
      spec.set(o, b.r), spec.set(o + 1, b.g), spec.set(o + 2, b.b);
    }
  set.tables.push_back(std::move(deon));
  set.tables.push_back(std::move(spec));
  report.entries += 2 * ce.size() * cp.size() * 3;
}

}  // namespace hairlut::detail
