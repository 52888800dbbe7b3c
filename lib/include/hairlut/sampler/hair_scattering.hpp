// hairlut::sampler::HairScattering — what a renderer calls per shading point: eval, sample and pdf
// of S = Σ_p M_p N_p from d'Eon 2011 tables, with directions in the fiber frame.
//
// Header-only and dependency-free (C++17, with sampler_fiber.hpp, axis_sampling.hpp and product_row.hpp). Built once
// from the typed views of a table set (HairTables: tensor or β-band N_p, M_p, the residual), from a
// set whose N_p is a Fourier series (FourierSet, with M_p tables), or from one material's tables
// (MaterialTables, material_scattering.hpp), then const and shareable between threads. A fiber is plain data (Fiber: RGB σa, β_m, β_n): there is no
// per-fiber setup, so σa may change per strand or per shading point. Fiber::tilt adds a cuticle
// scale angle to the tilts the tables were baked with. A runtime over a tensor, β-band or Fourier
// set may be prepared for one roughness (PreparedScattering, prepared_scattering.hpp), at about a
// material's cost per call, with σa per fiber read through the PreparedFiber that fiber() builds.
//
// Frame and angles (pbrt's hair frame): x along the fiber from root to tip, y–z the normal plane;
// θ = asin x, φ = atan2(z, y). wo is the direction the renderer holds (towards the viewer or the
// previous vertex), wi the one it samples (towards the light). In the tables' terms wo is the exit
// direction θr and wi the incidence θi: S(wo, wi) = Σ_p M_p(β_m; θi, θo) N_p(φ; β_n, σa, θd) with
// θd = (θo − θi)/2 and φ = φo − φi. A tilted table stores M(v, θi, θr − α_p): the tilt shifts the
// held direction, so ∫ M_p cos θi dθi = 1 for every θo and each lobe stays normalised over the
// direction that is sampled (as pbrt-v4 applies its scale angle to wo).
//
// Sampling, exactly from the density that pdf() returns (and, for a white fiber with untilted
// tables, in exact proportion to S cos θi; weights then equal the tables' albedo):
//   1. θi from m(θi) = Σ_p M̃_p(θi) Ê_p(θi) cos θi / G, where M̃_p is the M_p table interpolated
//      as it declares (Catmull–Rom or linear along every axis, clamped at 0) and Ê_p the lobe's
//      energy at θd = (θo − θi)/2, averaged over the channels, from the energy table's nodes
//      interpolated linearly and then linearly between the M_p table's θi nodes (product_row.hpp);
//      G normalises. So θi follows the product M_p E_p of the tables, lobe by lobe;
//   2. the lobe q from its share of S at the drawn θi, π_q ∝ M̃_q(θi) Ē_q(θd) Z^φ_q, so that the
//      choice of lobe is exact whatever the lobes' tilts: the weight depends on θi only, through
//      Σ_q M̃_q Ē_q Z^φ_q / Σ_p M̃_p Ê_p, which differs from a constant only by the linear
//      interpolation of Ê (Ē: the tables' energies, averaged over the three channels);
//   3. φ from lobe q's interpolated N_p shape at (β_n, σ̄a, θd), σ̄a the mean of the channels
//      (Z^φ_q its integral over φ); the residual is uniform in φ. A Fourier set's φ density is its
//      series at (β_n, σ̄a, θd), normalised by its integral c_0 F (Z^φ_q = 1), drawn by inverting
//      the series' closed-form CDF; its Ê_p are c_0 F on the coefficients' (σa, θd) nodes.
// Each stage inverts its density's own piecewise-polynomial CDF (product_row.hpp, axis_sampling.hpp), so
//   pdf = m(θi) / cos θi · Σ_q π_q(θi) n_q(φ) / Z^φ_q   per unit solid angle (dω = cos θi dθi dφ),
// and a sample's weight S / pdf is, in pbrt's terms, f |cos θ| / pdf (S = ∫ over dω carries the cos).
// Each u ∈ [0, 1) is mapped into [ε, 1 − ε] (ε = 2⁻⁴⁰) so that u = 0 never lands on a zero of the
// density (θi = ±π/2, where cos θi = 0).
//
// Where the tables are tilted the lobes' energies are taken at different θd: the physics itself is
// not energy conserving there (docs/conventions.md, "Tilt"), and the weights average to its albedo.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <vector>

#include "hairlut/sampler/axis_sampling.hpp"
#include "hairlut/sampler/fourier_np.hpp"
#include "hairlut/sampler/material_scattering.hpp"
#include "hairlut/sampler/prepared_scattering.hpp"
#include "hairlut/sampler/product_row.hpp"
#include "hairlut/sampler/sampler_fiber.hpp"

namespace hairlut {
namespace sampler {

/// A direction drawn by HairScattering::sample. pdf == 0 (and weight 0) when nothing could be
/// drawn (no energy at this wo, or a NaN direction).
struct ScatteringSample {
  double wi[3] = {0.0, 0.0, 0.0};      ///< unit vector in the fiber frame
  double weight[3] = {0.0, 0.0, 0.0};  ///< S(wo, wi) / pdf per channel (pbrt's f |cos| / pdf)
  double pdf = 0.0;                    ///< per unit solid angle
  double theta_i = 0.0, phi = 0.0;     ///< θi and φ = φo − φi of wi [rad]
  int lobe = -1;                       ///< the lobe drawn (the residual is lobes() − 1)
};

/// The inclination θ = asin(w_x) and azimuth φ = atan2(w_z, w_y) of a unit vector in the fiber frame
/// (NaN in, NaN out). A direction along the fiber has φ = 0 whatever the signs of its zero
/// components (+ 0.0 turns −0 into +0, so atan2 never reads a −0 as the angle π).
inline void fiber_direction_angles(const double* w, double& theta, double& phi) {
  theta = w[0] == w[0] ? std::asin(std::max(-1.0, std::min(1.0, w[0]))) : w[0];
  phi = std::atan2(w[2] + 0.0, w[1] + 0.0);
}

/// N_p of a set baked in the Fourier representation (fourier_np.hpp): each explicit lobe's view,
/// the residual's (invalid: none), and the (θd, σa) axes their coefficients are stored on, on whose
/// nodes step 1 reads the lobes' energies. The views point into the set's values.
template <class T>
struct FourierSet {
  FourierNp<T, double> np[HairTables<T, double>::kMaxLobes];
  FourierNp<T, double> residual;
  Axis theta_d, sigma_a;
};

template <class T>
class HairScattering {
  using Mat = MaterialScattering<T>;

 public:
  static constexpr int kMaxLobes = HairTables<T, double>::kMaxLobes + 1;  ///< explicit + residual
  static constexpr int kMaxBands = HairTables<T, double>::kMaxBetaBands;

 private:
  // A density along one axis at one lookup: the mixture path where it is exact, else the
  // blended row (axis_sampling.hpp).
  struct Density {
    typename AxisSampler<T>::Mix mix;
    AxisRow row;
    bool mixed = false;
    double total = 0.0;
    std::vector<double> series;  // Fourier sets: the cosine amplitudes of N_p at (β_n, σ̄a, θd)
    void at(const AxisSampler<T>& s, const double* x) {
      mixed = s.mix(x, mix);
      if (mixed) {
        total = mix.total;
      } else {
        s.blend(x, row);
        total = row.ok ? row.total : 0.0;
      }
      if (!(total > 0.0)) total = 0.0;
    }
    double value(const AxisSampler<T>& s, double x) const { return mixed ? s.mix_value(mix, x) : s.value(row, x); }
    double sample(const AxisSampler<T>& s, double u) const { return mixed ? s.sample_mix(mix, u) : s.sample(row, u); }
  };
  // What depends on the fiber and θo only: each lobe's M̃_p row along θi, its product row M̃_p Ê_p
  // cos θi, and the lobe's share c_p of step 1's density.
  struct Point {
    double theta_o = 0.0;
    AxisRow m[kMaxLobes];      // M̃_p along θi at (β_m, θo)
    ProductRow g[kMaxLobes];   // M̃_p Ê_p cos θi along θi
    double c[kMaxLobes] = {};  // each lobe's share of m: its total over the sum
    double total = 0.0;        // G
  };
  // The lobe energies on the nodes of their energy table (σa × θd, linear in both), for Ê.
  struct Shaping {
    std::vector<double> e;  // [σa node][θd node]
    PreparedAxis sigma, theta;
    bool valid = false;
  };

 public:
  HairScattering() = default;
  /// From the typed views (which must outlive this object). np_data (optional) holds the stored
  /// sampling data of the N_p tables along φ, np_data[band · kMaxLobes + p] (table_sampling.hpp
  /// finds them in a file); where absent they are computed here. The M_p tables are copied once
  /// with θi as their last axis, and their sampling data along θi computed here.
  explicit HairScattering(const HairTables<T, double>& tables, const AxisData* np_data = nullptr) : t_(tables) {
    explicit_ = t_.lobes;
    lobes_ = explicit_ + (t_.has_residual ? 1 : 0);
    if (explicit_ < 1 || explicit_ > HairTables<T, double>::kMaxLobes) {
      explicit_ = lobes_ = 0;
      return;
    }
    bool ok = prepare_mp();
    for (int k = 0; k < t_.beta_bands; ++k)
      for (int p = 0; p < explicit_; ++p) {
        const NpLobe<T, double>& n = k == 0 ? t_.np[p] : t_.np_band[k - 1][p];
        ok = ok && n.valid();
        if (!n.valid()) continue;
        const FixedView<T, 4, double>& v = n.table();
        for (int d = 0; d < 4; ++d) n_axes_[k][p][d] = v.axis(d).axis();
        const AxisData stored = np_data ? np_data[k * kMaxLobes + p] : AxisData();
        n_axis_[k][p] = AxisSampler<T>(v.data(), n_axes_[k][p], 4, Measure::plain, stored);
        ok = ok && n_axis_[k][p].supported();
      }
    valid_ = ok;
  }
  /// From the tables of one material (MaterialTables, copied): σa and β are the material's, so
  /// every call ignores the Fiber's fields (material_scattering.hpp says how it samples).
  explicit HairScattering(const MaterialTables<T>& m) : mat_(m) {
    material_ = true;
    valid_ = mat_.valid();
    lobes_ = mat_.lobes();
  }
  /// A runtime over a set of any representation (`source`: tensor, β bands or Fourier) prepared
  /// for one roughness, roughness.beta_m, beta_n and tilt (its σa is not read), with σa free per
  /// fiber: PreparedScattering (prepared_scattering.hpp says what is resampled and how it
  /// samples). Every call reads this roughness, not the Fiber's; a fiber's σa is read through
  /// fiber() (a few µs per fiber), or per call where a Fiber is passed. Holds nothing of `source`.
  HairScattering(const HairScattering& source, const Fiber& roughness, const PreparedGrid& grid = {}) {
    prepared_ = true;
    if (!source.valid_ || source.material_ || source.prepared_) return;
    prep_ = PreparedScattering<T>(PrepSource{source, roughness}, grid);
    valid_ = prep_.valid();
    lobes_ = prep_.lobes();
  }
  /// From a set whose N_p is a Fourier series (FourierSet) and whose M_p are tables (HairTables'
  /// mp and mp_residual; its np views are not read). Both must outlive this object. Sampling as
  /// for tensor tables, with step 3's φ density the series itself at (β_n, σ̄a, θd), drawn by
  /// inverting its closed-form CDF (fourier_sample_abs_phi), and the energies Ê_p = c_0 F on the
  /// coefficients' (σa, θd) nodes.
  HairScattering(const HairTables<T, double>& mp_tables, const FourierSet<T>& np) : t_(mp_tables), fs_(np) {
    fourier_ = true;
    explicit_ = t_.lobes;
    lobes_ = explicit_ + (t_.has_residual ? 1 : 0);
    if (explicit_ < 1 || explicit_ > HairTables<T, double>::kMaxLobes) {
      explicit_ = lobes_ = 0;
      return;
    }
    bool ok = fs_.theta_d.count >= 1 && fs_.sigma_a.count >= 1;
    for (int p = 0; p < explicit_; ++p) ok = ok && fs_.np[p].valid();
    if (t_.has_residual) ok = ok && fs_.residual.valid();
    valid_ = ok && prepare_mp();
  }
  HairScattering(const HairScattering&) = delete;
  HairScattering& operator=(const HairScattering&) = delete;
  // The samplers point into this object's own copies (heap buffers, which a move keeps in place).
  HairScattering(HairScattering&&) = default;
  HairScattering& operator=(HairScattering&&) = default;

  /// False when a table is missing or its sampled axis is one the sampler cannot invert.
  bool valid() const { return valid_; }
  /// True when built from one material's tables (the Fiber's fields are then not read).
  bool material() const { return material_; }
  /// True when prepared for one roughness (the Fiber's β and tilt are then not read).
  bool prepared() const { return prepared_; }
  /// What a prepared runtime reads of a fiber: its σa's energies and weights (built in a few µs,
  /// for a strand or a shading point; prepared_scattering.hpp). Not ok for other runtimes.
  PreparedFiber fiber(const Fiber& f) const { return prepared_ ? prep_.fiber(f.sigma_a) : PreparedFiber(); }
  /// The prepared runtime itself (its node counts and size).
  const PreparedScattering<T>& preparation() const { return prep_; }
  /// Explicit lobes plus the residual (its index is lobes() − 1 when the tables have one).
  int lobes() const { return lobes_; }
  const HairTables<T, double>& tables() const { return t_; }

  /// S(wo, wi) per channel [1/sr] for unit vectors in the fiber frame.
  void eval(const Fiber& f, const double* wo, const double* wi, double* rgb) const {
    if (prepared_) return eval(fiber(f), wo, wi, rgb);
    if (material_ && valid_ && wo[0] == wo[0] && wi[0] == wi[0]) {
      // The sines are the directions' components along the fiber, and |φ| (all the tables need:
      // N_p is even in φ) is the angle between their projections on the normal plane (0 where one
      // is along the fiber: + 0.0 keeps a −0 dot from reading as π, as the GLSL runtime reads it).
      const double cross = wo[1] * wi[2] - wo[2] * wi[1], dot = wo[1] * wi[1] + wo[2] * wi[2] + 0.0;
      const double phi = std::atan2(std::fabs(cross), dot);
      if (phi == phi) {
        mat_.eval(Mat::incl_of_sin(wo[0]), Mat::incl_of_sin(wi[0]), phi, rgb);
        return;
      }
    }
    double to, po, ti, pi;
    fiber_direction_angles(wo, to, po);
    fiber_direction_angles(wi, ti, pi);
    eval(f, to, ti, po - pi, rgb);
  }
  /// The same for a prepared runtime and a fiber's state from fiber(); 0 for other runtimes.
  void eval(const PreparedFiber& pf, const double* wo, const double* wi, double* rgb) const {
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    if (!(wo[0] == wo[0]) || !(wi[0] == wi[0])) {
      rgb[0] = rgb[1] = rgb[2] = wo[0] + wi[0];
      return;
    }
    if (!prepared_ || !valid_) return;
    // The angles by fiber_angles' polynomials (≤ 2e-8 rad, far below the nodes' spacing), the
    // cosines as the lengths of the normal-plane projections: a third of the cost of asin and atan2,
    // which the shading point keeps so that pdf() reads back sample()'s own angles to rounding.
    double ti, to, phi;
    fiber_angles(wi, wo, ti, to, phi);
    const typename Mat::Incl o{to, std::min(std::max(wo[0], -1.0), 1.0), std::sqrt(wo[1] * wo[1] + wo[2] * wo[2])};
    const typename Mat::Incl i{ti, std::min(std::max(wi[0], -1.0), 1.0), std::sqrt(wi[1] * wi[1] + wi[2] * wi[2])};
    if (phi == phi) prep_.eval(pf, o, i, phi, rgb);
  }
  /// The same at θo, θi and φ = φo − φi [rad].
  void eval(const PreparedFiber& pf, double theta_o, double theta_i, double phi, double* rgb) const {
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    if (!(theta_o == theta_o) || !(theta_i == theta_i) || !(phi == phi)) {
      rgb[0] = rgb[1] = rgb[2] = theta_o + theta_i + phi;
      return;
    }
    if (prepared_ && valid_) prep_.eval(pf, Mat::incl(theta_o), Mat::incl(theta_i), phi, rgb);
  }
  /// S per channel at θo (held), θi (sampled), φ = φo − φi [rad]. NaN in every channel for a
  /// NaN argument; ≥ 0 otherwise.
  void eval(const Fiber& f, double theta_o, double theta_i, double phi, double* rgb) const {
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    if (!(theta_o == theta_o) || !(theta_i == theta_i) || !(phi == phi)) {
      rgb[0] = rgb[1] = rgb[2] = theta_o + theta_i + phi;
      return;
    }
    if (material_) {
      if (valid_) mat_.eval(Mat::incl(theta_o), Mat::incl(theta_i), phi, rgb);
      return;
    }
    if (prepared_) return eval(fiber(f), theta_o, theta_i, phi, rgb);
    if (!valid_) return;
    const double theta_d = 0.5 * (theta_o - theta_i);
    const NpLobe<T, double>* np = t_.np_at(f.beta_n);
    // The M_p tables' β and θi taps, located once for all lobes where their axes agree (a baked set).
    const bool shared = mp_shared_ && std::fabs(f.beta_m) < HUGE_VAL;
    FixedTaps<double> tb, ti;
    if (shared) tb = mp_view(0).axis(0).taps(f.beta_m), ti = mp_view(0).axis(1).taps(theta_i);
    for (int p = 0; p < lobes_; ++p) {
      double m;
      if (shared) {
        FixedTaps<double> tp[3] = {tb, ti, mp_view(p).axis(2).taps(held(f, p, theta_o))};
        m = detail::nonnegative(mp_view(p).combine(tp));
      } else {
        m = mp(p, f.beta_m, theta_i, held(f, p, theta_o));
      }
      if (!(m > 0.0)) continue;
      double n[3];
      if (!fourier_ && p < explicit_) {
        np[p].rgb(f.beta_n, f.sigma_a, theta_d, phi, n);
      } else {
        for (int c = 0; c < 3; ++c)
          n[c] = fourier_ ? (p < explicit_ ? fs_.np[p] : fs_.residual)(f.beta_n, f.sigma_a[c], theta_d, phi) : t_.np_residual(f.sigma_a[c], theta_d);
      }
      for (int c = 0; c < 3; ++c) rgb[c] += m * n[c];
    }
  }

  /// What sample(), pdf() and albedo() share at one shading point, a fiber and wo: each lobe's θi
  /// density. Built by at(); a renderer that draws a direction and also weighs light directions
  /// by pdf() at the same wo builds it once. Holds a pointer to its HairScattering.
  class ShadingPoint {
   public:
    /// False when nothing can be sampled here (no energy, a NaN wo, an invalid runtime).
    bool valid() const { return ok_; }
    /// Draws wi from three uniform numbers in [0, 1): u[0] the lobe of θi's mixture and then the
    /// lobe at θi, u[1] θi, u[2] φ. Returns the direction, S / pdf per channel and the pdf per
    /// unit solid angle (see the top of this file).
    ScatteringSample sample(const double* u) const {
      ScatteringSample s;
      if (!ok_) return s;
      const HairScattering& r = *rt_;
      if (r.material_ || r.prepared_) {
        const double v[3] = {open_unit(u[0]), open_unit(u[1]), open_unit(u[2])};
        return r.material_ ? drawn(r.mat_.sample(mpt_, v)) : drawn(r.prep_.sample(ppt_, fiber(), v));
      }
      // 1. θi from the mixture: the component by u0, then its inverse CDF at u1.
      double u0 = open_unit(u[0]);
      int p = -1;
      for (int k = 0; k < r.lobes_; ++k) {
        if (!(pt_->c[k] > 0.0)) continue;
        p = k;
        if (u0 < pt_->c[k]) break;
        u0 -= pt_->c[k];
      }
      if (p < 0) return s;
      u0 = std::min(std::max(u0 / pt_->c[p], 0.0), 1.0);
      const double ti = pt_->g[p].sample(open_unit(u[1]));
      if (!(ti == ti)) return s;
      const double m = r.theta_density(*pt_, ti);
      // 2. The lobe at θi, by what is left of u0, in proportion to share_q Z^φ_q.
      double share[kMaxLobes];
      Density n[kMaxLobes];
      const double norm = m > 0.0 ? r.phi_stage(f_, *pt_, ti, share, n) : 0.0;
      if (!(norm > 0.0)) return s;
      u0 = open_unit(u0) * norm;
      int q = -1;
      for (int k = 0; k < r.lobes_; ++k) {
        if (!(share[k] > 0.0)) continue;
        q = k;
        if (u0 < share[k]) break;
        u0 -= share[k];
      }
      if (q < 0) return s;
      // 3. φ from lobe q.
      const int band = r.t_.band_of(f_.beta_n);
      const double pi = 3.14159265358979323846;
      double phi;
      if (q >= r.explicit_) {
        phi = (2.0 * open_unit(u[2]) - 1.0) * pi;
      } else if (r.fourier_) {
        // |φ| from the series, its sign by which half of [0, 1) u falls in (N_p is even).
        const double v = 2.0 * open_unit(u[2]), a = fourier_sample_abs_phi(n[q].series.data(), static_cast<int>(n[q].series.size()), v < 1.0 ? v : v - 1.0);
        phi = v < 1.0 ? a : -a;
      } else {
        phi = n[q].sample(r.n_axis_[band][q], open_unit(u[2]));
      }
      if (!(phi == phi)) return s;
      const double pdf = m * r.phi_sum(f_, share, n, norm, phi);
      if (!(pdf > 0.0)) return s;
      const double phi_i = po_ - phi, cti = std::cos(ti);
      s.wi[0] = std::sin(ti), s.wi[1] = cti * std::cos(phi_i), s.wi[2] = cti * std::sin(phi_i);
      s.theta_i = ti, s.phi = phi, s.pdf = pdf, s.lobe = q;
      double rgb[3];
      r.eval(f_, to_, ti, phi, rgb);
      for (int c = 0; c < 3; ++c) s.weight[c] = rgb[c] / pdf;
      return s;
    }
    /// The pdf per unit solid angle with which sample() draws wi.
    double pdf(const double* wi) const {
      if (ok_ && (rt_->material_ || rt_->prepared_)) {
        const double phi = azimuth(wi);
        if (!(wi[0] == wi[0]) || !(phi == phi)) return 0.0;
        const typename Mat::Incl i = Mat::incl_of_sin(wi[0]);
        return rt_->material_ ? rt_->mat_.pdf(mpt_, i, phi) : rt_->prep_.pdf(ppt_, fiber(), i, phi);
      }
      double ti, pi;
      fiber_direction_angles(wi, ti, pi);
      return pdf(ti, po_ - pi);
    }
    /// The same at θi and φ = φo − φi [rad].
    double pdf(double theta_i, double phi) const {
      if (!ok_ || !(theta_i == theta_i) || !(phi == phi)) return 0.0;
      const HairScattering& r = *rt_;
      if (r.material_) return r.mat_.pdf(mpt_, Mat::incl(theta_i), phi);
      if (r.prepared_) return r.prep_.pdf(ppt_, fiber(), Mat::incl(theta_i), phi);
      const double m = r.theta_density(*pt_, theta_i);
      if (!(m > 0.0)) return 0.0;
      double share[kMaxLobes];
      Density n[kMaxLobes];
      const double norm = r.phi_stage(f_, *pt_, theta_i, share, n);
      return norm > 0.0 ? m * r.phi_sum(f_, share, n, norm, phi) : 0.0;
    }
    /// S(wo, wi) per channel.
    void eval(const double* wi, double* rgb) const {
      if ((rt_->material_ || rt_->prepared_) && rt_->valid_ && wi[0] == wi[0]) {
        const double phi = azimuth(wi);
        if (phi == phi) {
          if (rt_->material_) rt_->mat_.eval(mpt_.o, Mat::incl_of_sin(wi[0]), phi, rgb);
          else rt_->prep_.eval(fiber(), ppt_.o, Mat::incl_of_sin(wi[0]), phi, rgb);
          return;
        }
      }
      double ti, pi;
      fiber_direction_angles(wi, ti, pi);
      if (rt_->prepared_) rt_->eval(fiber(), to_, ti, po_ - pi, rgb);
      else rt_->eval(f_, to_, ti, po_ - pi, rgb);
    }
    /// The normalisation of sample()'s θi density: ∫ S dω averaged over the channels, with each
    /// lobe's energy interpolated linearly along θd and σa (Ê above; the tables interpolate E
    /// geometrically in σa and cubically in θd) and its φ integral taken as 1. For a white fiber
    /// the mean of the sample weights at this wo; 0 where nothing can be sampled. A prepared runtime's:
    /// its step 1's normalisation, for a coloured fiber near its ∫ S dω (prepared_scattering.hpp).
    double albedo() const {
      if (!ok_) return 0.0;
      return rt_->material_ ? rt_->mat_.albedo(mpt_) : rt_->prepared_ ? rt_->prep_.albedo(ppt_) : pt_->total;
    }

   private:
    friend class HairScattering;
    const HairScattering* rt_ = nullptr;
    Fiber f_;
    // |φ| between wo and wi: the angle between their projections on the normal plane, from wo's
    // unit projection (cos φo, sin φo).
    double azimuth(const double* wi) const {
      const double cross = cpo_ * wi[2] - spo_ * wi[1], dot = cpo_ * wi[1] + spo_ * wi[2] + 0.0;  // as in eval
      return std::atan2(std::fabs(cross), dot);
    }

    // A material's or a prepared runtime's draw as a sample: φi = φo − φ by the angle-difference
    // identities (no atan2 for φo).
    ScatteringSample drawn(const linear_rows::Draw& d) const {
      ScatteringSample s;
      if (!(d.pdf > 0.0)) return s;
      const double cf = std::cos(d.phi), sf = std::sin(d.phi);
      s.wi[0] = d.sin_i, s.wi[1] = d.cos_i * (cpo_ * cf + spo_ * sf), s.wi[2] = d.cos_i * (spo_ * cf - cpo_ * sf);
      s.theta_i = d.theta_i, s.phi = d.phi, s.pdf = d.pdf, s.lobe = d.lobe;
      for (int c = 0; c < 3; ++c) s.weight[c] = d.rgb[c] / d.pdf;
      return s;
    }
    // The prepared fiber: the point's own (at() from a Fiber) or the caller's.
    const PreparedFiber& fiber() const { return own_ ? *own_ : *pf_; }

    double po_ = 0.0, to_ = 0.0;
    double cpo_ = 1.0, spo_ = 0.0;  // cos φo, sin φo (material and prepared runtimes)
    std::optional<Point> pt_;  // generic tables (built only for them: its rows are large)
    typename Mat::Point mpt_;
    typename PreparedScattering<T>::Point ppt_;
    std::optional<PreparedFiber> own_;
    const PreparedFiber* pf_ = nullptr;
    bool ok_ = false;
  };

  /// The shading point of fiber f seen from wo (a unit vector in the fiber frame).
  ShadingPoint at(const Fiber& f, const double* wo) const {
    ShadingPoint sp;
    sp.rt_ = this, sp.f_ = f;
    if (prepared_) {
      sp.own_ = fiber(f);
      at_prepared(sp, wo);
      return sp;
    }
    if (material_) {
      const typename Mat::Incl o = Mat::incl_of_sin(wo[0]);
      const double r = std::sqrt(wo[1] * wo[1] + wo[2] * wo[2]);
      sp.to_ = o.theta;
      if (r > 0.0) sp.cpo_ = wo[1] / r, sp.spo_ = wo[2] / r;  // else φo = 0, as atan2(0, 0)
      if (o.theta == o.theta && r == r) sp.mpt_ = mat_.at(o);
      sp.ok_ = valid_ && sp.mpt_.ok;
      return sp;
    }
    double to;
    fiber_direction_angles(wo, to, sp.po_);
    sp.to_ = to;
    sp.pt_.emplace();
    sp.ok_ = valid_ && to == to && sp.po_ == sp.po_ && at_theta_o(f, to, *sp.pt_);
    return sp;
  }
  /// The shading point of a prepared runtime for a fiber's state from fiber(), which must outlive
  /// the point (invalid for other runtimes).
  ShadingPoint at(const PreparedFiber& pf, const double* wo) const {
    ShadingPoint sp;
    sp.rt_ = this, sp.pf_ = &pf;
    if (prepared_) at_prepared(sp, wo);
    return sp;
  }
  /// at(f, wo).sample(u).
  ScatteringSample sample(const Fiber& f, const double* wo, const double* u) const { return at(f, wo).sample(u); }
  /// at(f, wo).pdf(wi).
  double pdf(const Fiber& f, const double* wo, const double* wi) const { return at(f, wo).pdf(wi); }
  /// at(f, wo).albedo().
  double albedo(const Fiber& f, const double* wo) const { return at(f, wo).albedo(); }
  /// The same three for a prepared runtime's fiber state (fiber()).
  ScatteringSample sample(const PreparedFiber& f, const double* wo, const double* u) const { return at(f, wo).sample(u); }
  double pdf(const PreparedFiber& f, const double* wo, const double* wi) const { return at(f, wo).pdf(wi); }
  double albedo(const PreparedFiber& f, const double* wo) const { return at(f, wo).albedo(); }

 private:
  void at_prepared(ShadingPoint& sp, const double* wo) const {
    // θo by fast_acos (≤ 2e-8 rad), as eval() reads it: every later call reads the point's θo.
    const double r = std::sqrt(wo[1] * wo[1] + wo[2] * wo[2]);
    const typename Mat::Incl o{wo[0] == wo[0] ? 1.57079632679489661923 - fast_acos(wo[0]) : wo[0], std::min(std::max(wo[0], -1.0), 1.0), r};
    sp.to_ = o.theta;
    if (r > 0.0) sp.cpo_ = wo[1] / r, sp.spo_ = wo[2] / r;  // else φo = 0, as atan2(0, 0)
    if (o.theta == o.theta && r == r) sp.ppt_ = prep_.at(sp.fiber(), o);
    sp.ok_ = valid_ && sp.ppt_.ok;
  }
  // The set at one roughness, as PreparedScattering reads it.
  struct PrepSource {
    const HairScattering& r;
    Fiber f;
    int lobes() const { return r.explicit_; }
    bool residual() const { return r.t_.has_residual; }
    double beta_m() const { return f.beta_m; }
    double beta_n() const { return f.beta_n; }
    double sigma_max() const { return r.fourier_ ? r.fs_.sigma_a.hi : r.t_.np_at(f.beta_n)[0].table().axis(1).axis().hi; }
    double mp(int p, double theta_i, double theta_o) const { return r.mp(p, f.beta_m, theta_i, r.held(f, p, theta_o)); }
    double np(int p, double sigma_a, double theta_d, double phi) const {
      return r.fourier_ ? r.fs_.np[p](f.beta_n, sigma_a, theta_d, phi) : r.t_.np_at(f.beta_n)[p](f.beta_n, sigma_a, theta_d, phi);
    }
    bool has_energy(int p) const { return r.fourier_ || r.t_.np_at(f.beta_n)[p].has_energy(); }
    double energy(int p, double sigma_a, double theta_d) const {
      if (p < r.explicit_) return r.fourier_ ? r.fs_.np[p].energy(sigma_a, theta_d) : r.t_.np_at(f.beta_n)[p].energy(sigma_a, theta_d);
      return r.fourier_ ? r.fs_.residual.energy(sigma_a, theta_d) : 2.0 * 3.14159265358979323846 * r.t_.np_residual(sigma_a, theta_d);
    }
  };

  static double open_unit(double u) {
    constexpr double eps = 9.094947017729282e-13;  // 2^-40
    if (!(u == u)) u = 0.0;
    return eps + std::min(std::max(u, 0.0), 1.0) * (1.0 - 2.0 * eps);
  }
  // The held angle at which lobe p's M_p table is read: θo moved by the fiber's extra tilt (see
  // Fiber::tilt), folded back across a pole as the baker folds a tilted angle.
  double held(const Fiber& f, int p, double theta_o) const {
    if (f.tilt == 0.0 || p >= explicit_ || p > 2) return theta_o;
    const double shift = p == 0 ? 2.0 * f.tilt : p == 1 ? -f.tilt : -4.0 * f.tilt, half_pi = 1.57079632679489661923;
    const double t = theta_o - shift;
    return t > half_pi ? 2.0 * half_pi - t : t < -half_pi ? -2.0 * half_pi - t : t;
  }
  const FixedView<T, 3, double>& mp_view(int p) const { return (p < explicit_ ? t_.mp[p] : t_.mp_residual).table(); }
  double mp(int p, double beta_m, double theta_i, double theta_o) const {
    return p < explicit_ ? t_.mp[p](beta_m, theta_i, theta_o) : t_.mp_residual(beta_m, theta_i, theta_o);
  }
  // Ē_p(θd): the lobe's energy factor averaged over the channels (1 for a table that stores N_p
  // itself; its φ integral then carries the energy, Z^φ).
  double mean_energy(const Fiber& f, int p, double theta_d) const {
    double e = 0.0;
    if (fourier_) {
      const FourierNp<T, double>& v = p < explicit_ ? fs_.np[p] : fs_.residual;
      for (int c = 0; c < 3; ++c) e += std::max(0.0, v.energy(f.sigma_a[c], theta_d));
      return e / 3.0;
    }
    const NpLobe<T, double>* np = t_.np_at(f.beta_n);
    for (int c = 0; c < 3; ++c)
      e += p < explicit_ ? np[p].energy(f.sigma_a[c], theta_d) : 2.0 * 3.14159265358979323846 * t_.np_residual(f.sigma_a[c], theta_d);
    return e / 3.0;
  }
  bool at_theta_o(const Fiber& f, double theta_o, Point& pt) const;
  // Each lobe's M_p table copied with θi as its last axis, its sampler along θi, and the energies
  // that shape step 1 (prepare_shaping). False when a table is missing or cannot be sampled.
  bool prepare_mp();
  // The shaping table of lobe p: its energy factor table (explicit lobes stored as shape × energy),
  // 2π N of the residual at its nodes; none (Ê = 1) for a lobe whose table stores N_p itself.
  void prepare_shaping(int p);
  // m(θi) / cos θi = Σ_p M̃_p(θi) Ê_p(θi) / G: the θ factor of the pdf per unit solid angle (m, the
  // density of θi per radian, carries the cos θi of dω).
  double theta_density(const Point& pt, double theta_i) const {
    double m = 0.0;
    for (int p = 0; p < lobes_; ++p)
      if (pt.c[p] > 0.0) m += pt.g[p].value(theta_i);
    return m / pt.total;
  }
  // The lobes' shares at θi, share_q = M̃_q(θi) Ē_q(θd) Z^φ_q, with each explicit lobe's φ density
  // n_q at (β_n, σ̄a, |θd|) (Z^φ_q its integral; 1 for the residual, uniform in φ). Returns Σ share
  // (0: no lobe has energy here). π_q = share_q / Σ share.
  double phi_stage(const Fiber& f, const Point& pt, double theta_i, double* share, Density* n) const;
  // Σ_q π_q n_q(φ) / Z^φ_q [1/rad].
  double phi_sum(const Fiber& f, const double* share, const Density* n, double norm, double phi) const;
  static bool same_axis(const Axis& a, const Axis& b) {
    return a.spacing == b.spacing && a.placement == b.placement && a.wrap == b.wrap && a.lo == b.lo && a.hi == b.hi && a.count == b.count &&
           a.values == b.values && a.interpolation == b.interpolation && a.lo_end == b.lo_end;
  }
  // The axis with its ends clamped: θd and σa reach the shaping tables as |θd| ≤ π/2 and σa ≥ 0, so
  // an even θd axis needs no fold there (and locate() no remainder).
  static Axis clamped(Axis a) {
    a.wrap = Wrap::clamp;
    return a;
  }

  HairTables<T, double> t_;
  int explicit_ = 0, lobes_ = 0;
  bool valid_ = false, material_ = false, fourier_ = false, prepared_ = false;
  bool mp_shared_ = false;  // every lobe's M_p table on the same axes (eval locates β and θi once)
  MaterialScattering<T> mat_;
  PreparedScattering<T> prep_;
  FourierSet<T> fs_;
  std::vector<T> mt_[kMaxLobes];
  Axis mt_axes_[kMaxLobes][3];
  AxisSampler<T> m_axis_[kMaxLobes];
  CosineMoments mom_[kMaxLobes];
  Shaping shaping_[kMaxLobes];
  Axis n_axes_[kMaxBands][kMaxLobes][4];
  AxisSampler<T> n_axis_[kMaxBands][kMaxLobes];
};

}  // namespace sampler
}  // namespace hairlut

// The generic tables' path: step 1's θi densities, the shaping energies and the φ stage.
#include "hairlut/sampler/hair_scattering_tables.hpp"
