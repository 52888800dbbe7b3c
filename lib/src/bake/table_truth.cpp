#include "hairlut/bake/table_truth.hpp"

#include <algorithm>
#include <cmath>

#include "hairlut/util/angles.hpp"
#include "hairlut/physics/azimuthal_fourier.hpp"
#include "hairlut/physics/azimuthal_np.hpp"
#include "hairlut/physics/fiber_geometry.hpp"
#include "hairlut/physics/lobe_energy.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"
#include "hairlut/bake/model_kind.hpp"

namespace hairlut {
namespace {

constexpr double kWhiteFloor = 1e-3;      // a lobe absorbed below this fraction of its white value no longer counts
constexpr double kEnergyFloor = 1e-6;      // absolute floor of an energy or N_p value (dimensionless, 1/rad)

const char* kNpWords = "peak over all phi of the exact N_p of the same (beta, sigma_a, theta_d) slice, floored at 1e-3 x that peak of "
                       "the white fiber (sigma_a = 0) at the same (beta, theta_d)";
const char* kEnergyWords = "the exact value itself (relative error), floored at 1e-3 x the white fiber's (sigma_a = 0) value at the same "
                           "theta_d and at 1e-6";
const char* kMpWords = "peak over theta_r in [-pi/2, pi/2] of the exact M_p at the same (beta, theta_i)";

TableTruth peak_over_phi(TableTruth t) {
  t.peak_axis = -1;  // set by the caller (the index of phi)
  t.peak_lo = -kPi, t.peak_hi = kPi;
  t.white_floor = kWhiteFloor;
  t.absolute_floor = 1e-300;
  t.denominator = kNpWords;
  return t;
}

// N_p(β, φ) of lobe p at (θd, σa) by the Fourier series (azimuthal_fourier.hpp) to 1e−10 for every
// β ≥ beta_min: the coefficients once, each β's weights once per β (the last one is kept), then
// N terms per φ. For the peak search only (the points use the Gauss–Legendre reference). The
// rules come from `rules`, shared by every slab of a table: a new slab (each point of the
// worst-point search's climb) would otherwise build its rule again, O(order²), and near η = 1 the
// order reaches about 1700 (fourier_nodes), which made rule building 98% of a validation.
PointFunction fourier_np(double eta, AbsorptionPath path, double theta_d, double sigma, int p, double beta_min, int beta_axis, double beta_fixed,
                         int phi_axis, GaussLegendreCache& rules) {
  constexpr double kTolerance = 1e-10;
  const FiberGeometry g = FiberGeometry::make(eta, theta_d);
  const int terms = fourier_terms(beta_min, kTolerance);
  const GaussLegendreRule& rule = rules.get(fourier_nodes(terms, p, g, kTolerance));
  struct State {
    std::vector<double> c, w;
    double beta = -1.0;
  };
  auto st = std::make_shared<State>();
  fourier_coefficients(g, path, p, std::span<const double>(&sigma, 1), terms, rule, st->c);
  return [=](const std::vector<double>& y) {
    const double beta = beta_axis >= 0 ? y[static_cast<std::size_t>(beta_axis)] : beta_fixed;
    if (beta != st->beta) {
      st->w.assign(st->c.size(), 0.0);
      for (std::size_t n = 0; n < st->c.size(); ++n) {
        const double nb = static_cast<double>(n) * beta;
        st->w[n] = st->c[n] * (n == 0 ? 1.0 : 2.0 * std::exp(-0.5 * nb * nb)) / kTwoPi;
      }
      st->beta = beta;
    }
    // cos nφ by rotating (cos φ, sin φ) once per term, not one cos call per term: the search
    // sums a hundred terms or more at each point it climbs through, and the rotation's rounding,
    // about an ulp per term, stays far below the series' 1e−10.
    const double phi = y[static_cast<std::size_t>(phi_axis)];
    const double c1 = std::cos(phi), s1 = std::sin(phi);
    double cn = 1.0, sn = 0.0, sum = 0.0;
    for (std::size_t n = 0; n < st->w.size(); ++n) {
      sum += st->w[n] * cn;
      const double next = cn * c1 - sn * s1;
      sn = sn * c1 + cn * s1;
      cn = next;
    }
    return sum;
  };
}

// Where N_p of lobe p has features in |φ| at θd: the lobe's edges Φ(p, ±1) and, for p ≥ 2 when
// it exists, the caustic Φ(p, ±h_c) (dΦ/dh = 0), each wrapped to [0, π].
std::vector<double> np_features(double eta, double theta_d, int p) {
  const FiberGeometry g = FiberGeometry::make(eta, std::clamp(theta_d, -kHalfPi, kHalfPi));
  std::vector<double> out;
  auto add = [&](double gamma_i) {
    const double phi = wrap_azimuth(exit_azimuth(p, gamma_i, gamma_transmitted(std::sin(gamma_i), g.inv_eta_prime)));
    out.push_back(std::abs(phi));
  };
  add(kHalfPi), add(-kHalfPi);
  if (const double gc = caustic_gamma(p, g); gc >= 0.0) add(gc), add(-gc);
  return out;
}

}  // namespace

TableTruth with_np_denominator(TableTruth t, int phi_axis) {
  t = peak_over_phi(std::move(t));
  t.peak_axis = phi_axis;
  return t;
}

TableTruth with_energy_denominator(TableTruth t) {
  t.white_floor = kWhiteFloor, t.absolute_floor = kEnergyFloor, t.denominator = kEnergyWords;
  return t;
}

TableTruth with_mp_denominator(TableTruth t, int theta_r_axis) {
  t.peak_axis = theta_r_axis;
  t.peak_lo = -kHalfPi, t.peak_hi = kHalfPi;
  t.denominator = kMpWords;
  return t;
}

std::optional<TableTruth> table_truth(const Table& t, const TruthModel& info, std::shared_ptr<const GaussLegendreRule> rule) {
  std::vector<std::string> dims;
  for (const GridAxis& a : t.axes) dims.push_back(a.name);
  if (info.model && info.settings)  // a model with stages of its own (lib/models/) judges its tables
    if (std::optional<TableTruth> own = info.model->truth(t, *info.settings)) return own;
  const int p = t.attributes.value("p", -1);
  const bool is_residual = t.attributes.value("lobe", std::string()) == "residual";
  // Exact N_p: Gauss–Legendre of order 1024 in γ (converged to ~1e−14 for β ≥ 1°, see the
  // tests), the adaptive reference below 1°.
  auto np_slab = [info, rule](double theta_d, double sigma, int lobe) {
    const AttenuationSlice slice(info.eta, theta_d, sigma, info.path);
    auto slab = std::make_shared<NpQuadratureSlab>(slice, lobe, *rule, IntegrationVariable::gamma);
    return std::function<double(double, double)>([slice, slab, lobe](double beta, double phi) {
      if (beta < radians(1.0)) return azimuthal_np_reference(slice, lobe, beta, phi, 1e-9).value[0];
      return (*slab)(beta, phi);
    });
  };
  auto energy_of = [info](double theta_d, double sigma, int lobe_index, bool residual) {
    const AttenuationSlice slice(info.eta, theta_d, sigma, info.path);
    const auto e = lobe_energies_reference(slice, {info.explicit_lobes, true}, 1e-13).value;
    return residual ? e.back() : e[static_cast<std::size_t>(lobe_index)];
  };
  if (t.quantity == "N_p" && dims == std::vector<std::string>{"beta", "sigma_a", "theta_d", "phi"} && p >= 0) {
    auto build = [=](bool white) {
      return [=](const std::vector<double>& x) {
        auto f = np_slab(x[2], white ? 0.0 : x[1], p);
        return PointFunction([f](const std::vector<double>& y) { return f(y[0], y[3]); });
      };
    };
    TableTruth tr;
    tr.slab_axes = {1, 2};
    tr.make = build(false);
    tr.make_white = build(true);
    const double beta_min = std::max(radians(0.25), t.axes[0].nodes().front());
    tr.make_fast = [=, rules = std::make_shared<GaussLegendreCache>()](const std::vector<double>& x, bool white) {
      return fourier_np(info.eta, info.path, x[2], white ? 0.0 : x[1], p, beta_min, 0, 0.0, 3, *rules);
    };
    tr = peak_over_phi(tr);
    tr.peak_axis = 3;
    tr.peak_lo = 0.0;  // N_p of a circular fiber is even in phi
    tr.features = [eta = info.eta, p](const std::vector<double>& x) { return np_features(eta, x[2], p); };
    return tr;
  }
  if (t.quantity == "N_p" && dims == std::vector<std::string>{"channel", "theta_d", "phi"} && p >= 0 && t.attributes.contains("sigma_a")) {
    const auto sig = t.attributes["sigma_a"].get<std::vector<double>>();
    const double beta = t.attributes.value("beta", 0.1);
    auto build = [=](bool white) {
      return [=](const std::vector<double>& x) {
        const auto c = static_cast<std::size_t>(std::clamp<long>(std::lround(x[0]), 0, static_cast<long>(sig.size()) - 1));
        auto f = np_slab(x[1], white ? 0.0 : sig[c], p);
        return PointFunction([f, beta](const std::vector<double>& y) { return f(beta, y[2]); });
      };
    };
    TableTruth tr;
    tr.slab_axes = {0, 1};
    tr.make = build(false);
    tr.make_white = build(true);
    tr.make_fast = [=, rules = std::make_shared<GaussLegendreCache>()](const std::vector<double>& x, bool white) {
      const auto c = static_cast<std::size_t>(std::clamp<long>(std::lround(x[0]), 0, static_cast<long>(sig.size()) - 1));
      return fourier_np(info.eta, info.path, x[1], white ? 0.0 : sig[c], p, std::max(beta, radians(0.25)), -1, beta, 2, *rules);
    };
    tr = peak_over_phi(tr);
    tr.peak_axis = 2;
    tr.peak_lo = 0.0;  // N_p of a circular fiber is even in phi
    tr.features = [eta = info.eta, p](const std::vector<double>& x) { return np_features(eta, x[1], p); };
    tr.denominator = "peak over all phi of the exact N_p of the same (channel, theta_d) slice at the material's beta and the "
                     "channel's sigma_a, floored at 1e-3 x that peak of the white fiber (sigma_a = 0) at the same theta_d";
    return tr;
  }
  // Energies and the residual over (σa, θd), or a material's over (channel, θd) with σa per
  // channel from the table's attribute.
  const bool per_material = dims == std::vector<std::string>{"channel", "theta_d"} && t.attributes.contains("sigma_a");
  if ((t.quantity == "energy" || (t.quantity == "N_p" && is_residual)) && (dims == std::vector<std::string>{"sigma_a", "theta_d"} || per_material)) {
    const std::vector<double> sig = per_material ? t.attributes["sigma_a"].get<std::vector<double>>() : std::vector<double>();
    if (per_material && sig.empty()) return std::nullopt;
    const bool res = is_residual;
    const double scale = t.quantity == "N_p" ? 1.0 / kTwoPi : 1.0;
    auto build = [=](bool white) {
      return [=](const std::vector<double>&) {
        return PointFunction([=](const std::vector<double>& y) {
          const double sigma =
              per_material ? sig[static_cast<std::size_t>(std::clamp<long>(std::lround(y[0]), 0, static_cast<long>(sig.size()) - 1))] : y[0];
          return scale * energy_of(y[1], white ? 0.0 : sigma, res ? 0 : p, res);
        });
      };
    };
    TableTruth tr;
    tr.make = build(false);
    tr.make_white = build(true);
    tr.white_floor = kWhiteFloor, tr.absolute_floor = kEnergyFloor * scale;
    tr.denominator = kEnergyWords;
    return tr;
  }
  if (t.quantity == "M_p" && (dims == std::vector<std::string>{"beta", "theta_i", "theta_r"} || dims == std::vector<std::string>{"theta_i", "theta_r"})) {
    const double alpha = t.attributes.value("alpha", 0.0);
    const bool with_beta = dims.size() == 3;
    const double beta = t.attributes.value("beta", 0.1);
    TableTruth tr;
    tr.make = [=](const std::vector<double>&) {
      return PointFunction([=](const std::vector<double>& y) {
        return with_beta ? longitudinal_deon_tilted(y[0] * y[0], alpha, y[1], y[2]) : longitudinal_deon_tilted(beta * beta, alpha, y[0], y[1]);
      });
    };
    tr.peak_axis = with_beta ? 2 : 1;
    tr.peak_lo = -kHalfPi, tr.peak_hi = kHalfPi;
    tr.denominator = kMpWords;
    // The specular cone of the tilted lobe: M(v, θi, θr − α) peaks near θr = α − θi.
    tr.features = [=](const std::vector<double>& x) { return std::vector<double>{alpha - x[with_beta ? 1 : 0]}; };
    tr.sweep_cells = true;
    return tr;
  }
  for (const TableKind* k : table_kinds())
    if (std::optional<TableTruth> tr = k->truth(t)) return tr;
  return std::nullopt;
}

}  // namespace hairlut
