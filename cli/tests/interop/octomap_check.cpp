// A small checker built against the real OctoMap library by cli/tests/interop.rs.
//   octomap_check read FILE.bt     prints "nodes N", then "leaf x y z side" per occupied leaf (grid index =
//                                  OctoMap key - 32768) and "free x y z side" per free leaf
//   octomap_check write FILE.bt R  reads "x y z" lines (occupied voxels, grid indices) and "free x y z" lines
//                                  from stdin, and writes them with OctoMap's own writer (resolution R)
#include <octomap/octomap.h>

#include <iostream>
#include <sstream>
#include <string>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: octomap_check read FILE.bt | write FILE.bt RES\n";
    return 2;
  }
  const std::string mode = argv[1];
  if (mode == "read") {
    octomap::OcTree tree(1.0);
    if (!tree.readBinary(argv[2])) {
      std::cerr << "OctoMap could not read " << argv[2] << "\n";
      return 1;
    }
    std::cout << "nodes " << tree.size() << "\n";
    for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
      const octomap::OcTreeKey k = it.getIndexKey();
      const long side = 1L << (tree.getTreeDepth() - it.getDepth());
      std::cout << (tree.isNodeOccupied(*it) ? "leaf " : "free ") << long(k[0]) - 32768 << " "
                << long(k[1]) - 32768 << " " << long(k[2]) - 32768 << " " << side << "\n";
    }
    return 0;
  }
  if (mode == "write" && argc == 4) {
    octomap::OcTree tree(std::stod(argv[3]));
    std::string line;
    while (std::getline(std::cin, line)) {
      std::istringstream in(line);
      bool occupied = true;
      if (line.rfind("free", 0) == 0) {
        std::string word;
        in >> word;
        occupied = false;
      }
      long x, y, z;
      if (!(in >> x >> y >> z)) continue;
      octomap::OcTreeKey key(x + 32768, y + 32768, z + 32768);
      tree.updateNode(key, occupied, true);
    }
    tree.updateInnerOccupancy();
    if (!tree.writeBinary(argv[2])) return 1;
    return 0;
  }
  std::cerr << "unknown mode\n";
  return 2;
}
