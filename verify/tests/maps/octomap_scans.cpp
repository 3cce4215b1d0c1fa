// OctoMap's scan graphs and poses, for verify/tests/scans.rs. Floats in and out are their bits in hex
// (f32: 8 digits, f64: 16), so nothing is lost in text.
//   octomap_scans world GRAPH       reads GRAPH with ScanGraph::readBinary and prints each node as
//                                   OccupancyOcTreeBase::insertPointCloud(const ScanNode&) places it:
//                                   "node ID N OX OY OZ" (the sensor origin), then N lines "X Y Z".
//   octomap_scans pose              reads lines "X Y Z ROLL PITCH YAW PX PY PZ" (X Y Z P* f32, angles f64)
//                                   and prints, for Pose6D(X, Y, Z, ROLL, PITCH, YAW): its quaternion
//                                   "U QX QY QZ", transform(P) and inv().transform(P), on one line.
//   octomap_scans write GRAPH       reads "node X Y Z ROLL PITCH YAW" lines each followed by its points
//                                   "X Y Z" (the sensor's frame), adds them to a ScanGraph (addNode,
//                                   connectPrevious) and writes it with ScanGraph::writeBinary.
//   octomap_scans map GRAPH RES [MAXRANGE]
//                                   inserts every node of GRAPH into an OcTree with
//                                   insertPointCloud(const ScanNode&, maxrange) and prints
//                                   "leaf kx ky kz side logodds_bits" per leaf, as octomap_insert does.
#include <octomap/octomap.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <sstream>
#include <string>

using octomap::point3d;
using octomap::pose6d;

static float f32_of(const std::string& hex) {
  std::uint32_t bits = std::stoul(hex, nullptr, 16);
  float f;
  std::memcpy(&f, &bits, 4);
  return f;
}

static double f64_of(const std::string& hex) {
  std::uint64_t bits = std::stoull(hex, nullptr, 16);
  double d;
  std::memcpy(&d, &bits, 8);
  return d;
}

static std::string hex(float f) {
  std::uint32_t bits;
  std::memcpy(&bits, &f, 4);
  std::ostringstream out;
  out << std::hex << bits;
  return out.str();
}

static std::string hex3(const point3d& p) { return hex(p.x()) + " " + hex(p.y()) + " " + hex(p.z()); }

static int world(const char* file) {
  octomap::ScanGraph graph;
  if (!graph.readBinary(file)) return 1;
  for (auto it = graph.begin(); it != graph.end(); ++it) {
    const octomap::ScanNode& scan = **it;
    // What insertPointCloud(const ScanNode&, ...) computes, line for line (OccupancyOcTreeBase.hxx).
    octomap::Pointcloud& cloud = *(scan.scan);
    pose6d frame_origin = scan.pose;
    point3d sensor_origin = frame_origin.inv().transform(scan.pose.trans());
    octomap::Pointcloud transformed_scan(cloud);
    transformed_scan.transform(frame_origin);
    point3d transformed_sensor_origin = frame_origin.transform(sensor_origin);
    std::cout << "node " << scan.id << " " << transformed_scan.size() << " " << hex3(transformed_sensor_origin)
              << "\n";
    for (size_t i = 0; i < transformed_scan.size(); ++i) std::cout << hex3(transformed_scan[i]) << "\n";
  }
  return 0;
}

static int pose() {
  std::string line;
  while (std::getline(std::cin, line)) {
    std::istringstream in(line);
    std::string f[9];
    for (auto& s : f) in >> s;
    pose6d p(f32_of(f[0]), f32_of(f[1]), f32_of(f[2]), f64_of(f[3]), f64_of(f[4]), f64_of(f[5]));
    point3d v(f32_of(f[6]), f32_of(f[7]), f32_of(f[8]));
    const octomath::Quaternion& q = p.rot();
    std::cout << hex(q.u()) << " " << hex(q.x()) << " " << hex(q.y()) << " " << hex(q.z()) << " "
              << hex3(p.transform(v)) << " " << hex3(p.inv().transform(v)) << "\n";
  }
  return 0;
}

static int write(const char* file) {
  octomap::ScanGraph graph;
  octomap::Pointcloud* cloud = nullptr;
  pose6d pose;
  auto flush = [&]() {
    if (cloud) {
      graph.addNode(cloud, pose);
      graph.connectPrevious();
    }
  };
  std::string line;
  while (std::getline(std::cin, line)) {
    std::istringstream in(line);
    std::string first;
    if (!(in >> first)) continue;
    if (first == "node") {
      flush();
      std::string f[6];
      for (auto& s : f) in >> s;
      pose = pose6d(f32_of(f[0]), f32_of(f[1]), f32_of(f[2]), f64_of(f[3]), f64_of(f[4]), f64_of(f[5]));
      cloud = new octomap::Pointcloud();
    } else {
      std::string y, z;
      in >> y >> z;
      cloud->push_back(f32_of(first), f32_of(y), f32_of(z));
    }
  }
  flush();
  return graph.writeBinary(file) ? 0 : 1;
}

static int map(const char* file, double res, double maxrange) {
  octomap::ScanGraph graph;
  if (!graph.readBinary(file)) return 1;
  octomap::OcTree tree(res);
  for (auto it = graph.begin(); it != graph.end(); ++it) tree.insertPointCloud(**it, maxrange);
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    const octomap::OcTreeKey k = it.getKey();
    const long side = 1L << (tree.getTreeDepth() - it.getDepth());
    // The leaf's lowest key: OctoMap's key of a leaf above the lowest level is its centre's.
    const long lo[3] = {long(k[0]) & ~(side - 1), long(k[1]) & ~(side - 1), long(k[2]) & ~(side - 1)};
    std::cout << "leaf " << lo[0] << " " << lo[1] << " " << lo[2] << " " << side << " " << hex(it->getLogOdds())
              << "\n";
  }
  return 0;
}

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "world" && argc == 3) return world(argv[2]);
  if (mode == "pose" && argc == 2) return pose();
  if (mode == "write" && argc == 3) return write(argv[2]);
  if (mode == "map" && (argc == 4 || argc == 5))
    return map(argv[2], std::atof(argv[3]), argc == 5 ? std::atof(argv[4]) : -1.0);
  std::cerr << "usage: octomap_scans world GRAPH | pose | write GRAPH | map GRAPH RES [MAXRANGE]\n";
  return 2;
}
