// OpenVDB's side of ktree's shape operations (results/performance/shape.md, experiments/shape.sh), on the
// voxels ktree wrote (`perf --child shape OBJECT:write-inputs:DIR`: DIR/tree.vdb, a BoolGrid named
// "ktree", index = ktree voxel), on one thread:
//
//   peers morph  DIR dilate|erode box|cross R SIDE  tools::dilateActiveValues / erodeActiveValues on a
//                                                   MaskTree, R iterations of NN_FACE_EDGE_VERTEX (box) or
//                                                   NN_FACE (cross)
//   peers offset DIR dilate|erode R SIDE            tools::topologyToLevelSet (half-width 3, no closing),
//                                                   then LevelSetFilter::offset by -R (dilate) or R (erode)
//   peers band   DIR W SIDE                         tools::topologyToLevelSet of half-width W, no closing
//
// SIDE is the universe's side U: the results are clipped to [0, U)^3 before they are counted, as ktree's
// are (a dilation never reaches outside the universe there; an erosion counts the outside as empty, which
// OpenVDB's inactive background already is). Prints `key=value` lines as ktree's perf child does:
// `seconds` (best of REPEATS, default 3, in this process; reading the grid and copying it are not timed),
// `voxels` (active voxels of the result, or interior voxels of the offset level set), `peak_bytes` (VmHWM),
// `rss_loaded` (VmRSS once the grid is read), `tree_bytes_in` / `tree_bytes` (Tree::memUsage of the input
// mask and of the result), and for `offset` `levelset_seconds` (the level set alone), for `band` `band`
// and `band_inside` (active voxels, those with a negative value).
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/TopologyToLevelSet.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// A field of /proc/self/status (VmHWM, VmRSS), in bytes.
unsigned long long status_bytes(const std::string& field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::strtoull(line.c_str() + field.size() + 1, nullptr, 10) * 1024;
  }
  return 0;
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

template <typename TreeT>
uint64_t clipped_count(TreeT& tree, int side) {
  tree.clip(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(side - 1)));
  return tree.activeVoxelCount();
}

int positive(const char* s, const char* what) {
  const int v = std::atoi(s);
  if (v < 0) throw std::runtime_error(std::string("bad ") + what + ": " + s);
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 5) {
      std::fprintf(stderr, "usage: peers morph|offset|band DIR ...\n");
      return 2;
    }
    const std::string tool = argv[1], dir = argv[2];
    const int repeats = std::getenv("REPEATS") ? std::max(1, std::atoi(std::getenv("REPEATS"))) : 3;
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    openvdb::initialize();
    const auto grid = read_vdb(dir + "/tree.vdb");
    const openvdb::MaskTree input(grid->tree(), false, openvdb::TopologyCopy());
    const unsigned long long loaded = status_bytes("VmRSS");
    double best = std::numeric_limits<double>::infinity();
    uint64_t voxels = 0, tree_bytes = 0;
    std::string extra;
    if (tool == "morph" && argc == 7) {
      const std::string op = argv[3], element = argv[4];
      const int r = positive(argv[5], "radius"), side = positive(argv[6], "side");
      if (element != "box" && element != "cross") throw std::runtime_error("element must be box or cross");
      if (op != "dilate" && op != "erode") throw std::runtime_error("op must be dilate or erode");
      const auto nn = element == "box" ? openvdb::tools::NN_FACE_EDGE_VERTEX : openvdb::tools::NN_FACE;
      for (int i = 0; i < repeats; ++i) {
        openvdb::MaskTree tree(input);
        const auto start = Clock::now();
        if (op == "dilate") {
          openvdb::tools::dilateActiveValues(tree, r, nn, openvdb::tools::PRESERVE_TILES);
        } else {
          openvdb::tools::erodeActiveValues(tree, r, nn, openvdb::tools::PRESERVE_TILES);
        }
        best = std::min(best, since(start));
        tree_bytes = tree.memUsage();
        voxels = clipped_count(tree, side);
      }
    } else if (tool == "offset" && argc == 6) {
      const std::string op = argv[3];
      const int r = positive(argv[4], "radius"), side = positive(argv[5], "side");
      if (op != "dilate" && op != "erode") throw std::runtime_error("op must be dilate or erode");
      double best_ls = std::numeric_limits<double>::infinity();
      for (int i = 0; i < repeats; ++i) {
        openvdb::MaskGrid mask(openvdb::MaskTree::Ptr(new openvdb::MaskTree(input)));
        const auto start = Clock::now();
        auto ls = openvdb::tools::topologyToLevelSet(mask, 3, 0, 0, 0);
        best_ls = std::min(best_ls, since(start));
        openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(*ls);
        filter.offset(op == "dilate" ? -float(r) : float(r));
        best = std::min(best, since(start));
        tree_bytes = ls->tree().memUsage();
        auto interior = openvdb::tools::sdfInteriorMask(*ls);
        voxels = clipped_count(interior->tree(), side);
      }
      extra = "levelset_seconds=" + std::to_string(best_ls) + "\n";
    } else if (tool == "band" && argc == 5) {
      const int w = positive(argv[3], "width"), side = positive(argv[4], "side");
      for (int i = 0; i < repeats; ++i) {
        openvdb::MaskGrid mask(openvdb::MaskTree::Ptr(new openvdb::MaskTree(input)));
        const auto start = Clock::now();
        auto ls = openvdb::tools::topologyToLevelSet(mask, w, 0, 0, 0);
        best = std::min(best, since(start));
        tree_bytes = ls->tree().memUsage();
        ls->tree().clip(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(side - 1)));
        uint64_t band = 0, inside = 0;
        for (auto it = ls->tree().cbeginValueOn(); it; ++it) {
          const uint64_t n = it.getVoxelCount();
          band += n;
          if (*it < 0) inside += n;
        }
        voxels = band;
        extra = "band=" + std::to_string(band) + "\nband_inside=" + std::to_string(inside) + "\n";
      }
    } else {
      throw std::runtime_error("unknown tool or wrong arguments: " + tool);
    }
    std::printf("seconds=%.9f\nvoxels=%llu\npeak_bytes=%llu\nrss_loaded=%llu\ntree_bytes_in=%llu\ntree_bytes=%llu\n%s",
                best, static_cast<unsigned long long>(voxels), status_bytes("VmHWM"), loaded,
                static_cast<unsigned long long>(input.memUsage()), static_cast<unsigned long long>(tree_bytes),
                extra.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "peers: %s\n", e.what());
    return 1;
  }
}
