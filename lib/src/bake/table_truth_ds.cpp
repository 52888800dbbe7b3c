// References of the dual-scattering and mean-energy tables (table_truth.hpp).
#include <map>
#include <mutex>

#include "hairlut/physics/dual_scattering.hpp"
#include "hairlut/bake/engine_presets.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/bake/table_truth.hpp"

namespace hairlut {

struct DualScatteringMemo {
  std::mutex mutex;
  std::map<std::pair<std::string, std::vector<double>>, DualScatteringPoint> points;
};

std::shared_ptr<DualScatteringMemo> make_dual_scattering_memo() { return std::make_shared<DualScatteringMemo>(); }

namespace {

// The field of a dual-scattering point that table `name` holds, or nullptr.
std::function<double(const DualScatteringPoint&)> field_of(const std::string& name, const std::vector<std::string>& lobes) {
  if (name == "a_f") return [](const DualScatteringPoint& p) { return p.a_f; };
  if (name == "a_b") return [](const DualScatteringPoint& p) { return p.a_b; };
  if (name == "alpha_f") return [](const DualScatteringPoint& p) { return p.alpha_f; };
  if (name == "alpha_b") return [](const DualScatteringPoint& p) { return p.alpha_b; };
  if (name == "beta_f2") return [](const DualScatteringPoint& p) { return p.beta_f2; };
  if (name == "beta_b2") return [](const DualScatteringPoint& p) { return p.beta_b2; };
  if (name == "A_b") return [](const DualScatteringPoint& p) { return p.backscatter.A_b; };
  if (name == "delta_b") return [](const DualScatteringPoint& p) { return p.backscatter.delta_b; };
  if (name == "sigma_b") return [](const DualScatteringPoint& p) { return p.backscatter.sigma_b; };
  if (name == "sigma_b_mixed") return [](const DualScatteringPoint& p) { return p.backscatter.sigma_b_mixed; };
  if (name == "E_total") return [](const DualScatteringPoint& p) { return p.energy_total; };
  for (std::size_t l = 0; l < lobes.size(); ++l)
    if (name == "E_" + lobes[l]) return [l](const DualScatteringPoint& p) { return l < p.energy.size() ? p.energy[l] : 0.0; };
  return {};
}

std::size_t position(const std::vector<GridAxis>& axes, const std::string& name) {
  for (std::size_t i = 0; i < axes.size(); ++i)
    if (axes[i].name == name) return i;
  throw DomainError("dual-scattering table metadata names an axis \"" + name + "\" that its tables do not have");
}

}  // namespace

std::optional<TableTruth> dual_scattering_truth(const TableSet& set, const Table& t, std::shared_ptr<DualScatteringMemo> memo) {
  if (!set.metadata.contains("dual_scattering") || !set.metadata["dual_scattering"].contains("groups") || t.axes.size() != 3) return std::nullopt;
  const std::string path = t.path();
  for (const auto& item : set.metadata["dual_scattering"]["groups"].items()) {
    const nlohmann::ordered_json& entry = item.value();
    bool listed = false;
    for (const auto& p : entry.value("tables", nlohmann::ordered_json::array())) listed = listed || p.get<std::string>() == path;
    if (!listed) continue;
    const std::vector<std::string> lobes = entry.at("lobes").get<std::vector<std::string>>();
    const auto field = field_of(t.name, lobes);
    if (!field) return std::nullopt;
    const RoughnessMapping rmap = RoughnessMapping::from_json(entry.at("roughness_mapping"));
    const AbsorptionMapping amap = AbsorptionMapping::from_json(entry.at("absorption_mapping"));
    const double d_b = entry.value("density_factor", 0.7);
    const double eta = set.metadata.at("eta").get<double>();
    const AbsorptionPath ap = parse_absorption_path(set.metadata.at("absorption_path").get<std::string>(), "table metadata absorption_path");
    const std::size_t ia = position(t.axes, entry.at("absorption_axis")), ir = position(t.axes, entry.at("roughness_axis")),
                      it = position(t.axes, entry.at("theta_axis"));
    if (!memo) memo = make_dual_scattering_memo();
    const std::string group = item.key();
    TableTruth tr;
    tr.make = [=](const std::vector<double>&) {
      return PointFunction([=](const std::vector<double>& x) {
        const std::vector<double> key = {x[ia], x[ir], x[it]};
        {
          std::lock_guard<std::mutex> lock(memo->mutex);
          const auto found = memo->points.find({group, key});
          if (found != memo->points.end()) return field(found->second);
        }
        const HairModel m = table_model(rmap, amap, eta, ap, x[ir], x[ia]);
        DualScatteringOptions o;
        o.density_factor = d_b;
        const DualScatteringPoint p = dual_scattering(m, x[it], o);
        std::lock_guard<std::mutex> lock(memo->mutex);
        memo->points.emplace(std::make_pair(group, key), p);
        return field(p);
      });
    };
    if (t.quantity == "shift" || t.quantity == "width") {
      tr.absolute_floor = 1e-3;
      tr.denominator = "the exact value itself (relative error), floored at 1e-3 rad";
    } else if (t.quantity == "variance") {
      tr.absolute_floor = 1e-6;
      tr.denominator = "the exact value itself (relative error), floored at 1e-6 rad^2";
    } else {
      tr.absolute_floor = 1e-3;
      tr.denominator = "the exact value itself (relative error), floored at 1e-3";
    }
    return tr;
  }
  return std::nullopt;
}

}  // namespace hairlut
