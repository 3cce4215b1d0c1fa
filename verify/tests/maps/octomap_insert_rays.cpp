// Integrates rays one at a time with the real OctoMap library, for verify/tests/maps.rs.
//   octomap_insert_rays RES [MAXRANGE]   reads rays from stdin: "scan ox oy oz" sets the sensor, then
//                                        each "x y z" line is a ray's end, inserted in turn with
//                                        OcTree::insertRay(origin, end, maxrange) (lazy_eval = false).
//   octomap_insert_rays sphere           OctoMap's unit test InsertRay: 360 x 360 rays at 5 cm from
//                                        (0.01, 0.01, 0.02) to that point plus (2.01, 0.01, 0.01) turned
//                                        by 1 degree steps about z, then y (octomath's rotate_IP); prints
//                                        "end xbits ybits zbits" for each ray's end (the floats' bits in
//                                        hex) first.
// Then prints "outside N" (the rays insertRay returned false for), "size N" (the tree's node count) and
// "leaf kx ky kz side logodds_bits" per leaf (keys as OctoMap's, the log-odds' float bits in hex); for the
// sphere, last, "binary_size N": the node count after writing the map as .bt (which makes it maximum
// likelihood and prunes it), the number the unit test checks.
#include <octomap/math/Utils.h>
#include <octomap/octomap.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <sstream>
#include <string>

static std::uint32_t bits_of(float f) {
  std::uint32_t bits;
  std::memcpy(&bits, &f, 4);
  return bits;
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: octomap_insert_rays RES [MAXRANGE] < rays | octomap_insert_rays sphere\n";
    return 2;
  }
  const bool sphere = std::string(argv[1]) == "sphere";
  const double res = sphere ? 0.05 : std::atof(argv[1]);
  const double maxrange = (!sphere && argc > 2) ? std::atof(argv[2]) : -1.0;
  octomap::OcTree tree(res);
  tree.setProbHit(0.7);
  tree.setProbMiss(0.4);
  long outside = 0;
  if (sphere) {
    const octomap::point3d origin(0.01f, 0.01f, 0.02f);
    octomap::point3d on_surface(2.01f, 0.01f, 0.01f);
    for (int i = 0; i < 360; i++) {
      for (int j = 0; j < 360; j++) {
        const octomap::point3d end = origin + on_surface;
        std::cout << std::hex << "end " << bits_of(end.x()) << " " << bits_of(end.y()) << " "
                  << bits_of(end.z()) << std::dec << "\n";
        if (!tree.insertRay(origin, end)) outside++;
        on_surface.rotate_IP(0, 0, DEG2RAD(1.));
      }
      on_surface.rotate_IP(0, DEG2RAD(1.), 0);
    }
  } else {
    octomap::point3d origin(0, 0, 0);
    std::string line;
    while (std::getline(std::cin, line)) {
      std::istringstream in(line);
      std::string first;
      if (!(in >> first)) continue;
      float x, y, z;
      if (first == "scan") {
        in >> x >> y >> z;
        origin = octomap::point3d(x, y, z);
      } else {
        x = std::strtof(first.c_str(), nullptr);
        in >> y >> z;
        if (!tree.insertRay(origin, octomap::point3d(x, y, z), maxrange)) outside++;
      }
    }
  }
  std::cout << "outside " << outside << "\n";
  std::cout << "size " << tree.size() << "\n";
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    const octomap::OcTreeKey k = it.getKey();
    const long side = 1L << (tree.getTreeDepth() - it.getDepth());
    // The leaf's lowest key: OctoMap's key of a leaf above the lowest level is its centre's.
    const long lo[3] = {long(k[0]) & ~(side - 1), long(k[1]) & ~(side - 1), long(k[2]) & ~(side - 1)};
    std::cout << "leaf " << lo[0] << " " << lo[1] << " " << lo[2] << " " << side << " " << std::hex
              << bits_of(it->getLogOdds()) << std::dec << "\n";
  }
  if (sphere) {
    std::ostringstream bt;
    tree.writeBinary(bt);
    std::cout << "binary_size " << tree.size() << "\n";
  }
  return 0;
}
