#include "table_text.hpp"

#include "axis_identity.hpp"

namespace hairlut::detail {
namespace {

// The dumped form of the placeholder of axis i: the JSON string "\u0001<i>\u0001".
constexpr char kOpen[] = "\"\\u0001";
constexpr char kClose[] = "\\u0001\"";

}  // namespace

std::size_t TableText::index_of(const GridAxis& a) {
  for (std::size_t i = 0; i < axes_.size(); ++i)
    if (identical_axes(axes_[i].axis, a)) return i;
  const json j = a.to_json();
  axes_.push_back({a, j.dump(), j.dump(2), {}, -1});
  return axes_.size() - 1;
}

TableText::json TableText::with_placeholders(const Table& t) {
  return t.describe([this](const GridAxis& a) { return json("\x01" + std::to_string(index_of(a)) + "\x01"); });
}

std::string TableText::compact(const Table& t) { return substitute(with_placeholders(t).dump(), -1); }

std::string TableText::indented(const json& doc, int depth) { return substitute(doc.dump(2), 2 * depth); }

// Replaces each placeholder by its axis: compact (indent_by < 0) or indented by indent_by spaces
// after every line break of the axis's own indented dump.
std::string TableText::substitute(const std::string& text, int indent_by) {
  std::string out;
  out.reserve(text.size() * 4);
  std::size_t at = 0;
  while (true) {
    const std::size_t open = text.find(kOpen, at);
    if (open == std::string::npos) break;
    const std::size_t digits = open + sizeof kOpen - 1;
    const std::size_t close = text.find(kClose, digits);
    out.append(text, at, open - at);
    const std::size_t i = std::stoul(text.substr(digits, close - digits));
    Axis& a = axes_.at(i);
    if (indent_by < 0) {
      out += a.compact;
    } else {
      if (a.padded_by != indent_by) {  // the indented dump re-indented, once per axis and depth
        const std::string pad(static_cast<std::size_t>(indent_by), ' ');
        a.padded.clear();
        for (const char ch : a.indented) {
          a.padded.push_back(ch);
          if (ch == '\n') a.padded += pad;
        }
        a.padded_by = indent_by;
      }
      out += a.padded;
    }
    at = close + sizeof kClose - 1;
  }
  out.append(text, at, std::string::npos);
  return out;
}

}  // namespace hairlut::detail
