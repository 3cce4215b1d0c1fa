// Integrates scans with the real OctoMap library, for verify/tests/maps.rs.
//   octomap_insert RES [MAXRANGE]   reads scans from stdin: "scan ox oy oz" opens a scan seen from
//                                   (ox, oy, oz), then "x y z" lines are its points; each scan is
//                                   inserted with OcTree::insertPointCloud (discretize = false, lazy_eval =
//                                   false). Prints "leaf kx ky kz side logodds_bits" per leaf (keys as
//                                   OctoMap's, the log-odds' float bits in hex).
#include <octomap/octomap.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <sstream>
#include <string>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: octomap_insert RES [MAXRANGE] < scans\n";
    return 2;
  }
  const double res = std::atof(argv[1]);
  const double maxrange = argc > 2 ? std::atof(argv[2]) : -1.0;
  octomap::OcTree tree(res);
  octomap::Pointcloud cloud;
  octomap::point3d origin(0, 0, 0);
  bool open = false;
  std::string line;
  auto flush = [&]() {
    if (open) tree.insertPointCloud(cloud, origin, maxrange, false, false);
    cloud.clear();
  };
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
    const long side = 1L << (tree.getTreeDepth() - it.getDepth());
    const float l = it->getLogOdds();
    std::uint32_t bits;
    std::memcpy(&bits, &l, 4);
    // The leaf's lowest key: OctoMap's key of a leaf above the lowest level is its centre's.
    const long lo[3] = {long(k[0]) & ~(side - 1), long(k[1]) & ~(side - 1), long(k[2]) & ~(side - 1)};
    std::cout << "leaf " << lo[0] << " " << lo[1] << " " << lo[2] << " " << side << " " << std::hex
              << bits << std::dec << "\n";
  }
  return 0;
}
