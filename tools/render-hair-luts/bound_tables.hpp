// The tables the error bound of render-hair-luts reads (main.cpp, Bounder): per lobe of a table
// group, its N_p (or shape), the shape's energy factor and its M_p, each with what its axes stand
// for, so that one lookup routine fills generic (β, σa, θd, φ) and per-material (channel, θd, φ)
// tables alike. Private to the tool: renderers use HairScattering (hair_views.hpp).
#pragma once

#include <algorithm>
#include <deque>
#include <string>
#include <vector>

#include <hairlut/sampler/sampler.hpp>
#include <hairlut/tables/tables.hpp>
#include <hairlut/util/error.hpp>

namespace render {

/// What a table axis stands for.
enum class Coordinate : int { none = 0, beta, sigma_a, channel, theta_d, theta_i, theta_r, phi };

inline Coordinate coordinate_named(const std::string& name) {
  static const char* const names[] = {"beta", "sigma_a", "channel", "theta_d", "theta_i", "theta_r", "phi"};
  for (int k = 0; k < 7; ++k)
    if (name == names[k]) return static_cast<Coordinate>(k + 1);
  return Coordinate::none;
}

/// One table: values, axes and what each axis stands for (data null: no table).
struct TableRef {
  const float* data = nullptr;
  const hairlut::sampler::Axis* axes = nullptr;
  int dims = 0;
  Coordinate coords[8] = {};
  hairlut::sampler::GrazingFactor grazing;  ///< the values are the quantity divided by g(σa, θd) (Table::grazing_factor)
};

/// The tables of one lobe.
struct LobeRefs {
  TableRef np;      ///< N_p (or its shape, with `factor`); last axis φ, or none (the residual)
  TableRef factor;  ///< the table np is multiplied by (the shape's energy); optional
  TableRef mp;      ///< M_p
};

/// The fiber coordinates that the tables' axes beta, sigma_a and channel read.
struct FiberCoordinates {
  double beta = 0.0;
  double sigma_a = 0.0;
  double channel = 0.0;
};

/// The lobes of one table group, pointing into the TableSet (which must outlive them).
struct BoundTables {
  std::vector<std::string> lobe_names;
  std::deque<std::vector<hairlut::sampler::Axis>> axes;  // stable addresses
  std::vector<LobeRefs> lobes;
};

/// The lobes of `group`: "" for the generic tables (groups np and mp; band 0 of a set baked in β
/// bands), or "materials/<name>". Throws DomainError when a table is missing or not float32.
inline BoundTables bound_tables(const hairlut::TableSet& set, const std::string& group) {
  BoundTables h;
  auto ref = [&](const hairlut::Table* t) {
    TableRef r;
    if (!t) return r;
    if (t->precision != hairlut::Precision::float32) throw hairlut::DomainError(t->path() + ": the error bound reads float32 tables");
    std::vector<hairlut::sampler::Axis>& a = h.axes.emplace_back();
    for (const hairlut::GridAxis& g : t->axes) a.push_back(g.view());
    r.data = t->f32.data();
    r.axes = a.data();
    r.dims = static_cast<int>(a.size());
    r.grazing = t->grazing_factor();
    for (int d = 0; d < r.dims; ++d) r.coords[d] = coordinate_named(t->axes[static_cast<std::size_t>(d)].name);
    return r;
  };
  const bool generic = group.empty();
  for (const hairlut::Table& t : set.tables) {
    if (t.quantity != "N_p") continue;
    if (generic ? t.group != "np" : (t.group != group || t.name.rfind("np_", 0) != 0)) continue;
    if (t.attributes.contains("beta_band") && t.attributes["beta_band"].value("index", 0) != 0) continue;
    const std::string lobe = t.attributes.value("lobe", std::string());
    const std::string mp = generic ? "mp/" + lobe : group + "/mp_" + lobe;
    const hairlut::Table* m = set.find(mp);
    if (!m) throw hairlut::DomainError(mp + ": missing (the M_p table of lobe " + lobe + ")");
    LobeRefs l;
    l.np = ref(&t);
    l.mp = ref(m);
    if (!t.factor().empty()) {
      const hairlut::Table* f = set.find(t.factor());
      if (!f) throw hairlut::DomainError(t.factor() + ": missing (the factor of " + t.path() + ")");
      l.factor = ref(f);
    }
    h.lobe_names.push_back(lobe);
    h.lobes.push_back(l);
  }
  if (h.lobes.empty()) throw hairlut::DomainError((generic ? std::string("np") : group) + ": no N_p tables");
  return h;
}

}  // namespace render
