// Reads the first grid of a file, a level set, with OpenVDB and prints what OpenVDB makes of it:
//   class <grid class> background <b> active <n> interior <m>
// followed by one line "x y z" per interior voxel of tools::sdfInteriorMask (OpenVDB's own reading of the
// inside of a level set: values below zero, active or not, tiles included).
//
//   vdb_level_set_check FILE.vdb                                   the report
//   vdb_level_set_check FILE.vdb level-set OUT.vdb FLAGS [double] [half]
//       the report, and the level set written again by OpenVDB with the compression flags FLAGS (0 none,
//       1 zip, 2 active mask, 4 Blosc, or a sum), as a DoubleGrid with `double`, with half floats with `half`
//   vdb_level_set_check FILE.vdb mask OUT.vdb FLAGS
//       the report, and sdfInteriorMask's BoolGrid written with the compression flags FLAGS
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <cstdlib>
#include <iostream>
#include <string>

template <typename GridT>
static void writeOne(const std::string& path, typename GridT::Ptr grid, unsigned flags, bool half) {
    grid->setSaveFloatAsHalf(half);
    openvdb::io::File out(path);
    out.setCompression(flags);
    out.write(openvdb::GridPtrVec{grid});
    out.close();
}

int main(int argc, char** argv) {
    if (argc != 2 && argc < 5) {
        std::cerr << "usage: vdb_level_set_check FILE.vdb [level-set|mask OUT.vdb FLAGS [double] [half]]\n";
        return 2;
    }
    openvdb::initialize();
    openvdb::io::File file(argv[1]);
    file.open();
    openvdb::GridBase::Ptr base = file.readGrid(file.beginName().gridName());
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
    if (argc == 2) return 0;
    const std::string what = argv[2], out = argv[3];
    const unsigned flags = unsigned(std::strtoul(argv[4], nullptr, 10));
    bool asDouble = false, half = false;
    for (int i = 5; i < argc; ++i) {
        const std::string option = argv[i];
        if (option == "double") asDouble = true;
        else if (option == "half") half = true;
        else { std::cerr << "unknown option " << option << "\n"; return 2; }
    }
    if (what == "mask") {
        mask->setName("interior");
        writeOne<openvdb::BoolGrid>(out, mask, flags, false);
    } else if (what == "level-set" && !asDouble) {
        writeOne<openvdb::FloatGrid>(out, grid, flags, half);
    } else if (what == "level-set") {
        // The same values, active states and tiles in a DoubleGrid.
        auto d = openvdb::DoubleGrid::create(double(grid->background()));
        auto acc = d->getAccessor();
        for (auto it = grid->cbeginValueAll(); it; ++it) {
            if (it.isVoxelValue()) {
                acc.setValue(it.getCoord(), double(*it));
                acc.setActiveState(it.getCoord(), it.isValueOn());
            } else {
                d->tree().addTile(it.getLevel(), it.getCoord(), double(*it), it.isValueOn());
            }
        }
        d->setGridClass(openvdb::GRID_LEVEL_SET);
        d->setTransform(grid->transform().copy());
        d->setName(grid->getName());
        writeOne<openvdb::DoubleGrid>(out, d, flags, half);
    } else {
        std::cerr << "unknown mode " << what << "\n";
        return 2;
    }
    return 0;
}
