// Mean energy and dual scattering (Zinke 2008) from hairlut's M_p and N_p: the azimuthal half-range
// integrals by two algorithms and against quadrature of the detector, the white furnace, the grid
// against the point evaluation, the Zinke terms against their series, and a Monte Carlo simulation of
// the model (its own code path: no hairlut function but the one under test) within 4 standard errors.
#include <cmath>
#include <cstdint>
#include <hairlut/physics/azimuthal_fourier.hpp>
#include <hairlut/bake/bake_engine.hpp>
#include <hairlut/bake/dual_scattering_grid.hpp>
#include <hairlut/bake/engine_presets.hpp>
#include <hairlut/hairlut.hpp>
#include <numbers>

#include "catch.hpp"

using namespace hairlut;

namespace {

constexpr double pi = std::numbers::pi;

// ∫ g over [a, b] by adaptive Gauss–Kronrod with breakpoints.
double integrate(const std::function<double(double)>& g, std::vector<double> bp, double rel = 1e-12) {
  std::sort(bp.begin(), bp.end());
  AdaptiveOptions o;
  o.rel_tol = rel;
  o.abs_tol = 1e-16;
  o.max_intervals = 20000;
  return integrate_adaptive([&](double x, std::span<double> out) { out[0] = g(x); }, 1, bp, o).value[0];
}

}  // namespace

TEST_CASE("Detector half masses: W_b + W_f = 1 and each equals the integral of the wrapped normal", "[dual_scattering]") {
  double worst = 0.0;
  for (double beta : {1e-4, 0.01, 0.3, 1.0, 1.49, 1.51, 3.0, 20.0})
    for (double Phi : {0.0, 0.4, 1.5707963, 2.0, 3.14159, -2.5, 7.0, 40.0}) {
      const double wb = detector_mass_backward(beta, Phi), wf = detector_mass_forward(beta, Phi);
      CHECK(wb >= 0.0);
      CHECK(wf >= 0.0);
      CHECK(wb + wf == Approx(1.0).margin(1e-14));
      if (beta < 1e-3) continue;  // the quadrature below cannot see a step that narrow
      const double x = std::remainder(Phi, 2.0 * pi);
      std::vector<double> bp = {-pi / 2, pi / 2};
      if (std::abs(x) < pi / 2) bp.push_back(x);
      const double ref = integrate([&](double phi) { return gaussian_detector(beta, phi - Phi); }, bp);
      INFO("beta " << beta << " Phi " << Phi);
      CHECK(wb == Approx(ref).margin(1e-12));
      worst = std::max(worst, std::abs(wb - ref));
    }
  WARN("half mass of the detector against quadrature: max |error| = " << worst);
  CHECK_THROWS_AS(detector_mass_backward(0.0, 1.0), DomainError);
  CHECK_THROWS_AS(detector_mass_forward(0.1, NAN), DomainError);
}

TEST_CASE("Half-range integrals of N_p: the Fourier form and direct quadrature agree, and add up to the lobe energy", "[dual_scattering]") {
  double worst = 0.0, worst_sum = 0.0;
  for (double eta : {1.55, 1.2, 2.5})
    for (double theta_d : {0.0, 0.6, 1.2, 1.55})
      for (int p = 0; p <= 4; ++p)
        for (double beta : {0.025, 0.2, 1.0, 3.0}) {
          const FiberGeometry g = FiberGeometry::make(eta, theta_d);
          const std::vector<double> sigmas = {0.0, 0.5, 5.0};
          const int N = fourier_terms(beta, 1e-13);
          std::vector<double> C;
          fourier_coefficients(g, AbsorptionPath::chord, p, sigmas, N, GaussLegendreRule(fourier_nodes(N, p, g, 1e-13)), C);
          std::vector<double> direct(6);
          CHECK(half_range_direct(g, AbsorptionPath::chord, p, sigmas, beta, direct, 1e-12));
          for (std::size_t k = 0; k < sigmas.size(); ++k) {
            const HalfRangeEnergy f = half_range_fourier(std::span<const double>(C).subspan(k), sigmas.size(), beta, 1e-13);
            INFO("eta " << eta << " theta_d " << theta_d << " p " << p << " beta " << beta << " sigma_a " << sigmas[k]);
            CHECK(f.backward == Approx(direct[2 * k]).margin(1e-12));
            CHECK(f.forward == Approx(direct[2 * k + 1]).margin(1e-12));
            worst = std::max({worst, std::abs(f.backward - direct[2 * k]), std::abs(f.forward - direct[2 * k + 1])});
            const double e = lobe_energies_reference(AttenuationSlice(eta, theta_d, sigmas[k]), {p + 1, false}).value[static_cast<std::size_t>(p)];
            CHECK(direct[2 * k] + direct[2 * k + 1] == Approx(e).margin(1e-12));
            worst_sum = std::max(worst_sum, std::abs(direct[2 * k] + direct[2 * k + 1] - e));
          }
        }
  WARN("half ranges: Fourier against direct max |difference| = " << worst << "; backward + forward against the lobe energy " << worst_sum);
}

TEST_CASE("Half-range integrals against the adaptive N_p reference integrated over phi", "[dual_scattering]") {
  // A third algorithm: N_p(φ) by azimuthal_np_reference, integrated over each half of the circle.
  for (auto [p, beta, theta_d] : {std::tuple{0, 0.15, 0.3}, std::tuple{1, 0.1, 0.9}, std::tuple{2, 0.2, 0.2}}) {
    const AttenuationSlice slice(1.55, theta_d, 0.3);
    auto np = [&](double phi) { return azimuthal_np_reference(slice, p, beta, phi, 1e-11).value[0]; };
    const std::vector<double> bp_b = {0.0, pi / 2}, bp_f = {pi / 2, pi};
    const double back = 2.0 * integrate(np, bp_b, 1e-10), fwd = 2.0 * integrate(np, bp_f, 1e-10);
    const HalfRangeEnergy h = half_range_direct(slice, p, beta);
    INFO("p " << p << " beta " << beta);
    CHECK(h.backward == Approx(back).margin(1e-9));
    CHECK(h.forward == Approx(fwd).margin(1e-9));
  }
}

TEST_CASE("Half-range integrals stay finite and non-negative over the whole domain", "[dual_scattering][domain]") {
  for (double beta : {1e-7, 1e-4, 0.05, 50.0})
    for (double theta_d : {-1.5707963267948966, -0.3, 0.0, 1.5707963267948966})
      for (double sigma : {0.0, 1.0, 1e5})
        for (int p : {0, 1, 2, 5}) {
          const AttenuationSlice slice(1.55, theta_d, sigma);
          const HalfRangeEnergy h = half_range_direct(slice, p, beta);
          const double e = lobe_energies(slice, {p + 1, false}, GaussLegendreRule(256))[static_cast<std::size_t>(p)];
          INFO("beta " << beta << " theta_d " << theta_d << " sigma_a " << sigma << " p " << p);
          CHECK(std::isfinite(h.backward));
          CHECK(std::isfinite(h.forward));
          CHECK(h.backward >= 0.0);
          CHECK(h.forward >= 0.0);
          CHECK(h.backward + h.forward == Approx(e).margin(1e-9));
          if (beta == 50.0) CHECK(h.backward == Approx(0.5 * e).margin(1e-12));  // a very rough detector splits evenly
        }
}

TEST_CASE("White furnace: with sigma_a = 0 the lobes' mean energies sum to 1 and a_f + a_b = E", "[dual_scattering][furnace]") {
  double worst = 0.0;
  for (double beta : {0.02, 0.15, 0.6})
    for (double theta_i : {-1.5707963267948966, -0.7, 0.0, 0.5, 1.2, 1.5707963267948966}) {
      const HairModel m = HairModel::uniform(1.55, 0.0, beta, 3, true);
      const DualScatteringPoint pt = dual_scattering(m, theta_i);
      INFO("beta " << beta << " theta_i " << theta_i);
      CHECK(pt.converged);
      CHECK(pt.energy_total == Approx(1.0).margin(1e-8));
      CHECK(pt.a_f + pt.a_b == Approx(pt.energy_total).margin(1e-8));
      worst = std::max({worst, std::abs(pt.energy_total - 1.0), std::abs(pt.a_f + pt.a_b - 1.0)});
      // Consistent with the directional albedo, lobe by lobe.
      const AlbedoResult a = directional_albedo(m, theta_i);
      for (std::size_t l = 0; l < pt.energy.size(); ++l) CHECK(pt.energy[l] == Approx(a.per_lobe[l]).margin(1e-8));
      CHECK(pt.alpha_f == 0.0);
      CHECK(pt.backscatter.delta_b == 0.0);
      CHECK(pt.beta_f2 == Approx(beta * beta).epsilon(1e-12));
    }
  WARN("dual scattering white furnace: max |E - 1|, |a_f + a_b - 1| = " << worst);
}

TEST_CASE("Zinke terms: A_b against its series, limits, finiteness as a_f -> 1", "[dual_scattering]") {
  // A_1 = Σ_{k≥1} a_b a_f^{2k}, A_3 = a_b³ a_f² Σ_{k≥0} C(k+2, 2) a_f^{2k} (three backward events).
  for (double af : {0.1, 0.5, 0.8})
    for (double ab : {0.05, 0.2}) {
      double a1 = 0.0, a3 = 0.0;
      for (int k = 1; k < 4000; ++k) a1 += ab * std::pow(af, 2 * k);
      for (int k = 0; k < 4000; ++k) a3 += ab * ab * ab * af * af * 0.5 * (k + 1) * (k + 2) * std::pow(af, 2 * k);
      const ZinkeBackscatter z = zinke_backscatter(af, ab, 0.01, -0.02, 0.01, 0.04, 0.7);
      CHECK(z.A_b == Approx(a1 + a3).epsilon(1e-12));
      // σ_b is a weighted mean of √(2β_f² + β_b²) and √(2β_f² + 3β_b²), scaled by 1 + d_b a_f².
      const double lo = std::sqrt(2 * 0.01 + 0.04), hi = std::sqrt(2 * 0.01 + 3 * 0.04), s = 1 + 0.7 * af * af;
      CHECK(z.sigma_b >= s * lo * (1 - 1e-12));
      CHECK(z.sigma_b <= s * hi * (1 + 1e-12));
      // Δ_b is linear in the shifts: equal shifts α give α times the sum of the weights.
      const ZinkeBackscatter e = zinke_backscatter(af, ab, 0.03, 0.03, 0.01, 0.04, 0.7);
      const double one = 1 - af * af;
      CHECK(e.delta_b == Approx(0.03 * ((1 - 2 * ab * ab / (one * one)) + (2 * one * one + 4 * af * af * ab * ab) / (one * one * one))).epsilon(1e-12));
    }
  const ZinkeBackscatter none = zinke_backscatter(0.6, 0.0, 0.01, 0.02, 0.01, 0.04, 0.7);
  CHECK(none.A_b == 0.0);
  CHECK(none.sigma_b == Approx((1 + 0.7 * 0.36) * std::sqrt(0.06)).epsilon(1e-14));
  const ZinkeBackscatter edge = zinke_backscatter(1.0, 0.0, 0.01, 0.02, 0.01, 0.04, 0.7);
  CHECK(std::isfinite(edge.A_b));
  CHECK(std::isfinite(edge.delta_b));
  CHECK(std::isfinite(edge.sigma_b));
  CHECK_THROWS_AS(zinke_backscatter(1.5, 0.1, 0, 0, 0, 0, 0.7), DomainError);
}

TEST_CASE("The grid (interpolated halves, Fourier and direct) matches the point evaluation and is bit-identical for any thread count",
          "[dual_scattering][grid]") {
  DualScatteringGridRequest rq;
  rq.lobes = 3;
  rq.residual = true;
  rq.sigmas = {0.0, 0.4, 6.0};
  // Unreal-like lobes from a tiny roughness (direct half ranges) to a rough one (Fourier).
  for (double r : {0.02, 0.12, 0.45, 0.9}) {
    const double b = r * r;
    rq.roughness.push_back({{b, b, -0.07}, {b / 2, b / 2, 0.035}, {2 * b, 2 * b, 0.14}, {2 * b, 2 * b, 0.14}});
  }
  rq.thetas = {0.0, 0.6, 1.3, 1.5707963267948966};
  std::vector<DualScatteringPoint> one(48), two(48);
  BakeOptions o1, o2;
  o1.threads = 1;
  o2.threads = 2;
  const auto s1 = dual_scattering_grid(rq, o1, "", [&](std::size_t k, std::size_t r, std::size_t t, const DualScatteringPoint& p) { one[(k * 4 + r) * 4 + t] = p; });
  dual_scattering_grid(rq, o2, "", [&](std::size_t k, std::size_t r, std::size_t t, const DualScatteringPoint& p) { two[(k * 4 + r) * 4 + t] = p; });
  CHECK(s1.unconverged == 0);
  CHECK(s1.direct_widths > 0);
  CHECK(s1.fourier_widths > 0);
  double worst = 0.0;
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t r = 0; r < 4; ++r)
      for (std::size_t t = 0; t < 4; ++t) {
        const DualScatteringPoint& a = one[(k * 4 + r) * 4 + t];
        const DualScatteringPoint& b = two[(k * 4 + r) * 4 + t];
        CHECK(a.a_f == b.a_f);
        CHECK(a.a_b == b.a_b);
        CHECK(a.energy_total == b.energy_total);
        CHECK(a.backscatter.sigma_b == b.backscatter.sigma_b);
        if ((k + r + t) % 2) continue;  // half of the cells against the (slow) point evaluation
        HairModel m;
        m.sigma_a = rq.sigmas[k];
        m.lobes.assign(rq.roughness[r].begin(), rq.roughness[r].begin() + 3);
        m.residual = rq.roughness[r][3];
        const DualScatteringPoint ref = dual_scattering(m, rq.thetas[t]);
        INFO("sigma_a " << rq.sigmas[k] << " roughness " << r << " theta_i " << rq.thetas[t]);
        CHECK(a.a_f == Approx(ref.a_f).margin(2e-7));
        CHECK(a.a_b == Approx(ref.a_b).margin(2e-7));
        CHECK(a.energy_total == Approx(ref.energy_total).margin(2e-7));
        CHECK(a.alpha_b == Approx(ref.alpha_b).margin(2e-7));
        CHECK(a.backscatter.sigma_b == Approx(ref.backscatter.sigma_b).margin(2e-7));
        worst = std::max({worst, std::abs(a.a_f - ref.a_f), std::abs(a.a_b - ref.a_b), std::abs(a.energy_total - ref.energy_total)});
      }
  WARN("dual-scattering grid (513 theta_d nodes, cubic) against the point evaluation (no interpolation): max |error| = " << worst);
}

TEST_CASE("HDRP's unit-attenuation azimuthal distribution against quadrature of the detector", "[dual_scattering][unity]") {
  const std::vector<double> betas = {0.01, 0.1, 0.8};
  const std::vector<double> phis = {0.0, 1.0, 2.5, pi, -3.0, 5.0};
  double worst = 0.0;
  GaussLegendreCache rules;
  for (int p = 0; p <= 2; ++p)
    for (double theta_d : {0.2, 1.0}) {
      std::vector<double> out;
      unit_attenuation_np(1.55, p, theta_d, betas, phis, 1e-11, out, &rules);
      const FiberGeometry g = FiberGeometry::make(1.55, theta_d);
      auto Phi = [&](double gamma) { return exit_azimuth(p, gamma, std::asin(std::sin(gamma) * g.inv_eta_prime)); };
      for (std::size_t b = 0; b < betas.size(); ++b)
        for (std::size_t j = 0; j < phis.size(); ++j) {
          // ½∫ D(φ − Φ) dh over h in [−1, 1] = ∫_0^{π/2} ½ [D(φ − Φ(γ)) + D(φ + Φ(γ))] cos γ dγ.
          std::vector<double> bp = {0.0, pi / 2};
          for (double f : {phis[j], -phis[j]})
            for (double r : azimuthal_roots(g, p, f)) {
              bp.push_back(std::abs(r));
              for (double w = betas[b] / 4; w < 1.5; w *= 4) bp.push_back(std::abs(r) + w), bp.push_back(std::abs(r) - w);
            }
          std::erase_if(bp, [](double x) { return x < 0.0 || x > pi / 2; });
          const double ref = integrate(
              [&](double gamma) {
                return 0.5 * (gaussian_detector(betas[b], phis[j] - Phi(gamma)) + gaussian_detector(betas[b], phis[j] + Phi(gamma))) * std::cos(gamma);
              },
              bp, 1e-11);
          const double v = out[b * phis.size() + j];
          INFO("p " << p << " theta_d " << theta_d << " beta " << betas[b] << " phi " << phis[j]);
          CHECK(v == Approx(ref).margin(1e-8 * std::max(1.0, ref)));
          worst = std::max(worst, std::abs(v - ref) / std::max(1.0, ref));
        }
    }
  WARN("unit-attenuation N_p against quadrature: max error = " << worst);
}

TEST_CASE("Roughness and absorption mappings of the presets", "[dual_scattering][presets]") {
  EngineConfig ue;
  ue.preset = "unreal-hair-strands";
  const auto ue_specs = engine_preset_tables(ue, true);
  REQUIRE(ue_specs.size() == 2);
  const RoughnessMapping& m = ue_specs[0].roughness;
  const auto lobes = m.lobes_at(0.5);
  REQUIRE(lobes.size() == 4);
  CHECK(lobes[0].beta_m == Approx(0.25));
  CHECK(lobes[1].beta_n == Approx(0.125));
  CHECK(lobes[2].beta_m == Approx(0.5));
  CHECK(lobes[3].beta_m == Approx(0.5));
  CHECK(lobes[0].alpha == Approx(-0.07));
  CHECK(m.lobes_at(0.0)[0].beta_m == Approx(1.0 / (255.0 * 255.0)));  // the preset clamps to 1/255
  // The Unreal axes: texel x at sin θ = (x + ½)/64, texel z at √c = (z + ½)/16.
  const auto ta = ue_specs[0].axes[2].nodes(), ca = ue_specs[0].axes[0].nodes();
  for (int x : {0, 17, 63}) CHECK(std::sin(ta[static_cast<std::size_t>(x)]) == Approx((x + 0.5) / 64).epsilon(1e-14));
  for (int z : {0, 9, 15}) CHECK(std::sqrt(ca[static_cast<std::size_t>(z)]) == Approx((z + 0.5) / 16).epsilon(1e-14));
  CHECK(ue_specs[0].absorption.sigma_a(std::exp(-2.0)) == Approx(0.5));
  CHECK(std::isfinite(ue_specs[0].absorption.sigma_a(0.0)));
  // describe() / from_json() round trip (the validator rebuilds models from metadata). HDRP's textures
  // are not parameterised this way: test_hdrp_kernels checks them against HDRP's own kernels.
  const RoughnessMapping back = RoughnessMapping::from_json(ue_specs[0].roughness.describe());
  CHECK(back.lobes_at(0.3)[1].beta_m == ue_specs[0].roughness.lobes_at(0.3)[1].beta_m);
  CHECK(back.lobes_at(0.3)[2].alpha == ue_specs[0].roughness.lobes_at(0.3)[2].alpha);
  CHECK_THROWS_AS(m.lobes_at(1.5), DomainError);
}

TEST_CASE("Narrow longitudinal lobes: the theta_r integrals find peaks far narrower than a Gauss-Kronrod panel", "[dual_scattering][domain]") {
  // Without breakpoints around the peak every Kronrod node of a panel next to a lobe of width
  // β ≲ 1e−3 misses it and the integral comes out 0 or 1/2 with a converged estimate.
  for (double beta : {3e-4, 6e-5, 1e-6})
    for (double theta_i : {0.0078, -0.9, 1.5}) {
      INFO("beta " << beta << " theta_i " << theta_i);
      CHECK(longitudinal_energy_deon(beta * beta, 0.0, theta_i).value[0] == Approx(1.0).margin(1e-9));
      // A narrow tilted lobe puts its unit mass in θ* = θr − α at θ* = −θi: its energy is cos(α − θi)/cos θi.
      // (At θi = 1.5 the peak sits 8e−4 from the pole, where cos θr varies on the lobe's own scale.)
      const double limit = std::cos(-0.07 - theta_i) / std::cos(theta_i);
      CHECK(longitudinal_energy_deon(beta * beta, -0.07, theta_i).value[0] == Approx(limit).epsilon(theta_i > 1.4 ? 1e-3 : 1e-6));
      const HairModel m = HairModel::uniform(1.55, 0.0, beta, 3, true);
      CHECK(directional_albedo(m, theta_i).total == Approx(1.0).margin(1e-8));
      const DualScatteringPoint p = dual_scattering(m, theta_i);
      CHECK(p.energy_total == Approx(1.0).margin(1e-8));
      CHECK(p.a_f + p.a_b == Approx(1.0).margin(1e-8));
    }
}

TEST_CASE("Dual scattering stays finite over the domain: grazing, tiny and huge roughness, no and extreme absorption, tilts",
          "[dual_scattering][domain]") {
  auto finite_point = [](const DualScatteringPoint& p) {
    bool ok = std::isfinite(p.energy_total) && std::isfinite(p.a_f) && std::isfinite(p.a_b) && std::isfinite(p.alpha_f) &&
              std::isfinite(p.alpha_b) && std::isfinite(p.beta_f2) && std::isfinite(p.beta_b2) && std::isfinite(p.backscatter.A_b) &&
              std::isfinite(p.backscatter.delta_b) && std::isfinite(p.backscatter.sigma_b) && std::isfinite(p.backscatter.sigma_b_mixed);
    ok = ok && p.energy_total >= 0 && p.a_f >= 0 && p.a_b >= 0 && p.beta_f2 >= 0 && p.backscatter.A_b >= 0 && p.backscatter.sigma_b >= 0;
    for (std::size_t l = 0; l < p.energy.size(); ++l) ok = ok && p.energy[l] >= 0 && p.forward[l] >= 0 && p.backward[l] >= 0;
    return ok;
  };
  DualScatteringGridRequest rq;
  rq.sigmas = {0.0, 1e5};
  for (double beta : {1e-6, 3.0})
    for (double tilt : {0.0, 0.3}) rq.roughness.push_back({{beta, beta, -tilt}, {beta, beta, tilt}, {beta, beta, tilt}, {beta, beta, tilt}});
  rq.thetas = {-1.5707963267948966, 0.0, 1.5707963267948966};
  // The output is called concurrently for distinct cells (the grid runs on every core): each
  // cell's point goes to its own slot, and the checks run here on one thread (Catch's INFO and
  // CHECK are not thread-safe; from the workers they corrupted its heap now and then).
  const std::size_t nk = rq.sigmas.size(), nr = rq.roughness.size(), nt = rq.thetas.size();
  std::vector<DualScatteringPoint> points(nk * nr * nt);
  std::vector<char> seen(points.size(), 0);
  dual_scattering_grid(rq, BakeOptions{}, "", [&](std::size_t k, std::size_t r, std::size_t t, const DualScatteringPoint& p) {
    const std::size_t i = (k * nr + r) * nt + t;
    points[i] = p;
    seen[i] = 1;
  });
  for (std::size_t k = 0; k < nk; ++k)
    for (std::size_t r = 0; r < nr; ++r)
      for (std::size_t t = 0; t < nt; ++t) {
        const std::size_t i = (k * nr + r) * nt + t;
        INFO("sigma_a " << rq.sigmas[k] << " roughness " << r << " theta_i " << rq.thetas[t]);
        REQUIRE(seen[i] == 1);
        CHECK(finite_point(points[i]));
      }
  CHECK(points.size() == 24);
  for (double sigma : {0.0, 1e5})
    for (double theta_i : {-1.5707963267948966, 1.5707963267948966}) {
      HairModel m = HairModel::uniform(1.55, sigma, 3.0, 3, true);
      CHECK(finite_point(dual_scattering(m, theta_i)));
    }
}
