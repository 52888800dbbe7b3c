#include "hairlut/tables/grid.hpp"

#include <cmath>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {
namespace {

template <class E, std::size_t N>
E parse_enum(std::string_view text, std::string_view what, const std::pair<std::string_view, E> (&names)[N]) {
  std::string list;
  for (const auto& [name, value] : names) {
    if (text == name) return value;
    list += (list.empty() ? "\"" : ", \"") + std::string(name) + "\"";
  }
  throw DomainError(std::string(what) + " must be one of " + list + " (got \"" + std::string(text) + "\")");
}

constexpr std::pair<std::string_view, Spacing> kSpacings[] = {
    {"uniform", Spacing::uniform}, {"cos", Spacing::cos}, {"sin", Spacing::sin},
    {"log", Spacing::log},         {"sqrt", Spacing::sqrt}, {"explicit", Spacing::explicit_values}};
constexpr std::pair<std::string_view, Placement> kPlacements[] = {{"edges", Placement::edges},
                                                                  {"centers", Placement::centers}};
constexpr std::pair<std::string_view, Wrap> kWraps[] = {
    {"clamp", Wrap::clamp}, {"periodic", Wrap::periodic}, {"even", Wrap::even}, {"reflect", Wrap::reflect}};

constexpr std::pair<std::string_view, Interpolation> kInterpolations[] = {
    {"linear", Interpolation::linear}, {"cubic", Interpolation::cubic}, {"geometric", Interpolation::geometric}};

constexpr std::pair<std::string_view, End> kEnds[] = {{"extrapolate", End::extrapolate}, {"mirror", End::mirror}};

template <class E, std::size_t N>
std::string_view name_of(E value, const std::pair<std::string_view, E> (&names)[N]) {
  for (const auto& [name, v] : names)
    if (v == value) return name;
  return "?";
}

}  // namespace

std::string_view to_string(Spacing s) { return name_of(s, kSpacings); }
std::string_view to_string(Placement p) { return name_of(p, kPlacements); }
std::string_view to_string(Wrap w) { return name_of(w, kWraps); }
Spacing parse_spacing(std::string_view text, std::string_view what) { return parse_enum(text, what, kSpacings); }
Placement parse_placement(std::string_view text, std::string_view what) { return parse_enum(text, what, kPlacements); }
Wrap parse_wrap(std::string_view text, std::string_view what) { return parse_enum(text, what, kWraps); }
std::string_view to_string(Interpolation i) { return name_of(i, kInterpolations); }
Interpolation parse_interpolation(std::string_view text, std::string_view what) { return parse_enum(text, what, kInterpolations); }

std::string_view to_string(End e) { return name_of(e, kEnds); }
End parse_end(std::string_view text, std::string_view what) { return parse_enum(text, what, kEnds); }

sampler::Axis GridAxis::view() const {
  sampler::Axis a;
  a.spacing = spacing;
  a.placement = placement;
  a.wrap = wrap;
  a.lo = lo;
  a.hi = hi;
  a.count = count;
  a.values = values.empty() ? nullptr : values.data();
  a.interpolation = interpolation;
  a.lo_end = lo_end;
  return a;
}

std::vector<double> GridAxis::nodes() const {
  const sampler::Axis a = view();
  std::vector<double> n(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) n[static_cast<std::size_t>(i)] = sampler::node(a, i);
  return n;
}

void GridAxis::validate(const std::string& where) const {
  if (interpolation == Interpolation::cubic && spacing == Spacing::explicit_values)
    throw DomainError(where + ".interpolation cubic needs a mapped spacing, not explicit values");
  // A mirror lower end says the function is even about lo in the mapped coordinate: what f(t²)
  // is in t = √x at x = 0.
  if (lo_end == End::mirror && !(spacing == Spacing::sqrt && lo == 0.0 && wrap == Wrap::clamp))
    throw DomainError(where + ".lo_end mirror needs sqrt spacing from 0 with wrap clamp");
  if (count < 1) throw_domain_error(where + ".count", "must be >= 1", static_cast<long long>(count));
  if (count > (1 << 20)) throw_domain_error(where + ".count", "must be <= 1048576", static_cast<long long>(count));
  if (spacing == Spacing::explicit_values) {
    if (values.size() != static_cast<std::size_t>(count))
      throw DomainError(where + ".values must list count = " + std::to_string(count) + " values (got " +
                        std::to_string(values.size()) + ")");
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (!std::isfinite(values[i])) throw_domain_error(where + ".values[" + std::to_string(i) + "]", "must be finite", values[i]);
      if (i > 0 && !(values[i] > values[i - 1]))
        throw_domain_error(where + ".values[" + std::to_string(i) + "]", "must be greater than the value before it", values[i]);
    }
    if (wrap == Wrap::periodic) throw DomainError(where + " cannot be periodic with explicit values");
    if (!labels.empty() && labels.size() != values.size())
      throw DomainError(where + ".labels must have one label per value");
    return;
  }
  if (!std::isfinite(lo) || !std::isfinite(hi)) throw DomainError(where + ".range must be finite");
  if (count == 1 && placement == Placement::edges && wrap != Wrap::periodic) {
    if (!(lo <= hi)) throw_domain_error(where + ".range", "must not be inverted: range[0] <= range[1] required, range[0] is", lo);
  } else if (!(lo < hi)) {
    throw DomainError(where + ".range must be increasing (range[0] < range[1]); got [" + std::to_string(lo) + ", " +
                      std::to_string(hi) + "]");
  }
  if (count < 2 && placement == Placement::edges && wrap != Wrap::periodic && lo != hi)
    throw DomainError(where + ".count must be >= 2 for edge-placed nodes spanning a range (got 1)");
  switch (spacing) {
    case Spacing::log:
      if (!(lo > 0.0)) throw_domain_error(where + ".range[0]", "must be > 0 for log spacing", lo);
      break;
    case Spacing::sqrt:
      if (!(lo >= 0.0)) throw_domain_error(where + ".range[0]", "must be >= 0 for sqrt spacing", lo);
      break;
    case Spacing::cos:
      if (lo < 0.0 || hi > kPi) throw DomainError(where + ".range must lie in [0, pi] radians for cos spacing");
      break;
    case Spacing::sin:
      if (lo < -kHalfPi || hi > kHalfPi) throw DomainError(where + ".range must lie in [-pi/2, pi/2] radians for sin spacing");
      break;
    default: break;
  }
  if (wrap == Wrap::periodic && spacing != Spacing::uniform) throw DomainError(where + " must use uniform spacing to be periodic");
  if (wrap == Wrap::even && (lo < 0.0 || hi > kPi)) throw DomainError(where + ".range must lie in [0, pi] for an even azimuth axis");
}

nlohmann::ordered_json GridAxis::to_json() const {
  nlohmann::ordered_json j;
  j["name"] = name;
  j["units"] = units;
  j["long_name"] = long_name;
  j["count"] = count;
  j["spacing"] = to_string(spacing);
  j["placement"] = to_string(placement);
  j["wrap"] = to_string(wrap);
  j["range"] = {lo, hi};
  j["interpolation"] = to_string(interpolation);
  if (lo_end != End::extrapolate) j["lo_end"] = to_string(lo_end);  // absent: extrapolate (older files)
  j["values"] = nodes();
  if (!labels.empty()) j["labels"] = labels;
  return j;
}

GridAxis GridAxis::from_json(const nlohmann::json& j, const std::string& where) {
  auto field = [&](const char* key) -> const nlohmann::json& {
    if (!j.is_object() || !j.contains(key)) throw DomainError(where + ": missing axis field \"" + key + "\"");
    return j.at(key);
  };
  GridAxis a;
  try {
    a.name = field("name").get<std::string>();
    a.units = field("units").get<std::string>();
    a.long_name = j.value("long_name", std::string());
    a.count = field("count").get<int>();
    a.spacing = parse_spacing(field("spacing").get<std::string>(), where + ".spacing");
    a.placement = parse_placement(field("placement").get<std::string>(), where + ".placement");
    a.wrap = parse_wrap(field("wrap").get<std::string>(), where + ".wrap");
    const auto& range = field("range");
    if (!range.is_array() || range.size() != 2) throw DomainError(where + ".range must be [lo, hi]");
    a.lo = range[0].get<double>();
    a.hi = range[1].get<double>();
    if (a.spacing == Spacing::explicit_values) a.values = field("values").get<std::vector<double>>();
    if (j.contains("interpolation"))
      a.interpolation = parse_interpolation(j.at("interpolation").get<std::string>(), where + ".interpolation");
    if (j.contains("lo_end")) a.lo_end = parse_end(j.at("lo_end").get<std::string>(), where + ".lo_end");
    if (j.contains("labels")) a.labels = j.at("labels").get<std::vector<std::string>>();
  } catch (const nlohmann::json::exception& e) {
    throw DomainError(where + ": malformed axis description (" + std::string(e.what()) + ")");
  }
  a.validate(where);
  return a;
}

void validate_interpolation(const std::vector<GridAxis>& axes, const std::string& where) {
  int geometric = 0;
  for (const GridAxis& a : axes) {
    if (a.interpolation == Interpolation::geometric) ++geometric;
    if (a.interpolation == Interpolation::cubic && a.spacing == Spacing::explicit_values)
      throw DomainError(where + ".axes." + a.name + ".interpolation cubic needs a mapped spacing, not explicit values");
  }
  if (geometric > 1) throw DomainError(where + ": at most one axis may interpolate geometrically (got " + std::to_string(geometric) + ")");
}

GridAxis channel_axis(std::vector<std::string> labels, std::string long_name) {
  GridAxis a;
  a.name = "channel";
  a.units = "1";
  a.long_name = std::move(long_name);
  a.spacing = Spacing::explicit_values;
  a.count = static_cast<int>(labels.size());
  for (int i = 0; i < a.count; ++i) a.values.push_back(i);
  a.lo = 0.0;
  a.hi = a.count - 1.0;
  a.labels = std::move(labels);
  return a;
}

GridAxis narrowed_axis(const GridAxis& a, int first, int count, const std::string& where) {
  if (first < 0 || count < 1 || first > a.count - count)
    throw DomainError(where + ": nodes " + std::to_string(first) + " to " + std::to_string(first + count - 1) + " are outside the axis's " +
                      std::to_string(a.count));
  if (count == 1 && a.count > 1) throw DomainError(where + ": a part of an axis needs two nodes at least");
  if (a.wrap == Wrap::periodic) throw DomainError(where + ": a periodic axis cannot be narrowed");
  if (!a.labels.empty()) throw DomainError(where + ": a labelled axis cannot be narrowed");
  GridAxis n = a;
  n.count = count;
  if (first > 0) n.lo_end = End::extrapolate;  // a mirror holds about 0, which a later part does not start at
  if (a.spacing == Spacing::explicit_values) {
    n.values.assign(a.values.begin() + first, a.values.begin() + first + count);
    n.lo = n.values.front(), n.hi = n.values.back();
    return n;
  }
  const sampler::Axis v = a.view();
  if (a.placement == Placement::edges) {
    // The ends are nodes; the nodes between are recomputed from them (the same to rounding).
    n.lo = sampler::node(v, first), n.hi = sampler::node(v, first + count - 1);
  } else {
    // Cell-centred nodes: the part's range is the edges of its cells.
    const double t0 = sampler::mapped(a.spacing, a.lo), t1 = sampler::mapped(a.spacing, a.hi);
    n.lo = first == 0 ? a.lo : sampler::unmapped(a.spacing, t0 + (t1 - t0) * first / a.count);
    n.hi = first + count == a.count ? a.hi : sampler::unmapped(a.spacing, t0 + (t1 - t0) * (first + count) / a.count);
  }
  return n;
}

std::size_t grid_size(const std::vector<GridAxis>& axes) {
  std::size_t n = 1;
  for (const GridAxis& a : axes) {
    const auto c = static_cast<std::size_t>(a.count);
    if (c != 0 && n > (std::size_t{1} << 40) / c) throw DomainError("table has more than 2^40 entries");
    n *= c;
  }
  return n;
}

}  // namespace hairlut
