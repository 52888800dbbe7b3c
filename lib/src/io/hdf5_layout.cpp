#include "hdf5_layout.hpp"

namespace hairlut::detail {

Hdf5Layout whole_dataset_layout(std::size_t bytes, int deflate) {
  if (bytes <= kCompactSmallBytes) return Hdf5Layout::compact;
  return deflate > 0 ? Hdf5Layout::chunked : Hdf5Layout::contiguous;
}

herr_t set_unfiltered_layout(hid_t dcpl, Hdf5Layout layout) {
  switch (layout) {
    case Hdf5Layout::compact: return H5Pset_layout(dcpl, H5D_COMPACT);
    case Hdf5Layout::contiguous: return H5Pset_layout(dcpl, H5D_CONTIGUOUS);
    case Hdf5Layout::chunked: break;
  }
  return -1;
}

herr_t keep_attributes_compact(hid_t ocpl) { return H5Pset_attr_phase_change(ocpl, kCompactAttributes, kCompactAttributes - 8); }

}  // namespace hairlut::detail
