// The JSON Schema validator against the official JSON Schema Test Suite (Debian's
// json-schema-test-suite, draft 7 files of keywords whose semantics 2020-12 keeps), and its
// messages.
#include <filesystem>
#include <fstream>
#include <hairlut/bake/json_schema.hpp>
#include <set>

#include "catch.hpp"

using hairlut::JsonSchema;
using hairlut::SchemaError;
using json = nlohmann::json;

#ifndef HAIRLUT_JSON_SCHEMA_SUITE_DIR
#define HAIRLUT_JSON_SCHEMA_SUITE_DIR "/usr/share/json-schema-test-suite/tests/draft7"
#endif

namespace {

// Draft-7 forms that 2020-12 dropped or changed; groups using them are skipped.
bool uses_draft7_only(const json& s) {
  if (s.is_object()) {
    for (const char* k : {"definitions", "dependencies", "additionalItems", "$ref", "$id", "id"})
      if (s.contains(k)) return true;
    if (s.contains("items") && s["items"].is_array()) return true;
    for (const auto& [k, v] : s.items())
      if (uses_draft7_only(v)) return true;
  } else if (s.is_array()) {
    for (const auto& v : s)
      if (uses_draft7_only(v)) return true;
  }
  return false;
}

std::string first_message(const json& schema, const json& instance) {
  const auto v = JsonSchema(schema).validate(instance, 1);
  return v.empty() ? "(valid)" : v.front().message;
}

}  // namespace

TEST_CASE("Official JSON Schema Test Suite (keywords shared by draft 7 and 2020-12)", "[json-schema]") {
  const std::filesystem::path dir = HAIRLUT_JSON_SCHEMA_SUITE_DIR;
  if (!std::filesystem::is_directory(dir)) {
    WARN("json-schema-test-suite not installed at " << dir << "; skipped");
    return;
  }
  const char* files[] = {"type", "enum", "const", "multipleOf", "maximum", "minimum", "exclusiveMaximum", "exclusiveMinimum",
                         "maxLength", "minLength", "pattern", "maxItems", "minItems", "uniqueItems", "contains", "required",
                         "properties", "patternProperties", "additionalProperties", "propertyNames", "maxProperties",
                         "minProperties", "allOf", "anyOf", "oneOf", "not", "if-then-else", "boolean_schema", "default"};
  std::size_t groups = 0, skipped = 0, cases = 0, failed = 0;
  for (const char* name : files) {
    const auto path = dir / (std::string(name) + ".json");
    REQUIRE(std::filesystem::exists(path));
    std::ifstream in(path);
    const json suite = json::parse(in);
    for (const json& group : suite) {
      ++groups;
      if (uses_draft7_only(group["schema"])) {
        ++skipped;
        continue;
      }
      const JsonSchema schema(group["schema"]);
      for (const json& t : group["tests"]) {
        ++cases;
        const bool valid = schema.validate(t["data"], 1).empty();
        if (valid != t["valid"].get<bool>()) {
          ++failed;
          FAIL_CHECK(name << ": " << group["description"].get<std::string>() << " / " << t["description"].get<std::string>());
        }
      }
    }
  }
  WARN("JSON Schema Test Suite: " << groups - skipped << " of " << groups << " groups run, " << cases << " cases, " << failed
                                  << " failed");
  CHECK(failed == 0);
  CHECK(static_cast<double>(groups - skipped) >= 0.9 * static_cast<double>(groups));
}

TEST_CASE("Validator messages name the key path", "[json-schema]") {
  const json schema = json::parse(R"({
    "type": "object", "additionalProperties": false, "required": ["output"],
    "properties": {
      "fiber": { "type": "object", "properties": { "eta": { "type": "number", "exclusiveMinimum": 1 } } },
      "axes": { "type": "object", "additionalProperties": false, "properties": { "count": { "type": "integer", "minimum": 2 } } },
      "output": { "type": "object", "required": ["formats"], "properties": {
        "formats": { "type": "array", "minItems": 1, "uniqueItems": true, "items": { "enum": ["hdf5", "exr"] } } } },
      "name": { "type": "string", "pattern": "^[a-z]+$", "minLength": 2 }
    },
    "$defs": { "unused": true }
  })");
  CHECK(first_message(schema, json::parse(R"({"output": {"formats": ["hdf5"]}, "axis": {}})")) ==
        "(root): unknown key \"axis\" (did you mean \"axes\"?)");
  CHECK(first_message(schema, json::parse(R"({})")) == "(root): missing required key \"output\"");
  CHECK(first_message(schema, json::parse(R"({"output": {}})")) == "output: missing required key \"formats\"");
  CHECK(first_message(schema, json::parse(R"({"output": {"formats": []}})")) == "output.formats: must have at least 1 item (got 0)");
  CHECK(first_message(schema, json::parse(R"({"output": {"formats": ["hdf5", "png"]}})")) ==
        "output.formats[1]: must be one of \"hdf5\", \"exr\" (got \"png\")");
  CHECK(first_message(schema, json::parse(R"({"output": {"formats": ["exr", "exr"]}})")) ==
        "output.formats[1]: duplicates item 0 (items must be unique)");
  CHECK(first_message(schema, json::parse(R"({"output": {"formats": ["exr"]}, "fiber": {"eta": "1.55"}})")) ==
        "fiber.eta: must be a number (got string \"1.55\")");
  CHECK(first_message(schema, json::parse(R"({"output": {"formats": ["exr"]}, "fiber": {"eta": 1}})")) ==
        "fiber.eta: must be > 1 (got 1)");
  CHECK(first_message(schema, json::parse(R"({"output": {"formats": ["exr"]}, "axes": {"count": 1}})")) ==
        "axes.count: must be >= 2 (got 1)");
  CHECK(first_message(schema, json::parse(R"({"output": {"formats": ["exr"]}, "axes": {"count": 2.5}})")) ==
        "axes.count: must be an integer (got number 2.5)");
  CHECK(first_message(schema, json::parse(R"({"output": {"formats": ["exr"]}, "name": "A"})")).rfind("name: must have at least 2 characters", 0) == 0);
  CHECK(first_message(schema, json::parse(R"({"output": {"formats": ["exr"]}, "name": "AB"})")) ==
        "name: must match the pattern \"^[a-z]+$\" (got \"AB\")");
  CHECK(first_message(schema, json::parse(R"({"output": {"formats": ["exr"]}, "axes": {"count": 3.0}})")) == "(valid)");
}

TEST_CASE("$ref, prefixItems, dependentRequired and oneOf", "[json-schema]") {
  const json schema = json::parse(R"({
    "$defs": { "pos": { "type": "number", "exclusiveMinimum": 0 } },
    "type": "object",
    "properties": {
      "beta": { "$ref": "#/$defs/pos" },
      "pair": { "prefixItems": [{ "type": "string" }, { "type": "number" }], "items": false },
      "axis": { "type": "object", "oneOf": [
        { "title": "count with range", "required": ["count", "range"] },
        { "title": "explicit values", "required": ["values"] } ] },
      "mat": { "oneOf": [ { "title": "melanin", "type": "object", "required": ["melanin"], "properties": { "melanin": { "type": "number", "minimum": 0 } } },
                          { "title": "rgb", "type": "array" } ] }
    },
    "dependentRequired": { "range": ["count"] }
  })");
  CHECK(first_message(schema, json::parse(R"({"beta": -1})")) == "beta: must be > 0 (got -1)");
  CHECK(first_message(schema, json::parse(R"({"pair": ["a", 1]})")) == "(valid)");
  CHECK(first_message(schema, json::parse(R"({"pair": ["a", "b"]})")) == "pair[1]: must be a number (got string \"b\")");
  CHECK(first_message(schema, json::parse(R"({"pair": ["a", 1, 2]})")) == "pair[2]: is not allowed here");
  CHECK(first_message(schema, json::parse(R"({"range": 1})")) == "(root): key \"range\" requires key \"count\"");
  CHECK(first_message(schema, json::parse(R"({"axis": {}})")) ==
        "axis: must match exactly one of: count with range; explicit values");
  CHECK(first_message(schema, json::parse(R"({"axis": {"count": 1, "range": 2, "values": 3}})")) ==
        "axis: matches more than one of: count with range; explicit values (must match exactly one)");
  // The branch that matched its discriminators reports its own, deeper error.
  CHECK(first_message(schema, json::parse(R"({"mat": {"melanin": -2}})")) == "mat.melanin: must be >= 0 (got -2)");
}

TEST_CASE("Unsupported schemas are refused when loaded", "[json-schema]") {
  CHECK_THROWS_AS(JsonSchema(json::parse(R"({"type": "object", "unevaluatedProperties": false})")), SchemaError);
  CHECK_THROWS_AS(JsonSchema(json::parse(R"({"$ref": "https://example.com/s.json"})")), SchemaError);
  CHECK_THROWS_AS(JsonSchema(json::parse(R"({"items": [{"type": "string"}]})")), SchemaError);
  CHECK_THROWS_AS(JsonSchema(json::parse(R"({"pattern": "("})")), SchemaError);
  CHECK_NOTHROW(JsonSchema(json::parse(R"({"$comment": "x", "deprecated": true, "format": "email"})")));
}
