// The contract every table kind of lib/kinds/ keeps (hairlut/bake/table_kind.hpp,
// hairlut/report/table_kind_report.hpp), checked for each kind the build found, so that a new
// kind's folder is tested without a test of its own: the published config schema carries its
// fragment; each example entry of the fragment parses through a whole config, and its normalized
// form bakes the same values; it bakes what its size estimate counts, into its own group; its reference
// (through table_truth, as the validator reaches it) gives every stored value at the nodes; the
// validator's side owns those tables and reports on them.
#include <filesystem>
#include <fstream>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/bake/table_kind.hpp>
#include <hairlut/bake/table_truth.hpp>
#include <hairlut/report/table_kind_report.hpp>
#include <hairlut/report/validate.hpp>
#include <hairlut/util/error.hpp>
#include <set>

#include "catch.hpp"

#ifndef HAIRLUT_SOURCE_DIR
#error "HAIRLUT_SOURCE_DIR must name the source tree"
#endif

using namespace hairlut;
using json = nlohmann::json;

namespace {

const TableKindReport* report_of(std::string_view name) {
  for (const TableKindReport* r : table_kind_reports())
    if (r->name() == name) return r;
  return nullptr;
}

// The coordinates of every node of t, in the order of its values.
std::vector<std::vector<double>> node_points(const Table& t) {
  std::vector<std::vector<double>> nodes;
  for (const GridAxis& a : t.axes) nodes.push_back(a.nodes());
  std::vector<std::vector<double>> points = {{}};
  for (const auto& n : nodes) {
    std::vector<std::vector<double>> next;
    for (const auto& p : points)
      for (double x : n) {
        next.push_back(p);
        next.back().push_back(x);
      }
    points = std::move(next);
  }
  return points;
}

}  // namespace

TEST_CASE("table kinds: the published config schema is the library's, with every kind's fragment", "[kinds][config]") {
  std::ifstream in(std::filesystem::path(HAIRLUT_SOURCE_DIR) / "schemas" / "hairlut-config.schema.json");
  REQUIRE(in);
  const json published = json::parse(in);
  const json assembled = config_schema();
  std::string differences;
  for (const json& op : json::diff(published, assembled)) differences += " " + op["op"].get<std::string>() + " " + op["path"].get<std::string>();
  INFO("schemas/hairlut-config.schema.json differs from lib/src/bake/config.schema.json with lib/kinds/*/schema.json:" << differences);
  CHECK(differences.empty());
  for (const TableKind* k : table_kinds())
    CHECK(published["properties"]["tables"]["properties"].contains(std::string(k->name())));
}

TEST_CASE("table kinds: each kind's examples parse, bake what the estimate counts and meet their references", "[kinds]") {
  REQUIRE(!table_kinds().empty());
  std::set<std::string> names;
  for (const TableKind* kind : table_kinds()) {
    const std::string name(kind->name());
    INFO("kind " << name);
    CHECK(names.insert(name).second);
    const json fragment = json::parse(kind->schema());
    REQUIRE(fragment.contains("examples"));
    REQUIRE(!fragment["examples"].empty());
    for (const json& example : fragment["examples"]) {
      INFO("example " << example.dump());
      json doc = {{"name", "kind-" + name}, {"output", {{"basename", "kind-" + name}, {"formats", {"hdf5"}}}}};
      doc["tables"][name] = example;
      const BakeConfig c = parse_config(doc, "example", std::filesystem::temp_directory_path());
      REQUIRE(c.kinds.size() == 1);
      REQUIRE(c.kinds[0].kind == kind);
      const TableKindSettings& s = *c.kinds[0].settings;

      // The normalized entry is what the config records (and its hash covers), and it bakes the
      // same values as the entry it came from.
      const json normalized = kind->normalized(s);
      CHECK(c.normalized["tables"][name] == normalized);

      TableSet set, again;
      BakeReport report, report_again;
      kind->bake(s, Precision::float32, set, report);
      kind->bake(*kind->parse(normalized), Precision::float32, again, report_again);
      REQUIRE(!set.tables.empty());
      REQUIRE(again.tables.size() == set.tables.size());
      for (std::size_t i = 0; i < set.tables.size(); ++i) CHECK(again.tables[i].f32 == set.tables[i].f32);
      std::uint64_t counted = 0, stored = 0;
      for (const TableKindSize& z : kind->sizes(s)) counted += z.values * z.tables;
      for (const Table& t : set.tables) stored += t.size();
      CHECK(counted == stored);
      CHECK(report.entries == stored);

      const TableKindReport* r = report_of(name);
      for (const Table& t : set.tables) {
        INFO("table " << t.path());
        CHECK(t.group == name);
        const std::optional<TableTruth> truth = table_truth(t, TruthModel{}, nullptr);
        REQUIRE(truth);
        REQUIRE(truth->make);
        // At the nodes a table stores the function itself, rounded to float.
        double worst = 0.0;
        const auto points = node_points(t);
        REQUIRE(points.size() == t.size());
        for (std::size_t o = 0; o < points.size(); ++o) {
          const double exact = truth->make(points[o])(points[o]);
          const double scale = std::max(std::abs(exact), std::max(truth->absolute_floor, 1e-300));
          worst = std::max(worst, std::abs(t.get(o) - exact) / scale);
        }
        CHECK(worst <= 1e-6);
        if (r) CHECK(r->owns(t));
      }
      if (r) {
        const nlohmann::ordered_json section = r->section(set);
        REQUIRE(!section.is_null());
        CHECK(!r->html(section).empty());
      }
    }
  }
}

TEST_CASE("table kinds: each validator section belongs to a kind and checks its kind's threshold", "[kinds][validate]") {
  // Each kind's threshold has its default, can be set by name, and is refused at 0.
  for (const TableKind* k : table_kinds()) {
    const std::string name(k->threshold().name);
    ValidationThresholds th;
    CHECK(th.get(name) == k->threshold().value);
    th.set(name, 0.5);
    CHECK(th.get(name) == 0.5);
    CHECK(th.to_json()[name] == 0.5);
    CHECK_THROWS_AS(th.set(name, 0.0), DomainError);
  }
  for (const TableKindReport* r : table_kind_reports()) {
    INFO("kind " << std::string(r->name()));
    bool found = false;
    for (const TableKind* k : table_kinds()) found = found || k->name() == r->name();
    CHECK(found);
    CHECK_NOTHROW(ValidationThresholds{}.get(std::string(r->accuracy_check())));
    for (const TableKind* k : table_kinds())
      if (k->name() == r->name()) CHECK(k->threshold().name == r->accuracy_check());
    CHECK(!r->accuracy_title().empty());
  }
}
