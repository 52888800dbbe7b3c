// Unity HDRP's hair look-up textures as HDRP itself defines them: the three kernels of
// HairMultipleScatteringPreIntegration.compute (Unity-Technologies/Graphics, Packages/
// com.unity.render-pipelines.high-definition/Runtime/Material/Hair/, commit e3089c7ac636) with the
// reference hair model they call (Reference/HairReferenceCommon.hlsl, Reference/HairReference.hlsl)
// and the surface conversion of Hair.hlsl. docs/presets/unity-hdrp-hair.md lists every fact taken.
//
// What is exact and what is not: the point functions (Chiang's variance and logistic-scale fits,
// HDRP's 10-term I0 series and its large-argument logarithm, Karis's modified index, the trimmed
// logistic, Schlick's Fresnel, the guard epsilons inside square roots) are evaluated as HDRP writes
// them, in double precision. The integrals HDRP estimates with Riemann sums and 32 Hammersley
// samples (over the fiber width h, the light azimuth and the hemisphere) are computed here to a
// relative 1e-10 by adaptive Gauss–Kronrod between the integrands' kinks and peaks, with the trimmed
// logistic's azimuthal weights in closed form. Two guards are left out because they are not part of
// the integrals' definition: the 1e-4 added to |wi.z| before it is divided out of the reference BSDF
// (with it the forward integral diverges logarithmically) and the 1e-5 added inside atan2's second
// argument (a shift of the azimuth on a set of measure zero in the limit).
#pragma once

#include <array>
#include <span>
#include <vector>

namespace hairlut::hdrp {

inline constexpr double kEta = 1.55;                 ///< ReferenceBSDFData.eta (HairReferenceCommon.hlsl)
inline constexpr double kCuticleDegrees = 3.0;       ///< α of the kernels: cuticleAngle −3° negated by Hair.hlsl; "hardcoded for 3º"
inline constexpr double kRadialSmoothness = 0.7;     ///< ConfigureFiberSurface's perceptualRadialSmoothness
inline constexpr double kRadialRoughness = 1.0 - kRadialSmoothness;  ///< β_n of the attenuation kernel
inline constexpr double kGuard = 1e-5;               ///< epsilon inside the cosines' square roots
/// Luminance of a grey value c (the attenuation kernel's Luminance(specR) with equal channels): c times
/// the sum of Color.hlsl's weights 0.2126729 + 0.7151522 + 0.0721750 (1.0000001).
inline constexpr double kLuminanceOfGrey = 0.2126729 + 0.7151522 + 0.0721750;

/// Fresnel reflectance at normal incidence of η = 1.55 (IorToFresnel0): ((η − 1)/(η + 1))².
double fresnel0();
/// Schlick's approximation F0 + (1 − F0)(1 − u)⁵ (F_Schlick with f90 = 1).
double fresnel_schlick(double f0, double u);
/// sqrt(max(0, 1 − (s² + 1e−5))): the guarded cosine of ReferenceAngles.
double guarded_cos(double sin_theta);
/// Chiang 2016 eq. 7 as LongitudinalVarianceFromBeta: v_R = (0.726β + 0.812β² + 3.7|β|²⁰)², v_TT = v_R/4,
/// v_TRT = 4v_R, the residual's = v_TRT.
std::array<double, 4> longitudinal_variances(double beta);
/// Chiang 2016 eq. 8 as LogisticScaleFromBeta: s = √(π/8)(0.265β + 1.194β² + 5.372|β|²²).
double logistic_scale(double beta);
/// HDRP's BesselI: Σ_{i<10} |x|^{2i} / (4^i (i!)²) (the first ten terms of I0's series).
double bessel_i0_series(double x);
/// HDRP's LogBesselI: x + ½(−ln 2π + ln(1/x) + 1/(8x)) for x > 12, else ln(bessel_i0_series(x)).
double log_bessel_i0(double x);
/// HDRP's LongitudinalScattering (d'Eon 2011 eq. 7 with the two branches above): v < 0.1:
/// exp(LogBesselI(a) − b − 1/v + 0.6931 + ln(1/(2v))), else e^{−b} I0(a) / (2v sinh(1/v)), a = cos_i cos_o / v,
/// b = sin_i sin_o / v.
double longitudinal(double cos_i, double cos_o, double sin_i, double sin_o, double v);
/// ApplyCuticleTilts with GetAlphaScalesFromAlpha(α): lobe 0 turns θo by −2α, lobe 1 by +α, lobe 2 by
/// +4α, lobe 3 (residual) not at all; the cosine is taken absolute. Writes {sin, cos}.
std::array<double, 2> tilt(int p, double sin_o, double cos_o, double alpha);
/// Karis's modified index for η = 1.55 (ModifiedRefractionIndex): 1.19/c + 0.36c.
double modified_eta_karis(double cos_theta_d);
/// Marschner's Φ(p, γo, γt) = 2pγt − 2γo + pπ (AzimuthalDirection).
double azimuthal_direction(int p, double gamma_o, double gamma_t);
/// The logistic density e^{−|x|/s} / (s (1 + e^{−|x|/s})²) divided by its mass on [−π, π] (TrimmedLogistic).
double trimmed_logistic(double x, double s);

/// Which point functions the textures use: HDRP's own (the engine-named preset), or the exact ones
/// (the unity-hdrp-hair-deon variant: d'Eon's M_p with the exact I0 and csch and no guard epsilon,
/// the exact Bravais index √(η² − sin²θd)/cos θd instead of Karis's fit, the exact dielectric
/// Fresnel reflectance instead of Schlick's). Axes, mappings, tilts, the trimmed logistic and the
/// integrals are the same in both.
enum class Functions { hdrp, exact };

/// One texel of the longitudinal texture (ComputeLongitudinalScattering): sin θi = u_x, sin θo = u_y
/// (both in [−1, 1]), roughness β = u_z; writes M_R, M_TT, M_TRT.
std::array<double, 3> longitudinal_texel(double sin_i, double sin_o, double beta, Functions functions = Functions::hdrp);

/// One texel of the azimuthal texture (ComputeAzimuthalScattering): ½ ∫_{−1}^{1} TL(wrap(φ − Φ(p, asin h,
/// asin(h/η'))), s) dh with η' = modified_eta_karis(cos θd), s = logistic_scale(β), the integral exact
/// (adaptive Gauss–Kronrod in γ = asin h between the roots of φ − Φ ≡ 0 and ≡ π mod 2π and the
/// caustic). Domain: p in {0, 1, 2}, cos θd in (0, 1], β > 0. rel_tol: relative accuracy asked.
double azimuthal_texel(int p, double phi, double cos_theta_d, double beta, double rel_tol = 1e-10, Functions functions = Functions::hdrp);

/// The azimuthal weight of the attenuation kernel's back half: ∫_{−π}^{π} (π − |Δ|) TL_w(Δ − c, s) dΔ
/// with TL_w the 2π-periodic trimmed logistic, in closed form (logistic CDF and its first moment).
/// The front half's weight is π − this.
double back_weight(double c, double s);

/// The attenuation texture (ComputeAttenuationForward/Backward) at every (smoothness x, sin θ y,
/// diffuse colour z) of the lists: front[(z · Y + y) · X + x] and back[...] as HDRP stores them,
/// (1/π) ∫_0^π dφ ∫_{half sphere} dω ½ ∫ dh S. The integral separates into
/// (1/π) Σ_p [∫ M_p cos θi dθi] [½ ∫ A_p(h) w(Φ_p(h)) dh] (the longitudinal part depends on
/// smoothness and θ only, the azimuthal one on θ and colour only), each factor exact to rel_tol.
/// Domain: every value in [0, 1]. Throws DomainError.
void attenuation_table(std::span<const double> smoothness, std::span<const double> sin_theta, std::span<const double> diffuse,
                       std::vector<double>& front, std::vector<double>& back, double rel_tol = 1e-10,
                       Functions functions = Functions::hdrp);

/// Chiang 2016 eq. 9 as HDRP's AbsorptionFromReflectance at radial roughness b: (ln max(d, 1e−3) / D(b))²,
/// then ReferenceBSDFData's floor max(σa, 1e−5).
double absorption_from_diffuse(double diffuse, double radial_roughness);

}  // namespace hairlut::hdrp
