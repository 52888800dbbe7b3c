#include "hairlut/util/error.hpp"

#include <cstdio>

namespace hairlut {

std::string one_line(std::string message) {
  for (char& c : message)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  return message;
}

void throw_domain_error(std::string_view name, std::string_view requirement, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  throw DomainError(std::string(name) + " " + std::string(requirement) + " (got " + buf + ")");
}

void throw_domain_error(std::string_view name, std::string_view requirement, long long value) {
  throw DomainError(std::string(name) + " " + std::string(requirement) + " (got " + std::to_string(value) + ")");
}

}  // namespace hairlut
