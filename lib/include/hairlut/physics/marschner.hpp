// Marschner et al. 2003's azimuthal scattering function for a smooth fiber (§4.2–4.3, §5.2), as a
// second model next to d'Eon 2011, with the details of Khungurn 2013:
//   N_p(φ) = Σ_r A(p, h_r) / |2 dΦ/dh(p, h_r)|   over the paths h_r with Φ(p, h_r) ≡ φ (eq. 8),
// Φ(p, h) = 2pγt − 2γi + pπ (eq. 3, hairlut's sign as in conventions.md), the attenuation A with
// the Bravais indices η', η'' (§4.3), the TRT caustic replacement (§5.2.2: k_G, w_c, Δη', Δh_M
// and the smoothstep fade past the caustic merge at η' = 2) and the eccentricity index η*(φh)
// (§5.2.3). Paths are found exactly (bracketed root finding on the monotone pieces of Φ, all one
// or three TRT roots) or with Marschner's cubic approximation of Snell's law (eq. 10).
//
// Exact and approximate, and the choices made where the papers leave room:
// - "exact" roots are exact to rounding (|Φ − φ| ≤ 1e−12); "cubic" replaces γt(γi) by
//   γ̂t = (3c/π)γi − (4c/π³)γi³, c = asin(1/η'). The cubic form uses its own map consistently:
//   roots of Φ̂ = φ and the density |2 dΦ̂/dh|⁻¹, so each lobe still carries ½∫A dh (the
//   push-forward of the offsets) and the caustic it removes is the cubic map's own fold (Descartes'
//   h_c² = (4 − η'²)/3 is the exact map's fold). A(p, h) is evaluated exactly at the root's h.
//   Khungurn evaluates the exact dΦ/dh at the cubic root instead; that neither conserves the
//   lobe's energy nor puts the removed caustic where the cubic map's singularity is.
// - A(p, h) = F(η', η'', γi) for p = 0 and (1 − F)² F^{p−1} T^p otherwise (the internal
//   reflectance F(1/η', 1/η'', γt) equals F(η', η'', γi)), T = exp(−σa' ℓ(γt)) with
//   σa' = σa / cos θt and ℓ the chord 2cos γt (default) or the papers' 4cos²γt. With these
//   indices Marschner's A equals d'Eon's exactly (see fresnel_bravais), so the smooth-fiber
//   lobes of the two models agree away from caustics.
// - Eccentricity changes the TRT geometry only (Φ, its roots, its density and its caustic use
//   η*(φh)); the Fresnel and absorption factors use η (default, the paper's "the model does not
//   account for eccentricity in the Fresnel factor") or η* (`EccentricFresnel::eta_star`, as in
//   Khungurn's pseudocode, which feeds η* to all of N_TRT). R and TT use η.
// - The caustic Gaussians g(φ ∓ φc; w_c) are evaluated at the wrapped difference (continuous
//   across φ = ±π); "smoothstep(2, 2 + Δη', η')" is 1 below 2 and 0 above 2 + Δη', with the
//   cubic Hermite 1 − (3u² − 2u³) in between; past the merge the caustic sits at φc = 0 with the
//   attenuation of the path h = 0 and Δh = Δh_M.
#pragma once

#include <nlohmann/json.hpp>
#include <span>
#include <string_view>
#include <vector>

#include "hairlut/util/angles.hpp"
#include "hairlut/physics/attenuation.hpp"
#include "hairlut/physics/fiber_geometry.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"

namespace hairlut {

/// How the paths reaching an azimuth are found.
enum class MarschnerRoots {
  exact,  ///< bracketed root finding on Φ(p, h) (Marschner §4.2)
  cubic   ///< Marschner's cubic approximation of Snell's law (§5.2.1, eq. 10)
};
std::string_view to_string(MarschnerRoots roots);
/// Parses "exact" or "cubic"; throws DomainError naming `what` otherwise.
MarschnerRoots parse_marschner_roots(std::string_view text, std::string_view what = "roots");

/// Which index the Fresnel and absorption factors of an eccentric TRT lobe use.
enum class EccentricFresnel {
  eta,      ///< the fiber's η (default)
  eta_star  ///< η*(φh), as Khungurn's pseudocode does
};
std::string_view to_string(EccentricFresnel e);
/// Parses "eta" or "eta-star"; throws DomainError naming `what` otherwise.
EccentricFresnel parse_eccentric_fresnel(std::string_view text, std::string_view what = "eccentric_fresnel");

/// The TRT caustic replacement of Marschner 2003 §5.2.2 (Table 1 ranges in the comments).
struct CausticParams {
  bool enabled = true;                ///< false: eq. 8 as is (infinite at the caustic azimuths)
  double k_G = 0.5;                   ///< glint scale factor (0.5 to 5)
  double w_c = radians(15.0);         ///< azimuthal width of the caustic, radians (10° to 25°)
  double delta_eta_prime = 0.3;       ///< η' range of the fade past the merge (0.2 to 0.4)
  double delta_h_max = 0.5;           ///< caustic intensity limit Δh_M
};

/// Everything Marschner's N_p depends on besides (p, σa, θd, φ, φh).
struct MarschnerParams {
  double eta = 1.55;                   ///< index of refraction η > 1
  AbsorptionPath path = AbsorptionPath::chord;
  MarschnerRoots roots = MarschnerRoots::exact;
  CausticParams caustic;
  double eccentricity = 1.0;           ///< a: 1 for a circular fiber (Table 1: 0.85 to 1)
  EccentricFresnel eccentric_fresnel = EccentricFresnel::eta;

  /// Throws DomainError naming the first bad field: η > 1; k_G ≥ 0; w_c in (0, π]; Δη' > 0;
  /// Δh_M in (0, 2]; a > 0 with η*(φh) > 1 for every φh (for η = 1.55: a in (0.707, 1.414)).
  void validate() const;
};

/// η*(φh) = ½((η1* + η2*) + cos(2φh)(η1* − η2*)), η1* = 2(η − 1)a² − η + 2,
/// η2* = 2(η − 1)a⁻² − η + 2 (Marschner §5.2.3): the index that makes the circular model mimic an
/// elliptical fiber of eccentricity a, for the azimuthal half angle φh measured from the axis
/// where η* = η1*. Even in φh with period π; η* = η for a = 1. Domain: η > 1, a > 0, φh finite.
/// The result may be ≤ 1 for extreme a (MarschnerParams::validate() rejects that).
double eccentric_eta(double eta, double a, double phi_h);

/// c = asin(1/η'), the refraction angle at the fiber's edge, from 1/η' in [0, 1].
inline double cubic_edge_angle(double inv_eta_prime) { return std::asin(inv_eta_prime); }

/// Marschner's cubic approximation of Snell's law (§5.2.1), matching value and slope at ±π/2:
///   γ̂t(γi) = (3c/π) γi − (4c/π³) γi³.   Domain: γi in [−π/2, π/2], c in [0, π/2].
double cubic_gamma_t(double gamma_i, double c);

/// Eq. 10: Φ̂(p, γi) = (6pc/π − 2) γi − (8pc/π³) γi³ + pπ.
double cubic_exit_azimuth(int p, double gamma_i, double c);

/// dΦ̂/dγi = (6pc/π − 2) − (24pc/π³) γi².
double cubic_exit_azimuth_derivative(int p, double gamma_i, double c);

/// Every γi in [−π/2, π/2] with Φ̂(p, γi) ≡ φ (mod 2π), ascending: the real roots of the cubic
/// (closed form, then polished by Newton steps so |Φ̂ − φ − 2πk| is at rounding level).
/// Domain: p ≥ 0, 1/η' in [0, 1), φ finite.
std::vector<double> cubic_azimuthal_roots(double inv_eta_prime, int p, double phi);

/// One smooth-fiber path to an azimuth: its entry angle γi and its density
/// |2 dΦ/dh|⁻¹ = cos γi / (2 |dΦ/dγi|) (+∞ exactly at a fold).
struct AzimuthalPath {
  double gamma_i = 0.0;
  double density = 0.0;
};

/// The paths of lobe p reaching φ, exactly or with the cubic map. For TRT, one or three.
std::vector<AzimuthalPath> marschner_paths(const FiberGeometry& geometry, int p, double phi, MarschnerRoots roots);

/// Where the TRT caustic sits and how it is replaced (Marschner §5.2.2).
struct TrtCaustic {
  bool folds = false;     ///< η' < 2: the map folds at ±γc (two caustics)
  double t = 0.0;         ///< weight of the replacement: 1 while the map folds, fading to 0 by η' = 2 + Δη'
  double phi_c = 0.0;     ///< caustic azimuth (≥ 0; the caustics are at ±φc; 0 past the merge)
  double gamma_c = 0.0;   ///< entry angle of the caustic path (0 past the merge)
  double d2phi_dh2 = 0.0; ///< d²Φ/dh² at the fold (0 past the merge)
  double delta_h = 0.0;   ///< Δh = min(Δh_M, 2 √(2 w_c / |d²Φ/dh²|)); Δh_M past the merge
};
/// The TRT caustic of the geometry (η' from it), with the exact or the cubic map.
TrtCaustic marschner_trt_caustic(const FiberGeometry& geometry, MarschnerRoots roots, const CausticParams& params);

/// Marschner's attenuation A(p, h) with the Bravais Fresnel factor, for one (η, θd, σa).
class MarschnerAttenuation {
 public:
  /// Validates η > 1, θd in [−π/2, π/2], σa ≥ 0.
  MarschnerAttenuation(double eta, double theta_d, double sigma_a, AbsorptionPath path = AbsorptionPath::chord);
  /// A(p, sin γi) for p ≥ 0 and γi in [−π/2, π/2]. Result in [0, 1].
  double operator()(int p, double gamma_i) const;

 private:
  double inv_eta_prime_, eta_double_prime_, sigma_a_prime_;
  AbsorptionPath path_;
};

/// Marschner's N_R, N_TT, N_TRT at one θd (and φh for an eccentric fiber), for any σa and φ.
/// The geometry (and the TRT caustic) is computed once; paths do not depend on σa.
class MarschnerAzimuthal {
 public:
  /// Validates the parameters and θd in [−π/2, π/2]; φh is used by TRT when a ≠ 1.
  MarschnerAzimuthal(const MarschnerParams& params, double theta_d, double phi_h = 0.0);

  /// N_p(φ) for p in {0, 1, 2}, σa ≥ 0: eq. 8 for R and TT, §5.2.2 for TRT. Finite and ≥ 0
  /// (with the caustic replacement enabled; without it +∞ exactly at a TRT caustic).
  double np(int p, double sigma_a, double phi) const;
  /// N_p(φ) for every σa of `sigmas` at once (the paths are solved once): out[k].
  void np(int p, std::span<const double> sigmas, double phi, std::span<double> out) const;
  /// Eq. 8 without the caustic replacement (+∞ exactly at a fold).
  double np_smooth(int p, double sigma_a, double phi) const;
  /// ∫_{−π}^{π} N_p dφ for every σa of `sigmas`: ½∫A dh for R and TT; for TRT
  /// ½∫A(h) w(Φ(h)) dh + t k_G A(h_c) Δh Σ± ∫g(φ ∓ φc; w_c) dφ with the replacement's weight w,
  /// by adaptive Gauss–Kronrod in γ to rel_tol. out[k].
  void energy(int p, std::span<const double> sigmas, std::span<double> out, double rel_tol = 1e-11) const;

  /// The geometry lobe p uses (η* for an eccentric TRT).
  const FiberGeometry& geometry(int p) const { return p == 2 ? trt_geometry_ : geometry_; }
  const TrtCaustic& caustic() const { return caustic_; }
  const MarschnerParams& params() const { return params_; }

 private:
  double caustic_weight(double phi) const;  // Π± (1 − t g(φ ∓ φc)/g(0))
  double caustic_lobes(double phi) const;   // g(φ − φc) + g(φ + φc)
  MarschnerAttenuation attenuation(int p, double sigma_a) const;

  MarschnerParams params_;
  double theta_d_, eta_fresnel_trt_;
  FiberGeometry geometry_, trt_geometry_;
  TrtCaustic caustic_;
};

/// One-call form: N_p(φ) of Marschner's model (p in {0, 1, 2}).
double marschner_np(const MarschnerParams& params, int p, double sigma_a, double theta_d, double phi, double phi_h = 0.0);

/// Marschner's longitudinal lobes with the relations of Table 1: α_TT = −α_R/2, α_TRT = −3α_R/2,
/// β_TT = β_R/2, β_TRT = 2β_R (α shifts θh, Marschner's convention; see longitudinal_mp.hpp).
struct MarschnerLobes {
  double alpha[3] = {0.0, 0.0, 0.0};  ///< θh shifts of R, TT, TRT (radians)
  double beta[3] = {0.1, 0.05, 0.2};  ///< Gaussian widths of R, TT, TRT (radians)
  /// Table 1's relations from α_R and β_R (β_R > 0).
  static MarschnerLobes table1(double alpha_r, double beta_r);
};

/// E(θi) of Marschner's full model (eq. 9) for one σa (and φh), total and per lobe:
///   E(θi) = Σ_p ∫ M_G(β_p; θi, θr) e_p(θd) cos²θr dθr,  e_p(θd) = ∫ N_p dφ (MarschnerAzimuthal::energy),
/// with M_G = g(β_p; θh − α_p)/cos²θd (or its 2θh form) and the energy measure cos²θr dθr of d'Eon
/// 2011 eq. 5 (Marschner's S carries no cos θr of its own). Not 1 in general: the published θh
/// Gaussian doubles the energy at low roughness, and the caustic replacement adds or removes some.
/// Adaptive Gauss–Kronrod over θr to rel_tol (converged in the result).
struct MarschnerAlbedo {
  double theta_i = 0.0;
  double total = 0.0;
  std::vector<double> per_lobe;  ///< R, TT, TRT
  bool converged = false;
};
MarschnerAlbedo marschner_directional_albedo(const MarschnerParams& params, const MarschnerLobes& lobes, GaussianArgument argument,
                                             double sigma_a, double theta_i, double phi_h = 0.0, double rel_tol = 1e-7);

/// Model "marschner2003" as a config and a table set's metadata give it: the fiber's parameters,
/// Table 1's R shift and the Gaussian's argument.
struct MarschnerConfig {
  MarschnerParams params;                              ///< η and the absorption path mirror the config's fiber
  double alpha_r = radians(-5.0);                      ///< R lobe's shift of θh (Table 1: −10° to −5°)
  GaussianArgument argument = GaussianArgument::theta_h;
  /// Table 1's lobes for a given β_R.
  MarschnerLobes lobes(double beta_r) const { return MarschnerLobes::table1(alpha_r, beta_r); }
};

/// The settings as the normalized config and the table metadata record them (angles in radians).
nlohmann::json marschner_json(const MarschnerConfig& m);
/// The inverse of marschner_json (for tables read back), with the fiber's η and path; throws
/// DomainError naming the malformed or out-of-domain field.
MarschnerConfig marschner_from_json(const nlohmann::json& j, double eta, AbsorptionPath path);

}  // namespace hairlut
