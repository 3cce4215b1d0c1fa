// The voxel-centre sphere of results/performance/scale.md (centre U/2, radius (U - 1)/2, U = 2^L: the
// voxels whose centres lie in the ball) built with OpenVDB on one thread, two ways:
//   fill:     its runs along z, made column by column from the same integer test ktree uses, each filled
//             into a BoolGrid (sparseFill of the run's box), then pruned;
//   levelset: OpenVDB's own narrow-band level-set sphere (createLevelSetSphere, half width 3, unthreaded),
//             a different output (a band around the surface, not the solid), shown as OpenVDB's fastest
//             sphere.
// Prints "seconds=S" (best of REPEATS) and "voxels=N" (active voxels, for fill the sphere's volume).
//
//   sphere L fill|levelset REPEATS
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

static int64_t isqrt(int64_t n) {
  if (n < 0) return -1;
  int64_t s = static_cast<int64_t>(std::sqrt(static_cast<double>(n)));
  while (s * s > n) --s;
  while ((s + 1) * (s + 1) <= n) ++s;
  return s;
}

static uint64_t fill(int level) {
  const int64_t u = int64_t(1) << level;
  const int64_t r2 = (u - 1) * (u - 1);
  openvdb::BoolGrid::Ptr grid = openvdb::BoolGrid::create(false);
  openvdb::BoolTree& tree = grid->tree();
  for (int64_t x = 0; x < u; ++x) {
    const int64_t dx = 2 * x + 1 - u;
    for (int64_t y = 0; y < u; ++y) {
      const int64_t dy = 2 * y + 1 - u;
      const int64_t rest = r2 - dx * dx - dy * dy;
      if (rest < 0) continue;
      // |2z + 1 - U| <= s  <=>  (U - s - 1)/2 <= z <= (U + s - 1)/2
      const int64_t s = isqrt(rest);
      int64_t z1 = u - s - 1;
      z1 = z1 <= 0 ? 0 : (z1 + 1) / 2;
      const int64_t z2 = std::min((u + s - 1) / 2, u - 1);
      if (z1 > z2) continue;
      tree.sparseFill(openvdb::CoordBBox(openvdb::Coord(x, y, z1), openvdb::Coord(x, y, z2)), true, true);
    }
  }
  tree.prune();
  return tree.activeVoxelCount();
}

static uint64_t levelset(int level) {
  const float u = static_cast<float>(int64_t(1) << level);
  auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
      (u - 1.0f) / 2.0f, openvdb::Vec3f(u / 2.0f, u / 2.0f, u / 2.0f), 1.0f, 3.0f, false);
  return grid->tree().activeVoxelCount();
}

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: sphere L fill|levelset REPEATS\n");
    return 2;
  }
  const int level = std::atoi(argv[1]);
  const bool is_fill = std::strcmp(argv[2], "fill") == 0;
  const int repeats = std::atoi(argv[3]);
  openvdb::initialize();
  double best = 1e300;
  uint64_t voxels = 0;
  for (int i = 0; i < repeats; ++i) {
    const auto start = std::chrono::steady_clock::now();
    voxels = is_fill ? fill(level) : levelset(level);
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
    best = std::min(best, took.count());
  }
  std::printf("seconds=%.6f\nvoxels=%llu\n", best, static_cast<unsigned long long>(voxels));
  return 0;
}
