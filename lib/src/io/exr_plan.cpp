// How write_exr groups the tables of a set into parts (exr_io.hpp): plain planning, no OpenEXR, so
// that the sidecar can name each table's part without loading the OpenEXR library.
#include <algorithm>

#include "hairlut/io/exr_io.hpp"

namespace hairlut {

std::vector<std::pair<std::string, std::vector<std::string>>> exr_part_plan(const TableSet& set) {
  std::vector<std::pair<std::string, std::vector<std::string>>> plan;
  std::vector<std::vector<const Table*>> groups;
  for (const Table& t : set.tables) {
    const bool has_channel = std::any_of(t.axes.begin(), t.axes.end(), [](const GridAxis& a) { return a.name == "channel"; });
    bool placed = false;
    if (!has_channel)
      for (auto& g : groups) {
        const Table& first = *g.front();
        const bool first_channel = std::any_of(first.axes.begin(), first.axes.end(), [](const GridAxis& a) { return a.name == "channel"; });
        if (!first_channel && g.size() < 4 && first.group == t.group && first.quantity == t.quantity &&
            first.axes.size() == t.axes.size() &&
            std::equal(first.axes.begin(), first.axes.end(), t.axes.begin(), [](const GridAxis& a, const GridAxis& b) { return a.to_json() == b.to_json(); })) {
          g.push_back(&t);
          placed = true;
          break;
        }
      }
    if (!placed) groups.push_back({&t});
  }
  for (const auto& g : groups) {
    std::string name = g.front()->group + "/";
    std::vector<std::string> paths;
    for (std::size_t i = 0; i < g.size(); ++i) {
      name += (i ? "+" : "") + g[i]->name;
      paths.push_back(g[i]->path());
    }
    plan.emplace_back(name, paths);
  }
  return plan;
}

}  // namespace hairlut
