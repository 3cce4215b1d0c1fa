//! OctoMap's `ColorOcTree` files against liboctomap both ways: OctoMap colours a map of synthetic scans
//! (`setNodeColor`, `integrateNodeColor`, `averageNodeColor`, `updateInnerOccupancy`) and writes it; ktree
//! reads the same voxels, log-odds and leaf colours. ktree writes a coloured map (leaves split where
//! colours differ); OctoMap reads the same leaves and colours, and its `updateInnerOccupancy` leaves the
//! inner nodes ktree wrote unchanged.

use std::process::Command;

use ktree::io::{read_color_ot_map, write_color_ot_map};
use ktree::map::{tree_from_leaves, OccupancyMap, MAP_LEVEL};
use ktree::space::morton_encode;
use ktree::value::Rgb;
use ktree::KTree;

use super::{leaves_tree, octomap_program, room_scans, run_with_input, scans_text};

/// OctoMap's "no colour".
const WHITE: Rgb = [255; 3];

/// The lines of a checker's output that start with `what`, each without its first word.
fn lines<'a>(text: &'a str, what: &'a str) -> impl Iterator<Item = &'a str> + 'a {
    text.lines()
        .filter_map(move |l| l.strip_prefix(what)?.strip_prefix(' '))
}

/// The log-odds and colours of a checker's `leaf kx ky kz side bits r g b` lines: the log-odds as a
/// valued tree, and the leaves whose colour is set (not white) as a colour tree.
fn coloured_leaves(text: &str) -> (KTree<3, f32>, KTree<3, Rgb>) {
    let mut log_odds = String::new();
    let mut colours = Vec::new();
    for line in lines(text, "leaf") {
        let f: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(f.len(), 8, "{line}");
        log_odds += &format!("leaf {}\n", f[..5].join(" "));
        let k: Vec<u32> = f[..4].iter().map(|s| s.parse().unwrap()).collect();
        let c: Vec<u8> = f[5..].iter().map(|s| s.parse().unwrap()).collect();
        let c = [c[0], c[1], c[2]];
        if c != WHITE {
            colours.push((morton_encode([k[0], k[1], k[2]]), k[3].trailing_zeros(), c));
        }
    }
    colours.sort_unstable_by_key(|l: &(u64, u32, Rgb)| l.0);
    (
        leaves_tree(&log_odds),
        tree_from_leaves(MAP_LEVEL, &colours).unwrap(),
    )
}

#[test]
fn octomaps_colour_files_read_in_ktree_with_every_leaf_colour() {
    let dir = tempfile::tempdir().unwrap();
    let Some(exe) = octomap_program(dir.path(), "octomap_colours") else {
        return;
    };
    let scans = room_scans();
    let ot = dir.path().join("octomap.ot");
    let mut cmd = Command::new(&exe);
    cmd.args(["write", "0.1"]).arg(&ot);
    let printed = run_with_input(&mut cmd, scans_text(&scans));
    let (their_log_odds, their_colours) = coloured_leaves(&printed);
    let mut map = OccupancyMap::<3>::new(0.1).unwrap();
    for (points, origin) in &scans {
        map.insert(points, *origin, None).unwrap();
    }
    let (read, colours) =
        read_color_ot_map(&std::fs::read(&ot).unwrap(), "octomap.ot", *map.model()).unwrap();
    assert_eq!(read.log_odds(), &their_log_odds);
    assert_eq!(read, map);
    assert_eq!(colours, their_colours);
    // Every occupied voxel is coloured; some free ones are.
    let coloured = colours.shape();
    assert_eq!((&map.occupied() - &coloured).unwrap().voxel_count(), 0);
    let free_coloured = (&map.free() & &coloured).unwrap().voxel_count();
    assert!(free_coloured > 0 && free_coloured < map.free().voxel_count());
}

#[test]
fn colour_files_written_by_ktree_read_in_octomap_with_the_same_leaves_and_inner_nodes() {
    let dir = tempfile::tempdir().unwrap();
    let Some(exe) = octomap_program(dir.path(), "octomap_colours") else {
        return;
    };
    let mut map = OccupancyMap::<3>::new(0.1).unwrap();
    for (points, origin) in &room_scans() {
        map.insert(points, *origin, None).unwrap();
    }
    // Occupied voxels coloured by their keys, free ones in two colours by a coarse checkerboard (so that
    // large free leaves split), a few free voxels uncoloured.
    let colour_of = |k: [u32; 3], occupied: bool| -> Option<Rgb> {
        if occupied {
            Some([
                (k[0] % 251) as u8,
                (k[1] % 241) as u8,
                (k[2] * 7 % 239) as u8,
            ])
        } else if k[2].is_multiple_of(9) {
            None
        } else if (k[0] / 4 + k[1] / 4 + k[2] / 4).is_multiple_of(2) {
            Some([30, 60, 90])
        } else {
            Some([0, 0, 0])
        }
    };
    let model = *map.model();
    let mut leaves = Vec::new();
    for (cell, l) in map.log_odds().value_leaves() {
        let Some(l) = l else { continue };
        let (o, side) = (cell.origin(), 1u32 << cell.log_side());
        // Leaves up to 2^12 voxels are coloured voxel by voxel; larger ones keep no colour.
        if side > 16 {
            continue;
        }
        for x in o[0]..o[0] + side {
            for y in o[1]..o[1] + side {
                for z in o[2]..o[2] + side {
                    if let Some(c) = colour_of([x, y, z], model.is_occupied(l)) {
                        leaves.push((morton_encode([x, y, z]), 0, c));
                    }
                }
            }
        }
    }
    leaves.sort_unstable_by_key(|l: &(u64, u32, Rgb)| l.0);
    let colours = tree_from_leaves::<3, Rgb>(MAP_LEVEL, &leaves).unwrap();
    assert!(colours.shape().voxel_count() > map.occupied().voxel_count());
    let ot = dir.path().join("ktree.ot");
    let mut bytes = Vec::new();
    write_color_ot_map(&mut bytes, &map, &colours).unwrap();
    std::fs::write(&ot, &bytes).unwrap();
    let out = Command::new(&exe).arg("read").arg(&ot).output().unwrap();
    assert!(out.status.success(), "OctoMap reads {}", ot.display());
    let text = String::from_utf8(out.stdout).unwrap();
    let (their_log_odds, their_colours) = coloured_leaves(&text);
    assert_eq!(&their_log_odds, map.log_odds());
    assert_eq!(their_colours, colours);
    // The inner nodes ktree wrote are what OctoMap's updateInnerOccupancy makes of their children.
    let inner: Vec<&str> = lines(&text, "inner").collect();
    let updated: Vec<&str> = lines(&text, "updated").collect();
    assert!(inner.len() > 100, "{} inner nodes", inner.len());
    assert_eq!(inner, updated);
    // And ktree reads back what it wrote.
    let (back, back_colours) = read_color_ot_map(&bytes, "ktree.ot", model).unwrap();
    assert_eq!((back, back_colours), (map, colours));
}
