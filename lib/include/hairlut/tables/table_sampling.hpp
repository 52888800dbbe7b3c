// The lobes of a loaded table set as the header-only hair sampler (sampling.hpp) reads them:
// generic d'Eon tables (np/<lobe> with its factor np/energy_<lobe>, mp/<lobe>, the residual) or
// the tables of one material (materials/<name>/np_<lobe>, energy_<lobe>, mp_<lobe>). What an
// engine does with the sidecar, done from a TableSet for the tools and tests. And the sampling data
// stored next to those tables (docs/table-format.md, "Sampling data"): made, found and checked.
#pragma once

#include <algorithm>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hairlut/util/error.hpp"
#include "hairlut/sampler/sampling.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// The measure along the sampled axis when t is a table the hair sampler samples (N_p over φ:
/// plain; M_p over θr: cos θr; generic or per material, values present), else nullopt.
std::optional<sampler::Measure> sampled_measure(const Table& t);
/// Where t's sampling data live: "sampling/<group>/<name>_<what>", what = cdf, mass or clamp_bound.
std::string sampling_path(const Table& t, const std::string& what);
/// The sampling data of every sampled table of the set whose axes the sampler supports, as tables
/// (AxisSampler::build_data of the stored values): <name>_cdf (float64, the table's axes),
/// <name>_mass (float64) over the other axes and <name>_clamp_bound (float32, the table's axes).
/// The clamp bounds are computed on `threads` OpenMP threads (0: all cores); the values do not
/// depend on the thread count. `progress` (optional) hears ("sampling data", tables done, tables).
using SamplingProgress = std::function<void(std::string_view stage, std::size_t done, std::size_t total)>;
std::vector<Table> sampling_tables(const TableSet& set, int threads = 0, const SamplingProgress& progress = {});
/// Appends sampling_tables(set, threads, progress) to the set (the baker does, after the tables
/// are complete).
void append_sampling_tables(TableSet& set, int threads = 0, const SamplingProgress& progress = {});
/// The stored sampling data of table t (pointers into the set), or empty when the set has none of
/// the right precision and shape, or when they are not t's own (AxisSampler::matches: prefix masses
/// recomputed from t's values, clamp bounds finite and ≥ 0); the sampler then computes them.
sampler::AxisData stored_sampling_data(const TableSet& set, const Table& t);

/// Stored sampling data against what the sampler computes from the stored values.
struct SamplingDataCheck {
  std::string table;                   ///< the sampled table
  bool present = false;                ///< sampling data stored for it
  std::string problem;                 ///< why none could be read ("" when read)
  double max_cdf_difference = 0.0;     ///< largest |stored − computed| prefix, over the slice's largest |prefix|
  double max_mass_difference = 0.0;    ///< the same for the slices' masses
  std::size_t bound_mismatches = 0;     ///< clamp bounds that differ
  std::size_t unclamped = 0, cells = 0;  ///< cells of the other axes with every clamp bound 0, and all of them
};
/// Every sampled table's stored data against the sampler's, recomputed on `threads` OpenMP threads
/// (0: all cores).
std::vector<SamplingDataCheck> check_sampling_data(const TableSet& set, int threads = 0);

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
    // A banded table serves its own band; one without a β axis (the residual) serves every band.
    const bool has_beta = std::any_of(t.axes.begin(), t.axes.end(), [](const GridAxis& a) { return a.name == "beta"; });
    if (t.attributes.contains("beta_band") ? t.attributes["beta_band"].value("index", 0) != beta_band : beta_band != 0 && has_beta) continue;
    const std::string lobe = t.attributes.value("lobe", std::string());
    const std::string mp = generic ? "mp/" + lobe : group + "/mp_" + lobe;
    const std::string energy = generic ? "np/energy_" + lobe : group + "/energy_" + lobe;
    const Table* m = set.find(mp);
    if (!m) throw DomainError(mp + ": missing (the M_p table of lobe " + lobe + ")");
    sampler::LobeTables<float> l;
    l.np = ref(&t);
    l.mp = ref(m);
    l.np_data = stored_sampling_data(set, t);
    l.mp_data = stored_sampling_data(set, *m);
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
