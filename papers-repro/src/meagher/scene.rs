//! Fig. 9 and Fig. 10–11 (claims M11, M12): five objects of about 1 200 nodes, and the milling scene with a
//! channel machined out by subtracting the tool bit swept along a path.

use std::fmt::Write as _;
use std::time::Instant;

use super::solids::{ball, cuboid, cylinder};
use super::Out;
use ktree::ops::{self, Affine};
use ktree::tree::storage::infallible;
use ktree::tree::KTree;

/// Universe level of the milling scene (256³).
pub const MILL_LEVEL: u32 = 8;
/// The tool's x positions along the path: from `PATH.0` to `PATH.1` in steps of one voxel.
pub const PATH: (u32, u32) = (72, 184);

struct Tool {
    bit: KTree<3>,
    shaft: KTree<3>,
    holder: KTree<3>,
}

/// The tool at x = `x0` (y = 128): a ball-end bit (cylinder of radius 12 with a ball of radius 12 at its
/// bottom, z = 48), a shaft of radius 8 from z = 100 to 160, and a box holder above.
fn tool(x0: u32) -> Result<Tool, String> {
    let l = MILL_LEVEL;
    let c2 = [2 * i64::from(x0), 256, 96];
    let body = cylinder(l, 2, c2, 24, (48, 100))?;
    let tip = ball(l, c2, 24)?;
    let bit = ops::union(&body, &tip).map_err(|e| e.to_string())?;
    let shaft = cylinder(l, 2, c2, 16, (100, 160))?;
    let holder = cuboid(l, [x0 - 24, 104, 160], [x0 + 24, 152, 224])?;
    Ok(Tool { bit, shaft, holder })
}

fn row(md: &mut String, csv: &mut String, name: &str, paper: &str, tree: &KTree<3>, note: &str) {
    let _ = writeln!(
        md,
        "| {name} | {paper} | {} | {} | {} | {note} |",
        tree.node_count(),
        tree.bytes_at_two_bits(),
        tree.voxel_count()
    );
    let _ = writeln!(
        csv,
        "{name},{paper},{},{},{}",
        tree.node_count(),
        tree.bytes_at_two_bits(),
        tree.voxel_count()
    );
}

/// The milling scene: table of node counts, the channel, timings; returns the README section and the
/// machined scene (workpiece after the cut, clamp and the tool at the path's end) as one tree.
pub fn milling(out: &Out) -> Result<(String, KTree<3>), String> {
    let l = MILL_LEVEL;
    let workpiece = cuboid(l, [32, 64, 0], [224, 192, 64])?;
    // Clamp: two jaws gripping the workpiece's ends and a bar across them, not aligned to large cells.
    let jaw1 = cuboid(l, [20, 84, 0], [32, 172, 76])?;
    let jaw2 = cuboid(l, [224, 84, 0], [236, 172, 76])?;
    let clamp = ops::union(&jaw1, &jaw2).map_err(|e| e.to_string())?;
    let start = tool(PATH.0)?;
    let mut md = String::new();
    let mut csv = String::from("object,paper_nodes,nodes,bytes_at_2_bits,voxels\n");
    let _ = writeln!(
        md,
        "### (a) Milling scene (Fig. 10–11, M12)\n\nUniverse 256³ (L = {l}), z up. Workpiece: the box \
         [32, 224) × [64, 192) × [0, 64). Clamp: two jaws [20, 32) and [224, 236) × [84, 172) × [0, 76). Tool \
         at x = {}, y = 128: bit = cylinder of radius 12 for 48 ≤ z < 100 ∪ ball of radius 12 centred at \
         z = 48 (a ball-end mill); shaft = cylinder of radius 8 for 100 ≤ z < 160; holder = box 48 × 48 × 64. \
         All by exact voxel-centre tests with the library's solids (`ktree::solid`: `BoxSolid`, `Quadric::ball`, \
         `Quadric::cylinder` cut by a box with CSG on rays), then tree Booleans (`ktree::ops`). Dimensions are \
         ours — the paper gives only counts — and were *not* tuned to match them.\n",
        PATH.0
    );
    let _ = writeln!(
        md,
        "| object | paper nodes | our nodes | our bytes at 2 bits/node | voxels | note |\n|---|---:|---:|---:|---:|---|"
    );
    row(
        &mut md,
        &mut csv,
        "workpiece",
        "40",
        &workpiece,
        "axis-aligned box",
    );
    row(
        &mut md,
        &mut csv,
        "clamp",
        "200",
        &clamp,
        "two boxes, edges off the coarse grid",
    );
    row(
        &mut md,
        &mut csv,
        "tool bit",
        "7 432",
        &start.bit,
        "curved: most of the scene's nodes",
    );
    row(
        &mut md,
        &mut csv,
        "shaft",
        "40",
        &start.shaft,
        "ours is round; the paper's count suggests a box",
    );
    row(&mut md, &mut csv, "holder", "40", &start.holder, "box");
    let total: u64 = [&workpiece, &clamp, &start.bit, &start.shaft, &start.holder]
        .iter()
        .map(|t| t.node_count())
        .sum();
    let _ = writeln!(
        md,
        "| **all five** | 7 752 (< 2 000 bytes) | {total} | {} | | |",
        total.div_ceil(4)
    );

    // The channel: the bit swept along x by translation (union of translated copies), subtracted.
    let t0 = Instant::now();
    let mut swept = start.bit.clone();
    for dx in 1..=(PATH.1 - PATH.0) {
        let moved = infallible(ops::translate(&start.bit, [i64::from(dx), 0, 0]));
        swept = ops::union(&swept, &moved).map_err(|e| e.to_string())?;
    }
    let sweep_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let machined = ops::difference(&workpiece, &swept).map_err(|e| e.to_string())?;
    let diff_s = t1.elapsed().as_secs_f64();
    machined.assert_well_formed();
    let removed = workpiece.voxel_count() - machined.voxel_count();
    let end = tool(PATH.1)?;
    let collides = ops::interferes(&end.bit, &machined).map_err(|e| e.to_string())?;
    let holder_hits = ops::interferes(&end.holder, &machined).map_err(|e| e.to_string())?;
    let next = ops::interferes(&tool(PATH.1 + 1)?.bit, &machined).map_err(|e| e.to_string())?;
    let _ = writeln!(
        md,
        "\nMachining (Fig. 11):\n\n| object | paper nodes | our nodes | our bytes at 2 bits/node | voxels | note |\n|---|---:|---:|---:|---:|---|"
    );
    row(
        &mut md,
        &mut csv,
        "swept bit",
        "—",
        &swept,
        &format!("{} translated copies united", PATH.1 - PATH.0 + 1),
    );
    row(
        &mut md,
        &mut csv,
        "machined workpiece",
        "—",
        &machined,
        "workpiece ∖ swept bit (Fig. 11)",
    );
    let _ = writeln!(
        md,
        "\nThe channel removes {removed} voxels. Sweeping (translations by overlays + unions) took {sweep_s:.3} s, \
         the subtraction {diff_s:.4} s. Interference checks on the result (M14): the bit at the path's end \
         overlaps the machined workpiece: {collides} (expected false — its volume was removed); the holder: \
         {holder_hits} (expected false — it is above the workpiece); the bit one voxel further along x: \
         {next} (expected true — it bites fresh material).\n"
    );
    if collides || holder_hits || !next {
        return Err(
            "the tool interferes with the machined workpiece: the sweep or subtraction is wrong"
                .into(),
        );
    }
    let _ = writeln!(
        md,
        "Differences from the paper: the shapes are our guesses at Fig. 10 at a resolution the paper does not \
         state, so only orders of magnitude compare. The workpiece ({}) and holder ({}) are boxes like \
         Meagher's 40-node ones; they cost more because their faces are not all on multiples of large powers \
         of two. Our clamp ({}) costs 16× the paper's 200 because its faces (x = 20, 236; y = 84, 172; \
         z = 76) are deliberately off the coarse grid. Our shaft is round ({} nodes), which suggests Meagher's \
         40-node shaft was a grid-aligned box. The round bit is the largest object in both ({} vs 7 432). \
         In all, our scene needs {} bytes at 2 bits a node against the paper's < 2 000.",
        workpiece.node_count(),
        start.holder.node_count(),
        clamp.node_count(),
        start.shaft.node_count(),
        start.bit.node_count(),
        total.div_ceil(4)
    );
    out.write("milling.csv", &csv)?;
    let mut scene = ops::union(&machined, &clamp).map_err(|e| e.to_string())?;
    for part in [&end.bit, &end.shaft, &end.holder] {
        scene = ops::union(&scene, part).map_err(|e| e.to_string())?;
    }
    scene.assert_well_formed();
    Ok((md, scene))
}

/// Bisection on an integer size parameter so that `count(size)` is as close as possible to `target`,
/// assuming the count grows with the size.
fn closest(
    lo: i64,
    hi: i64,
    target: u64,
    count: impl Fn(i64) -> Result<u64, String>,
) -> Result<(i64, u64), String> {
    let mut best = (lo, count(lo)?);
    for s in lo..=hi {
        let c = count(s)?;
        if c.abs_diff(target) < best.1.abs_diff(target) {
            best = (s, c);
        }
        if c > target * 2 {
            break;
        }
    }
    Ok(best)
}

/// Fig. 9 (M11): five disjoint objects of about 1 200 nodes each.
pub fn five_objects(out: &Out) -> Result<String, String> {
    let l = 6;
    let centre = Affine::<3>::universe_centre(l);
    let sphere = |r: i64| ball(l, [64, 64, 64], r);
    let cyl = |r: i64| cylinder(l, 0, [64, 64, 64], r, (20, 44));
    let cube = |s: i64| -> Result<KTree<3>, String> {
        let s = s as u32;
        let b = cuboid(l, [32 - s, 32 - s, 32 - s], [32 + s, 32 + s, 32 + s])?;
        let m = Affine::rotation_about(0, 1, 30.0, centre)
            .and_then(|r| Ok(Affine::rotation_about(1, 2, 20.0, centre)?.after(&r)))
            .map_err(|e| e.to_string())?;
        ops::transform(&b, &m).map_err(|e| e.to_string())
    };
    let ring = |r: i64| -> Result<KTree<3>, String> {
        let outer = cylinder(l, 2, [64, 64, 64], r, (26, 38))?;
        let inner = cylinder(l, 2, [64, 64, 64], r / 2, (26, 38))?;
        ops::difference(&outer, &inner).map_err(|e| e.to_string())
    };
    let lens = |r: i64| -> Result<KTree<3>, String> {
        let a = ball(l, [64 - r / 2, 64, 64], r)?;
        let b = ball(l, [64 + r / 2, 64, 64], r)?;
        ops::intersection(&a, &b).map_err(|e| e.to_string())
    };
    type Maker<'a> = Box<dyn Fn(i64) -> Result<KTree<3>, String> + 'a>;
    let makers: Vec<(&str, &str, Maker)> = vec![
        ("sphere", "radius (half-voxels)", Box::new(sphere)),
        (
            "cylinder (along x, length 24)",
            "radius (half-voxels)",
            Box::new(cyl),
        ),
        (
            "cube rotated 30° about z, 20° about x",
            "half side (voxels)",
            Box::new(cube),
        ),
        (
            "ring (cylinder minus cylinder, height 12)",
            "outer radius (half-voxels)",
            Box::new(ring),
        ),
        (
            "lens (intersection of two balls)",
            "ball radius (half-voxels)",
            Box::new(lens),
        ),
    ];
    let mut md = String::new();
    let mut csv = String::from("object,size,nodes,bytes_at_2_bits\n");
    let _ = writeln!(
        md,
        "### (b) Five objects of about 1 200 nodes (Fig. 9, M11)\n\nUniverse 64³ (L = {l}). Each object's size \
         is **tuned**: the paper gives only the node counts, so we searched the size parameter whose count is \
         closest to 1 200. What is being reproduced is that objects of this complexity take ≈ 300 bytes at \
         2 bits a node and are recognisable shapes. Built with our Booleans and affine rotation.\n\n\
         | object | size parameter | paper nodes | our nodes | paper bytes | our bytes at 2 bits/node |\n|---|---|---:|---:|---:|---:|"
    );
    for (name, param, make) in &makers {
        let (size, nodes) = closest(2, 64, 1200, |s| Ok(make(s)?.node_count()))?;
        let t = make(size)?;
        t.assert_well_formed();
        let _ = writeln!(
            md,
            "| {name} | {param} = {size} | ≈ 1 200 | {nodes} | ≈ 300 | {} |",
            t.bytes_at_two_bits()
        );
        let _ = writeln!(csv, "{name},{size},{nodes},{}", t.bytes_at_two_bits());
    }
    let _ = writeln!(
        md,
        "\nNode counts move in steps as the size changes by one unit, so \"closest to 1 200\" can be off by \
         some tens; bytes are nodes / 4 exactly, as in the paper."
    );
    out.write("five_objects.csv", &csv)?;
    Ok(md)
}
