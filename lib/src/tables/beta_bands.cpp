#include "hairlut/tables/beta_bands.hpp"

namespace hairlut {

std::string beta_band_suffix(int k) { return k == 0 ? std::string() : "_band" + std::to_string(k); }

int beta_band_of(const std::vector<double>& his, double beta) {
  const int n = static_cast<int>(his.size());
  for (int k = 0; k + 1 < n; ++k)
    if (beta <= his[static_cast<std::size_t>(k)]) return k;
  return n > 0 ? n - 1 : 0;
}

}  // namespace hairlut
