// OctoMap's own readers and writers of map files, for verify/tests/maps.rs.
//   octomap_files read FILE.ot|FILE.bt       prints "leaf kx ky kz side logodds_bits" per leaf (lowest keys,
//                                            the log-odds' float bits in hex)
//   octomap_files cast FILE.ot IGNORE MAXRANGE  reads rays "ox oy oz dx dy dz" from stdin and prints, per
//                                            ray, castRay's result (1 or 0) and the key of its end point
//   octomap_files write RES OUT.ot OUT.bt    reads scans from stdin as octomap_insert does, inserts each
//                                            with OcTree::insertPointCloud and writes both files with
//                                            OcTree::write and OcTree::writeBinary
#include <octomap/octomap.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

static void print_leaves(octomap::OcTree& tree) {
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    const octomap::OcTreeKey k = it.getKey();
    const long side = 1L << (tree.getTreeDepth() - it.getDepth());
    const float l = it->getLogOdds();
    std::uint32_t bits;
    std::memcpy(&bits, &l, 4);
    std::cout << "leaf " << (long(k[0]) & ~(side - 1)) << " " << (long(k[1]) & ~(side - 1)) << " "
              << (long(k[2]) & ~(side - 1)) << " " << side << " " << std::hex << bits << std::dec << "\n";
  }
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: octomap_files read FILE | write RES OUT.ot OUT.bt < scans\n";
    return 2;
  }
  const std::string mode = argv[1];
  if (mode == "read") {
    const std::string file = argv[2];
    if (file.size() > 3 && file.substr(file.size() - 3) == ".bt") {
      octomap::OcTree tree(0.1);
      if (!tree.readBinary(file)) return 1;
      print_leaves(tree);
    } else {
      std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(file));
      auto* tree = dynamic_cast<octomap::OcTree*>(read.get());
      if (!tree) return 1;
      print_leaves(*tree);
    }
    return 0;
  }
  if (mode == "cast" && argc >= 5) {
    std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(argv[2]));
    auto* tree = dynamic_cast<octomap::OcTree*>(read.get());
    if (!tree) return 1;
    const bool ignore = std::atoi(argv[3]) != 0;
    const double maxrange = std::atof(argv[4]);
    float o[3], d[3];
    while (std::cin >> o[0] >> o[1] >> o[2] >> d[0] >> d[1] >> d[2]) {
      octomap::point3d end(0, 0, 0);
      const bool hit = tree->castRay(octomap::point3d(o[0], o[1], o[2]), octomap::point3d(d[0], d[1], d[2]), end,
                                     ignore, maxrange);
      const octomap::OcTreeKey k = tree->coordToKey(end);
      std::cout << (hit ? 1 : 0) << " " << k[0] << " " << k[1] << " " << k[2] << "\n";
    }
    return 0;
  }
  if (mode != "write" || argc < 5) return 2;
  octomap::OcTree tree(std::atof(argv[2]));
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
  if (!tree.write(argv[3])) return 1;
  if (!tree.writeBinary(argv[4])) return 1;
  return 0;
}
