// volume/openvdb_extern.h — OpenVDB's grid and tree classes, declared as instantiated elsewhere.
// Owns nothing at run time; it is a build-time measure. libopenvdb already holds (and exports)
// Grid<T> and Tree<T> for the standard value types. Creating a grid in a unit instantiates its
// vtable and with it every virtual member (topology and buffer I/O, print, memUsage, ...) and
// all the node code behind them: about 50 s of compile time per unit that creates grids of
// four value types (tests/volume/test_grid.cpp: 62 s -> 13 s of CPU with g++). Declared
// extern, each unit uses libopenvdb's copies. Node classes (RootNode, InternalNode, LeafNode)
// are left alone: libopenvdb does not export all of their inline members. A member that a
// unit needs and libopenvdb does not export is a link error, never a silent change.
// Included by the precompiled header (CMakeLists.txt) and by volume/grid.h.
#pragma once
#include <openvdb/openvdb.h>

#define VDBSPLAT_OPENVDB_EXTERN_TREE(ValueT)                                                     \
    extern template class openvdb::tree::Tree<openvdb::tree::RootNode<                          \
        openvdb::tree::InternalNode<openvdb::tree::InternalNode<                                 \
            openvdb::tree::LeafNode<ValueT, 3>, 4>, 5>>>;                                        \
    extern template class openvdb::Grid<openvdb::tree::Tree<openvdb::tree::RootNode<            \
        openvdb::tree::InternalNode<openvdb::tree::InternalNode<                                 \
            openvdb::tree::LeafNode<ValueT, 3>, 4>, 5>>>>;

VDBSPLAT_OPENVDB_EXTERN_TREE(float)
VDBSPLAT_OPENVDB_EXTERN_TREE(double)
VDBSPLAT_OPENVDB_EXTERN_TREE(int32_t)
VDBSPLAT_OPENVDB_EXTERN_TREE(int64_t)
VDBSPLAT_OPENVDB_EXTERN_TREE(bool)
VDBSPLAT_OPENVDB_EXTERN_TREE(openvdb::ValueMask)
VDBSPLAT_OPENVDB_EXTERN_TREE(openvdb::Vec3s)
VDBSPLAT_OPENVDB_EXTERN_TREE(openvdb::Vec3d)
VDBSPLAT_OPENVDB_EXTERN_TREE(openvdb::Vec3i)

#undef VDBSPLAT_OPENVDB_EXTERN_TREE
