//! `ktree transform A [--scale S] [--rotate R] [--translate T] [--matrix M] --out B`: geometric transforms
//! of a tree file, applied in the order scale, rotate, translate, matrix; a `.ktree` with values keeps each
//! voxel's value (nearest-neighbour: values are never blended) and is written as a `.ktree`.
//!
//! When every step is exact — a rational scale `p/q` (about the universe's origin corner), rotations by
//! multiples of 90° (about the universe's centre) and an integer translation, no matrix — the steps run as
//! the exact integer operations (rational overlays, child reordering, translation overlays). Otherwise all
//! steps are concatenated into one affine matrix applied in a single overlay pass (Meagher's M6).

use crate::common::error::{CliError, CliResult};
use std::path::PathBuf;

use ktree::io::ktree::v3::write_valued_ktree_file_noted;
use ktree::ops::{Affine, AxisMap, Geometry, Projective};

use crate::common::tree_file::{read_framed, write_framed};
use crate::common::vector::{list, List};
use crate::outln;

/// Arguments of `ktree transform`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The input tree file.
    input: PathBuf,
    /// Translation: K numbers separated by commas (integers move exactly; fractions use the affine pass).
    #[arg(long, value_name = "X,…", allow_hyphen_values = true, value_parser = list::<f64>)]
    translate: Option<List<f64>>,
    /// Rotations about the universe's centre, applied left to right: `AXIS:DEGREES` about a named axis in
    /// 3-D (`x:30,z:-45`), or `I-J:DEGREES` in the plane of axes I → J in any K (`0-1:90`).
    #[arg(long, allow_hyphen_values = true)]
    rotate: Option<String>,
    /// Uniform scale about the universe's origin corner: `P/Q` (exact) or a decimal number.
    #[arg(long)]
    scale: Option<String>,
    /// A homogeneous (K+1)×(K+1) matrix, row-major, comma-separated, acting on column vectors [x; 1]. A last
    /// row other than 0 … 0 1 makes it projective (e.g. Meagher's perspective deformation).
    #[arg(long, value_name = "M11,M12,…", allow_hyphen_values = true, value_parser = list::<f64>)]
    matrix: Option<List<f64>>,
    #[command(flatten)]
    out: crate::common::args::TreeOut,
}

/// One parsed rotation: the plane (from, to) and the angle.
fn rotations(text: &str, k: usize) -> Result<Vec<(usize, usize, f64)>, String> {
    text.split(',')
        .map(|part| {
            let (axis, deg) = part
                .split_once(':')
                .ok_or_else(|| format!("--rotate: '{part}' is not AXIS:DEGREES"))?;
            let deg: f64 = deg
                .trim()
                .parse()
                .ok()
                .filter(|d: &f64| d.is_finite())
                .ok_or_else(|| format!("--rotate: '{deg}' is not an angle in degrees"))?;
            let plane = match (axis.trim(), k) {
                ("x", 3) => (1, 2),
                ("y", 3) => (2, 0),
                ("z", 3) => (0, 1),
                (pair, _) => {
                    let (i, j) = pair.split_once('-').ok_or_else(|| {
                        format!("--rotate: '{pair}' is not an axis (x, y, z in 3-D) or a plane I-J")
                    })?;
                    let parse = |s: &str| {
                        s.trim()
                            .parse::<usize>()
                            .ok()
                            .filter(|&a| a < k)
                            .ok_or_else(|| format!("--rotate: axis '{s}' is not below K = {k}"))
                    };
                    (parse(i)?, parse(j)?)
                }
            };
            if plane.0 == plane.1 {
                return Err(format!(
                    "--rotate: the plane {}-{} needs two different axes",
                    plane.0, plane.1
                ));
            }
            Ok((plane.0, plane.1, deg))
        })
        .collect()
}

fn rational(text: &str) -> Option<(u32, u32)> {
    match text.split_once('/') {
        Some((p, q)) => Some((p.trim().parse().ok()?, q.trim().parse().ok()?)),
        None => text.trim().parse::<u32>().ok().map(|p| (p, 1)),
    }
}

/// The transforms of `args` applied to `tree` (binary or valued) of level `level`.
fn apply<const K: usize, T: Geometry<K> + Clone>(
    tree: &T,
    level: u32,
    args: &Args,
) -> CliResult<T> {
    let translate = match &args.translate {
        Some(List(v)) => {
            if v.len() != K {
                return Err(format!(
                    "--translate needs {K} numbers for a K = {K} tree, got {}",
                    v.len()
                )
                .into());
            }
            Some(v.clone())
        }
        None => None,
    };
    let rotate = match &args.rotate {
        Some(r) => rotations(r, K)?,
        None => Vec::new(),
    };
    let scale_ratio = args.scale.as_deref().map(rational);
    let scale_value = match &args.scale {
        Some(s) => {
            let v = match rational(s) {
                Some((p, q)) if q != 0 => f64::from(p) / f64::from(q),
                _ => s
                    .trim()
                    .parse::<f64>()
                    .map_err(|_| format!("--scale: '{s}' is not P/Q or a number"))?,
            };
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("--scale must be positive, got {s}").into());
            }
            Some(v)
        }
        None => None,
    };
    // A matrix whose last row is not 0 … 0 1 is projective (e.g. a perspective deformation).
    let (matrix, projective) = match &args.matrix {
        Some(List(v)) => match Affine::<K>::from_homogeneous(v) {
            Ok(a) => (Some(a), None),
            Err(_) => (
                None,
                Some(Projective::<K>::from_homogeneous(v).map_err(CliError::caused)?),
            ),
        },
        None => (None, None),
    };
    let exact = matrix.is_none()
        && projective.is_none()
        && !matches!(scale_ratio, Some(None))
        && rotate.iter().all(|r| r.2 % 90.0 == 0.0)
        && translate
            .as_ref()
            .is_none_or(|t| t.iter().all(|v| v.fract() == 0.0));
    if exact {
        let mut t = tree.clone();
        if let Some(Some((p, q))) = scale_ratio {
            t = t.scaled(p, q).map_err(CliError::caused)?;
        }
        for &(from, to, deg) in &rotate {
            let turns = ((deg / 90.0) as i64).rem_euclid(4);
            let q = AxisMap::<K>::quarter_turn(from, to).map_err(CliError::caused)?;
            for _ in 0..turns {
                t = t.rotated(&q);
            }
        }
        if let Some(v) = &translate {
            t = t.translated(std::array::from_fn(|i| v[i] as i64));
        }
        return Ok(t);
    }
    // One affine pass.
    let mut m = Affine::<K>::identity();
    if let Some(s) = scale_value {
        m = Affine::scaling_about(s, [0.0; K]).after(&m);
    }
    let centre = Affine::<K>::universe_centre(level);
    for &(from, to, deg) in &rotate {
        m = Affine::rotation_about(from, to, deg, centre)
            .map_err(CliError::caused)?
            .after(&m);
    }
    if let Some(v) = &translate {
        m = Affine::translation(std::array::from_fn(|i| v[i])).after(&m);
    }
    if let Some(x) = matrix {
        m = x.after(&m);
    }
    if let Some(p) = projective {
        let all = p.after(&Projective::from_affine(&m));
        return tree.projective(&all).map_err(CliError::caused);
    }
    tree.affine(&m).map_err(CliError::caused)
}

/// Applies the transforms and writes the result.
pub fn run(args: Args) -> CliResult {
    if args.translate.is_none()
        && args.rotate.is_none()
        && args.scale.is_none()
        && args.matrix.is_none()
    {
        return Err("give at least one of --translate, --rotate, --scale, --matrix".into());
    }
    if crate::values::is_valued(&args.input) {
        return run_valued(&args);
    }
    // The voxels move in the universe; the universe keeps its place in the world (and its notes).
    let (tree, frame, notes) = read_framed(&args.input)?;
    ktree::with_dim!(&tree, AnyTree, t => {
        let out = apply(t, t.level(), &args).map_err(|e| e.within(args.input.display()))?;
        write_framed(&args.out.out, &out, frame.as_ref(), &notes)
    })
}

/// The transforms of a tree with values, each voxel keeping its value, to a `.ktree`.
fn run_valued(args: &Args) -> CliResult {
    let out = &args.out.out;
    if out.extension().is_none_or(|e| e != "ktree") {
        return Err(format!(
            "{}: a tree with values is written as a .ktree",
            out.display()
        )
        .into());
    }
    let (k, dtype) = crate::values::file_dtype(&args.input)?;
    let dtype =
        dtype.ok_or_else(|| format!("{}: the tree holds no values", args.input.display()))?;
    let (level, voxels, nodes) = ktree::with_valued!(k, dtype, KK, V => {
        // The voxels move in the universe; the universe keeps its place in the world.
        // The labels' names (the notes) go with them.
        let (t, frame, notes) = crate::convert_values::read_noted::<KK, V>(&args.input)?;
        let moved = apply(&t, t.level(), args).map_err(|e| e.within(args.input.display()))?;
        write_valued_ktree_file_noted(out, &moved, frame.as_ref(), &notes).map_err(CliError::caused)?;
        (moved.level(), moved.voxel_count(), moved.node_count())
    }, else return Err(format!("{}: no transform of K = {k} {} trees", args.input.display(), dtype.name()).into()));
    outln!(
        "{}: K = {k}, L = {level}, {} values, {voxels} voxels, {nodes} nodes",
        out.display(),
        dtype.name()
    );
    Ok(())
}
