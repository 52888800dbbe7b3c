// HairScattering's path for generic tables (tensor or β-band N_p, or a Fourier N_p, with M_p
// tables): the θi density of step 1 at a shading point (at_theta_o), the M_p tables' copies and
// the energies that shape it (prepare_mp, prepare_shaping), and the lobes' shares and φ densities
// at a drawn θi (phi_stage, phi_sum); defined apart from the class (hair_scattering.hpp, which
// includes this file and says how it samples).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "hairlut/sampler/hair_scattering.hpp"

namespace hairlut {
namespace sampler {

template <class T>
bool HairScattering<T>::at_theta_o(const Fiber& f, double theta_o, Point& pt) const {
  pt.theta_o = theta_o;
  double sum = 0.0;
  std::vector<double> ebar;
  // Where θd falls on the energy table's axis at each θi node: the same for every lobe whose
  // energy and M_p axes match the previous lobe's (all of them, in a baked set), so located once.
  std::vector<Lerp> at_node;
  std::vector<char> located;
  const Shaping* located_for = nullptr;
  const CosineMoments* located_mom = nullptr;
  for (int p = 0; p < lobes_; ++p) {
    const double x[2] = {f.beta_m, held(f, p, theta_o)};
    m_axis_[p].blend(x, pt.m[p], false);
    pt.c[p] = 0.0;
    if (!pt.m[p].ok) continue;
    const CosineMoments& mom = mom_[p];
    const Shaping& sh = shaping_[p];
    // Ê is bilinear in (σa, θd) on the energy table's nodes, averaged over the channels: the
    // channels' mean at σa is taken once on each θd node (a linear map), so that each θi node
    // below reads one θd interpolation.
    if (sh.valid) {
      const std::size_t nt = static_cast<std::size_t>(sh.theta.axis.count);
      ebar.assign(nt, 0.0);
      for (int c = 0; c < 3; ++c) {
        const Lerp ls = sh.sigma.locate(f.sigma_a[c]);
        const double* r0 = &sh.e[static_cast<std::size_t>(ls.i0) * nt];
        const double* r1 = &sh.e[static_cast<std::size_t>(ls.i1) * nt];
        const double w0 = (1.0 - ls.w) / 3.0, w1 = ls.w / 3.0;
        for (std::size_t j = 0; j < nt; ++j) ebar[j] += w0 * r0[j] + w1 * r1[j];
      }
    }
    if (sh.valid && !(located_for && same_axis(located_for->theta.axis, sh.theta.axis) && located_mom->lo() == mom.lo() &&
                      located_mom->h() == mom.h() && located_mom->cells() == mom.cells())) {
      located_for = &sh, located_mom = &mom;
      at_node.resize(static_cast<std::size_t>(mom.cells()) + 1);
      located.assign(static_cast<std::size_t>(mom.cells()) + 1, 0);
    }
    pt.g[p].prepare(mom, pt.m[p].coef.data(), [&](int k) {
      if (!sh.valid) return 1.0;
      Lerp& lt = at_node[static_cast<std::size_t>(k)];
      if (!located[static_cast<std::size_t>(k)]) {
        lt = sh.theta.locate(std::fabs(0.5 * (theta_o - (mom.lo() + k * mom.h()))));
        located[static_cast<std::size_t>(k)] = 1;
      }
      return (1.0 - lt.w) * ebar[static_cast<std::size_t>(lt.i0)] + lt.w * ebar[static_cast<std::size_t>(lt.i1)];
    });
    pt.c[p] = pt.g[p].total();
    sum += pt.c[p];
  }
  if (!(sum > 0.0) || !(sum < HUGE_VAL)) return false;
  pt.total = sum;
  for (int p = 0; p < lobes_; ++p) pt.c[p] /= sum;
  return true;
}

template <class T>
bool HairScattering<T>::prepare_mp() {
  bool ok = true;
  for (int p = 0; p < lobes_; ++p) {
    const MpLobe<T, double>& m = p < explicit_ ? t_.mp[p] : t_.mp_residual;
    ok = ok && m.valid();
    if (!m.valid()) continue;
    const FixedView<T, 3, double>& v = m.table();
    const Axis a[3] = {v.axis(0).axis(), v.axis(1).axis(), v.axis(2).axis()};
    const std::size_t nb = static_cast<std::size_t>(a[0].count), ni = static_cast<std::size_t>(a[1].count), nr = static_cast<std::size_t>(a[2].count);
    std::vector<T>& out = mt_[p];
    out.resize(nb * ni * nr);
    for (std::size_t b = 0; b < nb; ++b)
      for (std::size_t i = 0; i < ni; ++i)
        for (std::size_t r = 0; r < nr; ++r) out[(b * nr + r) * ni + i] = v.data()[(b * ni + i) * nr + r];
    mt_axes_[p][0] = a[0], mt_axes_[p][1] = a[2], mt_axes_[p][2] = a[1];
    // Rows blended per shading point only (at_theta_o): no mixture data, which would take a
    // pass over the table and more memory than the table itself.
    m_axis_[p] = AxisSampler<T>(out.data(), mt_axes_[p], 3, Measure::cosine, typename AxisSampler<T>::BlendOnly());
    ok = ok && m_axis_[p].supported();
    mom_[p] = CosineMoments(a[1].lo, (a[1].hi - a[1].lo) / (a[1].count - 1), a[1].count - 1);
    if (p == 0) mp_shared_ = true;
    else
      for (int d = 0; d < 3; ++d) mp_shared_ = mp_shared_ && same_axis(a[d], mt_axes_[0][d == 1 ? 2 : d == 2 ? 1 : 0]);
    prepare_shaping(p);
  }
  return ok;
}

template <class T>
void HairScattering<T>::prepare_shaping(int p) {
  Shaping& sh = shaping_[p];
  if (fourier_) {
    // c_0 F on the coefficients' own nodes (the residual's table is its energy too).
    const FourierNp<T, double>& v = p < explicit_ ? fs_.np[p] : fs_.residual;
    const Axis sa = fs_.sigma_a, td = fs_.theta_d;
    sh.sigma = PreparedAxis(clamped(sa)), sh.theta = PreparedAxis(clamped(td));
    sh.e.resize(static_cast<std::size_t>(sa.count) * static_cast<std::size_t>(td.count));
    for (int i = 0; i < sa.count; ++i)
      for (int j = 0; j < td.count; ++j)
        sh.e[static_cast<std::size_t>(i) * static_cast<std::size_t>(td.count) + static_cast<std::size_t>(j)] = std::max(0.0, v.energy(node(sa, i), node(td, j)));
  } else if (p < explicit_) {
    const NpLobe<T, double>& n = t_.np[p];
    if (!n.has_energy()) return;
    const FixedView<T, 2, double>& v = n.energy();
    sh.sigma = PreparedAxis(clamped(v.axis(0).axis())), sh.theta = PreparedAxis(clamped(v.axis(1).axis()));
    const std::size_t count = static_cast<std::size_t>(sh.sigma.axis.count) * static_cast<std::size_t>(sh.theta.axis.count);
    sh.e.assign(v.data(), v.data() + count);
    // A table that stores E_p / g (reaching 90°): the energies themselves on the nodes.
    if (!n.energy_factor().none())
      for (int i = 0; i < sh.sigma.axis.count; ++i)
        for (int j = 0; j < sh.theta.axis.count; ++j)
          sh.e[static_cast<std::size_t>(i) * static_cast<std::size_t>(sh.theta.axis.count) + static_cast<std::size_t>(j)] *=
              n.energy_factor()(node(sh.sigma.axis, i), node(sh.theta.axis, j));
  } else {
    if (!t_.np_residual.valid()) return;
    const Axis sa = t_.np_residual.table().axis(0).axis(), td = t_.np_residual.table().axis(1).axis();
    if (sa.count < 1 || td.count < 1) return;
    sh.sigma = PreparedAxis(clamped(sa)), sh.theta = PreparedAxis(clamped(td));
    sh.e.resize(static_cast<std::size_t>(sa.count) * static_cast<std::size_t>(td.count));
    for (int i = 0; i < sa.count; ++i)
      for (int j = 0; j < td.count; ++j)
        sh.e[static_cast<std::size_t>(i) * static_cast<std::size_t>(td.count) + static_cast<std::size_t>(j)] =
            2.0 * 3.14159265358979323846 * t_.np_residual(node(sa, i), node(td, j));
  }
  sh.valid = !sh.e.empty();
}

template <class T>
double HairScattering<T>::phi_stage(const Fiber& f, const Point& pt, double theta_i, double* share, Density* n) const {
  const double theta_d = 0.5 * (pt.theta_o - theta_i);
  const int band = t_.band_of(f.beta_n);
  const double x[3] = {f.beta_n, (f.sigma_a[0] + f.sigma_a[1] + f.sigma_a[2]) / 3.0, std::fabs(theta_d)};
  double norm = 0.0;
  for (int q = 0; q < lobes_; ++q) {
    const double m = pt.c[q] > 0.0 ? m_axis_[q].value(pt.m[q], theta_i) : 0.0;
    share[q] = m > 0.0 ? m * mean_energy(f, q, theta_d) : 0.0;
    if (share[q] > 0.0 && q < explicit_ && fourier_) {
      // The series at σ̄a, normalised by its own integral: Ē_q carries the energy.
      std::vector<double>& a = n[q].series;
      a.resize(static_cast<std::size_t>(std::max(0, fs_.np[q].params().terms)));
      a.resize(static_cast<std::size_t>(fs_.np[q].series(f.beta_n, x[1], theta_d, a.data())));
      n[q].total = a.empty() ? 0.0 : 2.0 * 3.14159265358979323846 * a[0];
      if (!(n[q].total > 0.0)) share[q] = 0.0;
    } else if (share[q] > 0.0 && q < explicit_) {
      n[q].at(n_axis_[band][q], x);
      share[q] *= n[q].total;
    }
    if (!(share[q] > 0.0) || !(share[q] < HUGE_VAL)) share[q] = 0.0;
    norm += share[q];
  }
  return norm > 0.0 && norm < HUGE_VAL ? norm : 0.0;
}

template <class T>
double HairScattering<T>::phi_sum(const Fiber& f, const double* share, const Density* n, double norm, double phi) const {
  const int band = t_.band_of(f.beta_n);
  const double pi = 3.14159265358979323846;
  double s = 0.0;
  for (int q = 0; q < lobes_; ++q) {
    if (!(share[q] > 0.0)) continue;
    double d = 1.0 / (2.0 * pi);
    if (q < explicit_ && fourier_) d = std::max(0.0, fourier_cosine_sum(n[q].series.data(), static_cast<int>(n[q].series.size()), phi)) / n[q].total;
    else if (q < explicit_) d = n[q].value(n_axis_[band][q], detail::fold_phi(phi, n_axes_[band][q][3])) / n[q].total;
    s += share[q] * d;
  }
  return s / norm;
}

}  // namespace sampler
}  // namespace hairlut
