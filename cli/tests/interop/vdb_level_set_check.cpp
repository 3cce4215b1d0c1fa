// Reads a level set written by `ktree distance` with OpenVDB and prints what OpenVDB makes of it:
//   class <grid class> background <b> active <n> interior <m>
// followed by one line "x y z" per interior voxel of tools::sdfInteriorMask (OpenVDB's own reading of the
// inside of a level set: values below zero, active or not, tiles included).
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <iostream>

int main(int argc, char** argv) {
    if (argc != 2) { std::cerr << "usage: vdb_level_set_check FILE.vdb\n"; return 2; }
    openvdb::initialize();
    openvdb::io::File file(argv[1]);
    file.open();
    openvdb::GridBase::Ptr base = file.readGrid("ktree");
    file.close();
    auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid) { std::cerr << "not a FloatGrid\n"; return 1; }
    auto mask = openvdb::tools::sdfInteriorMask(*grid);
    std::cout << "class " << openvdb::GridBase::gridClassToString(grid->getGridClass())
              << "\nbackground " << grid->background() << "\nactive " << grid->activeVoxelCount()
              << "\ninterior " << mask->activeVoxelCount() << "\n";
    for (auto it = mask->cbeginValueOn(); it; ++it) {
        openvdb::CoordBBox box;
        it.getBoundingBox(box);
        for (auto c = box.begin(); c; ++c) {
            std::cout << (*c)[0] << " " << (*c)[1] << " " << (*c)[2] << "\n";
        }
    }
    return 0;
}
