// A validator for the subset of JSON Schema draft 2020-12 that hairlut's schemas use.
//
// Debian ships no C++ JSON Schema validator, so this one is written here; it is checked against
// the official JSON Schema Test Suite (tests/test_json_schema.cpp) and, for hairlut's own
// schemas, against python3-jsonschema. Its messages go straight to users: one line each, naming
// the key path ("tables.np.axes.beta.count: must be >= 1 (got 0)").
#pragma once

#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

namespace hairlut {

/// A schema that uses a keyword this validator does not implement, or is malformed.
class SchemaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One violation: the dotted key path of the offending value ("" for the root) and a one-line
/// message "<path>: <reason>" ("(root): <reason>" at the root).
struct SchemaViolation {
  std::string path;
  std::string message;
};

/// A compiled schema. Supported keywords: $schema, $id, $defs, $ref (local JSON pointers),
/// $comment, title, description, default, examples, deprecated, readOnly, writeOnly, format
/// (annotation), type, enum, const, multipleOf, maximum, exclusiveMaximum, minimum,
/// exclusiveMinimum, maxLength, minLength, pattern, maxItems, minItems, uniqueItems, prefixItems,
/// items, contains, minContains, maxContains, maxProperties, minProperties, required, properties,
/// patternProperties, additionalProperties, propertyNames, dependentRequired, dependentSchemas,
/// allOf, anyOf, oneOf, not, if/then/else, and boolean schemas.
class JsonSchema {
 public:
  /// Throws SchemaError naming an unsupported keyword or a non-local $ref and where it is.
  explicit JsonSchema(nlohmann::json schema);
  /// The violations of `instance`, in document order, at most max_errors of them.
  std::vector<SchemaViolation> validate(const nlohmann::json& instance, std::size_t max_errors = 20) const;
  const nlohmann::json& document() const { return schema_; }

 private:
  nlohmann::json schema_;
  std::shared_ptr<const std::map<std::string, std::regex>> regexes_;  // compiled patterns, read-only
};

}  // namespace hairlut
