// OpenVDB's own reading and writing of an Int32Grid (labels), for the typed grids ktree reads and writes.
//
//   vdb_values_check FILE.vdb
//       reads the first grid of FILE as an Int32Grid and prints
//         type <grid type> class <grid class> active <n>
//       then one line "x y z value tile" per active voxel, a tile's voxels each on its own line with tile 1
//   vdb_values_check --write VOXELS.txt OUT.vdb
//       an Int32Grid (background 0) of the lines "x y z value" of VOXELS.txt, pruned (equal active voxels
//       of a node into a tile), written with OpenVDB's default compression; prints "active <n> tiles <m>"
#include <openvdb/openvdb.h>
#include <openvdb/tools/Prune.h>
#include <fstream>
#include <iostream>
#include <string>

static int list(const std::string& path) {
    openvdb::io::File file(path);
    file.open();
    openvdb::GridBase::Ptr base = file.readGrid(file.beginName().gridName());
    file.close();
    auto grid = openvdb::gridPtrCast<openvdb::Int32Grid>(base);
    if (!grid) {
        std::cerr << "not an Int32Grid: " << base->type() << "\n";
        return 1;
    }
    std::cout << "type " << grid->type() << " class "
              << openvdb::GridBase::gridClassToString(grid->getGridClass()) << " active "
              << grid->activeVoxelCount() << "\n";
    for (auto it = grid->cbeginValueOn(); it; ++it) {
        openvdb::CoordBBox box;
        it.getBoundingBox(box);
        const int tile = it.isTileValue() ? 1 : 0;
        for (auto c = box.begin(); c; ++c) {
            std::cout << (*c)[0] << " " << (*c)[1] << " " << (*c)[2] << " " << *it << " " << tile << "\n";
        }
    }
    return 0;
}

static int write(const std::string& voxels, const std::string& path) {
    auto grid = openvdb::Int32Grid::create(0);
    grid->setName("labels");
    auto access = grid->getAccessor();
    std::ifstream in(voxels);
    int x, y, z, v;
    while (in >> x >> y >> z >> v) access.setValue(openvdb::Coord(x, y, z), v);
    openvdb::tools::prune(grid->tree());
    openvdb::Index64 tiles = 0;
    for (auto it = grid->cbeginValueOn(); it; ++it) tiles += it.isTileValue() ? 1 : 0;
    openvdb::io::File out(path);
    out.write(openvdb::GridPtrVec{grid});
    out.close();
    std::cout << "active " << grid->activeVoxelCount() << " tiles " << tiles << "\n";
    return 0;
}

int main(int argc, char** argv) {
    openvdb::initialize();
    if (argc == 2) return list(argv[1]);
    if (argc == 4 && std::string(argv[1]) == "--write") return write(argv[2], argv[3]);
    std::cerr << "usage: vdb_values_check FILE.vdb | vdb_values_check --write VOXELS.txt OUT.vdb\n";
    return 2;
}
