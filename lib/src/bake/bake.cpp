// bake(): the bake of a config's model (lib/models/<model>/), which runs its stages, the table
// kinds of lib/kinds/ and the sampling data.
#include "hairlut/bake/bake.hpp"

#include "hairlut/bake/model_kind.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {

// Tables larger than the memory budget are baked slab by slab, which every checksummed note must
// precede: refuse what needs whole tables.
void check_slab_by_slab(const BakeConfig& c) {
  if (!c.model_kind().slab_by_slab())
    throw DomainError("model " + c.model + ": tables larger than the memory budget cannot be baked slab by slab (raise --memory-budget)");
  if (c.output.sampling_data)
    throw DomainError("output.sampling_data: the sampling data are computed from whole tables; tables larger than the memory budget "
                      "cannot carry them (set output.sampling_data false, or raise --memory-budget)");
  if (c.np_target_error)
    throw DomainError("tables.np.target_error: the achieved error is measured on whole tables; tables larger than the memory budget "
                      "cannot use it (raise --memory-budget or give the axes' counts)");
  if (c.np_axes && c.quadrature.method == NpQuadratureConfig::Method::adaptive)
    throw DomainError("tables.np.quadrature.method adaptive: tables larger than the memory budget are baked slab by slab, which needs "
                      "the fourier or gauss-legendre method (or raise --memory-budget)");
}

TableSet bake(const BakeConfig& c, const BakeOptions& opt, BakeReport* report_out, SlabbedTables* slabbed) {
  if (slabbed) check_slab_by_slab(c);
  return c.model_kind().bake(c, opt, report_out, slabbed);
}

}  // namespace hairlut
