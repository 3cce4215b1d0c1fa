// OctoMap's ColorOcTree files, for verify/tests/maps/colours.rs.
//   octomap_colours read FILE.ot         reads FILE.ot with AbstractOcTree::read as a ColorOcTree; prints
//                                        "leaf kx ky kz side logodds_bits r g b" per leaf (lowest keys, the
//                                        log-odds' float bits in hex), then "inner ..." the same per inner
//                                        node as read, then "updated ..." per inner node after
//                                        updateInnerOccupancy
//   octomap_colours write RES OUT.ot     reads scans from stdin ("scan ox oy oz", then "x y z" lines),
//                                        inserts each with insertPointCloud, colours every occupied leaf
//                                        with setNodeColor by its key, integrates a second colour with
//                                        integrateNodeColor where the key's x is even, colours the free
//                                        leaves whose key's y is a multiple of 5 with averageNodeColor,
//                                        runs updateInnerOccupancy, writes OUT.ot and prints its leaves as
//                                        `read` does
#include <octomap/ColorOcTree.h>
#include <octomap/octomap.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

static void print_node(const char* what, const octomap::ColorOcTree& tree, const octomap::OcTreeKey& k,
                       unsigned depth, const octomap::ColorOcTreeNode& node) {
  const long side = 1L << (tree.getTreeDepth() - depth);
  const float l = node.getLogOdds();
  std::uint32_t bits;
  std::memcpy(&bits, &l, 4);
  const octomap::ColorOcTreeNode::Color c = node.getColor();
  std::cout << what << " " << (long(k[0]) & ~(side - 1)) << " " << (long(k[1]) & ~(side - 1)) << " "
            << (long(k[2]) & ~(side - 1)) << " " << side << " " << std::hex << bits << std::dec << " "
            << unsigned(c.r) << " " << unsigned(c.g) << " " << unsigned(c.b) << "\n";
}

static void print_leaves(const octomap::ColorOcTree& tree) {
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    print_node("leaf", tree, it.getKey(), it.getDepth(), *it);
  }
}

static void print_inner(const char* what, const octomap::ColorOcTree& tree) {
  for (auto it = tree.begin_tree(); it != tree.end_tree(); ++it) {
    if (!it.isLeaf()) print_node(what, tree, it.getKey(), it.getDepth(), *it);
  }
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: octomap_colours read FILE.ot | write RES OUT.ot < scans\n";
    return 2;
  }
  const std::string mode = argv[1];
  if (mode == "read") {
    std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(argv[2]));
    auto* tree = dynamic_cast<octomap::ColorOcTree*>(read.get());
    if (!tree) return 1;
    print_leaves(*tree);
    print_inner("inner", *tree);
    tree->updateInnerOccupancy();
    print_inner("updated", *tree);
    return 0;
  }
  if (mode != "write" || argc < 4) return 2;
  octomap::ColorOcTree tree(std::atof(argv[2]));
  octomap::Pointcloud cloud;
  octomap::point3d origin(0, 0, 0);
  bool open = false;
  auto flush = [&]() {
    if (open) tree.insertPointCloud(cloud, origin);
    cloud.clear();
  };
  std::string line;
  while (std::getline(std::cin, line)) {
    std::istringstream in(line);
    std::string first;
    if (!(in >> first)) continue;
    if (first == "scan") {
      flush();
      float x, y, z;
      in >> x >> y >> z;
      origin = octomap::point3d(x, y, z);
      open = true;
    } else {
      float x = std::strtof(first.c_str(), nullptr), y, z;
      in >> y >> z;
      cloud.push_back(x, y, z);
    }
  }
  flush();
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    const octomap::OcTreeKey k = it.getKey();
    if (tree.isNodeOccupied(*it)) {
      tree.setNodeColor(k, k[0] % 251, k[1] % 241, (k[2] * 7) % 239);
      if (k[0] % 2 == 0) tree.integrateNodeColor(k, 200, 100, (k[1] * 3) % 256);
    } else if (k[1] % 5 == 0) {
      tree.averageNodeColor(k, 30, 60, 90);
    }
  }
  tree.updateInnerOccupancy();
  if (!tree.write(argv[3])) return 1;
  print_leaves(tree);
  return 0;
}
