#pragma once
// Shared by the fuzz targets that read HDF5 files: reading or refusing an input
// must leave no HDF5 file, group, dataset, named datatype or attribute open. One
// left open by contactrom is a leak of ours; libhdf5's own error paths on
// corrupted files leak memory without leaving anything open, and fuzz/lsan.supp
// suppresses those (LeakSanitizer cannot tell the two apart: libhdf5 is built
// without frame pointers, so its stacks stop inside the library). Transient
// dataspaces and datatypes are not counted (HDF5 has no public count of them).
#include <hdf5.h>

namespace contactrom {
namespace fuzz {

/// Traps (a libFuzzer finding) when any HDF5 object of any file is still open.
inline void require_no_open_hdf5_objects() {
  if (H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL | H5F_OBJ_LOCAL) != 0) __builtin_trap();
}

}  // namespace fuzz
}  // namespace contactrom
