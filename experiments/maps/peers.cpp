// OctoMap's side of experiments/maps.sh: `peers RES FILE REPEATS` reads a scan (`x y z` lines, the sensor
// at the origin), inserts it into an empty OcTree REPEATS times with insertPointCloud (discretize = false,
// lazy_eval = false) and prints the best time, the map's occupied and free voxel counts (leaves expanded),
// the sum of its log-odds over voxels (to compare with ktree's) and the tree's memory (memoryUsage()).
// `peers sequence RES FILE.log` reads a sequence of scans (OctoMap's .log, ScanGraph::readPlainASCII),
// integrates them one after the other (insertPointCloud of each ScanNode, as graph2tree does) and prints
// each scan's time and the tree's size after it, then the same totals. `peers queries RES FILE N M`
// integrates the scan, then times search() of N points and castRay of M rays from the origin, drawn by the
// same generator as ktree's `maps queries`.
#include <octomap/octomap.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>
#include <algorithm>

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

// A 64-bit LCG, 53 bits a number in [0, 1): the same draws as ktree's side.
struct Draw {
  unsigned long long state;
  double next() {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(state >> 11) / double(1ULL << 53);
  }
};

static int queries(double res, const char* path, size_t n, size_t m) {
  octomap::Pointcloud cloud;
  std::ifstream in(path);
  float x, y, z;
  while (in >> x >> y >> z) cloud.push_back(x, y, z);
  octomap::OcTree tree(res);
  tree.insertPointCloud(cloud, octomap::point3d(0, 0, 0));
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (size_t i = 0; i < cloud.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], double(cloud[i](a)));
      hi[a] = std::max(hi[a], double(cloud[i](a)));
    }
  Draw draw{42};
  std::vector<octomap::point3d> at(n), directions(m);
  for (auto& p : at)
    for (int a = 0; a < 3; ++a) p(a) = float(lo[a] + (hi[a] - lo[a]) * draw.next());
  for (auto& d : directions)
    for (int a = 0; a < 3; ++a) d(a) = float(2.0 * draw.next() - 1.0);
  double best_search = 1e300, best_cast = 1e300;
  size_t counts[3] = {0, 0, 0}, hits = 0;
  for (int r = 0; r < 3; ++r) {
    counts[0] = counts[1] = counts[2] = 0;
    auto start = std::chrono::steady_clock::now();
    for (const auto& p : at) {
      const octomap::OcTreeNode* node = tree.search(p);
      counts[node == nullptr ? 0 : (tree.isNodeOccupied(node) ? 2 : 1)]++;
    }
    best_search = std::min(best_search,
                           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    hits = 0;
    start = std::chrono::steady_clock::now();
    octomap::point3d end;
    for (const auto& d : directions) hits += tree.castRay(octomap::point3d(0, 0, 0), d, end, false, -1.0);
    best_cast = std::min(best_cast,
                         std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::printf("search_seconds=%.6f\ncast_seconds=%.6f\nunknown=%zu free=%zu occupied=%zu\nhits=%zu\n", best_search,
              best_cast, counts[0], counts[1], counts[2], hits);
  return 0;
}

int main(int argc, char** argv) {
  if (argc == 4 && std::string(argv[1]) == "sequence") return sequence(std::atof(argv[2]), argv[3]);
  if (argc == 6 && std::string(argv[1]) == "queries")
    return queries(std::atof(argv[2]), argv[3], std::strtoull(argv[4], nullptr, 10), std::strtoull(argv[5], nullptr, 10));
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
