// The M_p tables: d'Eon's longitudinal function of every lobe (and the residual), generic over
// (β, θi, θr) or per material over (θi, θr) with the material's β.
#include <string>
#include <vector>

#include "bake_internal.hpp"
#include "bake_stages.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"

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

}  // namespace hairlut::detail
