#include "hairlut/physics/marschner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "hairlut/physics/azimuthal_np.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/fresnel.hpp"
#include "hairlut/util/quadrature.hpp"
#include "monotone_roots.hpp"

namespace hairlut {
namespace {

constexpr double kPi3 = kPi * kPi * kPi;

void check_lobe(int p) {
  if (p < 0 || p > 2) throw_domain_error("p", "must be 0 (R), 1 (TT) or 2 (TRT) in Marschner's model", static_cast<long long>(p));
}

// cos γt = √(1 − (sin γi / η')²) for the geometry's 1/η'.
double cos_gamma_t(double gamma_i, double inv_eta_prime) {
  const double s = std::sin(gamma_i) * inv_eta_prime;
  return std::sqrt((1.0 - s) * (1.0 + s));
}

// Φ(p, γi) of the exact or the cubic map, unwrapped.
double map_phi(MarschnerRoots roots, int p, double gamma_i, double inv_eta_prime, double c) {
  if (roots == MarschnerRoots::cubic) return cubic_exit_azimuth(p, gamma_i, c);
  return exit_azimuth(p, gamma_i, std::asin(std::sin(gamma_i) * inv_eta_prime));
}

// dΦ/dγi of the exact or the cubic map.
double map_slope(MarschnerRoots roots, int p, double gamma_i, double inv_eta_prime, double c) {
  if (roots == MarschnerRoots::cubic) return cubic_exit_azimuth_derivative(p, gamma_i, c);
  return exit_azimuth_derivative(p, std::cos(gamma_i), cos_gamma_t(gamma_i, inv_eta_prime), inv_eta_prime);
}

// The fold γ̂c ≥ 0 of the cubic map of lobe p (dΦ̂/dγ = 0), or −1 when it has none in (0, π/2):
// γ̂c² = (6pc/π − 2) π³ / (24pc).
double cubic_fold(int p, double c) {
  const double a1 = 6.0 * p * c / kPi - 2.0;
  if (p < 1 || !(a1 > 0.0)) return -1.0;
  return std::min(kHalfPi, std::sqrt(a1 * kPi3 / (24.0 * p * c)));
}

// "smoothstep(a, b, x)" of Marschner §5.2.2: 1 below a, 0 above b, 1 − (3u² − 2u³) between.
double smoothstep_down(double a, double b, double x) {
  if (!(x > a)) return 1.0;
  if (!(x < b)) return 0.0;
  const double u = (x - a) / (b - a);
  return 1.0 - u * u * (3.0 - 2.0 * u);
}

// Normalized Gaussian g(x; w) = exp(−x²/2w²)/(√(2π) w).
double gaussian(double x, double w) { return std::exp(-0.5 * (x / w) * (x / w)) / (std::sqrt(2.0 * kPi) * w); }

}  // namespace

std::string_view to_string(MarschnerRoots roots) { return roots == MarschnerRoots::exact ? "exact" : "cubic"; }

MarschnerRoots parse_marschner_roots(std::string_view text, std::string_view what) {
  if (text == "exact") return MarschnerRoots::exact;
  if (text == "cubic") return MarschnerRoots::cubic;
  throw DomainError(std::string(what) + " must be \"exact\" or \"cubic\" (got \"" + std::string(text) + "\")");
}

std::string_view to_string(EccentricFresnel e) { return e == EccentricFresnel::eta ? "eta" : "eta-star"; }

EccentricFresnel parse_eccentric_fresnel(std::string_view text, std::string_view what) {
  if (text == "eta") return EccentricFresnel::eta;
  if (text == "eta-star") return EccentricFresnel::eta_star;
  throw DomainError(std::string(what) + " must be \"eta\" or \"eta-star\" (got \"" + std::string(text) + "\")");
}

void MarschnerParams::validate() const {
  require_greater("eta", eta, 1.0, "must be a finite number > 1");
  require_non_negative("caustic.k_G", caustic.k_G);
  require_positive("caustic.w_c", caustic.w_c);
  if (caustic.w_c > kPi) throw_domain_error("caustic.w_c", "must be at most pi radians", caustic.w_c);
  require_positive("caustic.delta_eta_prime", caustic.delta_eta_prime);
  require_positive("caustic.delta_h_max", caustic.delta_h_max);
  if (caustic.delta_h_max > 2.0) throw_domain_error("caustic.delta_h_max", "must be at most 2 (the fiber's width)", caustic.delta_h_max);
  require_positive("eccentricity", eccentricity);
  // η1* > 1 ⟺ a² > 1/2 and η2* > 1 ⟺ a² < 2, whatever η.
  if (!(eccentricity * eccentricity > 0.5 && eccentricity * eccentricity < 2.0))
    throw_domain_error("eccentricity", "must lie in (0.7071, 1.4142) so that eta* > 1 at every phi_h", eccentricity);
}

double eccentric_eta(double eta, double a, double phi_h) {
  require_greater("eta", eta, 1.0, "must be a finite number > 1");
  require_positive("eccentricity", a);
  if (!std::isfinite(phi_h)) throw_domain_error("phi_h", "must be finite", phi_h);
  const double eta1 = 2.0 * (eta - 1.0) * a * a - eta + 2.0;
  const double eta2 = 2.0 * (eta - 1.0) / (a * a) - eta + 2.0;
  return 0.5 * ((eta1 + eta2) + std::cos(2.0 * phi_h) * (eta1 - eta2));
}

double cubic_gamma_t(double gamma_i, double c) { return (3.0 * c / kPi) * gamma_i - (4.0 * c / kPi3) * gamma_i * gamma_i * gamma_i; }

double cubic_exit_azimuth(int p, double gamma_i, double c) {
  return (6.0 * p * c / kPi - 2.0) * gamma_i - (8.0 * p * c / kPi3) * gamma_i * gamma_i * gamma_i + p * kPi;
}

double cubic_exit_azimuth_derivative(int p, double gamma_i, double c) {
  return (6.0 * p * c / kPi - 2.0) - (24.0 * p * c / kPi3) * gamma_i * gamma_i;
}

// The cubic's roots come from bracketing on its monotone pieces (between ±γ̂c) rather than from
// Cardano's formula, which loses digits where the leading coefficient 8pc/π³ vanishes (θd → π/2)
// and near the double root at the fold; the roots are the same.
std::vector<double> cubic_azimuthal_roots(double inv_eta_prime, int p, double phi) {
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  if (!(inv_eta_prime >= 0.0 && inv_eta_prime < 1.0)) throw_domain_error("inv_eta_prime", "must lie in [0, 1)", inv_eta_prime);
  if (!std::isfinite(phi)) throw_domain_error("phi", "must be finite", phi);
  const double c = cubic_edge_angle(inv_eta_prime);
  std::vector<double> edges = {-kHalfPi, kHalfPi};
  if (const double gc = cubic_fold(p, c); gc > 0.0 && gc < kHalfPi) edges = {-kHalfPi, -gc, gc, kHalfPi};
  return detail::monotone_piece_roots([&](double g) { return cubic_exit_azimuth(p, g, c); }, edges, phi);
}

std::vector<AzimuthalPath> marschner_paths(const FiberGeometry& g, int p, double phi, MarschnerRoots roots) {
  const double a = g.inv_eta_prime, c = cubic_edge_angle(a);
  const std::vector<double> gammas = roots == MarschnerRoots::exact ? azimuthal_roots(g, p, phi) : cubic_azimuthal_roots(a, p, phi);
  std::vector<AzimuthalPath> paths;
  paths.reserve(gammas.size());
  for (double gamma : gammas) {
    const double slope = std::abs(map_slope(roots, p, gamma, a, c));
    const double ci = std::cos(gamma);
    paths.push_back({gamma, slope > 0.0 ? ci / (2.0 * slope) : (ci > 0.0 ? std::numeric_limits<double>::infinity() : 0.0)});
  }
  return paths;
}

TrtCaustic marschner_trt_caustic(const FiberGeometry& g, MarschnerRoots roots, const CausticParams& params) {
  TrtCaustic k;
  const double a = g.inv_eta_prime, c = cubic_edge_angle(a);
  k.delta_h = params.delta_h_max;
  if (a > 0.5) {  // η' < 2: the TRT map folds at ±γc
    k.folds = true;
    k.t = 1.0;
    if (roots == MarschnerRoots::exact) {
      k.gamma_c = caustic_gamma(2, g);  // Descartes: sin²γc = (4 − η'²)/3
      // Φ_γγ = 2p γt'' with γt'' = a (a² − 1) sin γ / cos³γt (the slope vanishes at the fold).
      const double ct = cos_gamma_t(k.gamma_c, a);
      const double phi_gg = 4.0 * a * (a * a - 1.0) * std::sin(k.gamma_c) / (ct * ct * ct);
      k.d2phi_dh2 = phi_gg / (std::cos(k.gamma_c) * std::cos(k.gamma_c));
    } else {
      k.gamma_c = std::max(0.0, cubic_fold(2, c));
      const double phi_gg = -96.0 * c * k.gamma_c / kPi3;  // Φ̂_γγ = −48pc γ/π³, p = 2
      k.d2phi_dh2 = phi_gg / (std::cos(k.gamma_c) * std::cos(k.gamma_c));
    }
    k.phi_c = std::abs(wrap_azimuth(map_phi(roots, 2, k.gamma_c, a, c)));
    if (k.d2phi_dh2 != 0.0) k.delta_h = std::min(params.delta_h_max, 2.0 * std::sqrt(2.0 * params.w_c / std::abs(k.d2phi_dh2)));
  } else {
    k.t = a > 0.0 ? smoothstep_down(2.0, 2.0 + params.delta_eta_prime, 1.0 / a) : 0.0;
  }
  if (!params.enabled) k.t = 0.0;
  return k;
}

MarschnerAttenuation::MarschnerAttenuation(double eta, double theta_d, double sigma_a, AbsorptionPath path)
    : path_(path) {
  const FiberGeometry g = FiberGeometry::make(eta, theta_d);
  require_non_negative("sigma_a", sigma_a);
  inv_eta_prime_ = g.inv_eta_prime;
  eta_double_prime_ = eta * eta * g.inv_eta_prime;  // η'' = η² cos θd / √(η² − sin²θd)
  sigma_a_prime_ = reduced_absorption(sigma_a, g);
}

double MarschnerAttenuation::operator()(int p, double gamma_i) const {
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  gamma_i = checked_inclination("gamma_i", gamma_i);
  double F = 0.0, one_minus_F = 0.0;
  detail::fresnel_bravais_unchecked(inv_eta_prime_, eta_double_prime_, std::cos(gamma_i), F, one_minus_F);
  if (p == 0) return F;
  const double ct = cos_gamma_t(gamma_i, inv_eta_prime_);
  const double length = path_ == AbsorptionPath::chord ? 2.0 * ct : 4.0 * ct * ct;
  const double T = std::exp(-sigma_a_prime_ * length);
  return one_minus_F * one_minus_F * std::pow(F, p - 1) * std::pow(T, p);
}

MarschnerAzimuthal::MarschnerAzimuthal(const MarschnerParams& params, double theta_d, double phi_h) : params_(params) {
  params_.validate();
  theta_d_ = checked_inclination("theta_d", theta_d);
  geometry_ = FiberGeometry::make(params_.eta, theta_d_);
  const double eta_trt = params_.eccentricity == 1.0 ? params_.eta : eccentric_eta(params_.eta, params_.eccentricity, phi_h);
  trt_geometry_ = FiberGeometry::make(eta_trt, theta_d_);
  eta_fresnel_trt_ = params_.eccentric_fresnel == EccentricFresnel::eta_star ? eta_trt : params_.eta;
  caustic_ = marschner_trt_caustic(trt_geometry_, params_.roots, params_.caustic);
}

MarschnerAttenuation MarschnerAzimuthal::attenuation(int p, double sigma_a) const {
  return MarschnerAttenuation(p == 2 ? eta_fresnel_trt_ : params_.eta, theta_d_, sigma_a, params_.path);
}

double MarschnerAzimuthal::caustic_weight(double phi) const {
  if (caustic_.t == 0.0) return 1.0;
  const double w = params_.caustic.w_c;
  const double x1 = wrap_azimuth(phi - caustic_.phi_c), x2 = wrap_azimuth(phi + caustic_.phi_c);
  return (1.0 - caustic_.t * std::exp(-0.5 * (x1 / w) * (x1 / w))) * (1.0 - caustic_.t * std::exp(-0.5 * (x2 / w) * (x2 / w)));
}

double MarschnerAzimuthal::caustic_lobes(double phi) const {
  const double w = params_.caustic.w_c;
  return gaussian(wrap_azimuth(phi - caustic_.phi_c), w) + gaussian(wrap_azimuth(phi + caustic_.phi_c), w);
}

void MarschnerAzimuthal::np(int p, std::span<const double> sigmas, double phi, std::span<double> out) const {
  check_lobe(p);
  if (!std::isfinite(phi)) throw_domain_error("phi", "must be finite", phi);
  const auto paths = marschner_paths(geometry(p), p, phi, params_.roots);
  const double weight = p == 2 ? caustic_weight(phi) : 1.0;
  const double lobes = p == 2 && caustic_.t > 0.0 ? caustic_lobes(phi) : 0.0;
  for (std::size_t k = 0; k < sigmas.size(); ++k) {
    const MarschnerAttenuation A = attenuation(p, sigmas[k]);
    double sum = 0.0;
    for (const AzimuthalPath& path : paths) {
      if (path.density == 0.0) continue;
      const double a = A(p, path.gamma_i);
      if (a == 0.0 || weight == 0.0) continue;  // a fold removed by the replacement (weight 0) adds 0
      sum += a * path.density * weight;
    }
    if (lobes > 0.0) sum += caustic_.t * params_.caustic.k_G * A(2, caustic_.gamma_c) * caustic_.delta_h * lobes;
    out[k] = sum;
  }
}

double MarschnerAzimuthal::np(int p, double sigma_a, double phi) const {
  double v = 0.0;
  np(p, std::span<const double>(&sigma_a, 1), phi, std::span<double>(&v, 1));
  return v;
}

double MarschnerAzimuthal::np_smooth(int p, double sigma_a, double phi) const {
  check_lobe(p);
  if (!std::isfinite(phi)) throw_domain_error("phi", "must be finite", phi);
  const MarschnerAttenuation A = attenuation(p, sigma_a);
  double sum = 0.0;
  for (const AzimuthalPath& path : marschner_paths(geometry(p), p, phi, params_.roots))
    if (path.density > 0.0) {
      const double a = A(p, path.gamma_i);
      if (a > 0.0) sum += a * path.density;
    }
  return sum;
}

void MarschnerAzimuthal::energy(int p, std::span<const double> sigmas, std::span<double> out, double rel_tol) const {
  check_lobe(p);
  const FiberGeometry& g = geometry(p);
  const double a = g.inv_eta_prime, c = cubic_edge_angle(a);
  std::vector<MarschnerAttenuation> A;
  for (double s : sigmas) A.push_back(attenuation(p, s));
  // ∫ N_p dφ = ½∫ A(h) w(Φ(h)) dh = 2 ∫_0^{π/2} ½ A(γ) w(Φ(γ)) cos γ dγ (A and w are even), the
  // push-forward of the offsets through the map the lobe uses; breakpoints at the fold and at the
  // paths reaching ±φc, where the weight w dips.
  std::vector<double> bp = {0.0, kHalfPi};
  if (p == 2 && caustic_.t > 0.0) {
    if (caustic_.folds) bp.push_back(caustic_.gamma_c);
    for (const AzimuthalPath& path : marschner_paths(g, p, caustic_.phi_c, params_.roots)) bp.push_back(std::abs(path.gamma_i));
  }
  std::sort(bp.begin(), bp.end());
  bp.erase(std::unique(bp.begin(), bp.end()), bp.end());
  AdaptiveOptions opt;
  opt.rel_tol = rel_tol;
  opt.abs_tol = 1e-15;
  const AdaptiveResult r = integrate_adaptive(
      [&](double gamma, std::span<double> v) {
        const double w = p == 2 ? caustic_weight(map_phi(params_.roots, p, gamma, a, c)) : 1.0;
        const double ci = std::cos(gamma);
        for (std::size_t k = 0; k < A.size(); ++k) v[k] = A[k](p, gamma) * w * ci;
      },
      A.size(), bp, opt);
  const double lobe_mass = 2.0 * std::erf(kPi / (std::sqrt(2.0) * params_.caustic.w_c));  // Σ± ∫_{−π}^{π} g(wrap(φ ∓ φc)) dφ
  for (std::size_t k = 0; k < A.size(); ++k) {
    out[k] = r.value[k];
    if (p == 2 && caustic_.t > 0.0) out[k] += caustic_.t * params_.caustic.k_G * A[k](2, caustic_.gamma_c) * caustic_.delta_h * lobe_mass;
  }
}

double marschner_np(const MarschnerParams& params, int p, double sigma_a, double theta_d, double phi, double phi_h) {
  return MarschnerAzimuthal(params, theta_d, phi_h).np(p, sigma_a, phi);
}

MarschnerLobes MarschnerLobes::table1(double alpha_r, double beta_r) {
  require_positive("beta_R", beta_r);
  alpha_r = checked_inclination("alpha_R", alpha_r);
  MarschnerLobes l;
  l.alpha[0] = alpha_r, l.alpha[1] = -alpha_r / 2.0, l.alpha[2] = -1.5 * alpha_r;
  l.beta[0] = beta_r, l.beta[1] = beta_r / 2.0, l.beta[2] = 2.0 * beta_r;
  return l;
}

MarschnerAlbedo marschner_directional_albedo(const MarschnerParams& params, const MarschnerLobes& lobes, GaussianArgument argument,
                                             double sigma_a, double theta_i, double phi_h, double rel_tol) {
  params.validate();
  require_non_negative("sigma_a", sigma_a);
  theta_i = checked_inclination("theta_i", theta_i);
  for (int p = 0; p < 3; ++p) require_positive("beta", lobes.beta[p]);
  std::vector<double> bp = {-kHalfPi, kHalfPi};
  for (int p = 0; p < 3; ++p) {  // each lobe's centre θh = α_p, i.e. θr = 2α_p − θi
    const double centre = 2.0 * lobes.alpha[p] - theta_i;
    if (std::abs(centre) < kHalfPi) bp.push_back(centre);
  }
  std::sort(bp.begin(), bp.end());
  const double sig[1] = {sigma_a};
  AdaptiveOptions opt;
  opt.rel_tol = rel_tol;
  opt.abs_tol = 1e-14;
  const AdaptiveResult r = integrate_adaptive(
      [&](double theta_r, std::span<double> out) {
        const double theta_d = 0.5 * (theta_r - theta_i);
        const MarschnerAzimuthal az(params, theta_d, phi_h);
        const double c2 = std::cos(theta_r) * std::cos(theta_r);
        for (int p = 0; p < 3; ++p) {
          double e = 0.0;
          az.energy(p, sig, std::span<double>(&e, 1), 1e-10);
          out[static_cast<std::size_t>(p)] = longitudinal_gaussian(lobes.beta[p], lobes.alpha[p], theta_i, theta_r, argument) * e * c2;
        }
      },
      3, bp, opt);
  MarschnerAlbedo m;
  m.theta_i = theta_i;
  m.per_lobe = r.value;
  for (double v : r.value) m.total += v;
  m.converged = r.converged;
  return m;
}

nlohmann::json marschner_json(const MarschnerConfig& m) {
  const CausticParams& k = m.params.caustic;
  return {{"roots", to_string(m.params.roots)},
          {"caustic", {{"k_G", k.k_G}, {"w_c", k.w_c}, {"delta_eta_prime", k.delta_eta_prime}, {"delta_h_max", k.delta_h_max}}},
          {"eccentricity", m.params.eccentricity},
          {"eccentric_fresnel", to_string(m.params.eccentric_fresnel)},
          {"longitudinal", {{"alpha_R", m.alpha_r}, {"argument", m.argument == GaussianArgument::theta_h ? "theta-h" : "2theta-h"},
                            {"relations", "alpha_TT = -alpha_R/2, alpha_TRT = -3 alpha_R/2, beta_TT = beta_R/2, beta_TRT = 2 beta_R (Table 1)"}}}};
}

MarschnerConfig marschner_from_json(const nlohmann::json& j, double eta, AbsorptionPath path) {
  MarschnerConfig m;
  try {
    m.params.eta = eta;
    m.params.path = path;
    m.params.roots = parse_marschner_roots(j.at("roots").get<std::string>(), "marschner.roots");
    const auto& k = j.at("caustic");
    m.params.caustic.k_G = k.at("k_G").get<double>();
    m.params.caustic.w_c = k.at("w_c").get<double>();
    m.params.caustic.delta_eta_prime = k.at("delta_eta_prime").get<double>();
    m.params.caustic.delta_h_max = k.at("delta_h_max").get<double>();
    m.params.eccentricity = j.at("eccentricity").get<double>();
    m.params.eccentric_fresnel = parse_eccentric_fresnel(j.at("eccentric_fresnel").get<std::string>(), "marschner.eccentric_fresnel");
    const auto& l = j.at("longitudinal");
    m.alpha_r = l.at("alpha_R").get<double>();
    const std::string arg = l.at("argument").get<std::string>();
    if (arg != "theta-h" && arg != "2theta-h") throw DomainError("marschner.longitudinal.argument must be theta-h or 2theta-h (got \"" + arg + "\")");
    m.argument = arg == "theta-h" ? GaussianArgument::theta_h : GaussianArgument::two_theta_h;
  } catch (const nlohmann::json::exception& e) {
    throw DomainError(std::string("marschner settings malformed (") + e.what() + ")");
  }
  try {
    m.params.validate();
  } catch (const DomainError& e) {
    throw DomainError("marschner." + std::string(e.what()));
  }
  // The config schema's bounds, for settings read back from a file.
  if (!(m.params.caustic.w_c >= 0.5 * kPi / 180.0))
    throw DomainError("marschner.caustic.w_c must be at least 0.5 degrees (got " + nlohmann::json(m.params.caustic.w_c).dump() + " rad)");
  if (!(std::abs(m.alpha_r) <= kPi / 4.0))
    throw DomainError("marschner.longitudinal.alpha_R must lie in [-45, 45] degrees (got " + nlohmann::json(m.alpha_r).dump() + " rad)");
  return m;
}

}  // namespace hairlut
