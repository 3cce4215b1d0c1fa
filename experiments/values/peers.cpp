// OpenVDB's side of experiments/values.sh: a dense volume (x fastest, little-endian u32 labels or f32
// densities, side 2^L) into an Int32Grid or FloatGrid by tools::copyFromDense (serial, tolerance 0) and
// tools::prune (tolerance 0), on one thread; then the values at 10^7 random points (the splitmix64 points
// of experiments/examples/values.rs) through one ValueAccessor (OpenVDB's cached accessor).
// The dense array is given to OpenVDB in its own default layout (ZYX, z fastest: copied before timing)
// when LAYOUT is zyx, or as it is in the file (LayoutXYZ) when xyz.
// Prints key=value lines: seconds (best of R), active (active voxels), mem_bytes (Grid::memUsage after
// the prune), query_seconds (best of R), checksum (the sum of the values, 0 where inactive).
//
//   peers labels|density L FILE xyz|zyx R
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/Prune.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <vector>

static std::vector<openvdb::Coord> points(int level) {
  uint64_t state = 0x9E3779B97F4A7C15ull;
  const uint64_t mask = (uint64_t(1) << level) - 1;
  std::vector<openvdb::Coord> out;
  out.reserve(10000000);
  for (int i = 0; i < 10000000; ++i) {
    state += 0x9E3779B97F4A7C15ull;
    uint64_t z = state;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    out.emplace_back(int(z & mask), int((z >> 21) & mask), int((z >> 42) & mask));
  }
  return out;
}

template <typename GridT, openvdb::tools::MemoryLayout Layout>
static void run(int level, std::vector<typename GridT::ValueType>& data, int repeats) {
  using V = typename GridT::ValueType;
  const int u = 1 << level;
  const openvdb::CoordBBox box(openvdb::Coord(0), openvdb::Coord(u - 1));
  openvdb::tools::Dense<V, Layout> dense(box, data.data());
  double best = 1e300;
  typename GridT::Ptr grid;
  for (int r = 0; r < repeats; ++r) {
    grid.reset();
    auto start = std::chrono::steady_clock::now();
    typename GridT::Ptr g = GridT::create(V(0));
    openvdb::tools::copyFromDense(dense, *g, V(0), /*serial=*/true);
    openvdb::tools::prune(g->tree(), V(0), /*threaded=*/false);
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    grid = g;
  }
  std::printf("seconds=%.9f\nactive=%llu\nmem_bytes=%llu\n", best,
              (unsigned long long)grid->activeVoxelCount(), (unsigned long long)grid->memUsage());
  std::vector<typename GridT::ValueType>().swap(data);
  const std::vector<openvdb::Coord> pts = points(level);
  best = 1e300;
  double checksum = 0;
  for (int r = 0; r < repeats; ++r) {
    auto start = std::chrono::steady_clock::now();
    typename GridT::ConstAccessor acc = grid->getConstAccessor();
    double sum = 0;
    for (const openvdb::Coord& p : pts) sum += double(acc.getValue(p));
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    checksum = sum;
  }
  std::printf("query_seconds=%.9f\nchecksum=%.10g\n", best, checksum);
}

template <typename GridT>
static void load_and_run(int level, const char* file, bool zyx, int repeats) {
  using V = typename GridT::ValueType;
  const size_t u = size_t(1) << level;
  std::vector<V> data(u * u * u);
  std::ifstream in(file, std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(data.data()), std::streamsize(data.size() * sizeof(V)))) {
    std::fprintf(stderr, "%s: cannot read %zu values\n", file, data.size());
    std::exit(1);
  }
  if (zyx) {
    std::vector<V> t(data.size());
    for (size_t z = 0; z < u; ++z)
      for (size_t y = 0; y < u; ++y)
        for (size_t x = 0; x < u; ++x) t[z + u * (y + u * x)] = data[x + u * (y + u * z)];
    data.swap(t);
    run<GridT, openvdb::tools::LayoutZYX>(level, data, repeats);
  } else {
    run<GridT, openvdb::tools::LayoutXYZ>(level, data, repeats);
  }
}

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr, "usage: peers labels|density L FILE xyz|zyx R\n");
    return 2;
  }
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  openvdb::initialize();
  const bool labels = std::strcmp(argv[1], "labels") == 0;
  const int level = std::atoi(argv[2]);
  const bool zyx = std::strcmp(argv[4], "zyx") == 0;
  const int repeats = std::atoi(argv[5]);
  if (labels)
    load_and_run<openvdb::Int32Grid>(level, argv[3], zyx, repeats);
  else
    load_and_run<openvdb::FloatGrid>(level, argv[3], zyx, repeats);
  return 0;
}
