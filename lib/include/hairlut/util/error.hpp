// Errors raised by hairlut for out-of-domain arguments and bad input.
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>
#include <string_view>

namespace hairlut {

/// The message with every control character (newlines included) replaced by a space, so that an
/// error built from file contents stays one line.
std::string one_line(std::string message);

/// An argument outside a function's documented domain. The message is one line that names the
/// argument, the requirement and the value, e.g. "beta must be > 0 (got -0.1)".
class DomainError : public std::invalid_argument {
 public:
  explicit DomainError(const std::string& message) : std::invalid_argument(one_line(message)) {}
};

/// Thrown when the caller's cancellation flag was raised: by bake(), by the writers of a bake's
/// files (while they wait for a lock or before they commit) and by the validators. Here, at the
/// bottom, because every layer that polls the flag throws it.
class BakeCancelled : public std::runtime_error {
 public:
  BakeCancelled() : std::runtime_error("bake cancelled") {}
};

/// Throws DomainError("<name> <requirement> (got <value>)").
[[noreturn]] void throw_domain_error(std::string_view name, std::string_view requirement, double value);
[[noreturn]] void throw_domain_error(std::string_view name, std::string_view requirement, long long value);

/// Requires a finite value > 0.
inline void require_positive(std::string_view name, double value) {
  if (!(value > 0.0) || !std::isfinite(value)) throw_domain_error(name, "must be a finite number > 0", value);
}
/// Requires a finite value >= 0.
inline void require_non_negative(std::string_view name, double value) {
  if (!(value >= 0.0) || !std::isfinite(value)) throw_domain_error(name, "must be a finite number >= 0", value);
}
/// Requires a finite value > lower.
inline void require_greater(std::string_view name, double value, double lower, std::string_view requirement) {
  if (!(value > lower) || !std::isfinite(value)) throw_domain_error(name, requirement, value);
}
/// Requires a finite value in [lo, hi].
inline void require_in_range(std::string_view name, double value, double lo, double hi, std::string_view requirement) {
  if (!(value >= lo && value <= hi)) throw_domain_error(name, requirement, value);
}

}  // namespace hairlut
