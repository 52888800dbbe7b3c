// The lobes of a loaded table set as the header-only hair sampler (sampling.hpp) reads them:
// generic d'Eon tables (np/<lobe> with its factor np/energy_<lobe>, mp/<lobe>, the residual) or
// the tables of one material (materials/<name>/np_<lobe>, energy_<lobe>, mp_<lobe>). What an
// engine does with the sidecar, done from a TableSet for the tools and tests.
#pragma once

#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "hairlut/util/error.hpp"
#include "hairlut/sampler/sampling.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// The sampler of one table group, with the axis views it points into. Valid while the TableSet
/// lives (the sampler points into its float32 values).
struct HairTables {
  std::vector<std::string> lobe_names;
  std::deque<std::vector<sampler::Axis>> axes;  // stable addresses
  std::vector<sampler::LobeTables<float>> lobes;
  std::unique_ptr<sampler::HairSampler<float>> sampler;
};

/// The lobes of `group`: "" for the generic tables (groups np and mp), or "materials/<name>".
/// Generic tables baked in β bands: the N_p tables of band `beta_band` (its attribute
/// `beta_band.index`; docs/table-format.md), which serve fibres whose β lies in that band.
/// Throws DomainError when a table is missing, is not float32, or cannot be sampled.
inline HairTables hair_tables(const TableSet& set, const std::string& group, int beta_band = 0) {
  HairTables h;
  auto ref = [&](const Table* t) {
    sampler::TableRef<float> r;
    if (!t) return r;
    if (t->precision != Precision::float32) throw DomainError(t->path() + ": sampling reads float32 tables");
    std::vector<sampler::Axis>& a = h.axes.emplace_back();
    for (const GridAxis& g : t->axes) a.push_back(g.view());
    r.data = t->f32.data();
    r.axes = a.data();
    r.dims = static_cast<int>(a.size());
    for (int d = 0; d < r.dims; ++d) r.coords[d] = sampler::coordinate_named(t->axes[static_cast<std::size_t>(d)].name);
    return r;
  };
  const bool generic = group.empty();
  for (const Table& t : set.tables) {
    if (t.quantity != "N_p") continue;
    if (generic ? t.group != "np" : (t.group != group || t.name.rfind("np_", 0) != 0)) continue;
    if (t.attributes.contains("beta_band") ? t.attributes["beta_band"].value("index", 0) != beta_band : beta_band != 0) continue;
    const std::string lobe = t.attributes.value("lobe", std::string());
    const std::string mp = generic ? "mp/" + lobe : group + "/mp_" + lobe;
    const std::string energy = generic ? "np/energy_" + lobe : group + "/energy_" + lobe;
    const Table* m = set.find(mp);
    if (!m) throw DomainError(mp + ": missing (the M_p table of lobe " + lobe + ")");
    sampler::LobeTables<float> l;
    l.np = ref(&t);
    l.mp = ref(m);
    if (!t.factor().empty()) {
      const Table* f = set.find(t.factor());
      if (!f) throw DomainError(t.factor() + ": missing (the factor of " + t.path() + ")");
      l.factor = ref(f);
    }
    l.energy = ref(set.find(energy));
    h.lobe_names.push_back(lobe);
    h.lobes.push_back(l);
  }
  if (h.lobes.empty()) throw DomainError((generic ? std::string("np") : group) + ": no N_p tables to sample");
  if (static_cast<int>(h.lobes.size()) > sampler::HairSampler<float>::max_lobes)
    throw DomainError((generic ? std::string("np") : group) + ": more lobes than the sampler takes");
  h.sampler = std::make_unique<sampler::HairSampler<float>>(h.lobes.data(), static_cast<int>(h.lobes.size()));
  if (!h.sampler->supported()) throw DomainError((generic ? std::string("np") : group) + ": tables the sampler cannot sample");
  return h;
}

}  // namespace hairlut
