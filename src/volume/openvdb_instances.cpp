// volume/openvdb_instances.cpp — the one unit that instantiates OpenVDB's Grid and Tree classes
// for the value types of VDBSPLAT_OPENVDB_VALUE_TYPES (every other unit sees them declared
// extern: volume/openvdb_extern.h). Explicit instantiation definitions give every member a
// definition whatever a unit's optimiser inlines, so no build depends on which of them
// libopenvdb happens to export.
#include "volume/openvdb_extern.h"

#define VDBSPLAT_OPENVDB_INSTANTIATE(ValueT)                                                    \
    template class VDBSPLAT_OPENVDB_TREE(ValueT);                                               \
    template class openvdb::Grid<VDBSPLAT_OPENVDB_TREE(ValueT)>;

VDBSPLAT_OPENVDB_VALUE_TYPES(VDBSPLAT_OPENVDB_INSTANTIATE)
