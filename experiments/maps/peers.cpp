// OctoMap's side of experiments/maps.sh: `peers RES FILE REPEATS` reads a scan (`x y z` lines, the sensor
// at the origin), inserts it into an empty OcTree REPEATS times with insertPointCloud (discretize = false,
// lazy_eval = false) and prints the best time, the map's occupied and free voxel counts (leaves expanded),
// the sum of its log-odds over voxels (to compare with ktree's) and the tree's memory (memoryUsage()).
#include <octomap/octomap.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: peers RES FILE REPEATS\n";
    return 2;
  }
  const double res = std::atof(argv[1]);
  const int repeats = std::atoi(argv[3]);
  octomap::Pointcloud cloud;
  std::ifstream in(argv[2]);
  float x, y, z;
  while (in >> x >> y >> z) cloud.push_back(x, y, z);
  double best = 1e300;
  std::unique_ptr<octomap::OcTree> tree;
  for (int r = 0; r < repeats; ++r) {
    auto t = std::make_unique<octomap::OcTree>(res);
    const auto start = std::chrono::steady_clock::now();
    t->insertPointCloud(cloud, octomap::point3d(0, 0, 0));
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (s < best) best = s;
    tree = std::move(t);
  }
  unsigned long long occupied = 0, free_ = 0;
  double sum = 0;
  for (auto it = tree->begin_leafs(); it != tree->end_leafs(); ++it) {
    const double side = std::ldexp(1.0, int(tree->getTreeDepth() - it.getDepth()));
    const double n = side * side * side;
    (tree->isNodeOccupied(*it) ? occupied : free_) += (unsigned long long)n;
    sum += double(it->getLogOdds()) * n;
  }
  std::printf("points=%zu\nseconds=%.6f\noccupied=%llu\nfree=%llu\nchecksum=%.3f\nmap_bytes=%zu\n", cloud.size(),
              best, occupied, free_, sum, tree->memoryUsage());
  return 0;
}
