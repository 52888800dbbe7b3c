#include "hairlut/bake/dual_scattering_grid.hpp"


#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>

#include "hairlut/util/angles.hpp"
#include "hairlut/physics/azimuthal_fourier.hpp"
#include "hairlut/physics/directional_albedo.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"
#include "bake_internal.hpp"

namespace hairlut {
namespace {

// Cubic Lagrange weights of a uniform grid at s = θd/h: the four nodes n0 … n0 + 3 (node −1 stands
// for node 1: the curves are even in θd) and their weights.
struct Stencil {
  int node[4];
  double w[4];
};

Stencil stencil_at(double s, int J) {
  Stencil st{};
  int j = static_cast<int>(std::floor(s));
  j = std::clamp(j, 0, J - 1);
  const int n0 = std::clamp(j - 1, -1, std::max(J - 3, -1));
  const double t = s - n0;
  st.w[0] = -(t - 1.0) * (t - 2.0) * (t - 3.0) / 6.0;
  st.w[1] = t * (t - 2.0) * (t - 3.0) / 2.0;
  st.w[2] = -t * (t - 1.0) * (t - 3.0) / 2.0;
  st.w[3] = t * (t - 1.0) * (t - 2.0) / 6.0;
  for (int i = 0; i < 4; ++i) st.node[i] = std::abs(n0 + i);
  return st;
}

double apply(const Stencil& st, const double* y) {
  return std::max(0.0, st.w[0] * y[st.node[0]] + st.w[1] * y[st.node[1]] + st.w[2] * y[st.node[2]] + st.w[3] * y[st.node[3]]);
}

}  // namespace

DualScatteringGridStats dual_scattering_grid(const DualScatteringGridRequest& rq, const BakeOptions& opt, const std::string& stage,
                                             const DualScatteringGridOutput& out) {
  require_greater("eta", rq.eta, 1.0, "must be a finite number > 1");
  if (rq.lobes < 1 || rq.lobes > 64) throw_domain_error("lobes", "must lie in [1, 64]", static_cast<long long>(rq.lobes));
  if (rq.theta_d_intervals < 8 || rq.theta_d_intervals > 65536)
    throw_domain_error("theta_d_intervals", "must lie in [8, 65536]", static_cast<long long>(rq.theta_d_intervals));
  for (double s : rq.sigmas) require_non_negative("sigma_a", s);
  std::vector<double> thetas;
  for (double t : rq.thetas) thetas.push_back(checked_inclination("theta_i", t));
  const int P = rq.lobes;
  const std::size_t L = static_cast<std::size_t>(P) + (rq.residual ? 1 : 0);
  for (std::size_t r = 0; r < rq.roughness.size(); ++r) {
    if (rq.roughness[r].size() != L)
      throw DomainError("roughness[" + std::to_string(r) + "] must list " + std::to_string(L) + " lobes (got " +
                        std::to_string(rq.roughness[r].size()) + ")");
    HairModel m;
    m.eta = rq.eta;
    m.lobes.assign(rq.roughness[r].begin(), rq.roughness[r].begin() + P);
    if (rq.residual) m.residual = rq.roughness[r].back();
    try {
      m.validate();
    } catch (const DomainError& e) {
      throw DomainError("roughness[" + std::to_string(r) + "]: " + e.what());
    }
  }
  const std::size_t K = rq.sigmas.size(), R = rq.roughness.size(), T = thetas.size();
  DualScatteringGridStats stats;
  stats.cells = K * R * T;
  if (stats.cells == 0) return stats;
  const auto rules = rq.rules ? rq.rules : std::make_shared<GaussLegendreCache>();
  const double tol = rq.fourier_tolerance;

  // Distinct azimuthal widths per explicit lobe, split into the Fourier and the direct sets.
  std::vector<std::vector<double>> widths(static_cast<std::size_t>(P));
  for (int p = 0; p < P; ++p) {
    auto& w = widths[static_cast<std::size_t>(p)];
    for (const auto& lobes : rq.roughness) w.push_back(lobes[static_cast<std::size_t>(p)].beta_n);
    std::sort(w.begin(), w.end());
    w.erase(std::unique(w.begin(), w.end()), w.end());
  }
  auto width_index = [&](int p, double beta) {
    const auto& w = widths[static_cast<std::size_t>(p)];
    return static_cast<std::size_t>(std::lower_bound(w.begin(), w.end(), beta) - w.begin());
  };
  std::vector<std::size_t> first_fourier(static_cast<std::size_t>(P));  // widths[p][i] for i ≥ this use Fourier
  for (int p = 0; p < P; ++p) {
    const auto& w = widths[static_cast<std::size_t>(p)];
    std::size_t i = 0;
    // β · N ≤ 1 leaves e^{−N²β²/2} ≥ e^{−1/2}: far more than the allowed terms (and fourier_terms
    // refuses β that would need millions).
    auto fourier_ok = [&](double beta) { return beta * rq.fourier_max_terms > 1.0 && fourier_terms(beta, tol) <= rq.fourier_max_terms; };
    while (i < w.size() && !fourier_ok(w[i])) ++i;
    first_fourier[static_cast<std::size_t>(p)] = i;
    stats.direct_widths += i;
    stats.fourier_widths += w.size() - i;
  }

  // ---- Curves over θd: e[l][k][j]; half[p][width][k] holds b and f at [2j], [2j + 1].
  const int J = rq.theta_d_intervals;
  const std::size_t nodes = static_cast<std::size_t>(J) + 1;
  // Nodes θd_j = (π/2) sin((π/2) j/J): uniform in u = (2/π) asin(2θd/π), dense near θd = π/2, where
  // the halves of grazing paths change fastest; the curves stay even in u about 0.
  auto theta_d_of = [J](std::size_t j) { return std::min(kHalfPi, kHalfPi * std::sin(kHalfPi * static_cast<double>(j) / J)); };
  auto grid_coordinate = [J](double theta_d) {
    return static_cast<double>(J) * std::asin(std::clamp(theta_d / kHalfPi, 0.0, 1.0)) / kHalfPi;
  };
  std::vector<std::vector<std::vector<double>>> energy(L, std::vector<std::vector<double>>(K, std::vector<double>(nodes)));
  std::vector<std::vector<std::vector<std::vector<double>>>> half(static_cast<std::size_t>(P));
  for (int p = 0; p < P; ++p)
    half[static_cast<std::size_t>(p)].assign(widths[static_cast<std::size_t>(p)].size(),
                                             std::vector<std::vector<double>>(K, std::vector<double>(2 * nodes)));
  const GaussLegendreRule energy_rule(rq.options.energy_order);
  std::atomic<std::size_t> unconverged{0};
  detail::parallel_for(nodes, opt, stage + " (azimuthal halves)", K, [&](std::size_t j) {
    const double theta_d = theta_d_of(j);
    const FiberGeometry g = FiberGeometry::make(rq.eta, theta_d);
    for (std::size_t k = 0; k < K; ++k) {
      const auto e = lobe_energies(AttenuationSlice(rq.eta, theta_d, rq.sigmas[k], rq.path), LobeSet{P, rq.residual}, energy_rule);
      for (std::size_t l = 0; l < L; ++l) energy[l][k][j] = e[l];
    }
    std::vector<double> C, two(2 * K);
    for (int p = 0; p < P; ++p) {
      const auto& w = widths[static_cast<std::size_t>(p)];
      const std::size_t ff = first_fourier[static_cast<std::size_t>(p)];
      auto& hp = half[static_cast<std::size_t>(p)];
      if (ff < w.size()) {
        const int N = fourier_terms(w[ff], tol);
        const FiberNodes fn = FiberNodes::make(g, rq.path, rules->get(fourier_nodes(N, p, g, tol)));
        fourier_coefficients(fn, g, p, rq.sigmas, N, C);
        for (std::size_t i = ff; i < w.size(); ++i)
          for (std::size_t k = 0; k < K; ++k) {
            const HalfRangeEnergy hr = half_range_fourier(std::span<const double>(C).subspan(k), K, w[i], tol);
            hp[i][k][2 * j] = hr.backward;
            hp[i][k][2 * j + 1] = hr.forward;
          }
      }
      for (std::size_t i = 0; i < ff; ++i) {
        if (!half_range_direct(g, rq.path, p, rq.sigmas, w[i], two, 1e-10)) ++unconverged;
        for (std::size_t k = 0; k < K; ++k) {
          hp[i][k][2 * j] = two[2 * k];
          hp[i][k][2 * j + 1] = two[2 * k + 1];
        }
      }
    }
  });

  // ---- Cells: one work item per (roughness, incidence), every absorption at once (M_p does not
  // depend on σa). Components: [k][l][energy, forward, backward].
  detail::parallel_for(R * T, opt, stage, K, [&](std::size_t item) {
    const std::size_t r = item / T, t = item % T;
    const double theta_i = thetas[t];
    const std::vector<LobeParams>& lobes = rq.roughness[r];
    std::vector<double> bp;
    for (const LobeParams& l : lobes) add_longitudinal_breakpoints(bp, l.beta_m, l.alpha, theta_i);
    std::erase_if(bp, [](double x) { return !(x > -kHalfPi && x < kHalfPi); });
    bp.push_back(-kHalfPi);
    bp.push_back(kHalfPi);
    std::sort(bp.begin(), bp.end());
    bp.erase(std::unique(bp.begin(), bp.end()), bp.end());
    std::vector<const std::vector<std::vector<double>>*> lobe_half(static_cast<std::size_t>(P));
    for (int p = 0; p < P; ++p)
      lobe_half[static_cast<std::size_t>(p)] = &half[static_cast<std::size_t>(p)][width_index(p, lobes[static_cast<std::size_t>(p)].beta_n)];
    std::vector<double> M(L);
    auto integrand = [&](double theta_r, std::span<double> v) {
      const double c = std::cos(theta_r);
      for (std::size_t l = 0; l < L; ++l)
        M[l] = longitudinal_deon_tilted(lobes[l].beta_m * lobes[l].beta_m, lobes[l].alpha, theta_i, theta_r) * c;
      const double s = grid_coordinate(0.5 * std::abs(theta_r - theta_i));
      const Stencil st = stencil_at(s, J);
      // The odd stencil nodes of the interleaved (b, f) curves: node n → [2n] and [2n + 1].
      Stencil sb = st, sf = st;
      for (int i = 0; i < 4; ++i) sb.node[i] = 2 * st.node[i], sf.node[i] = 2 * st.node[i] + 1;
      for (std::size_t k = 0; k < K; ++k) {
        double* o = v.data() + k * 3 * L;
        for (std::size_t l = 0; l < L; ++l) {
          const double e = apply(st, energy[l][k].data());
          double f = 0.5 * e, b = 0.5 * e;  // the residual is uniform in φ
          if (static_cast<int>(l) < P) {
            const double* y = (*lobe_half[l])[k].data();
            b = apply(sb, y);
            f = apply(sf, y);
          }
          o[3 * l] = M[l] * e;
          o[3 * l + 1] = M[l] * f;
          o[3 * l + 2] = M[l] * b;
        }
      }
    };
    {
      AdaptiveOptions ao;
      ao.rel_tol = rq.options.rel_tol;
      ao.abs_tol = 1e-14;
      const AdaptiveResult res = integrate_adaptive(integrand, 3 * L * K, bp, ao);
      if (!res.converged) ++unconverged;
      for (std::size_t k = 0; k < K; ++k) {
        DualScatteringPoint pt;
        pt.theta_i = theta_i;
        const double* o = res.value.data() + k * 3 * L;
        for (std::size_t l = 0; l < L; ++l) {
          pt.energy.push_back(std::max(0.0, o[3 * l]));
          pt.forward.push_back(std::max(0.0, o[3 * l + 1]));
          pt.backward.push_back(std::max(0.0, o[3 * l + 2]));
        }
        finish_dual_scattering(pt, lobes, rq.options.density_factor);
        pt.converged = res.converged;
        out(k, r, t, pt);
      }
    }
  });
  stats.unconverged = unconverged.load();
  return stats;
}

}  // namespace hairlut
