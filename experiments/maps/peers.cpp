// OctoMap's side of experiments/maps.sh: `peers RES FILE REPEATS` reads a scan (`x y z` lines, the sensor
// at the origin), inserts it into an empty OcTree REPEATS times with insertPointCloud (discretize = false,
// lazy_eval = false) and prints the best time, the map's occupied and free voxel counts (leaves expanded),
// the sum of its log-odds over voxels (to compare with ktree's) and the tree's memory (memoryUsage()).
// `peers sequence RES FILE.log` reads a sequence of scans (OctoMap's .log, ScanGraph::readPlainASCII),
// integrates them one after the other (insertPointCloud of each ScanNode, as graph2tree does) and prints
// each scan's time and the tree's size after it, then the same totals.
#include <octomap/octomap.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>

static void print_map(const octomap::OcTree& tree, size_t points, double seconds) {
  unsigned long long occupied = 0, free_ = 0;
  double sum = 0;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    const double side = std::ldexp(1.0, int(tree.getTreeDepth() - it.getDepth()));
    const double n = side * side * side;
    (tree.isNodeOccupied(*it) ? occupied : free_) += (unsigned long long)n;
    sum += double(it->getLogOdds()) * n;
  }
  std::printf("points=%zu\nseconds=%.6f\noccupied=%llu\nfree=%llu\nchecksum=%.3f\nmap_bytes=%zu\n", points,
              seconds, occupied, free_, sum, tree.memoryUsage());
}

static int sequence(double res, const char* path) {
  octomap::ScanGraph graph;
  graph.readPlainASCII(path);
  if (graph.size() == 0) {
    std::cerr << path << ": no scan read\n";
    return 1;
  }
  octomap::OcTree tree(res);
  double total = 0;
  size_t points = 0, i = 0;
  for (auto it = graph.begin(); it != graph.end(); ++it, ++i) {
    const auto start = std::chrono::steady_clock::now();
    tree.insertPointCloud(**it);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    total += s;
    points += (*it)->scan->size();
    std::printf("scan=%zu points=%zu seconds=%.6f nodes=%zu\n", i, (*it)->scan->size(), s, tree.size());
  }
  print_map(tree, points, total);
  return 0;
}

int main(int argc, char** argv) {
  if (argc == 4 && std::string(argv[1]) == "sequence") return sequence(std::atof(argv[2]), argv[3]);
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
  print_map(*tree, cloud.size(), best);
  return 0;
}
