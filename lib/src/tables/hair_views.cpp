#include "hairlut/tables/hair_views.hpp"

#include <algorithm>
#include <string>
#include <type_traits>
#include <vector>

#include "hairlut/util/error.hpp"
#include "hairlut/physics/melanin.hpp"
#include "hairlut/tables/beta_bands.hpp"
#include "hairlut/tables/fourier_tables.hpp"
#include "hairlut/tables/table_sampling.hpp"

namespace hairlut {
namespace {

// The table at `path` with the named axes in that order, stored as T.
template <class T>
const Table& require(const TableSet& set, const std::string& path, const std::vector<std::string>& axes) {
  const Table* t = set.find(path);
  if (!t) throw DomainError("table " + path + ": missing (needed by the typed views)");
  std::string want, have;
  for (const auto& a : axes) want += (want.empty() ? "" : ", ") + a;
  for (const auto& a : t->axes) have += (have.empty() ? "" : ", ") + a.name;
  if (want != have) throw DomainError("table " + path + ": axes (" + have + "), the typed views need (" + want + ")");
  const bool f32 = t->precision == Precision::float32;
  if (f32 != std::is_same_v<T, float>)
    throw DomainError("table " + path + ": stored as " + std::string(f32 ? "float32" : "float64") + "; use hair_tables<" +
                      (f32 ? "float" : "double") + ", R>");
  return *t;
}

template <class T>
const T* values(const Table& t) {
  if constexpr (std::is_same_v<T, float>) return t.f32.data();
  else return t.f64.data();
}

template <class T, std::size_t N>
void axes_of(const Table& t, sampler::Axis (&out)[N]) {
  for (std::size_t d = 0; d < N; ++d) out[d] = t.axes[d].view();
}

// The factor table of t (sigma_a, theta_d), or nullptr.
template <class T>
const Table* factor_of(const TableSet& set, const Table& t) {
  const std::string f = t.factor();
  if (f.empty()) return nullptr;
  return &require<T>(set, f, {"sigma_a", "theta_d"});
}

// The same nodes and interpolation (names and labels aside).
bool same_axis(const GridAxis& a, const GridAxis& b) {
  return a.spacing == b.spacing && a.placement == b.placement && a.wrap == b.wrap && a.interpolation == b.interpolation && a.lo_end == b.lo_end &&
         a.lo == b.lo && a.hi == b.hi && a.count == b.count && a.values == b.values;
}

}  // namespace

template <class T, class R>
sampler::HairTables<T, R> hair_tables(const TableSet& set) {
  const std::string model = set.metadata.value("model", std::string());
  if (model != "deon2011") throw DomainError("table set: model " + (model.empty() ? std::string("(none)") : model) + ", the typed views read deon2011 tables");
  sampler::HairTables<T, R> h;
  const auto& lobes = set.metadata.at("lobes");
  if (lobes.size() > static_cast<std::size_t>(h.kMaxLobes) || lobes.empty())
    throw DomainError("table set: " + std::to_string(lobes.size()) + " lobes, the typed views read 1 to " + std::to_string(h.kMaxLobes));
  h.lobes = static_cast<int>(lobes.size());
  h.eta = set.metadata.value("eta", 0.0);
  for (int p = 0; p < h.lobes; ++p) {
    const std::string lobe = lobes[static_cast<std::size_t>(p)].get<std::string>();
    const Table& n = require<T>(set, "np/" + lobe, {"beta", "sigma_a", "theta_d", "phi"});
    sampler::Axis na[4], ea[2];
    axes_of<T>(n, na);
    const Table* e = factor_of<T>(set, n);
    if (e) axes_of<T>(*e, ea);
    h.np[p] = sampler::NpLobe<T, R>(values<T>(n), na, e ? values<T>(*e) : nullptr, e ? ea : nullptr, e ? e->grazing_factor() : sampler::GrazingFactor{});
    // β bands (beta_bands.hpp): band k ≥ 1 is np/<lobe>_band<k>.
    const auto bands = set.metadata.find("np_beta_bands");
    const int nb = bands != set.metadata.end() && bands->is_array() ? static_cast<int>(bands->size()) : 1;
    if (nb > h.kMaxBetaBands || nb < 1)
      throw DomainError("table set: " + std::to_string(nb) + " beta bands, the typed views read 1 to " + std::to_string(h.kMaxBetaBands));
    h.beta_bands = nb;
    for (int k = 0; k < nb; ++k) {
      const Table& b = k == 0 ? n : require<T>(set, "np/" + lobe + beta_band_suffix(k), {"beta", "sigma_a", "theta_d", "phi"});
      h.band_hi[k] = b.axes[0].hi;
      if (k == 0) continue;
      sampler::Axis ba[4], bea[2];
      axes_of<T>(b, ba);
      const Table* be = factor_of<T>(set, b);
      if (be) axes_of<T>(*be, bea);
      h.np_band[k - 1][p] = sampler::NpLobe<T, R>(values<T>(b), ba, be ? values<T>(*be) : nullptr, be ? bea : nullptr, be ? be->grazing_factor() : sampler::GrazingFactor{});
    }
    const Table& m = require<T>(set, "mp/" + lobe, {"beta", "theta_i", "theta_r"});
    sampler::Axis ma[3];
    axes_of<T>(m, ma);
    h.mp[p] = sampler::MpLobe<T, R>(values<T>(m), ma);
  }
  if (set.metadata.value("residual", false)) {
    const Table& n = require<T>(set, "np/residual", {"sigma_a", "theta_d"});
    sampler::Axis na[2], ea[2];
    axes_of<T>(n, na);
    const Table* e = factor_of<T>(set, n);
    if (e) axes_of<T>(*e, ea);
    h.np_residual = sampler::NpResidual<T, R>(values<T>(n), na, e ? values<T>(*e) : nullptr, e ? ea : nullptr,
                                              n.grazing_factor(), e ? e->grazing_factor() : sampler::GrazingFactor{});
    const Table& m = require<T>(set, "mp/residual", {"beta", "theta_i", "theta_r"});
    sampler::Axis ma[3];
    axes_of<T>(m, ma);
    h.mp_residual = sampler::MpLobe<T, R>(values<T>(m), ma);
    h.has_residual = true;
  }
  return h;
}

template sampler::HairTables<float, float> hair_tables<float, float>(const TableSet&);
template sampler::HairTables<float, double> hair_tables<float, double>(const TableSet&);
template sampler::HairTables<double, float> hair_tables<double, float>(const TableSet&);
template sampler::HairTables<double, double> hair_tables<double, double>(const TableSet&);

namespace {

// The runtime over a set whose N_p is a Fourier series: the series' views and the M_p tables.
template <class T>
sampler::HairScattering<T> fourier_scattering(const TableSet& set) {
  const std::string model = set.metadata.value("model", std::string());
  if (model != "deon2011") throw DomainError("table set: model " + (model.empty() ? std::string("(none)") : model) + ", the runtime reads deon2011 tables");
  sampler::HairTables<T, double> h;
  sampler::FourierSet<T> fs;
  const auto& lobes = set.metadata.at("lobes");
  if (lobes.empty() || lobes.size() > static_cast<std::size_t>(h.kMaxLobes))
    throw DomainError("table set: " + std::to_string(lobes.size()) + " lobes, the runtime reads 1 to " + std::to_string(h.kMaxLobes));
  h.lobes = static_cast<int>(lobes.size());
  h.eta = set.metadata.value("eta", 0.0);
  auto mp_of = [&](const std::string& lobe) {
    const std::string path = "mp/" + lobe;
    if (!set.find(path)) throw DomainError("table " + path + ": missing (the runtime needs M_p tables beside the Fourier N_p: tables.mp in the config)");
    const Table& m = require<T>(set, path, {"beta", "theta_i", "theta_r"});
    sampler::Axis ma[3];
    axes_of<T>(m, ma);
    return sampler::MpLobe<T, double>(values<T>(m), ma);
  };
  const Table* first = nullptr;
  auto coefficients = [&](const std::string& lobe) {
    const std::string path = std::string(kFourierGroup) + "/" + lobe;
    const Table* t = set.find(path);
    if (!t) throw DomainError("table " + path + ": missing (the set has no Fourier N_p of lobe " + lobe + ")");
    if (!first) first = t;
    if (t->axes.size() < 2 || first->axes.size() < 2 || !same_axis(t->axes[0], first->axes[0]) || !same_axis(t->axes[1], first->axes[1]))
      throw DomainError("table " + path + ": its theta_d and sigma_a axes differ from " + first->path() + "'s");
    return fourier_np<T, double>(set, lobe);
  };
  for (int p = 0; p < h.lobes; ++p) {
    const std::string lobe = lobes[static_cast<std::size_t>(p)].get<std::string>();
    fs.np[p] = coefficients(lobe);
    h.mp[p] = mp_of(lobe);
  }
  fs.theta_d = first->axes[0].view(), fs.sigma_a = first->axes[1].view();
  if (set.metadata.value("residual", false)) {
    fs.residual = fourier_np<T, double>(set, "residual");
    h.mp_residual = mp_of("residual");
    h.has_residual = true;
  }
  sampler::HairScattering<T> r(h, fs);
  if (!r.valid()) throw DomainError("table set: the runtime cannot sample its Fourier N_p or M_p tables (an M_p theta_i axis that is not uniform)");
  return r;
}

}  // namespace

template <class T>
sampler::HairScattering<T> hair_scattering(const TableSet& set) {
  using Runtime = sampler::HairScattering<T>;
  if (has_fourier_np(set)) return fourier_scattering<T>(set);
  const sampler::HairTables<T, double> views = hair_tables<T, double>(set);
  std::vector<sampler::AxisData> stored(static_cast<std::size_t>(Runtime::kMaxBands * Runtime::kMaxLobes));
  const auto& lobes = set.metadata.at("lobes");
  for (int k = 0; k < views.beta_bands; ++k)
    for (int p = 0; p < views.lobes; ++p) {
      const std::string path = "np/" + lobes[static_cast<std::size_t>(p)].get<std::string>() + (k == 0 ? std::string() : beta_band_suffix(k));
      if (const Table* t = set.find(path)) stored[static_cast<std::size_t>(k * Runtime::kMaxLobes + p)] = stored_sampling_data(set, *t);
    }
  Runtime r(views, stored.data());
  if (!r.valid()) throw DomainError("table set: the runtime cannot sample its N_p or M_p tables (a sampled axis that is not uniform, or a geometric axis before it)");
  return r;
}

template sampler::HairScattering<float> hair_scattering<float>(const TableSet&);
template sampler::HairScattering<double> hair_scattering<double>(const TableSet&);

template <class T>
sampler::MaterialTables<T> material_tables(const TableSet& set, std::string_view group) {
  const std::string g(group);
  if (g.rfind("materials/", 0) != 0) throw DomainError("table group " + g + ": not a material (materials/<name>)");
  const auto& lobes = set.metadata.at("lobes");
  sampler::MaterialTables<T> m;
  if (lobes.empty() || lobes.size() > static_cast<std::size_t>(m.kMaxLobes))
    throw DomainError("table set: " + std::to_string(lobes.size()) + " lobes, the runtime reads 1 to " + std::to_string(m.kMaxLobes));
  m.lobes = static_cast<int>(lobes.size());
  // Every lobe's tables on the first lobe's axes: the runtime interleaves them per node.
  auto same = [&](const Table& t, const Table& first) {
    for (std::size_t d = 0; d < t.axes.size(); ++d)
      if (!same_axis(t.axes[d], first.axes[d])) throw DomainError("table " + t.path() + ": axis " + t.axes[d].name + " differs from " + first.path() + "'s");
  };
  auto channels = [](const Table& n) {
    if (n.axes[0].count != 3) throw DomainError("table " + n.path() + ": " + std::to_string(n.axes[0].count) + " channels, the runtime reads 3");
  };
  const Table* n0 = nullptr;
  const Table* m0 = nullptr;
  for (int p = 0; p < m.lobes; ++p) {
    const std::string lobe = lobes[static_cast<std::size_t>(p)].get<std::string>();
    const Table& n = require<T>(set, g + "/np_" + lobe, {"channel", "theta_d", "phi"});
    const Table& mt = require<T>(set, g + "/mp_" + lobe, {"theta_i", "theta_r"});
    channels(n);
    if (!n0) n0 = &n, m0 = &mt;
    same(n, *n0), same(mt, *m0);
    m.np[p] = values<T>(n), m.mp[p] = values<T>(mt);
    m.grazing[p] = n.grazing_factor();
    if (m.grazing[p].x_scale != 0.0) throw DomainError("table " + n.path() + ": an explicit lobe's grazing factor must be a power of cos theta_d alone");
  }
  m.theta_d = n0->axes[1].view(), m.phi = n0->axes[2].view();
  m.theta_i = m0->axes[0].view(), m.theta_r = m0->axes[1].view();
  if (set.find(g + "/np_residual")) {
    const Table& n = require<T>(set, g + "/np_residual", {"channel", "theta_d"});
    const Table& mt = require<T>(set, g + "/mp_residual", {"theta_i", "theta_r"});
    channels(n);
    if (!same_axis(n.axes[1], n0->axes[1])) throw DomainError("table " + n.path() + ": axis theta_d differs from " + n0->path() + "'s");
    same(mt, *m0);
    m.np_residual = values<T>(n), m.mp_residual = values<T>(mt);
    m.residual_grazing = n.grazing_factor();
    if (!m.residual_grazing.none()) {
      // Its factor reads the material's σa, which the table records per channel.
      const auto sa = n.attributes.find("sigma_a");
      if (sa == n.attributes.end() || !sa->is_array() || sa->size() != 3)
        throw DomainError("table " + n.path() + ": divided by a grazing factor but without the material's sigma_a (3 channels)");
      for (int c = 0; c < 3; ++c) {
        const auto& v = (*sa)[static_cast<std::size_t>(c)];
        if (!v.is_number() || !(v.get<double>() >= 0.0) || !(v.get<double>() <= 1e6))
          throw DomainError("table " + n.path() + ": attribute sigma_a must hold 3 numbers in [0, 1e6]");
        m.sigma_a[c] = v.get<double>();
      }
    }
  }
  return m;
}

template sampler::MaterialTables<float> material_tables<float>(const TableSet&, std::string_view);
template sampler::MaterialTables<double> material_tables<double>(const TableSet&, std::string_view);

template <class T>
sampler::HairScattering<T> hair_scattering(const TableSet& set, std::string_view group) {
  if (group.empty() || group == "np" || group == "mp") return hair_scattering<T>(set);
  const std::string g(group);
  if (g.rfind("materials/", 0) != 0) throw DomainError("table group " + g + ": not a material (materials/<name>) or the generic tables (\"\")");
  sampler::HairScattering<T> r(material_tables<T>(set, g));
  if (!r.valid())
    throw DomainError("table group " + g + ": the runtime reads linear, edge-placed axes with theta_i over [-90, 90] deg, phi over [0, 180] deg and theta_d within [0, 90] deg");
  return r;
}

template sampler::HairScattering<float> hair_scattering<float>(const TableSet&, std::string_view);
template sampler::HairScattering<double> hair_scattering<double>(const TableSet&, std::string_view);

template <class T, class R>
sampler::FourierNp<T, R> fourier_np(const TableSet& set, std::string_view lobe) {
  const std::string path = std::string(kFourierGroup) + "/" + std::string(lobe);
  const Table* t = set.find(path);
  if (!t) throw DomainError("table " + path + ": missing (the set has no Fourier N_p of lobe " + std::string(lobe) + ")");
  const FourierTableInfo info = fourier_table_info(*t);
  const Table& checked = require<T>(set, path, {"theta_d", "sigma_a", "n"});
  const sampler::FourierNp<T, R> view(values<T>(checked), checked.axes[0].view(), checked.axes[1].view(), info.params);
  if (!view.valid()) throw DomainError("table " + path + ": the sampler cannot read its axes or attributes");
  return view;
}

template sampler::FourierNp<float, float> fourier_np<float, float>(const TableSet&, std::string_view);
template sampler::FourierNp<float, double> fourier_np<float, double>(const TableSet&, std::string_view);
template sampler::FourierNp<double, float> fourier_np<double, float>(const TableSet&, std::string_view);
template sampler::FourierNp<double, double> fourier_np<double, double>(const TableSet&, std::string_view);

int lobe_index(const TableSet& set, std::string_view lobe) {
  const auto it = set.metadata.find("lobes");
  std::string have;
  if (it != set.metadata.end())
    for (std::size_t p = 0; p < it->size(); ++p) {
      const std::string name = (*it)[p].get<std::string>();
      if (name == lobe) return static_cast<int>(p);
      have += (have.empty() ? "" : ", ") + name;
    }
  throw DomainError("table set: no lobe " + std::string(lobe) + " (lobes: " + (have.empty() ? std::string("none") : have) + ")");
}

sampler::Fiber fiber_from_melanin(double eumelanin, double pheomelanin, double beta_m, double beta_n) {
  require_positive("beta_m", beta_m);
  require_positive("beta_n", beta_n);
  const Rgb s = melanin_sigma_a_rgb(eumelanin, pheomelanin);
  sampler::Fiber f;
  f.sigma_a[0] = s.r, f.sigma_a[1] = s.g, f.sigma_a[2] = s.b;
  f.beta_m = beta_m, f.beta_n = beta_n;
  return f;
}

std::vector<std::string> material_groups(const TableSet& set) {
  std::vector<std::string> groups;
  for (const Table& t : set.tables)
    if (t.group.rfind("materials/", 0) == 0 && std::find(groups.begin(), groups.end(), t.group) == groups.end()) groups.push_back(t.group);
  return groups;
}

}  // namespace hairlut
