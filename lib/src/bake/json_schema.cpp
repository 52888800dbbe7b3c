#include "hairlut/bake/json_schema.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <regex>
#include <set>

namespace hairlut {
namespace {

// std::regex's default (depth-first) matcher recurses once per input character, so a long string
// overflows the stack. libstdc++'s breadth-first matcher (the __polynomial flag, a Thompson-style
// simulation) keeps its recursion bounded by the pattern's size and its time linear in the input
// for the anchored patterns the schemas use. Elsewhere, strings longer than kMaxPatternInput code
// points are refused instead of matched.
#if defined(__GLIBCXX__)
constexpr auto kRegexFlags = std::regex::ECMAScript | std::regex_constants::__polynomial;
constexpr std::size_t kMaxPatternInput = std::size_t(-1);
#else
constexpr auto kRegexFlags = std::regex::ECMAScript;
constexpr std::size_t kMaxPatternInput = 4096;
#endif

const std::set<std::string> kKeywords = {
    "$schema", "$id", "$defs", "$ref", "$comment", "title", "description", "default", "examples", "deprecated", "readOnly",
    "writeOnly", "format", "type", "enum", "const", "multipleOf", "maximum", "exclusiveMaximum", "minimum",
    "exclusiveMinimum", "maxLength", "minLength", "pattern", "maxItems", "minItems", "uniqueItems", "prefixItems", "items",
    "contains", "minContains", "maxContains", "maxProperties", "minProperties", "required", "properties",
    "patternProperties", "additionalProperties", "propertyNames", "dependentRequired", "dependentSchemas", "allOf", "anyOf",
    "oneOf", "not", "if", "then", "else"};

std::string join_path(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
std::string index_path(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }
std::string shown(const std::string& path) { return path.empty() ? "(root)" : path; }

// A short rendering of a value for messages: strings quoted, long values elided.
std::string brief(const nlohmann::json& v) {
  std::string s = v.dump();
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

std::string kind_of(const nlohmann::json& v) {
  switch (v.type()) {
    case nlohmann::json::value_t::null: return "null";
    case nlohmann::json::value_t::boolean: return "boolean " + v.dump();
    case nlohmann::json::value_t::string: return "string " + brief(v);
    case nlohmann::json::value_t::number_integer:
    case nlohmann::json::value_t::number_unsigned:
    case nlohmann::json::value_t::number_float: return "number " + v.dump();
    case nlohmann::json::value_t::array: return "an array";
    case nlohmann::json::value_t::object: return "an object";
    default: return "a value";
  }
}

bool is_integer(const nlohmann::json& v) {
  if (v.is_number_integer() || v.is_number_unsigned()) return true;
  if (!v.is_number_float()) return false;
  const double d = v.get<double>();
  return std::isfinite(d) && d == std::floor(d);
}

bool has_type(const nlohmann::json& v, const std::string& t) {
  if (t == "null") return v.is_null();
  if (t == "boolean") return v.is_boolean();
  if (t == "object") return v.is_object();
  if (t == "array") return v.is_array();
  if (t == "string") return v.is_string();
  if (t == "number") return v.is_number();
  if (t == "integer") return is_integer(v);
  return false;
}

std::string article(const std::string& t) {
  if (t == "integer" || t == "object" || t == "array") return "an " + t;
  if (t == "null") return "null";
  return "a " + t;
}

// JSON equality with 1 == 1.0 (nlohmann compares numbers of different kinds by value already,
// except inside containers; compare recursively to be sure).
bool json_equal(const nlohmann::json& a, const nlohmann::json& b) {
  if (a.is_number() && b.is_number()) return a.get<double>() == b.get<double>();
  if (a.type() != b.type()) return false;
  if (a.is_array()) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (!json_equal(a[i], b[i])) return false;
    return true;
  }
  if (a.is_object()) {
    if (a.size() != b.size()) return false;
    for (auto it = a.begin(); it != a.end(); ++it) {
      const auto jt = b.find(it.key());
      if (jt == b.end() || !json_equal(*it, *jt)) return false;
    }
    return true;
  }
  return a == b;
}

std::size_t code_points(const std::string& s) {
  std::size_t n = 0;
  for (unsigned char c : s)
    if ((c & 0xC0) != 0x80) ++n;
  return n;
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string number_text(const nlohmann::json& v) { return v.dump(); }

// Resolves a local reference "#", "#/a/b" (JSON pointer, ~0 ~1 and %xx escapes).
const nlohmann::json* resolve(const nlohmann::json& root, const std::string& ref) {
  if (ref == "#") return &root;
  if (ref.rfind("#/", 0) != 0) return nullptr;
  std::string pointer;
  for (std::size_t i = 1; i < ref.size(); ++i) {
    if (ref[i] == '%' && i + 2 < ref.size()) {
      pointer += static_cast<char>(std::stoi(ref.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      pointer += ref[i];
    }
  }
  try {
    return &root.at(nlohmann::json::json_pointer(pointer));
  } catch (const nlohmann::json::exception&) {
    return nullptr;
  }
}

// A one-phrase description of a subschema for "must match one of" messages.
std::string describe_schema(const nlohmann::json& s) {
  if (s.is_boolean()) return s.get<bool>() ? "anything" : "nothing";
  if (s.contains("title") && s["title"].is_string()) return s["title"].get<std::string>();
  if (s.contains("description") && s["description"].is_string()) {
    std::string d = s["description"].get<std::string>();
    if (d.size() > 60) d = d.substr(0, 57) + "...";
    return d;
  }
  if (s.contains("type")) return s["type"].is_string() ? article(s["type"].get<std::string>()) : s["type"].dump();
  if (s.contains("const")) return brief(s["const"]);
  if (s.contains("required")) return "an object with " + s["required"].dump();
  return brief(s);
}

struct Validator {
  const nlohmann::json& root;
  const std::map<std::string, std::regex>& regexes;

  // Appends violations of `inst` against `s` to `out` (up to `max`); returns true if valid.
  bool check(const nlohmann::json& s, const nlohmann::json& inst, const std::string& path, std::vector<SchemaViolation>& out, std::size_t max,
             int depth) const {
    if (depth > 64) {
      add(out, max, path, "schema nesting too deep (recursive $ref?)");
      return false;
    }
    if (s.is_boolean()) {
      if (s.get<bool>()) return true;
      add(out, max, path, "is not allowed here");
      return false;
    }
    bool ok = true;
    if (const auto r = s.find("$ref"); r != s.end()) {
      const nlohmann::json* target = resolve(root, r->get<std::string>());
      if (!target) {
        add(out, max, path, "schema error: cannot resolve $ref " + r->dump());
        return false;
      }
      ok &= check(*target, inst, path, out, max, depth + 1);
    }
    if (const auto t = s.find("type"); t != s.end()) {
      std::vector<std::string> types = t->is_string() ? std::vector<std::string>{t->get<std::string>()} : t->get<std::vector<std::string>>();
      if (std::none_of(types.begin(), types.end(), [&](const std::string& x) { return has_type(inst, x); })) {
        std::string want;
        for (std::size_t i = 0; i < types.size(); ++i) want += (i ? (i + 1 == types.size() ? " or " : ", ") : "") + article(types[i]);
        add(out, max, path, "must be " + want + " (got " + kind_of(inst) + ")");
        return false;  // the other keywords would only repeat the type error
      }
    }
    if (const auto e = s.find("enum"); e != s.end()) {
      if (std::none_of(e->begin(), e->end(), [&](const nlohmann::json& x) { return json_equal(x, inst); })) {
        std::string list;
        for (std::size_t i = 0; i < e->size(); ++i) list += (i ? ", " : "") + brief((*e)[i]);
        add(out, max, path, "must be one of " + list + " (got " + brief(inst) + ")");
        ok = false;
      }
    }
    if (const auto c = s.find("const"); c != s.end() && !json_equal(*c, inst)) {
      add(out, max, path, "must be " + brief(*c) + " (got " + brief(inst) + ")");
      ok = false;
    }
    if (inst.is_number()) ok &= check_number(s, inst, path, out, max);
    if (inst.is_string()) ok &= check_string(s, inst, path, out, max);
    if (inst.is_array()) ok &= check_array(s, inst, path, out, max, depth);
    if (inst.is_object()) ok &= check_object(s, inst, path, out, max, depth);
    ok &= check_combinators(s, inst, path, out, max, depth);
    return ok;
  }

  static void add(std::vector<SchemaViolation>& out, std::size_t max, const std::string& path, const std::string& reason) {
    if (out.size() < max) out.push_back({path, shown(path) + ": " + reason});
  }

  bool check_number(const nlohmann::json& s, const nlohmann::json& inst, const std::string& path, std::vector<SchemaViolation>& out,
                    std::size_t max) const {
    bool ok = true;
    const double v = inst.get<double>();
    auto bound = [&](const char* key, auto fails, const char* op) {
      const auto b = s.find(key);
      if (b != s.end() && fails(v, b->template get<double>())) {
        add(out, max, path, std::string("must be ") + op + " " + number_text(*b) + " (got " + number_text(inst) + ")");
        ok = false;
      }
    };
    bound("minimum", [](double x, double b) { return x < b; }, ">=");
    bound("exclusiveMinimum", [](double x, double b) { return x <= b; }, ">");
    bound("maximum", [](double x, double b) { return x > b; }, "<=");
    bound("exclusiveMaximum", [](double x, double b) { return x >= b; }, "<");
    if (const auto m = s.find("multipleOf"); m != s.end()) {
      const double q = v / m->get<double>();
      if (!std::isfinite(q) || std::abs(q - std::round(q)) > 1e-9 * std::max(1.0, std::abs(q))) {
        add(out, max, path, "must be a multiple of " + number_text(*m) + " (got " + number_text(inst) + ")");
        ok = false;
      }
    }
    return ok;
  }

  bool check_string(const nlohmann::json& s, const nlohmann::json& inst, const std::string& path, std::vector<SchemaViolation>& out,
                    std::size_t max) const {
    bool ok = true;
    const std::string& str = inst.get_ref<const std::string&>();
    const std::size_t n = code_points(str);
    if (const auto m = s.find("minLength"); m != s.end() && n < m->get<std::size_t>()) {
      add(out, max, path, "must have at least " + m->dump() + " character" + (m->get<std::size_t>() == 1 ? "" : "s") + " (got " + std::to_string(n) + ")");
      ok = false;
    }
    bool too_long = false;
    if (const auto m = s.find("maxLength"); m != s.end() && n > m->get<std::size_t>()) {
      add(out, max, path, "must have at most " + m->dump() + " characters (got " + std::to_string(n) + ")");
      ok = false;
      too_long = true;
    }
    // A string already too long is not matched against the pattern as well (one reason is enough).
    if (const auto p = s.find("pattern"); p != s.end() && !too_long) {
      if (n > kMaxPatternInput) {
        add(out, max, path, "is too long to match the pattern " + p->dump() + " (" + std::to_string(n) + " characters)");
        ok = false;
      } else if (!std::regex_search(str, regexes.at(p->get<std::string>()))) {
        add(out, max, path, "must match the pattern " + p->dump() + " (got " + brief(inst) + ")");
        ok = false;
      }
    }
    return ok;
  }

  bool check_array(const nlohmann::json& s, const nlohmann::json& inst, const std::string& path, std::vector<SchemaViolation>& out,
                   std::size_t max, int depth) const {
    bool ok = true;
    const std::size_t n = inst.size();
    auto items_word = [](std::size_t k) { return k == 1 ? std::string(" item") : std::string(" items"); };
    if (const auto m = s.find("minItems"); m != s.end() && n < m->get<std::size_t>()) {
      add(out, max, path, "must have at least " + m->dump() + items_word(m->get<std::size_t>()) + " (got " + std::to_string(n) + ")");
      ok = false;
    }
    if (const auto m = s.find("maxItems"); m != s.end() && n > m->get<std::size_t>()) {
      add(out, max, path, "must have at most " + m->dump() + items_word(m->get<std::size_t>()) + " (got " + std::to_string(n) + ")");
      ok = false;
    }
    if (const auto u = s.find("uniqueItems"); u != s.end() && u->get<bool>()) {
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j)
          if (json_equal(inst[i], inst[j])) {
            add(out, max, index_path(path, j), "duplicates item " + std::to_string(i) + " (items must be unique)");
            ok = false;
          }
    }
    std::size_t prefix = 0;
    if (const auto p = s.find("prefixItems"); p != s.end()) {
      prefix = std::min(p->size(), n);
      for (std::size_t i = 0; i < prefix; ++i) ok &= check((*p)[i], inst[i], index_path(path, i), out, max, depth + 1);
    }
    if (const auto it = s.find("items"); it != s.end())
      for (std::size_t i = prefix; i < n; ++i) ok &= check(*it, inst[i], index_path(path, i), out, max, depth + 1);
    if (const auto c = s.find("contains"); c != s.end()) {
      std::size_t matches = 0;
      for (std::size_t i = 0; i < n; ++i) {
        std::vector<SchemaViolation> tmp;
        if (check(*c, inst[i], index_path(path, i), tmp, 1, depth + 1)) ++matches;
      }
      const std::size_t lo = s.contains("minContains") ? s["minContains"].get<std::size_t>() : 1;
      const bool has_hi = s.contains("maxContains");
      if (matches < lo) {
        add(out, max, path, "must contain at least " + std::to_string(lo) + " item(s) matching " + describe_schema(*c) + " (got " +
                                std::to_string(matches) + ")");
        ok = false;
      }
      if (has_hi && matches > s["maxContains"].get<std::size_t>()) {
        add(out, max, path, "must contain at most " + s["maxContains"].dump() + " item(s) matching " + describe_schema(*c) +
                                " (got " + std::to_string(matches) + ")");
        ok = false;
      }
    }
    return ok;
  }

  bool check_object(const nlohmann::json& s, const nlohmann::json& inst, const std::string& path, std::vector<SchemaViolation>& out,
                    std::size_t max, int depth) const {
    bool ok = true;
    if (const auto r = s.find("required"); r != s.end())
      for (const auto& key : *r)
        if (!inst.contains(key.get<std::string>())) {
          add(out, max, path, "missing required key " + key.dump());
          ok = false;
        }
    const std::size_t n = inst.size();
    if (const auto m = s.find("minProperties"); m != s.end() && n < m->get<std::size_t>()) {
      add(out, max, path, "must have at least " + m->dump() + (m->get<std::size_t>() == 1 ? " property" : " properties") + " (got " +
                              std::to_string(n) + ")");
      ok = false;
    }
    if (const auto m = s.find("maxProperties"); m != s.end() && n > m->get<std::size_t>()) {
      add(out, max, path, "must have at most " + m->dump() + " properties (got " + std::to_string(n) + ")");
      ok = false;
    }
    if (const auto d = s.find("dependentRequired"); d != s.end())
      for (auto it = d->begin(); it != d->end(); ++it)
        if (inst.contains(it.key()))
          for (const auto& need : *it)
            if (!inst.contains(need.get<std::string>())) {
              add(out, max, path, "key \"" + it.key() + "\" requires key " + need.dump());
              ok = false;
            }
    if (const auto d = s.find("dependentSchemas"); d != s.end())
      for (auto it = d->begin(); it != d->end(); ++it)
        if (inst.contains(it.key())) ok &= check(*it, inst, path, out, max, depth + 1);
    const auto props = s.find("properties");
    const auto pattern_props = s.find("patternProperties");
    const auto additional = s.find("additionalProperties");
    const auto names = s.find("propertyNames");
    for (auto it = inst.begin(); it != inst.end(); ++it) {
      const std::string& key = it.key();
      const std::string child = join_path(path, key);
      bool matched = false;
      if (props != s.end() && props->contains(key)) {
        matched = true;
        ok &= check((*props)[key], *it, child, out, max, depth + 1);
      }
      if (pattern_props != s.end())
        for (auto pp = pattern_props->begin(); pp != pattern_props->end(); ++pp)
          if (code_points(key) <= kMaxPatternInput && std::regex_search(key, regexes.at(pp.key()))) {
            matched = true;
            ok &= check(*pp, *it, child, out, max, depth + 1);
          }
      if (!matched && additional != s.end()) {
        if (additional->is_boolean() && !additional->get<bool>()) {
          std::string msg = "unknown key \"" + key + "\"";
          if (props != s.end()) {
            std::string best;
            std::size_t best_d = 3;
            for (auto p = props->begin(); p != props->end(); ++p) {
              const std::size_t dist = edit_distance(key, p.key());
              if (dist < best_d) best_d = dist, best = p.key();
            }
            if (!best.empty()) msg += " (did you mean \"" + best + "\"?)";
          }
          add(out, max, path, msg);
          ok = false;
        } else {
          ok &= check(*additional, *it, child, out, max, depth + 1);
        }
      }
      if (names != s.end()) {
        std::vector<SchemaViolation> tmp;
        if (!check(*names, nlohmann::json(key), child, tmp, 1, depth + 1)) {
          std::string reason = tmp.empty() ? "is not allowed" : tmp.front().message.substr(tmp.front().message.find(": ") + 2);
          add(out, max, path, "key \"" + key + "\" is not a valid name: " + reason);
          ok = false;
        }
      }
    }
    return ok;
  }

  // Violations of each branch, collected silently.
  std::vector<std::vector<SchemaViolation>> branches(const nlohmann::json& list, const nlohmann::json& inst, const std::string& path, int depth,
                                                     std::vector<bool>& valid) const {
    std::vector<std::vector<SchemaViolation>> all;
    valid.clear();
    for (const nlohmann::json& b : list) {
      std::vector<SchemaViolation> tmp;
      valid.push_back(check(b, inst, path, tmp, 20, depth + 1));
      all.push_back(std::move(tmp));
    }
    return all;
  }

  // The branch that got furthest: errors deepest below `path`, then fewest errors. Returns -1 if
  // every branch fails right at `path` (no branch clearly applies).
  static int best_branch(const std::vector<std::vector<SchemaViolation>>& errs, const std::string& path) {
    int best = -1;
    std::size_t best_depth = 0, best_count = 0;
    for (std::size_t i = 0; i < errs.size(); ++i) {
      if (errs[i].empty()) continue;
      std::size_t deepest = 0;
      bool all_deeper = true;
      for (const auto& v : errs[i]) {
        deepest = std::max(deepest, v.path.size());
        if (v.path.size() <= path.size()) all_deeper = false;
      }
      if (!all_deeper) continue;
      if (best < 0 || deepest > best_depth || (deepest == best_depth && errs[i].size() < best_count))
        best = static_cast<int>(i), best_depth = deepest, best_count = errs[i].size();
    }
    return best;
  }

  bool check_combinators(const nlohmann::json& s, const nlohmann::json& inst, const std::string& path, std::vector<SchemaViolation>& out,
                         std::size_t max, int depth) const {
    bool ok = true;
    if (const auto a = s.find("allOf"); a != s.end())
      for (const nlohmann::json& b : *a) ok &= check(b, inst, path, out, max, depth + 1);
    auto choose = [&](const nlohmann::json& list, bool exactly_one) {
      std::vector<bool> valid;
      const auto errs = branches(list, inst, path, depth, valid);
      const auto n_valid = static_cast<std::size_t>(std::count(valid.begin(), valid.end(), true));
      if (n_valid == 0) {
        const int best = best_branch(errs, path);
        if (best >= 0) {
          for (const auto& v : errs[static_cast<std::size_t>(best)])
            if (out.size() < max) out.push_back(v);
        } else {
          std::string list_text;
          for (std::size_t i = 0; i < list.size(); ++i) list_text += (i ? "; " : "") + describe_schema(list[i]);
          add(out, max, path, std::string(exactly_one ? "must match exactly one of: " : "must match one of: ") + list_text);
        }
        return false;
      }
      if (exactly_one && n_valid > 1) {
        std::string matched;
        for (std::size_t i = 0; i < list.size(); ++i)
          if (valid[i]) matched += (matched.empty() ? "" : "; ") + describe_schema(list[i]);
        add(out, max, path, "matches more than one of: " + matched + " (must match exactly one)");
        return false;
      }
      return true;
    };
    if (const auto a = s.find("anyOf"); a != s.end()) ok &= choose(*a, false);
    if (const auto a = s.find("oneOf"); a != s.end()) ok &= choose(*a, true);
    if (const auto n = s.find("not"); n != s.end()) {
      std::vector<SchemaViolation> tmp;
      if (check(*n, inst, path, tmp, 1, depth + 1)) {
        add(out, max, path, "must not be " + describe_schema(*n));
        ok = false;
      }
    }
    if (const auto i = s.find("if"); i != s.end()) {
      std::vector<SchemaViolation> tmp;
      const bool cond = check(*i, inst, path, tmp, 1, depth + 1);
      if (cond && s.contains("then")) ok &= check(s["then"], inst, path, out, max, depth + 1);
      if (!cond && s.contains("else")) ok &= check(s["else"], inst, path, out, max, depth + 1);
    }
    return ok;
  }
};

// Checks that a schema uses only supported keywords and local refs; compiles its patterns.
void inspect(const nlohmann::json& s, const std::string& where, std::map<std::string, std::regex>& regexes) {
  if (s.is_boolean()) return;
  if (!s.is_object()) throw SchemaError("schema at " + where + " must be an object or a boolean");
  auto sub = [&](const char* key) {
    if (s.contains(key)) inspect(s[key], where + "/" + key, regexes);
  };
  auto sub_map = [&](const char* key) {
    if (!s.contains(key)) return;
    if (!s[key].is_object()) throw SchemaError(std::string(key) + " at " + where + " must be an object");
    for (auto it = s[key].begin(); it != s[key].end(); ++it) inspect(*it, where + "/" + key + "/" + it.key(), regexes);
  };
  auto sub_list = [&](const char* key) {
    if (!s.contains(key)) return;
    if (!s[key].is_array() || s[key].empty()) throw SchemaError(std::string(key) + " at " + where + " must be a non-empty array");
    for (std::size_t i = 0; i < s[key].size(); ++i) inspect(s[key][i], where + "/" + key + "/" + std::to_string(i), regexes);
  };
  auto compile = [&](const std::string& pattern) {
    if (regexes.count(pattern)) return;
    try {
      regexes.emplace(pattern, std::regex(pattern, kRegexFlags));
    } catch (const std::regex_error&) {
      throw SchemaError("invalid regular expression " + nlohmann::json(pattern).dump() + " at " + where);
    }
  };
  for (auto it = s.begin(); it != s.end(); ++it)
    if (!kKeywords.count(it.key())) throw SchemaError("unsupported keyword \"" + it.key() + "\" at " + where);
  if (s.contains("$ref") && (!s["$ref"].is_string() || s["$ref"].get<std::string>().rfind('#', 0) != 0))
    throw SchemaError("only local $ref (\"#...\") is supported, got " + s["$ref"].dump() + " at " + where);
  if (s.contains("items") && s["items"].is_array())
    throw SchemaError("array-valued \"items\" (draft 7 tuples) is not 2020-12; use prefixItems, at " + where);
  if (s.contains("pattern")) compile(s["pattern"].get<std::string>());
  if (s.contains("patternProperties"))
    for (auto it = s["patternProperties"].begin(); it != s["patternProperties"].end(); ++it) compile(it.key());
  sub_map("$defs");
  sub_map("properties");
  sub_map("patternProperties");
  sub_map("dependentSchemas");
  sub("additionalProperties");
  sub("items");
  sub("contains");
  sub("propertyNames");
  sub("not");
  sub("if");
  sub("then");
  sub("else");
  sub_list("prefixItems");
  sub_list("allOf");
  sub_list("anyOf");
  sub_list("oneOf");
}

}  // namespace

JsonSchema::JsonSchema(nlohmann::json schema) : schema_(std::move(schema)) {
  auto regexes = std::make_shared<std::map<std::string, std::regex>>();
  inspect(schema_, "#", *regexes);
  regexes_ = std::move(regexes);
}

std::vector<SchemaViolation> JsonSchema::validate(const nlohmann::json& instance, std::size_t max_errors) const {
  const Validator v{schema_, *regexes_};
  std::vector<SchemaViolation> out;
  v.check(schema_, instance, "", out, std::max<std::size_t>(max_errors, 1), 0);
  return out;
}

}  // namespace hairlut
