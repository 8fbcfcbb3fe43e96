// scripts/tree-without-libopenvdb.cpp — session 17's start-up experiment (docs/performance.md):
// does code that builds and walks a FloatTree need libopenvdb.so? Linked without it, the link
// fails only on the functions the tree's virtual functions name (io:: stream helpers,
// Metadata, util::printBytes, math::simplify), which rendering never calls:
//   g++ -O2 -std=c++20 scripts/tree-without-libopenvdb.cpp -o /tmp/t -ltbb 2>&1 |
//       grep -o "undefined reference to \`[^']*'" | sort -u | wc -l        # 25 (with Imath's table)
// and with -lopenvdb -lImath-3_1 it links and runs.
#include <openvdb/tree/Tree.h>
#include <openvdb/tree/LeafNode.h>
#include <openvdb/math/Transform.h>
#include <cstdio>
using Tree = openvdb::tree::Tree4<float, 5, 4, 3>::Type;
int main() {
  Tree t(0.f);
  for (int i = 0; i < 100; ++i) t.setValue(openvdb::Coord(i, i/2, i/3), float(i));
  std::vector<const Tree::LeafNodeType*> leaves; t.getNodes(leaves);
  double s = 0; for (auto* l : leaves) for (auto it = l->cbeginValueOn(); it; ++it) s += *it;
  auto it = t.cbeginValueOn(); it.setMaxDepth(it.getLeafDepth() - 1); int tiles = 0; for (; it; ++it) tiles += it.isTileValue();
  printf("%zu leaves sum %g tiles %d active %llu\n", leaves.size(), s, tiles, (unsigned long long)t.activeVoxelCount());
}
