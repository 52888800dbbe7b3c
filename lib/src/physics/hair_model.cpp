#include "hairlut/physics/hair_model.hpp"

#include <cmath>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {
namespace {

void validate_lobe(const LobeParams& l, const std::string& where) {
  require_positive(where + ".beta_m", l.beta_m);
  require_positive(where + ".beta_n", l.beta_n);
  require_in_range(where + ".alpha", l.alpha, -kHalfPi, kHalfPi, "must lie in [-pi/2, pi/2] radians");
}

}  // namespace

void HairModel::validate() const {
  require_greater("eta", eta, 1.0, "must be a finite number > 1");
  require_non_negative("sigma_a", sigma_a);
  if (lobes.empty()) throw DomainError("lobes must list at least one lobe (got none)");
  if (lobes.size() > 1000) throw_domain_error("lobes", "must list at most 1000 lobes", static_cast<long long>(lobes.size()));
  for (std::size_t p = 0; p < lobes.size(); ++p) validate_lobe(lobes[p], "lobes[" + std::to_string(p) + "]");
  if (residual) validate_lobe(*residual, "residual");
}

HairModel HairModel::uniform(double eta, double sigma_a, double beta, int lobe_count, bool with_residual) {
  HairModel m;
  m.eta = eta;
  m.sigma_a = sigma_a;
  m.lobes.assign(static_cast<std::size_t>(std::max(lobe_count, 0)), LobeParams{beta, beta, 0.0});
  if (with_residual) m.residual = LobeParams{beta, beta, 0.0};
  m.validate();
  return m;
}

std::string lobe_name(int p) {
  if (p < 0) throw_domain_error("p", "must be >= 0", static_cast<long long>(p));
  if (p == 0) return "R";
  std::string name(static_cast<std::size_t>(p + 1), 'R');  // built in place: GCC 12 warns (-Wrestrict) on "T" + s + "T"
  name.front() = 'T';
  name.back() = 'T';
  return name;
}

int parse_lobe(const std::string& name, const std::string& what) {
  if (name == "R") return 0;
  if (name.size() >= 2 && name.front() == 'T' && name.back() == 'T' &&
      name.find_first_not_of('R', 1) == name.size() - 1)
    return static_cast<int>(name.size()) - 1;
  if (name.size() >= 2 && name[0] == 'p' && name.find_first_not_of("0123456789", 1) == std::string::npos &&
      name.size() <= 5)
    return std::stoi(name.substr(1));
  throw DomainError(what + " must be R, TT, TRT, TRRT, ... or p<N> (got \"" + name + "\")");
}

}  // namespace hairlut
