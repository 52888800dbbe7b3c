#include "hairlut/bake/hdrp_kernels.hpp"

#include <algorithm>
#include <cmath>

#include "hairlut/util/angles.hpp"
#include "hairlut/bake/engine_presets.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/physics/fresnel.hpp"
#include "hairlut/physics/longitudinal_mp.hpp"
#include "hairlut/util/quadrature.hpp"

namespace hairlut::hdrp {
namespace {

double sq(double x) { return x * x; }

// ln(1 + e^x) without overflow.
double softplus(double x) { return x > 0.0 ? x + std::log1p(std::exp(-x)) : std::log1p(std::exp(x)); }

double logistic_cdf(double x, double s) { return 1.0 / (1.0 + std::exp(-x / s)); }

// ∫_0^u t l(t) dt up to a constant: u CDF(u) − s ln(1 + e^{u/s}) (its derivative is u l(u)).
double logistic_moment(double u, double s) { return u * logistic_cdf(u, s) - s * softplus(u / s); }

// ∫_a^b (A + B t) l(t) dt.
double linear_times_logistic(double a, double b, double A, double B, double s) {
  return A * (logistic_cdf(b, s) - logistic_cdf(a, s)) + B * (logistic_moment(b, s) - logistic_moment(a, s));
}

// The 2π-periodic wrap of HDRP's AzimuthalScattering loops, into [−π, π].
double wrap(double x) { return std::remainder(x, kTwoPi); }

// Φ(p, γ) of the azimuthal kernel at γ = asin h with γt = clamp(asin(h/η'), −1, 1).
double phase(int p, double gamma, double eta_prime) {
  const double gt = std::clamp(std::asin(std::sin(gamma) / eta_prime), -1.0, 1.0);
  return azimuthal_direction(p, gamma, gt);
}

// Breakpoints on [a, b] where Φ is monotone: the roots of Φ(γ) = φ − kπ for every integer k
// (k even: the peak of the logistic, k odd: the kink of its wrap), by bisection.
template <class Phase>
void add_roots(const Phase& f, double a, double b, double phi, std::vector<double>& out) {
  const double fa = f(a), fb = f(b);
  const double lo = std::min(fa, fb), hi = std::max(fa, fb);
  const long k0 = static_cast<long>(std::ceil((phi - hi) / kPi)), k1 = static_cast<long>(std::floor((phi - lo) / kPi));
  for (long k = k0; k <= k1; ++k) {
    const double target = phi - static_cast<double>(k) * kPi;
    if (!(target > lo && target < hi)) continue;
    double x0 = a, x1 = b;
    const bool increasing = fb > fa;
    for (int i = 0; i < 200; ++i) {
      const double m = 0.5 * (x0 + x1);
      if (!(m > x0 && m < x1)) break;
      ((f(m) < target) == increasing ? x0 : x1) = m;
    }
    out.push_back(0.5 * (x0 + x1));
  }
}

std::vector<double> sorted_unique(std::vector<double> v, double lo, double hi) {
  for (double& x : v) x = std::clamp(x, lo, hi);
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

// cos θ of a direction of sine s: HDRP's guarded form, or the exact one.
double cos_of(double s, Functions f) { return f == Functions::exact ? std::sqrt(std::max(0.0, 1.0 - s * s)) : guarded_cos(s); }

// M_p at (sin θi, cos θi) and the tilted (sin θo', cos θo'): HDRP's formula, or d'Eon's exactly.
double longitudinal_of(double ci, double co, double si, double so, double v, Functions f) {
  if (f == Functions::exact) return longitudinal_deon(v, std::atan2(si, ci), std::atan2(so, co));
  return longitudinal(ci, co, si, so, v);
}

}  // namespace

double fresnel0() { return sq((kEta - 1.0) / (kEta + 1.0)); }

double fresnel_schlick(double f0, double u) {
  const double x = 1.0 - u, x2 = x * x;
  return (1.0 - f0) * (x * x2 * x2) + f0;
}

double guarded_cos(double s) { return std::sqrt(std::max(0.0, 1.0 - (s * s + kGuard))); }

std::array<double, 4> longitudinal_variances(double beta) {
  const double v = sq(0.726 * beta + 0.812 * beta * beta + 3.7 * std::pow(std::abs(beta), 20.0));
  return {v, 0.25 * v, 4.0 * v, 4.0 * v};
}

double logistic_scale(double beta) {
  return 0.62665706865775012560 * (0.265 * beta + 1.194 * beta * beta + 5.372 * std::pow(std::abs(beta), 22.0));
}

double bessel_i0_series(double x) {
  double sum = 0.0, factorial = 1.0;
  for (int i = 0; i < 10; ++i) {
    if (i > 0) factorial *= i;
    sum += std::pow(std::abs(x), 2.0 * i) / (std::pow(4.0, i) * factorial * factorial);
  }
  return sum;
}

double log_bessel_i0(double x) {
  if (x > 12.0) return x + 0.5 * (-std::log(kTwoPi) + std::log(1.0 / x) + 1.0 / (8.0 * x));
  return std::log(bessel_i0_series(x));
}

double longitudinal(double cos_i, double cos_o, double sin_i, double sin_o, double v) {
  const double a = cos_i * cos_o / v, b = sin_i * sin_o / v;
  if (v < 0.1) return std::exp(log_bessel_i0(a) - b - 1.0 / v + 0.6931 + std::log(1.0 / (2.0 * v)));
  return std::exp(-b) * bessel_i0_series(a) / (std::sinh(1.0 / v) * 2.0 * v);
}

std::array<double, 2> tilt(int p, double sin_o, double cos_o, double alpha) {
  // GetAlphaScalesFromAlpha: α, 2α, 4α by the double-angle identities.
  double sa[3], ca[3];
  sa[0] = std::sin(alpha);
  ca[0] = std::sqrt(std::max(0.0, 1.0 - sa[0] * sa[0]));
  for (int i = 1; i < 3; ++i) {
    sa[i] = 2.0 * ca[i - 1] * sa[i - 1];
    ca[i] = ca[i - 1] * ca[i - 1] - sa[i - 1] * sa[i - 1];
  }
  double s = sin_o, c = cos_o;
  if (p == 0) s = sin_o * ca[1] - cos_o * sa[1], c = cos_o * ca[1] + sin_o * sa[1];
  else if (p == 1) s = sin_o * ca[0] + cos_o * sa[0], c = cos_o * ca[0] - sin_o * sa[0];
  else if (p == 2) s = sin_o * ca[2] + cos_o * sa[2], c = cos_o * ca[2] - sin_o * sa[2];
  return {s, std::abs(c)};
}

double modified_eta_karis(double c) { return 1.19 / c + 0.36 * c; }

double azimuthal_direction(int p, double gamma_o, double gamma_t) { return 2.0 * p * gamma_t - 2.0 * gamma_o + p * kPi; }

double trimmed_logistic(double x, double s) {
  const double e = std::exp(-std::abs(x) / s);
  return e / (s * sq(1.0 + e)) / (logistic_cdf(kPi, s) - logistic_cdf(-kPi, s));
}

std::array<double, 3> longitudinal_texel(double sin_i, double sin_o, double beta, Functions fn) {
  const double cos_i = cos_of(sin_i, fn), cos_o = cos_of(sin_o, fn);
  const auto v = longitudinal_variances(beta);
  std::array<double, 3> m{};
  for (int p = 0; p < 3; ++p) {
    const auto [s, c] = tilt(p, sin_o, cos_o, radians(kCuticleDegrees));
    m[static_cast<std::size_t>(p)] = longitudinal_of(cos_i, c, sin_i, s, v[static_cast<std::size_t>(p)], fn);
  }
  return m;
}

double azimuthal_texel(int p, double phi, double cos_theta_d, double beta, double rel_tol, Functions fn) {
  if (p < 0 || p > 2) throw DomainError("hdrp azimuthal texel: lobe must be 0, 1 or 2");
  require_in_range("cos theta_d", cos_theta_d, 1e-300, 1.0, "must lie in (0, 1]");
  require_positive("azimuthal roughness", beta);
  const double eta_prime = fn == Functions::exact ? std::sqrt(kEta * kEta - (1.0 - cos_theta_d * cos_theta_d)) / cos_theta_d
                                                  : modified_eta_karis(cos_theta_d);
  const double s = logistic_scale(beta);
  auto f = [&](double g) { return phase(p, g, eta_prime); };
  // Monotone branches of Φ: one, or three for TRT when the caustic cos²γc = (η'² − 1)/3 lies inside.
  std::vector<double> ends = {-kHalfPi, kHalfPi};
  if (p == 2 && (eta_prime * eta_prime - 1.0) / 3.0 < 1.0) {
    const double gc = std::acos(std::sqrt((eta_prime * eta_prime - 1.0) / 3.0));
    ends = {-kHalfPi, -gc, gc, kHalfPi};
  }
  std::vector<double> bp = ends;
  for (std::size_t i = 0; i + 1 < ends.size(); ++i) add_roots(f, ends[i], ends[i + 1], phi, bp);
  bp = sorted_unique(bp, -kHalfPi, kHalfPi);
  AdaptiveOptions opt;
  opt.rel_tol = rel_tol;
  opt.abs_tol = 1e-300;
  opt.max_intervals = 4000;
  const AdaptiveResult r = integrate_adaptive(
      [&](double g, std::span<double> out) { out[0] = 0.5 * trimmed_logistic(wrap(phi - f(g)), s) * std::cos(g); }, 1, bp, opt);
  return r.value[0];
}

double back_weight(double c, double s) {
  const double a = std::abs(wrap(c));
  const double mass = logistic_cdf(kPi, s) - logistic_cdf(-kPi, s);
  return (linear_times_logistic(-kPi, -a, kPi + a, 1.0, s) + linear_times_logistic(-a, kPi - a, kPi - a, -1.0, s) +
          linear_times_logistic(kPi - a, kPi, a - kPi, 1.0, s)) /
         mass;
}

double absorption_from_diffuse(double diffuse, double b) {
  const double d = (((((0.245 * b) + 5.574) * b - 10.73) * b + 2.532) * b - 0.215) * b + 5.969;  // GetAbsorptionDenominator
  return std::max(sq(std::log(std::max(diffuse, 1e-3)) / d), 1e-5);
}

void attenuation_table(std::span<const double> smoothness, std::span<const double> sin_theta, std::span<const double> diffuse,
                       std::vector<double>& front, std::vector<double>& back, double rel_tol, Functions fn) {
  for (auto list : {smoothness, sin_theta, diffuse})
    for (double x : list) require_in_range("hdrp attenuation coordinate", x, 0.0, 1.0, "must lie in [0, 1]");
  const std::size_t X = smoothness.size(), Y = sin_theta.size(), Z = diffuse.size();
  const double alpha = radians(kCuticleDegrees), f0 = fresnel0();
  const double s = logistic_scale(kRadialRoughness);
  AdaptiveOptions opt;
  opt.rel_tol = rel_tol;
  opt.abs_tol = 1e-300;

  // Longitudinal factors L_p(x, y) = ∫_{−1}^{1} M_p du (u = sin θi, so du = cos θi dθi).
  std::vector<std::array<double, 4>> L(X * Y);
  const double edge = std::sqrt(1.0 - kGuard);  // beyond it the guarded cos θi is 0
  for (std::size_t y = 0; y < Y; ++y) {
    const double so = sin_theta[y], co = cos_of(so, fn);
    std::array<std::array<double, 2>, 4> t;
    for (int p = 0; p < 4; ++p) t[static_cast<std::size_t>(p)] = tilt(p, so, co, alpha);
    for (std::size_t x = 0; x < X; ++x) {
      const double beta_m = 1.0 - std::min(smoothness[x], 0.99);  // PerceptualSmoothnessToPerceptualRoughness(min(s, 1 − 1e−2))
      const auto v = longitudinal_variances(beta_m);
      std::vector<double> bp = {-1.0, -edge, edge, 1.0};
      for (std::size_t p = 0; p < 4; ++p) {
        bp.push_back(-t[p][0]);  // the lobe's peak, θi = −θo'
        const double c = 12.0 * v[p] / std::max(t[p][1], 1e-300);  // LogBesselI changes formula at a = 12
        if (fn == Functions::hdrp && v[p] < 0.1 && c < 1.0 && 1.0 - kGuard - c * c > 0.0) {
          const double u = std::sqrt(1.0 - kGuard - c * c);
          bp.push_back(u), bp.push_back(-u);
        }
      }
      bp = sorted_unique(bp, -1.0, 1.0);
      const AdaptiveResult r = integrate_adaptive(
          [&](double u, std::span<double> out) {
            const double ci = cos_of(u, fn);
            for (std::size_t p = 0; p < 4; ++p) out[p] = longitudinal_of(ci, t[p][1], u, t[p][0], v[p], fn);
          },
          4, bp, opt);
      for (std::size_t p = 0; p < 4; ++p) L[y * X + x][p] = r.value[p];
    }
  }

  // Azimuthal factors over γ = asin h: ½∫ A_p dh (p = 0..3) and ½∫ A_p w_back(Φ_p) dh (p = 0..2).
  std::vector<std::array<double, 7>> Q(Y * Z);
  for (std::size_t y = 0; y < Y; ++y) {
    const double so = sin_theta[y], co = cos_of(so, fn);
    const double cos_t = std::sqrt(std::max(0.0, 1.0 - sq(so / kEta)));
    const double eta_p = std::sqrt(kEta * kEta - so * so) / co;
    for (std::size_t z = 0; z < Z; ++z) {
      const double sigma = absorption_from_diffuse(diffuse[z], kRadialRoughness);
      const double bp[3] = {-kHalfPi, 0.0, kHalfPi};
      const AdaptiveResult r = integrate_adaptive(
          [&](double g, std::span<double> out) {
            const double h = std::sin(g), jac = 0.5 * std::cos(g);  // ½ dh = ½ cos γ dγ
            const double sgt = h / eta_p, cgt = std::sqrt(std::max(0.0, 1.0 - sgt * sgt));
            const double gt = std::clamp(std::asin(sgt), -1.0, 1.0), go = std::asin(h);
            const double T = std::exp(-sigma * (2.0 * cgt / cos_t));
            const double ct = co * std::sqrt(std::max(0.0, 1.0 - h * h));
            const double F = fn == Functions::exact ? fresnel_reflectance(kEta, ct) : fresnel_schlick(f0, ct);
            double A[4];
            A[0] = F;
            A[1] = sq(1.0 - F) * T;
            A[2] = A[1] * T * F;
            A[3] = A[2] * F * T / (1.0 - T * F);
            for (int p = 0; p < 4; ++p) out[static_cast<std::size_t>(p)] = jac * A[p];
            for (int p = 0; p < 3; ++p) out[static_cast<std::size_t>(4 + p)] = jac * A[p] * back_weight(azimuthal_direction(p, go, gt), s);
          },
          7, bp, opt);
      for (std::size_t k = 0; k < 7; ++k) Q[y * Z + z][k] = r.value[k];
    }
  }

  front.assign(X * Y * Z, 0.0);
  back.assign(X * Y * Z, 0.0);
  for (std::size_t z = 0; z < Z; ++z)
    for (std::size_t y = 0; y < Y; ++y)
      for (std::size_t x = 0; x < X; ++x) {
        const auto& l = L[y * X + x];
        const auto& q = Q[y * Z + z];
        // The residual is uniform in Δ: ∫ w dΔ / 2π = π²/2π = π/2 for either half.
        const double residual = l[3] * q[3] * kHalfPi;
        double f = residual, b = residual;
        for (std::size_t p = 0; p < 3; ++p) {
          b += l[p] * q[4 + p];
          f += l[p] * (kPi * q[p] - q[4 + p]);
        }
        const std::size_t i = (z * Y + y) * X + x;
        front[i] = kLuminanceOfGrey * f / kPi;
        back[i] = kLuminanceOfGrey * b / kPi;
      }
}

}  // namespace hairlut::hdrp
