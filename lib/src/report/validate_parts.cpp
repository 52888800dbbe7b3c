// Validation of a set larger than memory: its N_p tables over β read in parts of consecutive β rows
// (as a slabbed bake writes them), each part validated by validate_tables over its own cells, the
// reports merged into one (validate.hpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "hairlut/io/table_io.hpp"
#include "hairlut/report/validate.hpp"
#include "hairlut/util/error.hpp"
#include "validate_sections.hpp"

namespace hairlut {

using detail::validation::json;

namespace {

// Values read at a time while the content checksum is streamed.
constexpr std::size_t kRunBytes = std::size_t{16} << 20;

std::uint64_t values_bytes(const Table& t) { return static_cast<std::uint64_t>(grid_size(t.axes)) * (t.precision == Precision::float64 ? 8u : 4u); }

bool in_parts(const Table& t) { return t.group == "np" && t.axes.size() == 4 && t.axes[0].name == "beta"; }

// A check of one part merged into the same check of the parts before: failing anywhere fails, and
// the value is the worst (the largest for "<=" and "==", the smallest for ">=" and ">").
void merge_check(json& into, const json& c, const std::string& part_text) {
  const std::string a = into["status"].get<std::string>(), b = c["status"].get<std::string>();
  if (b == "skipped") return;
  auto take = [&] {
    into["value"] = c["value"];
    into["detail"] = part_text + ": " + c["detail"].get<std::string>();
  };
  if (a == "skipped") {
    into = c;
    into["detail"] = part_text + ": " + c["detail"].get<std::string>();
    return;
  }
  if (b == "fail") into["status"] = "fail";
  if (!c["value"].is_number() || !into["value"].is_number()) return;
  const std::string cmp = c.value("comparison", std::string("<="));
  const double v = c["value"].get<double>(), w = into["value"].get<double>();
  if ((cmp == ">=" || cmp == ">") ? v < w : v > w) take();
}

// The accuracy entry of a table read in parts, merged with the same table's entry of the next
// part into one over both: the cells along the part axis (the first, and the heat maps' rows)
// are the parts' side by side, every other cell the worse of the two; the figures are the whole's
// (points added, the worst kept, the mean weighted, the 99th percentile the larger).
void merge_accuracy(json& a, const json& b) {
  json& x = a["off_node"];
  const json& y = b["off_node"];
  const double na = x["points"].get<double>(), nb = y["points"].get<double>();
  x["mean_rel"] = na + nb > 0 ? (x["mean_rel"].get<double>() * na + y["mean_rel"].get<double>() * nb) / (na + nb) : 0.0;
  x["points"] = x["points"].get<std::uint64_t>() + y["points"].get<std::uint64_t>();
  for (const char* k : {"max_rel", "p99_rel", "max_abs"}) x[k] = std::max(x[k].get<double>(), y[k].get<double>());
  if (b["worst"]["max_rel"].get<double>() > a["worst"]["max_rel"].get<double>()) a["worst"] = b["worst"];
  a["search"]["points"] = a["search"]["points"].get<std::uint64_t>() + b["search"]["points"].get<std::uint64_t>();
  for (const json& st : b["search"]["stages"]) {
    auto it = std::find_if(a["search"]["stages"].begin(), a["search"]["stages"].end(), [&](const json& t) { return t["stage"] == st["stage"]; });
    if (it == a["search"]["stages"].end()) {
      a["search"]["stages"].push_back(st);
      continue;
    }
    const auto points = (*it)["points"].get<std::uint64_t>() + st["points"].get<std::uint64_t>();
    if (st["max_rel"].get<double>() > (*it)["max_rel"].get<double>()) *it = st;
    (*it)["points"] = points;
  }
  const std::string axis = a["part"]["axis"].get<std::string>();
  auto worse = [](const json& u, const json& v) {  // NaN or null (no point in the cell) loses
    if (!u.is_number() || std::isnan(u.get<double>())) return v;
    if (!v.is_number() || std::isnan(v.get<double>())) return u;
    return json(std::max(u.get<double>(), v.get<double>()));
  };
  for (json& pa : a["per_axis"]) {
    auto it = std::find_if(b["per_axis"].begin(), b["per_axis"].end(), [&](const json& t) { return t["axis"] == pa["axis"]; });
    if (it == b["per_axis"].end()) continue;
    json& cells = pa["cells_max_rel"];
    if (pa["axis"] == axis) {
      for (const json& c : (*it)["cells_max_rel"]) cells.push_back(c);
      pa["count"] = cells.size() + 1;
    } else {
      for (std::size_t i = 0; i < cells.size() && i < (*it)["cells_max_rel"].size(); ++i) cells[i] = worse(cells[i], (*it)["cells_max_rel"][i]);
    }
    std::size_t at = 0;
    for (std::size_t i = 0; i < cells.size(); ++i)
      if (cells[i].is_number() && !std::isnan(cells[i].get<double>()) &&
          (!cells[at].is_number() || std::isnan(cells[at].get<double>()) || cells[i].get<double>() > cells[at].get<double>()))
        at = i;
    pa["worst_cell"] = at;
    pa["max_rel"] = cells.empty() ? json(0.0) : cells[at];
  }
  for (json& h : a["heatmaps"]) {
    auto it = std::find_if(b["heatmaps"].begin(), b["heatmaps"].end(), [&](const json& t) { return t["x"] == h["x"] && t["y"] == h["y"]; });
    if (it == b["heatmaps"].end()) continue;
    if (h["y"] == axis) {
      for (const json& c : (*it)["y_centres"]) h["y_centres"].push_back(c);
      for (const json& row : (*it)["max_rel"]) h["max_rel"].push_back(row);
    } else {
      for (std::size_t i = 0; i < h["max_rel"].size() && i < (*it)["max_rel"].size(); ++i)
        for (std::size_t j = 0; j < h["max_rel"][i].size() && j < (*it)["max_rel"][i].size(); ++j)
          h["max_rel"][i][j] = worse(h["max_rel"][i][j], (*it)["max_rel"][i][j]);
    }
  }
}

}  // namespace

std::optional<std::uint64_t> hdf5_values_bytes(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return std::nullopt;  // a FIFO would block the read: the loader refuses it
  std::ifstream in(file, std::ios::binary);
  char head[8] = {};
  if (in) in.read(head, 8);
  if (!in || std::string(head, 8) != std::string("\x89HDF\r\n\x1a\n", 8)) return std::nullopt;
  std::uint64_t n = 0;
  for (const Table& t : read_hdf5_outline(file, false).tables) n += values_bytes(t);
  return n;
}

nlohmann::ordered_json validate_tables_in_parts(const std::filesystem::path& file, const std::string& source, std::uint64_t memory_budget,
                                                const ValidationOptions& given) {
  ValidationOptions options = given;
  if (!options.seed) {
    std::random_device device;
    options.seed = (static_cast<std::uint64_t>(device()) << 32) ^ device();
  }
  // NaN, Inf and negative values, counted as the checksum's stream passes (the parts overlap).
  struct Counts {
    long long values = 0, nan = 0, inf = 0, negative = 0;
  };
  std::map<std::string, Counts> counts;
  const Hdf5RunVisitor count = [&](const Hdf5Run& run) {
    Counts& c = counts[run.table.path()];
    const bool signed_ok = detail::validation::may_be_negative(run.table);
    for (std::size_t i = 0; i < run.count; ++i) {
      const double v = run.f32 ? run.f32[i] : run.f64[i];
      if (std::isnan(v)) ++c.nan;
      else if (std::isinf(v)) ++c.inf;
      else if (v < 0.0 && !signed_ok) ++c.negative;
    }
    c.values += static_cast<long long>(run.count);
  };
  // What cannot be split is refused before the file is read through.
  const TableSet described = read_hdf5_outline(file, false);
  std::uint64_t whole = kValidationPartOverhead;
  for (const Table& t : described.tables) whole += values_bytes(t);
  for (const Table& t : described.tables)
    if (t.group.rfind("sampling/np", 0) == 0)
      throw DomainError(file.string() + ": holds sampling data for its N_p tables (" + t.path() +
                        "), which cannot be validated in parts (a set baked slab by slab has none); validated whole it needs a --memory-budget of " +
                        std::to_string((whole >> 20) + 1) + " MiB");
  if (options.progress) options.progress("checksum", 0, 1);
  const TableSetParts parts(file, kRunBytes, count);
  detail::validation::check_cancel(options);
  const TableSet& outline = parts.outline();

  // The tables read in parts and the β axis they share; what every part holds beside them.
  const GridAxis* beta = nullptr;
  std::uint64_t row_bytes = 0, rest_bytes = 0;
  for (const Table& t : outline.tables) {
    if (!in_parts(t)) {
      rest_bytes += values_bytes(t);
      continue;
    }
    if (beta && (beta->count != t.axes[0].count || beta->nodes() != t.axes[0].nodes()))
      throw DomainError(file.string() + ": " + t.path() + " has another beta axis than the other N_p tables");
    beta = &t.axes[0];
    row_bytes += values_bytes(t) / static_cast<std::uint64_t>(t.axes[0].count);
  }
  if (!beta) throw DomainError(file.string() + ": has no N_p tables over beta to validate in parts");
  const int n = beta->count;
  const std::uint64_t fixed = rest_bytes + kValidationPartOverhead;
  const std::uint64_t rows = memory_budget > fixed ? (memory_budget - fixed) / std::max<std::uint64_t>(row_bytes, 1) : 0;
  // A part of c cells holds c + 1 rows and one more beyond each inner end.
  const std::uint64_t need_rows = n < 3 ? static_cast<std::uint64_t>(n) : 3;
  if (rows < need_rows) {
    const std::uint64_t least = fixed + need_rows * row_bytes;
    throw DomainError("--memory-budget " + std::to_string(memory_budget >> 20) + " MiB cannot hold a part of " + file.string() + ": it needs " +
                      std::to_string((least >> 20) + 1) + " MiB at least (" + std::to_string(rest_bytes >> 20) + " MiB of tables held whole, " +
                      std::to_string(need_rows) + " beta rows of N_p of " + std::to_string(row_bytes >> 20) + " MiB each, and the validator)");
  }
  const int cells = std::max(n - 1, 1);
  const int per_part = static_cast<int>(std::clamp<std::uint64_t>(rows - 2, 1, static_cast<std::uint64_t>(cells)));
  const auto nodes = beta->nodes();
  std::vector<std::pair<int, int>> ranges;  // the cells [c0, c1) of each part, as nodes c0 … c1
  for (int c0 = 0; c0 < cells; c0 += per_part) ranges.emplace_back(c0, std::min(c0 + per_part, cells));
  if (n == 1) ranges = {{0, 0}};

  json merged;
  json part_list = json::array();
  for (std::size_t k = 0; k < ranges.size(); ++k) {
    detail::validation::check_cancel(options);
    const auto [c0, c1] = ranges[k];
    Hdf5Rows r;
    r.first = std::max(c0 - 1, 0);
    r.count = std::min(c1 + 1, n - 1) - r.first + 1;
    const TableSet set = parts.rows(r);
    ValidationOptions po = options;
    ValidationPart part;
    part.lo = nodes[static_cast<std::size_t>(c0)], part.hi = nodes[static_cast<std::size_t>(c1)];
    part.share = static_cast<double>(std::max(c1 - c0, 1)) / cells;
    part.index = static_cast<int>(k), part.count = static_cast<int>(ranges.size());
    po.part = part;
    const std::string text = "part " + std::to_string(k + 1) + " of " + std::to_string(ranges.size()) + " (beta " +
                             detail::validation::fmt(degrees(part.lo), 4) + " to " + detail::validation::fmt(degrees(part.hi), 4) + " deg)";
    if (options.progress)
      po.progress = [&, text](std::string_view stage, std::size_t done, std::size_t total) { options.progress(text + ": " + std::string(stage), done, total); };
    json report = validate_tables(set, source, po);
    part_list.push_back({{"index", k},
                         {"beta_nodes", {c0, c1}},
                         {"beta_range", {part.lo, part.hi}},
                         {"rows_read", {r.first, r.first + r.count - 1}},
                         {"bytes_held", set.bytes()},
                         {"status", report["summary"]["status"]}});
    if (k == 0) {
      merged = std::move(report);
      for (json& c : merged["checks"])
        if (c["status"] != "skipped") c["detail"] = text + ": " + c["detail"].get<std::string>();
      continue;
    }
    for (const json& c : report["checks"]) {
      auto it = std::find_if(merged["checks"].begin(), merged["checks"].end(), [&](const json& m) { return m["id"] == c["id"]; });
      if (it == merged["checks"].end()) {
        merged["checks"].push_back(c);
        merged["checks"].back()["detail"] = text + ": " + c["detail"].get<std::string>();
      } else {
        merge_check(*it, c, text);
      }
    }
    for (const json& a : report["accuracy"]) {
      if (!a.contains("part")) continue;
      auto it = std::find_if(merged["accuracy"].begin(), merged["accuracy"].end(), [&](const json& m) { return m["path"] == a["path"]; });
      if (it == merged["accuracy"].end()) merged["accuracy"].push_back(a);
      else merge_accuracy(*it, a);
    }
    if (report.contains("furnace") && report["furnace"].contains("curves"))
      for (const json& c : report["furnace"]["curves"]) merged["furnace"]["curves"].push_back(c);
  }

  for (json& a : merged["accuracy"])
    if (a.contains("part")) a["part"] = {{"axis", "beta"}, {"parts", ranges.size()}, {"note", "measured part by part, merged (report \"parts\")"}};

  // NaN, Inf and negatives from the stream, each value once.
  long long nan = 0, inf = 0, neg = 0;
  json per_table = json::array();
  for (const Table& t : outline.tables) {
    const Counts& c = counts[t.path()];
    nan += c.nan, inf += c.inf, neg += c.negative;
    per_table.push_back({{"path", t.path()}, {"values", c.values}, {"nan", c.nan}, {"inf", c.inf}, {"negative", c.negative}});
  }
  merged["sanity"]["tables"] = per_table;
  for (json& c : merged["checks"])
    if (c["id"] == "sanity_values")
      c = detail::validation::check("sanity_values", "No NaN, Inf or negative value in any table", nan + inf + neg == 0, static_cast<double>(nan + inf + neg),
                                    0, "==",
                                    std::to_string(nan) + " NaN, " + std::to_string(inf) + " Inf, " + std::to_string(neg) + " negative in " +
                                        std::to_string(outline.tables.size()) + " tables (counted over the file, each value once)");
  int passed = 0, failed = 0, skipped_n = 0;
  for (const json& c : merged["checks"]) {
    const std::string s = c["status"].get<std::string>();
    (s == "pass" ? passed : s == "fail" ? failed : skipped_n)++;
  }
  merged["summary"] = {{"status", failed == 0 ? "pass" : "fail"}, {"passed", passed}, {"failed", failed}, {"skipped", skipped_n}};
  merged["parts"] = {{"memory_budget_bytes", memory_budget},
                     {"values_bytes", rest_bytes + row_bytes * static_cast<std::uint64_t>(n)},
                     {"split", "N_p tables over beta read in parts of consecutive beta rows (one row beyond each inner end for the cubic taps); the other tables whole"},
                     {"merge", "a check fails if it fails in any part and reports the worst part's value; accuracy_p99_rel is the largest of the parts' 99th "
                               "percentiles, which bounds the set's from above; each part draws random points in proportion to its cells; no half-float "
                               "figures for the tables read in parts; NaN, Inf and negatives counted over the whole file as its checksum is verified"},
                     {"parts", part_list}};
  return merged;
}

}  // namespace hairlut
