//! `ktree project FILE --axis A [--range LO:HI] --out OUT` and `ktree slice FILE --axis A --at C --out
//! OUT`: a K-tree seen in K − 1 dimensions — the union of its slices along an axis over a range of
//! positions, or one slice. The output is any tree file; a quadtree (from an octree) may also be written as
//! a `.png` occupancy grid with its `.yaml` (ROS's map_server: occupied black, free white). The slice of a
//! tree with values (a version 3 `.ktree`) keeps each voxel's value and is written as a `.ktree`.

use std::path::{Path, PathBuf};

use ktree::export::grid_map::write_grid_map;
use ktree::export::Frame;
use ktree::io::ktree::v3::write_valued_ktree_file;
use ktree::io::{AnyMappedTree, FileTree, ReadOptions};
use ktree::ops::{project, slice_values};
use ktree::tree::storage::TreeStorage;
use ktree::value::Value;
use ktree::{AnyTree, KTree};

use crate::common::error::{CliError, CliResult};
use crate::common::vector::vector;
use crate::outln;

/// Arguments of `ktree project`.
#[derive(Debug, clap::Args)]
pub struct ProjectArgs {
    /// The tree file (K = 2, 3 or 4).
    input: PathBuf,
    /// The axis projected along: x, y, z, w or 0–3.
    #[arg(long, value_parser = parse_axis)]
    axis: usize,
    /// The positions along the axis, LO:HI both included (default: all): voxels for a tree file, world
    /// coordinates (metres) for an occupancy map (.ot, .bt, a map's .ktree).
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true, value_parser = parse_range)]
    range: Option<(f64, f64)>,
    #[command(flatten)]
    out: OutArgs,
}

/// Arguments of `ktree slice`.
#[derive(Debug, clap::Args)]
pub struct SliceArgs {
    /// The tree file (K = 2, 3 or 4).
    input: PathBuf,
    /// The axis cut across: x, y, z, w or 0–3.
    #[arg(long, value_parser = parse_axis)]
    axis: usize,
    /// The position along the axis, in voxels.
    #[arg(long)]
    at: u32,
    #[command(flatten)]
    out: OutArgs,
}

/// Where the tree of K − 1 dimensions goes.
#[derive(Debug, clap::Args)]
pub struct OutArgs {
    /// The output: a tree file (.ktree, .rays, …), or for a quadtree a .png occupancy grid (+ .yaml).
    #[arg(long)]
    pub out: PathBuf,
    /// A .png map: the side of a cell in metres (the YAML's resolution).
    #[arg(long, default_value_t = 1.0)]
    voxel_size: f64,
    /// A .png map: the world position of cell (0, 0)'s lower corner, as x,y.
    #[arg(long, value_name = "X,Y", allow_hyphen_values = true, value_parser = vector::<f64, 2>)]
    origin: Option<[f64; 2]>,
}

fn parse_axis(text: &str) -> Result<usize, String> {
    match text {
        "x" | "0" => Ok(0),
        "y" | "1" => Ok(1),
        "z" | "2" => Ok(2),
        "w" | "t" | "3" => Ok(3),
        _ => Err(format!("'{text}': an axis is x, y, z, w or 0 to 3")),
    }
}

fn parse_range(text: &str) -> Result<(f64, f64), String> {
    let (lo, hi) = text
        .split_once(':')
        .ok_or_else(|| format!("'{text}': expected LO:HI"))?;
    let number = |t: &str| {
        t.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{t}' in '{text}' is not a number"))
    };
    let (lo, hi) = (number(lo)?, number(hi)?);
    if lo > hi {
        return Err(format!("'{text}': LO is larger than HI"));
    }
    Ok((lo, hi))
}

/// Whether `path` is an occupancy map file (OctoMap's `.ot` and `.bt`).
pub fn is_map_file(path: &Path) -> bool {
    crate::map::is_map_file(path)
}

/// `ktree project`.
pub fn run_project(a: ProjectArgs) -> CliResult {
    if is_map_file(&a.input) {
        return crate::map::project_map(&a.input, a.axis, a.range, &a.out.out);
    }
    let range = match a.range {
        None => 0..u32::MAX,
        Some((lo, hi)) => {
            let voxel = |v: f64| {
                (v >= 0.0 && v.fract() == 0.0 && v <= f64::from(u32::MAX))
                    .then_some(v as u32)
                    .ok_or_else(|| {
                        format!("--range: {v} is not a voxel coordinate (a whole number from 0)")
                    })
            };
            voxel(lo)?..voxel(hi)?.saturating_add(1)
        }
    };
    run(&a.input, a.axis, range, &a.out, "projection")
}

/// `ktree slice`.
pub fn run_slice(a: SliceArgs) -> CliResult {
    if crate::values::is_valued(&a.input) {
        return slice_valued(&a);
    }
    let file = open(&a.input)?;
    let side = 1u64 << file.level();
    if u64::from(a.at) >= side {
        return Err(format!(
            "{}: --at {} is outside the universe (0 to {})",
            a.input.display(),
            a.at,
            side - 1
        )
        .into());
    }
    run(&a.input, a.axis, a.at..a.at + 1, &a.out, "slice")
}

/// The slice of a tree with values, each voxel with its value, to a `.ktree`.
fn slice_valued(a: &SliceArgs) -> CliResult {
    if a.out.out.extension().is_none_or(|e| e != "ktree") {
        return Err(format!(
            "{}: the slice of a tree with values is written as a .ktree",
            a.out.out.display()
        )
        .into());
    }
    let tree = crate::values::read_valued(&a.input)?;
    let (k, dtype) = (tree.k(), tree.dtype());
    if k == 1 {
        return Err(format!(
            "{}: a bintree (K = 1) has no slice of fewer dimensions",
            a.input.display()
        )
        .into());
    }
    if a.axis >= k {
        return Err(format!(
            "{}: axis {} is not below K = {k}",
            a.input.display(),
            a.axis
        )
        .into());
    }
    fn down<const K: usize, const J: usize, V: Value>(
        tree: &KTree<K, V>,
        a: &SliceArgs,
    ) -> CliResult<(u128, u64)> {
        let lower: KTree<J, V> = slice_values(tree, a.axis, a.at).map_err(CliError::caused)?;
        write_valued_ktree_file(&a.out.out, &lower).map_err(CliError::caused)?;
        Ok((lower.voxel_count(), lower.node_count()))
    }
    // J = K − 1 (a bintree, K = 1, was refused above: its J stands at 1 only to name a type).
    let (voxels, nodes) = ktree::with_valued!(k, dtype, KK, V => {
        let t = tree.as_typed::<KK, V>().ok_or("the tree is of its own dimension and type")?;
        down::<KK, { if KK > 1 { KK - 1 } else { 1 } }, V>(t, a)?
    }, else return Err(format!("{}: no slice of K = {k} {} trees", a.input.display(), dtype.name()).into()));
    outln!(
        "{}: slice along axis {} at {}: K = {}, L = {}, {} values, {voxels} voxels, {nodes} nodes",
        a.out.out.display(),
        a.axis,
        a.at,
        k - 1,
        tree.level(),
        dtype.name()
    );
    Ok(())
}

fn open(path: &Path) -> CliResult<FileTree> {
    ktree::input::open_tree(path, &ReadOptions::default()).map_err(CliError::caused)
}

fn run(
    input: &Path,
    axis: usize,
    range: std::ops::Range<u32>,
    out: &OutArgs,
    what: &str,
) -> CliResult {
    let file = open(input)?;
    let k = file.k();
    if axis >= k {
        return Err(format!("{}: axis {axis} is not below K = {k}", input.display()).into());
    }
    fn down<const K: usize, const J: usize, T: TreeStorage<K>>(
        tree: &T,
        axis: usize,
        range: std::ops::Range<u32>,
    ) -> CliResult<KTree<J>> {
        project::<K, J, T>(tree, axis, range).map_err(CliError::caused)
    }
    let lower: AnyTree = match &file {
        FileTree::Memory(AnyTree::K2(t)) => down::<2, 1, _>(t, axis, range)?.into(),
        FileTree::Memory(AnyTree::K3(t)) => down::<3, 2, _>(t, axis, range)?.into(),
        FileTree::Memory(AnyTree::K4(t)) => down::<4, 3, _>(t, axis, range)?.into(),
        FileTree::Mapped(AnyMappedTree::K2(t)) => down::<2, 1, _>(t, axis, range)?.into(),
        FileTree::Mapped(AnyMappedTree::K3(t)) => down::<3, 2, _>(t, axis, range)?.into(),
        FileTree::Mapped(AnyMappedTree::K4(t)) => down::<4, 3, _>(t, axis, range)?.into(),
        _ => {
            return Err(format!(
                "{}: a bintree (K = 1) has no {what} of fewer dimensions",
                input.display()
            )
            .into())
        }
    };
    let png = out.out.extension().is_some_and(|e| e == "png");
    if png {
        let AnyTree::K2(quad) = &lower else {
            return Err(format!(
                "{}: a .png map is a quadtree; the {what} of this K = {k} tree has K = {}",
                out.out.display(),
                k - 1
            )
            .into());
        };
        if !(out.voxel_size.is_finite() && out.voxel_size > 0.0) {
            return Err(format!(
                "--voxel-size {}: expected a positive number",
                out.voxel_size
            )
            .into());
        }
        let [x, y] = out.origin.unwrap_or([0.0; 2]);
        let frame = Frame {
            voxel_size: out.voxel_size,
            origin: [x, y, 0.0],
        };
        let yaml = write_grid_map(&out.out, quad, None, &frame).map_err(CliError::caused)?;
        outln!(
            "{} and {}: {what} along axis {axis}, {} occupied cells of {}²",
            out.out.display(),
            yaml.display(),
            quad.voxel_count(),
            1u64 << quad.level()
        );
        return Ok(());
    }
    ktree::with_dim!(&lower, AnyTree, t => crate::common::tree_file::write_tree(&out.out, t))
        .map_err(CliError::caused)?;
    outln!(
        "{}: {what} along axis {axis}: K = {}, L = {}, {} voxels, {} nodes",
        out.out.display(),
        lower.k(),
        lower.level(),
        ktree::with_dim!(&lower, AnyTree, t => t.voxel_count()),
        ktree::with_dim!(&lower, AnyTree, t => t.node_count())
    );
    Ok(())
}
