//! The embedded default object: a 1/8 sphere like Akman & Franklin's (a ball centred at a corner of the
//! universe, clipped to it), built by stacking; its statistics are written to
//! `results/default-object/stats.md` and `stats.json`.

use std::fmt::Write as _;
use std::path::Path;

use ktree::fs::write_atomic;
use ktree::rays::ball_rays;
use ktree::stacking::paper::stack_with_stats;

/// Universe level of the default object.
pub const LEVEL: u32 = 5;
/// Radius in voxels of the default object's ball, centred at the origin corner.
pub const RADIUS: i64 = 32;

/// Builds the default object, writes its statistics, and returns them as text.
///
/// # Errors
/// When the results cannot be written.
pub fn run(results: &Path) -> Result<String, String> {
    let rays = ball_rays::<3>(LEVEL, [0, 0, 0], 2 * RADIUS).map_err(|e| e.to_string())?;
    let (tree, stats) = stack_with_stats(&rays);
    tree.check().map_err(|e| e.to_string())?;
    let counts = tree.counts();
    let mut md = String::new();
    let _ = writeln!(md, "# Default object: a 1/8 sphere\n");
    let _ = writeln!(
        md,
        "Voxels whose centres lie in the ball of radius {RADIUS} centred at the corner (0, 0, 0) of a \
         level-{LEVEL} octree universe (side {}), as rays along z, stacked into an octree.\n",
        1u32 << LEVEL
    );
    let _ = writeln!(md, "| quantity | value |\n|---|---:|");
    for (name, value) in [
        ("rays", rays.len() as u64),
        ("voxels", rays.voxel_count() as u64),
        ("maximal rows", stats.maximal_rows),
        ("nodes (obels)", tree.node_count()),
        ("full", counts.full),
        ("empty", counts.empty),
        ("partial", counts.partial),
        ("bytes at 2 bits/node", tree.bytes_at_two_bits()),
        ("dimension-level lists used", stats.lists_used() as u64),
        (
            "dimension-level lists available",
            stats.lists_available() as u64,
        ),
    ] {
        let _ = writeln!(md, "| {name} | {value} |");
    }
    let _ = writeln!(
        md,
        "\nNodes per level:\n\n| level | full | empty | partial |\n|---:|---:|---:|---:|"
    );
    for c in tree.counts_per_level() {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} |",
            c.level, c.full, c.empty, c.partial
        );
    }
    let _ = writeln!(
        md,
        "\nThe paper's 1/8 sphere had 833 rays and 6 569 obels; which universe and radius it used is \
         searched in the Akman & Franklin reproduction."
    );
    let dir = results.join("default-object");
    write_atomic(&dir.join("stats.md"), md.as_bytes()).map_err(|e| e.to_string())?;
    Ok(md)
}
