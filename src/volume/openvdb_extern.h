// volume/openvdb_extern.h — OpenVDB's Grid and Tree classes for the value types vdbsplat uses
// (float, double, int32, Vec3s), declared extern: instantiated once, in
// volume/openvdb_instances.cpp, instead of in every unit that creates a grid.
// A build-time measure, nothing at run time. Creating a grid instantiates its vtable and with
// it every virtual member (topology and buffer I/O, print, memUsage, ...) and the node code
// behind them: about 50 s of compile time per unit that creates grids of four value types
// (tests/volume/test_grid.cpp: 62 s -> 13 s of CPU with g++ -O2). Node classes (RootNode,
// InternalNode, LeafNode) are not declared extern; they are instantiated where they are used.
// Included by the precompiled header (CMakeLists.txt) and by the volume headers.
#pragma once
#include <openvdb/openvdb.h>

/// Applies @p X to each value type whose Grid and Tree are instantiated in one unit.
#define VDBSPLAT_OPENVDB_VALUE_TYPES(X) X(float) X(double) X(int32_t) X(openvdb::Vec3s)

/// The tree type of a value type: OpenVDB's standard 5-4-3 configuration.
#define VDBSPLAT_OPENVDB_TREE(ValueT)                                                           \
    openvdb::tree::Tree<openvdb::tree::RootNode<openvdb::tree::InternalNode<                    \
        openvdb::tree::InternalNode<openvdb::tree::LeafNode<ValueT, 3>, 4>, 5>>>

#define VDBSPLAT_OPENVDB_EXTERN(ValueT)                                                         \
    extern template class VDBSPLAT_OPENVDB_TREE(ValueT);                                        \
    extern template class openvdb::Grid<VDBSPLAT_OPENVDB_TREE(ValueT)>;

VDBSPLAT_OPENVDB_VALUE_TYPES(VDBSPLAT_OPENVDB_EXTERN)
#undef VDBSPLAT_OPENVDB_EXTERN
