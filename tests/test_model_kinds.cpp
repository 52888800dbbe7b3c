// The contract every model of lib/models/ keeps (hairlut/bake/model_kind.hpp,
// hairlut/report/model_kind_report.hpp), checked for each model the build found, so that a new
// model's folder is tested without a test of its own: the config schema carries its name, settings
// and rules; its example config parses as that model and records its settings; the memory plan
// counts what it bakes; its settings come back from the tables' metadata; every table's reference
// (through table_truth, as the validator reaches it) gives the stored values at the nodes; the
// validator's side writes its energy sections with their checks, and renders them for report.html.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/bake_estimate.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/bake/model_kind.hpp>
#include <hairlut/bake/table_truth.hpp>
#include <hairlut/report/model_kind_report.hpp>
#include <hairlut/report/validate.hpp>
#include <hairlut/util/error.hpp>
#include <set>

#include "catch.hpp"

using namespace hairlut;
using json = nlohmann::json;

namespace {

const ModelKindReport* model_report(std::string_view name) {
  for (const ModelKindReport* r : model_kind_reports())
    if (r->name() == name) return r;
  return nullptr;
}

// The coordinates of every node of t, in the order of its values.
std::vector<std::vector<double>> all_nodes(const Table& t) {
  std::vector<std::vector<double>> points = {{}};
  for (const GridAxis& a : t.axes) {
    std::vector<std::vector<double>> next;
    for (const auto& p : points)
      for (double x : a.nodes()) {
        next.push_back(p);
        next.back().push_back(x);
      }
    points = std::move(next);
  }
  return points;
}

BakeConfig example_config(const ModelKind& m) {
  const json fragment = json::parse(m.schema());
  REQUIRE(fragment.contains("example"));
  return parse_config(fragment.at("example"), "example of " + std::string(m.name()), std::filesystem::temp_directory_path());
}

}  // namespace

TEST_CASE("models: each model's fragment joins the config schema with its names, settings and rules", "[models][config]") {
  const nlohmann::ordered_json schema = config_schema();
  const auto& names = schema["properties"]["model"]["enum"];
  std::size_t rules = 0;
  std::set<std::string> seen;
  REQUIRE(model_kinds().size() >= 2);
  for (const ModelKind* m : model_kinds()) {
    INFO("model " << std::string(m->name()));
    CHECK(seen.insert(std::string(m->name())).second);
    CHECK(seen.insert(std::string(m->short_name())).second);
    CHECK(std::find(names.begin(), names.end(), std::string(m->name())) != names.end());
    CHECK(std::find(names.begin(), names.end(), std::string(m->short_name())) != names.end());
    CHECK(find_model_kind(m->name()) == m);
    CHECK(find_model_kind(m->short_name()) == m);
    const json fragment = json::parse(m->schema());
    CHECK(schema["properties"]["model"]["description"].get<std::string>().find(fragment.at("description").get<std::string>()) !=
          std::string::npos);
    if (fragment.contains("properties"))
      for (const auto& [key, value] : fragment["properties"].items()) CHECK(schema["properties"].contains(key));
    rules += fragment.value("allOf", json::array()).size();
    CHECK(model_report(m->name()) != nullptr);
  }
  CHECK(names.size() == seen.size());
  CHECK(schema["allOf"].size() == rules);
  CHECK(find_model_kind("no-such-model") == nullptr);
  // A model's settings key with another model is refused by that model's rule, naming the key.
  for (const ModelKind* m : model_kinds()) {
    const json fragment = json::parse(m->schema());
    if (!fragment.contains("properties")) continue;
    for (const ModelKind* other : model_kinds()) {
      if (other == m) continue;
      json doc = json::parse(other->schema()).at("example");
      for (const auto& [key, value] : fragment["properties"].items()) {
        json with = doc;
        with[key] = json::object();
        INFO(std::string(m->name()) << "'s key " << key << " in a config of model " << std::string(other->name()));
        CHECK_THROWS_WITH(parse_config(with, "c.json", "."), Catch::Contains(key + ": must not be given with another model"));
      }
    }
  }
}

TEST_CASE("models: each model's example bakes what the estimate counts, and its tables meet their references at the nodes",
          "[models][bake]") {
  for (const ModelKind* m : model_kinds()) {
    const std::string name(m->name());
    INFO("model " << name);
    const BakeConfig c = example_config(*m);
    CHECK(c.model == name);
    CHECK(&c.model_kind() == m);
    const json recorded = c.model_settings ? c.model_settings->json() : json();
    BakeOptions opt;
    opt.threads = 2;
    BakeReport report;
    const TableSet set = bake(c, opt, &report);
    CHECK(set.metadata["model"] == name);

    // The memory plan counts every value of every table but the sampling data.
    std::uint64_t stored = 0;
    for (const Table& t : set.tables)
      if (t.group.rfind("sampling/", 0) != 0) stored += t.size();
    CHECK(estimate_bake(c).values == stored);

    // The settings come back from the metadata as the config recorded them.
    const std::shared_ptr<const ModelSettings> back = m->from_metadata(set.metadata, c.eta, c.path);
    CHECK((back ? back->json() : json()) == recorded);
    const json fragment = json::parse(m->schema());
    if (fragment.contains("properties"))  // its settings key: in the metadata and the normalized config as recorded
      for (const auto& [key, value] : fragment["properties"].items()) {
        CHECK(json(set.metadata[key]) == recorded);
        CHECK(c.normalized[key] == recorded);
      }

    // Read back from a hostile file: the settings missing or malformed are refused (DomainError,
    // which the validator reports in one line), and so is a model no folder has.
    if (fragment.contains("properties"))
      for (const auto& [key, value] : fragment["properties"].items()) {
        INFO("settings key " << key);
        json meta = set.metadata;
        meta.erase(key);
        CHECK_THROWS_AS(m->from_metadata(meta, c.eta, c.path), DomainError);
        meta[key] = "not an object";
        CHECK_THROWS_AS(m->from_metadata(meta, c.eta, c.path), DomainError);
        meta[key] = json::object();
        CHECK_THROWS_AS(m->from_metadata(meta, c.eta, c.path), DomainError);
      }
    TableSet unknown = set;
    unknown.metadata["model"] = "no-such-model";
    CHECK_THROWS_WITH(validate_tables(unknown, "unknown.h5", ValidationOptions{}), Catch::Contains("unknown model \"no-such-model\""));

    // Every N_p, energy and M_p table has its reference, and stores it at the nodes (to float
    // rounding and the bake's quadrature, relative to the table's largest value).
    const TruthModel truth_model{c.eta, c.path, c.lobe_count, m, back};
    const auto rule = std::make_shared<const GaussLegendreRule>(1024);
    std::size_t judged = 0;
    for (const Table& t : set.tables) {
      if (t.group.rfind("sampling/", 0) == 0) continue;
      INFO("table " << t.path());
      const std::optional<TableTruth> truth = table_truth(t, truth_model, rule);
      REQUIRE(truth);
      const auto nodes = all_nodes(t);
      REQUIRE(nodes.size() == t.size());
      double peak = 0.0, worst = 0.0;
      std::vector<double> exact(nodes.size());
      for (std::size_t o = 0; o < nodes.size(); ++o) {
        exact[o] = truth->make(nodes[o])(nodes[o]);
        peak = std::max(peak, std::abs(exact[o]));
      }
      for (std::size_t o = 0; o < nodes.size(); ++o) worst = std::max(worst, std::abs(t.get(o) - exact[o]));
      CHECK(worst <= 1e-6 * peak);
      ++judged;
    }
    CHECK(judged >= 1);

    // The validator's side: its energy sections, each with at least one check.
    const ModelKindReport* r = model_report(name);
    REQUIRE(r);
    TableSetModel info;
    info.model = name;
    info.eta = c.eta;
    info.path = c.path;
    for (int p = 0; p < c.lobe_count; ++p) info.lobes.push_back(lobe_name(p));
    info.explicit_lobes = c.lobe_count;
    info.residual = c.residual;
    info.kind = m;
    info.settings = back;
    std::vector<nlohmann::ordered_json> checks;
    nlohmann::ordered_json sections = nlohmann::ordered_json::object();
    ValidationOptions vopt;
    vopt.seed = 1;
    r->energy_sections(set, info, vopt, checks, sections);
    // (Whether they pass depends on the tables' resolution: the shipped configs' validation tests
    // hold each model's checks to their thresholds; the example's tables are coarse.)
    CHECK(!sections.empty());
    std::size_t judged_checks = 0;
    for (const auto& k : checks) {
      INFO(k.dump());
      const std::string status = k.value("status", std::string());
      CHECK((status == "pass" || status == "fail" || status == "skipped"));
      judged_checks += status != "skipped";
    }
    CHECK(judged_checks >= 1);
    CHECK(r->html(sections).find("<h2>") != std::string::npos);
  }
}
