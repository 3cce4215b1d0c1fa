// The peers of ktree's queries (results/performance/queries.md, experiments/queries.sh), on the voxels
// ktree wrote (`perf --child queries OBJECT:write-inputs:DIR`) and the same query arrays:
//
//   peers vdb-accessor  DIR/tree.vdb POINTS.bin THREADS   OpenVDB: a ValueAccessor per thread, getValue
//   peers vdb-getvalue  DIR/tree.vdb POINTS.bin THREADS   OpenVDB: tree().getValue (no cache)
//   peers vdb-rays      DIR/tree.vdb rays.bin   THREADS   OpenVDB: VolumeRayIntersector + voxel DDA
//   peers octomap-search DIR/tree.bt POINTS.bin THREADS   OctoMap: OcTree::search by key
//   peers octomap-rays  DIR/tree.bt  rays.bin   THREADS [N]  OctoMap: OcTree::castRay (the first N rays)
//
// THREADS is 1 or 0 (all: TBB's default). Prints `seconds=` (best of REPEATS, default 3, in this
// process; loading the grid and reading the inputs are not timed), `answers=` (points inside, or rays that
// hit) and for rays `voxel_sum=` (the sum of the coordinates of the voxels hit), as ktree's perf child does.
//
// Points: 3 × u32 little-endian a point. Rays: origin then direction, 6 × f64 a ray; voxel v is the box
// [v, v + 1) in ktree's coordinates, which are OpenVDB's index coordinates (the DDA and the intersector
// take voxel v as [v, v + 1)) and OctoMap's metric coordinates (resolution 1, key = v + 32768).
#include <openvdb/openvdb.h>
#include <openvdb/math/DDA.h>
#include <openvdb/math/Ray.h>
#include <openvdb/tools/RayIntersector.h>
#include <octomap/OcTree.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace {

template <typename T>
std::vector<T> read_array(const std::string& path, size_t width) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error("cannot read " + path);
  const auto bytes = static_cast<size_t>(in.tellg());
  if (bytes % (width * sizeof(T)) != 0) throw std::runtime_error(path + ": size is not a whole number of rows");
  std::vector<T> v(bytes / sizeof(T));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(bytes));
  return v;
}

struct Tally {
  uint64_t answers = 0;
  uint64_t voxel_sum = 0;
  Tally operator+(const Tally& o) const { return {answers + o.answers, voxel_sum + o.voxel_sum}; }
};

// Best wall time of `repeats` runs of `work(begin, end)` over n items, on one thread or TBB's pool.
template <typename Work>
std::pair<double, Tally> best_of(int repeats, size_t n, bool one, Work work) {
  double best = std::numeric_limits<double>::infinity();
  Tally tally;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    if (one) {
      tally = work(size_t(0), n);
    } else {
      tally = tbb::parallel_reduce(
          tbb::blocked_range<size_t>(0, n, 4096), Tally{},
          [&](const tbb::blocked_range<size_t>& r, Tally t) { return t + work(r.begin(), r.end()); },
          [](Tally a, Tally b) { return a + b; });
    }
    const std::chrono::duration<double> s = std::chrono::steady_clock::now() - start;
    best = std::min(best, s.count());
  }
  return {best, tally};
}

openvdb::BoolGrid::Ptr read_vdb(const std::string& path) {
  openvdb::io::File file(path);
  file.open();
  auto base = file.readGrid("ktree");
  file.close();
  auto grid = openvdb::gridPtrCast<openvdb::BoolGrid>(base);
  if (!grid) throw std::runtime_error(path + ": grid 'ktree' is not a BoolGrid");
  return grid;
}

// The first active voxel of the ray through the grid: the intersector gives the intervals of the ray in
// active leaves and tiles (front to back), a voxel DDA finds the first active voxel within them.
using RayT = openvdb::math::Ray<double>;
using Intersector = openvdb::tools::VolumeRayIntersector<openvdb::BoolGrid, 0, RayT>;

bool vdb_cast(Intersector& inter, const openvdb::BoolGrid::ConstAccessor& acc, const RayT& ray,
              openvdb::Coord& hit) {
  if (!inter.setIndexRay(ray)) return false;
  double t0 = 0, t1 = 0;
  while (inter.march(t0, t1)) {
    openvdb::math::DDA<RayT, 0> dda(ray, t0, t1);
    do {
      if (acc.isValueOn(dda.voxel())) {
        hit = dda.voxel();
        return true;
      }
    } while (dda.step());
  }
  return false;
}

// Where a ray from inside the universe [0, side)^3 leaves it, as a distance along its unit direction.
double exit_distance(const double* o, const double* d, double side) {
  double t = std::numeric_limits<double>::infinity();
  double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 0) t = std::min(t, (side - o[a]) / d[a]);
    if (d[a] < 0) t = std::min(t, (0 - o[a]) / d[a]);
  }
  return t * norm;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 5) {
      std::fprintf(stderr, "usage: peers TOOL MAP QUERIES THREADS [N]\n");
      return 2;
    }
    const std::string tool = argv[1], map = argv[2], queries = argv[3];
    const bool one = std::atoi(argv[4]) == 1;
    const int repeats = std::getenv("REPEATS") ? std::atoi(std::getenv("REPEATS")) : 3;
    std::unique_ptr<tbb::global_control> control;
    if (one) control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, 1);
    std::pair<double, Tally> result;
    if (tool == "vdb-accessor" || tool == "vdb-getvalue" || tool == "vdb-rays") {
      openvdb::initialize();
      const auto grid = read_vdb(map);
      const auto& tree = grid->tree();
      if (tool == "vdb-rays") {
        const auto rays = read_array<double>(queries, 6);
        const Intersector prototype(*grid);
        result = best_of(repeats, rays.size() / 6, one, [&](size_t b, size_t e) {
          Intersector inter(prototype);
          const auto acc = grid->getConstAccessor();
          Tally t;
          for (size_t i = b; i < e; ++i) {
            const double* r = &rays[6 * i];
            const RayT ray(openvdb::Vec3d(r[0], r[1], r[2]), openvdb::Vec3d(r[3], r[4], r[5]));
            openvdb::Coord hit;
            if (vdb_cast(inter, acc, ray, hit)) {
              t.answers += 1;
              t.voxel_sum += uint64_t(hit.x()) + uint64_t(hit.y()) + uint64_t(hit.z());
            }
          }
          return t;
        });
      } else {
        const auto points = read_array<uint32_t>(queries, 3);
        const bool cached = tool == "vdb-accessor";
        result = best_of(repeats, points.size() / 3, one, [&](size_t b, size_t e) {
          Tally t;
          if (cached) {
            const auto acc = grid->getConstAccessor();
            for (size_t i = b; i < e; ++i) {
              const uint32_t* p = &points[3 * i];
              t.answers += acc.getValue(openvdb::Coord(int(p[0]), int(p[1]), int(p[2])));
            }
          } else {
            for (size_t i = b; i < e; ++i) {
              const uint32_t* p = &points[3 * i];
              t.answers += tree.getValue(openvdb::Coord(int(p[0]), int(p[1]), int(p[2])));
            }
          }
          return t;
        });
      }
    } else if (tool == "octomap-search" || tool == "octomap-rays") {
      octomap::OcTree tree(map);
      if (tree.size() == 0) throw std::runtime_error(map + ": no tree read");
      if (tool == "octomap-search") {
        const auto points = read_array<uint32_t>(queries, 3);
        result = best_of(repeats, points.size() / 3, one, [&](size_t b, size_t e) {
          Tally t;
          for (size_t i = b; i < e; ++i) {
            const uint32_t* p = &points[3 * i];
            const octomap::OcTreeKey key(p[0] + 32768, p[1] + 32768, p[2] + 32768);
            const octomap::OcTreeNode* node = tree.search(key);
            t.answers += node != nullptr && tree.isNodeOccupied(node);
          }
          return t;
        });
      } else {
        auto rays = read_array<double>(queries, 6);
        size_t n = rays.size() / 6;
        if (argc > 5) n = std::min(n, size_t(std::atoll(argv[5])));
        // The universe's side: the ball and the armadillo fill [0, 2^L)^3, OctoMap's metric box of it.
        double mx, my, mz;
        tree.getMetricMax(mx, my, mz);
        const double side = std::exp2(std::ceil(std::log2(std::max({mx, my, mz}))));
        result = best_of(repeats, n, one, [&](size_t b, size_t e) {
          Tally t;
          for (size_t i = b; i < e; ++i) {
            const double* r = &rays[6 * i];
            const octomap::point3d origin{float(r[0]), float(r[1]), float(r[2])};
            const octomap::point3d direction{float(r[3]), float(r[4]), float(r[5])};
            octomap::point3d end;
            // Unknown cells (outside the universe) count as free; the cast stops where the ray leaves.
            if (tree.castRay(origin, direction, end, true, exit_distance(r, r + 3, side))) {
              t.answers += 1;
              t.voxel_sum += uint64_t(std::floor(end.x())) + uint64_t(std::floor(end.y())) +
                             uint64_t(std::floor(end.z()));
            }
          }
          return t;
        });
      }
    } else {
      throw std::runtime_error("unknown tool " + tool);
    }
    std::printf("seconds=%.9f\nanswers=%llu\nvoxel_sum=%llu\n", result.first,
                static_cast<unsigned long long>(result.second.answers),
                static_cast<unsigned long long>(result.second.voxel_sum));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "peers: %s\n", e.what());
    return 1;
  }
}
