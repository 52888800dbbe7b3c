// The sampler's mixture path (sampling.hpp, axis_sampling.hpp): the blended cumulative Σ w_c F_c of
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
// The default tables with linear interpolation along every N_p and M_p axis (the same nodes): the
// reconstruction on which the sampler's mixture fast path applies at every lookup.
HairTables linear_tables(const TableSet& set, bool cubic_sampled_axis) {
  HairTables h = hair_tables(set, "");
  for (sampler::LobeTables<float>& l : h.lobes) {
    l.np_data = l.mp_data = sampler::AxisData();  // the stored data are those of the tables as baked
    for (sampler::TableRef<float>* t : {&l.np, &l.mp})
      for (int d = 0; d < t->dims; ++d) {
        sampler::Axis& a = const_cast<sampler::Axis&>(t->axes[d]);
        if (a.interpolation == sampler::Interpolation::cubic && !(cubic_sampled_axis && d + 1 == t->dims)) a.interpolation = sampler::Interpolation::linear;
      }
  }
  h.sampler = std::make_unique<HairSampler<float>>(h.lobes.data(), static_cast<int>(h.lobes.size()));
  return h;
}
}  // namespace

TEST_CASE("Sampling: the mixture fast path on linear tables, pdf against quadrature, chi-square and furnace", "[sampling]") {
  const TableSet& set = default_tables();
  for (int cubic_sampled = 0; cubic_sampled < 2; ++cubic_sampled) {
    const HairTables h = linear_tables(set, cubic_sampled != 0);
    REQUIRE(h.sampler->supported());
    std::mt19937_64 rng(21 + static_cast<unsigned>(cubic_sampled));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    HairSampler<float>::Workspace ws;
    // pdf of each lobe = max(0, M̃)/∫ M̃ cos θr dθr × max(0, Ñ)/∫ Ñ dφ, from TableView lookups of
    // the linearised tables and independent quadrature.
    for (std::size_t p = 0; p < h.lobes.size(); ++p) {
      const HairSampler<float> one(&h.lobes[p], 1);
      const sampler::LobeTables<float>& l = h.lobes[p];
      const sampler::TableView<float> mp(l.mp.data, l.mp.axes, l.mp.dims), np(l.np.data, l.np.axes, l.np.dims);
      const bool has_phi = l.np.dims == 4;
      for (int k = 0; k < 20; ++k) {
        const FibreCoordinates f{std::exp(std::log(4.5 * kDeg) + u(rng) * std::log(40.0 / 4.5)), 4.0 * u(rng) * u(rng), 0.0};
        const double ti = (u(rng) - 0.5) * 170.0 * kDeg, tr = (u(rng) - 0.5) * 170.0 * kDeg, phi = (2.0 * u(rng) - 1.0) * kPi;
        const double td = 0.5 * (tr - ti);
        auto m_at = [&](double t) {
          const double x[3] = {f.beta, ti, t};
          return std::max(0.0, mp(x));
        };
        auto n_at = [&](double t) {
          const double x[4] = {f.beta, f.sigma_a, td, t};
          return std::max(0.0, np(x));
        };
        const double zm = integrate([&](double t) { return m_at(t) * std::cos(t); }, -0.5 * kPi, 0.5 * kPi, 160 * 8);
        const double pn = has_phi ? n_at(phi) / integrate(n_at, -kPi, kPi, 190 * 8) : 1.0 / (2.0 * kPi);
        const double expected = m_at(tr) / zm * pn;
        CHECK(std::fabs(one.pdf(f, ti, tr, phi, ws) - expected) <= 1e-7 * std::max(expected, 1e-12));
      }
    }
    // Chi-square and ∫ pdf = 1 of the mixture of all lobes at wide and narrow roughness, and a
    // furnace through sampling against quadrature of eval.
    for (const Case& c : {kGenericCases[0], kGenericCases[1]}) {
      const FibreCoordinates f{c.beta, 0.5, 0.0};
      double integral = 0.0;
      const double pvalue = chi_square(*h.sampler, f, c.theta_i, 200000, 700 + static_cast<unsigned>(cubic_sampled), &integral);
      const double exact = quadrature_energy(*h.sampler, f, c.theta_i);
      const Estimate e = furnace(*h.sampler, f, c.theta_i, 200000, 800 + static_cast<unsigned>(cubic_sampled));
      INFO(c.name << (cubic_sampled ? ", cubic sampled axes" : ", linear") << ": p-value " << pvalue << ", integral of pdf " << integral
                  << ", furnace " << e.mean << " +- " << e.error << ", quadrature " << exact);
      CHECK(std::fabs(integral - 1.0) <= 1e-3);
      CHECK(pvalue > 0.01 / 4.0);  // significance 0.01 over the 4 fits
      CHECK(std::fabs(e.mean - exact) <= 4.0 * e.error);
    }
  }
}
