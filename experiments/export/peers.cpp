// The peer of ktree's mesh export (results/performance/export.md, experiments/export.sh): OpenVDB's
// tools::volumeToMesh on a level set of the voxels ktree wrote (`perf --child export OBJECT:write-vdb:PATH`,
// a BoolGrid whose active voxels are the object, index = ktree's voxel):
//
//   peers PATH.vdb THREADS ADAPTIVITY
//
// The level set is tools::topologyToLevelSet of the BoolGrid (half width 3, no closing, dilation or
// smoothing: the zero crossing lies between each full voxel's centre and its empty neighbours'), built
// once and timed apart (`levelset_seconds=`). Then tools::volumeToMesh(level set, points, triangles, quads,
// isovalue 0, ADAPTIVITY) is timed: `seconds=` is the best of REPEATS (default 3) runs in this process.
// THREADS is 1 (tbb::global_control) or 0 (all: TBB's default). Also prints `voxels=` (the BoolGrid's
// active voxels), `points=`, `quads=`, `triangles=` (OpenVDB's own) and `triangles_total=` (a quad counted
// as two triangles).
#include <openvdb/openvdb.h>
#include <openvdb/tools/TopologyToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: peers PATH.vdb THREADS ADAPTIVITY\n");
    return 2;
  }
  const std::string path = argv[1];
  const int threads = std::atoi(argv[2]);
  const double adaptivity = std::atof(argv[3]);
  const char* env = std::getenv("REPEATS");
  const int repeats = env ? std::max(1, std::atoi(env)) : 3;
  std::unique_ptr<tbb::global_control> one;
  if (threads == 1) {
    one = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, 1);
  }
  try {
    openvdb::initialize();
    openvdb::io::File file(path);
    file.open();
    auto grids = file.getGrids();
    file.close();
    if (grids->empty()) throw std::runtime_error(path + ": no grid");
    auto mask = openvdb::gridPtrCast<openvdb::BoolGrid>(grids->front());
    if (!mask) throw std::runtime_error(path + ": the first grid is not a BoolGrid");
    using Clock = std::chrono::steady_clock;
    auto start = Clock::now();
    auto sdf = openvdb::tools::topologyToLevelSet(*mask, 3, 0, 0, 0);
    const std::chrono::duration<double> build = Clock::now() - start;
    double best = std::numeric_limits<double>::infinity();
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    for (int r = 0; r < repeats; ++r) {
      points.clear();
      triangles.clear();
      quads.clear();
      start = Clock::now();
      openvdb::tools::volumeToMesh(*sdf, points, triangles, quads, 0.0, adaptivity);
      const std::chrono::duration<double> s = Clock::now() - start;
      best = std::min(best, s.count());
    }
    std::printf("levelset_seconds=%.6f\nseconds=%.6f\nvoxels=%llu\npoints=%zu\nquads=%zu\ntriangles=%zu\n"
                "triangles_total=%zu\n",
                build.count(), best, static_cast<unsigned long long>(mask->activeVoxelCount()),
                points.size(), quads.size(), triangles.size(), triangles.size() + 2 * quads.size());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "peers: %s\n", e.what());
    return 1;
  }
  return 0;
}
