// The sampler's mixture path (axis_sampling.hpp, as HairScattering uses it): the blended cumulative Σ w_c F_c of
// the node slices' prefix integrals (weights of either sign), corrected where the clamp at 0 acts,
// samples the interpolant exactly; checked against the general path and independent quadrature.
#include "sampling_checks.hpp"

using namespace sampling_checks;  // and the hairlut names it brings (sampling_checks.hpp)

TEST_CASE("Axis sampling: the mixture fast path has the general path's density and normalisation, and draws from it", "[sampling]") {
  // Tables over (a, b, x) with a and b linear (weights ≥ 0) or Catmull–Rom (weights of either
  // sign) and x linear or Catmull–Rom: where mix() holds, its normalisation and pdf must equal the
  // blended row's to rounding, and its draws (monotone in u) must follow the CDF of an independent
  // quadrature of the clamped interpolant. Cubic interpolation of the spiky rows overshoots below
  // 0: there mix() must account for the clamp (Mix::fixes > 0).
  for (int other = 0; other < 2; ++other)
  for (int wrap = 0; wrap < 2; ++wrap)
    for (int cubic = 0; cubic < 2; ++cubic) {
      const int na = 4, nb = 3, nx = 17;
      std::vector<double> data(static_cast<std::size_t>(na * nb * nx));
      std::mt19937_64 rng(70 + static_cast<unsigned>(other * 4 + wrap * 2 + cubic));
      std::uniform_real_distribution<double> u(0.0, 1.0);
      // Smooth positive rows (no overshoot) for slices a < 2, spiky rows (Catmull–Rom dips
      // below 0 next to a spike) for a ≥ 2.
      for (int ia = 0; ia < na; ++ia)
        for (int ib = 0; ib < nb; ++ib)
          for (int ix = 0; ix < nx; ++ix) {
            double& v = data[static_cast<std::size_t>((ia * nb + ib) * nx + ix)];
            v = ia < 2 ? 1.0 + 0.5 * std::sin(0.4 * ix + ia + 2.0 * ib) + 0.2 * u(rng) : (u(rng) < 0.3 ? 5.0 * u(rng) : 0.0);
          }
      const sampler::Interpolation interp = cubic ? sampler::Interpolation::cubic : sampler::Interpolation::linear;
      sampler::Axis axes[3];
      const sampler::Interpolation outer = other ? sampler::Interpolation::cubic : sampler::Interpolation::linear;
      random_table_axes(axes, na, nb, nx, wrap, outer, outer, interp);
      const sampler::TableView<double> view(data.data(), axes, 3);
      const sampler::Measure measure = wrap == 0 ? sampler::Measure::cosine : sampler::Measure::plain;
      const AxisSampler<double> axis(data.data(), axes, 3, measure);
      REQUIRE(axis.has_mixture());
      const double lo = wrap == 0 ? -0.5 * kPi : -kPi, hi = wrap == 0 ? 0.5 * kPi : kPi;
      AxisRow row;
      AxisSampler<double>::Mix m;
      int fast = 0, refused = 0, clamped = 0;
      for (int trial = 0; trial < 16; ++trial) {
        // Half the trials among the smooth slices (a between the first two nodes), half anywhere.
        const double a = trial % 2 == 0 ? std::exp(std::log(0.1) + u(rng) * (std::log(1.0) - std::log(0.1)) / 3.0) : 0.1 + 0.9 * u(rng);
        double x[3] = {a, 2.0 * u(rng), 0.0};
        axis.blend(x, row);
        REQUIRE(row.ok);
        if (!axis.mix(x, m)) {
          ++refused;
          continue;
        }
        ++fast;
        if (m.fixes > 0) ++clamped;
        CHECK(std::fabs(m.total - row.total) <= 1e-12 * row.total);
        for (int k = 0; k < 100; ++k) {
          const double t = lo + (hi - lo) * u(rng);
          const double general = axis.pdf(row, t);
          const double fastpdf = axis.mix_value(m, t) * (measure == sampler::Measure::cosine ? std::cos(t) : 1.0) / m.total;
          CHECK(std::fabs(fastpdf - general) <= 1e-12 * std::max(general, 1.0 / (hi - lo)));
        }
        auto reference = [&](double t) {
          x[2] = t;
          const double v = std::max(0.0, view(x));
          return measure == sampler::Measure::cosine ? v * std::cos(t) : v;
        };
        const int cells = (nx - 1) * 256 * (wrap ? 2 : 1);
        const double total = integrate(reference, lo, hi, cells);
        CHECK(std::fabs(m.total - total) <= 1e-7 * total);
        // n stratified u, the reference CDF at each sorted draw: the draws are the inverse CDF of
        // stratified u, so the empirical CDF is within ½/n of the exact one, plus rounding.
        const int n = 2000;
        std::vector<double> cdf;
        for (int k = 0; k < n; ++k) {
          const double t = axis.sample_mix(m, (k + 0.5) / n);
          REQUIRE(t >= lo);
          REQUIRE(t <= hi);
          CHECK(axis.mix_value(m, t) > 0.0);
          cdf.push_back(t);
        }
        std::sort(cdf.begin(), cdf.end());
        // Cumulative reference integral at each sorted draw, accumulated piecewise.
        double acc = 0.0, prev = lo, ks = 0.0;
        for (int k = 0; k < n; ++k) {
          acc += integrate(reference, prev, cdf[static_cast<std::size_t>(k)], 8);
          prev = cdf[static_cast<std::size_t>(k)];
          ks = std::max(ks, std::fabs(acc / total - (k + 0.5) / n));
        }
        CHECK(ks <= 1.0 / n + 1e-6);
      }
      INFO("other axes " << (other ? "cubic" : "linear") << ", wrap " << wrap << " cubic " << cubic << ": fast " << fast << ", refused "
                         << refused << ", with the clamp accounted for " << clamped);
      CHECK(fast >= 8);
      if (cubic || other) CHECK(clamped >= 1);
      else CHECK(clamped == 0);
    }
}

namespace {
// The default tables with linear interpolation along every N_p and M_p axis (the same nodes; the
// energy factors as baked), optionally cubic along the axes the runtime samples (φ of N_p, θi of
// M_p): the reconstruction on which the sampler's mixture fast path applies at every lookup. The
// axes of each table in `axes` (which the views copy).
struct LinearTables {
  sampler::HairTables<float, double> h;
  std::vector<std::string> names;  // the explicit lobes, then "residual"
};
LinearTables linear_tables(const TableSet& set, bool cubic_sampled_axis) {
  LinearTables out{hair_tables<float, double>(set), lobe_names(set)};
  out.names.push_back("residual");
  auto axes_of = [&](const Table& t, int sampled, sampler::Axis* a) {
    for (std::size_t d = 0; d < t.axes.size(); ++d) {
      a[d] = t.axes[d].view();
      if (a[d].interpolation == sampler::Interpolation::cubic && !(cubic_sampled_axis && static_cast<int>(d) == sampled))
        a[d].interpolation = sampler::Interpolation::linear;
    }
  };
  for (std::size_t p = 0; p < out.names.size(); ++p) {
    const Table& np = *set.find("np/" + out.names[p]);
    const Table& mp = *set.find("mp/" + out.names[p]);
    const Table* e = set.find(np.factor());
    sampler::Axis na[4], ma[3], ea[2];
    axes_of(mp, 1, ma);
    if (e) ea[0] = e->axes[0].view(), ea[1] = e->axes[1].view();
    if (p + 1 < out.names.size()) {
      axes_of(np, 3, na);
      out.h.np[p] = sampler::NpLobe<float, double>(np.f32.data(), na, e ? e->f32.data() : nullptr, e ? ea : nullptr, e ? e->grazing_factor() : sampler::GrazingFactor{});
      out.h.mp[p] = sampler::MpLobe<float, double>(mp.f32.data(), ma);
    } else {
      axes_of(np, -1, na);
      out.h.np_residual = sampler::NpResidual<float, double>(np.f32.data(), na, e ? e->f32.data() : nullptr, e ? ea : nullptr,
                                                             np.grazing_factor(), e ? e->grazing_factor() : sampler::GrazingFactor{});
      out.h.mp_residual = sampler::MpLobe<float, double>(mp.f32.data(), ma);
    }
  }
  return out;
}
}  // namespace

TEST_CASE("Sampling: the mixture fast path on linear tables, pdf against quadrature, chi-square and furnace", "[sampling]") {
  const TableSet& set = default_tables();
  for (int cubic_sampled = 0; cubic_sampled < 2; ++cubic_sampled) {
    const LinearTables lin = linear_tables(set, cubic_sampled != 0);
    REQUIRE(lin.h.beta_bands == 1);
    const Runtime all(lin.h);
    REQUIRE(all.valid());
    std::mt19937_64 rng(21 + static_cast<unsigned>(cubic_sampled));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    // pdf of each explicit lobe alone = max(0, M̃) Ê / ∫ max(0, M̃) Ê cos θi dθi × max(0, Ñ) / ∫ Ñ
    // dφ, from TableView lookups of the linearised tables, Ê (energy_hat) and independent quadrature.
    for (int p = 0; p < lin.h.lobes; ++p) {
      sampler::HairTables<float, double> one = lin.h;
      one.lobes = 1, one.has_residual = false, one.np[0] = lin.h.np[p], one.mp[0] = lin.h.mp[p];
      const Runtime rt(one);
      REQUIRE(rt.valid());
      const auto& mv = lin.h.mp[p].table();
      const auto& nv = lin.h.np[p].table();
      const Table& mp = *set.find("mp/" + lin.names[static_cast<std::size_t>(p)]);
      const Table& energy = *set.find(set.find("np/" + lin.names[static_cast<std::size_t>(p)])->factor());
      for (int k = 0; k < 20; ++k) {
        const double beta = std::exp(std::log(4.5 * kDeg) + u(rng) * std::log(40.0 / 4.5)), sigma_a = 4.0 * u(rng) * u(rng);
        const sampler::Fiber f = grey_fiber(beta, sigma_a);
        const double ti = (u(rng) - 0.5) * 170.0 * kDeg, to = (u(rng) - 0.5) * 170.0 * kDeg, phi = (2.0 * u(rng) - 1.0) * kPi;
        const double td = 0.5 * (to - ti);
        auto m_at = [&](double t) {
          const double x[3] = {beta, t, to};
          return std::max(0.0, mv(x)) * energy_hat(energy, mp.axes[1], sigma_a, to, t);
        };
        auto n_at = [&](double t) {
          const double x[4] = {beta, sigma_a, td, t};
          return std::max(0.0, nv(x));
        };
        const double zm = integrate([&](double t) { return m_at(t) * std::cos(t); }, -0.5 * kPi, 0.5 * kPi, 160 * 8);
        const double pn = n_at(phi) / integrate(n_at, -kPi, kPi, 190 * 8), expected = m_at(ti) / zm * pn;
        // The runtime cuts the θi cells where M̃ stays below 1e-12 of its peak along θi (product_row.hpp):
        // there the pdf may be 0 where the reference is not, by at most the reference with M̃ at that cut.
        const double cut = 1e-12 * row_peak([&](double t) {
                             const double x[3] = {beta, t, to};
                             return mv(x);
                           }) * energy_hat(energy, mp.axes[1], sigma_a, to, ti) / zm * pn;
        const double pdf = rt.at(f, Held(to).wo).pdf(ti, phi);
        INFO("lobe " << p << " theta_i " << ti << " theta_o " << to << " phi " << phi << ": pdf " << pdf << ", expected " << expected);
        CHECK(std::fabs(pdf - expected) <= 1e-7 * std::max(expected, 1e-12) + cut);
      }
    }
    // Chi-square and ∫ pdf = 1 of the mixture of all lobes at wide and narrow roughness, and a
    // furnace through sampling against quadrature of eval.
    for (const Case& c : {kGenericCases[0], kGenericCases[1]}) {
      const sampler::Fiber f = grey_fiber(c.beta, 0.5);
      double integral = 0.0;
      const double pvalue = chi_square(all, f, c.theta_o, 200000, 700 + static_cast<unsigned>(cubic_sampled), &integral);
      const Quadrature exact = quadrature_energy(set, "", all, f, c.theta_o);
      const Estimate e = furnace(all, f, c.theta_o, 200000, 800 + static_cast<unsigned>(cubic_sampled));
      INFO(c.name << (cubic_sampled ? ", cubic sampled axes" : ", linear") << ": p-value " << pvalue << ", integral of pdf " << integral
                  << ", furnace " << e.mean << " +- " << e.error << ", quadrature " << exact.value << " +- " << exact.error);
      CHECK(std::fabs(integral - 1.0) <= 1e-3);
      CHECK(pvalue > 0.01 / 4.0);  // significance 0.01 over the 4 fits
      CHECK(std::fabs(e.mean - exact.value) <= 4.0 * e.error + exact.error + kCutBias * exact.value);
    }
  }
}
