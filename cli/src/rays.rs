//! `ktree rays --solid NAME ... --level L --out FILE`: an analytic solid (quadric or box) to rays.

use crate::common::error::{CliError, CliResult};
use crate::outln;

use ktree::fs::write_atomic_with;
use ktree::io::write_rays_source;
use ktree::solid::{BoxSolid, Frame, Quadric, Rational, Sample, Solid, SolidSource};
use ktree::stacking::default_split_depth;

use crate::common::output::{is_tree_file, TreeOutput};
use crate::common::vector::{list, List};

/// Arguments of `ktree rays`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The solid: ball, ellipsoid, paraboloid, cylinder, cone, half-space, box, or quadric (with --quadric).
    #[arg(long, default_value = "ball")]
    solid: String,
    /// Dimension K (1 … 4).
    #[arg(long, short = 'k', default_value_t = 3)]
    dim: usize,
    /// Universe level L (side 2^L).
    #[arg(long)]
    level: u32,
    /// Centre (ball, ellipsoid, cylinder) or apex (paraboloid, cone): K comma-separated numbers
    /// (decimals or fractions, exact). Default: the universe's centre.
    #[arg(long, alias = "centre", value_name = "X,…", allow_hyphen_values = true, value_parser = list::<Rational>)]
    center: Option<List<Rational>>,
    /// Radius (ball, cylinder; paraboloid and cone: radius at --height from the apex).
    #[arg(long)]
    radius: Option<String>,
    /// Semi-axes of an ellipsoid: K numbers.
    #[arg(long, value_name = "X,…", allow_hyphen_values = true, value_parser = list::<Rational>)]
    radii: Option<List<Rational>>,
    /// Height (paraboloid, cone).
    #[arg(long)]
    height: Option<String>,
    /// Axis (cylinder, cone): 0 … K−1. The paraboloid always opens along the last axis.
    #[arg(long, default_value_t = 0)]
    axis: usize,
    /// Half-space n·x ≤ offset: the normal n (K numbers).
    #[arg(long, value_name = "X,…", allow_hyphen_values = true, value_parser = list::<Rational>)]
    normal: Option<List<Rational>>,
    /// Half-space offset.
    #[arg(long, allow_hyphen_values = true)]
    offset: Option<String>,
    /// Box lower corner (K numbers).
    #[arg(long, value_name = "X,…", allow_hyphen_values = true, value_parser = list::<Rational>)]
    lo: Option<List<Rational>>,
    /// Box upper corner (K numbers).
    #[arg(long, value_name = "X,…", allow_hyphen_values = true, value_parser = list::<Rational>)]
    hi: Option<List<Rational>>,
    /// A raw quadric matrix Ξ, (K+1)×(K+1), rows separated by ';', entries by ',' (solid: VᵀΞV ≤ 0).
    #[arg(long, value_name = "A,B,…;…", allow_hyphen_values = true)]
    quadric: Option<String>,
    /// Parameters are in the unit cube (the universe is [0,1]^K) instead of voxels.
    #[arg(long)]
    unit_cube: bool,
    /// Test each voxel's lowest corner instead of its centre.
    #[arg(long)]
    corner: bool,
    #[command(flatten)]
    out: crate::common::args::RaysOrTreeOut,
    #[command(flatten)]
    build: crate::common::memory::BuildArgs,
}

/// The `n` numbers of `--what`.
fn numbers(v: Vec<Rational>, n: usize, what: &str) -> Result<Vec<Rational>, String> {
    if v.len() != n {
        return Err(format!("--{what} needs {n} numbers, got {}", v.len()));
    }
    Ok(v)
}

/// The number of `--what`, required.
fn one(text: &Option<String>, what: &str) -> CliResult<Rational> {
    text.as_deref()
        .ok_or_else(|| format!("--{what} is required for this solid"))?
        .parse()
        .map_err(|e| CliError::about(format!("--{what}"), e))
}

fn arr<const K: usize>(
    given: &Option<List<Rational>>,
    what: &str,
) -> Result<Option<[Rational; K]>, String> {
    given
        .as_ref()
        .map(|l| numbers(l.0.clone(), K, what).map(|v| std::array::from_fn(|i| v[i])))
        .transpose()
}

fn solid<const K: usize>(a: &Args) -> CliResult<Solid<K>> {
    let frame = if a.unit_cube {
        Frame::UnitCube
    } else {
        Frame::Voxel
    };
    let middle = if a.unit_cube {
        Rational::new(1, 2).ok_or("internal")?
    } else {
        Rational::int(1 << a.level.saturating_sub(1).min(62))
    };
    let centre = arr::<K>(&a.center, "center")?.unwrap_or([middle; K]);
    let q = match a.solid.as_str() {
        "ball" => Quadric::ball(centre, one(&a.radius, "radius")?, frame).map_err(CliError::caused)?,
        "ellipsoid" => {
            let radii = arr::<K>(&a.radii, "radii")?.ok_or("--radii is required for an ellipsoid")?;
            Quadric::ellipsoid(centre, radii, frame).map_err(CliError::caused)?
        }
        "paraboloid" => Quadric::paraboloid(centre, one(&a.radius, "radius")?, one(&a.height, "height")?, frame)
            .map_err(CliError::caused)?,
        "cylinder" => Quadric::cylinder(a.axis, centre, one(&a.radius, "radius")?, frame).map_err(CliError::caused)?,
        "cone" => Quadric::cone(a.axis, centre, one(&a.radius, "radius")?, one(&a.height, "height")?, frame)
            .map_err(CliError::caused)?,
        "half-space" => {
            let n = arr::<K>(&a.normal, "normal")?.ok_or("--normal is required for a half-space")?;
            Quadric::half_space(n, one(&a.offset, "offset")?, frame).map_err(CliError::caused)?
        }
        "box" => {
            let lo = arr::<K>(&a.lo, "lo")?.ok_or("--lo is required for a box")?;
            let hi = arr::<K>(&a.hi, "hi")?.ok_or("--hi is required for a box")?;
            return BoxSolid::new(lo, hi, frame).map(Solid::Box).map_err(CliError::caused);
        }
        "quadric" => {
            let text = a.quadric.as_deref().ok_or("--quadric MATRIX is required for --solid quadric")?;
            let rows: Vec<Vec<Rational>> = text
                .split(';')
                .map(|r| {
                    let row = list::<Rational>(r).map_err(|e| format!("--quadric: {e}"))?;
                    numbers(row.0, K + 1, "quadric")
                })
                .collect::<Result<_, _>>()?;
            Quadric::from_rational_matrix(&rows, frame).map_err(CliError::caused)?
        }
        other => {
            return Err(format!(
                "unknown solid '{other}': choose ball, ellipsoid, paraboloid, cylinder, cone, half-space, box or quadric"
            )
            .into())
        }
    };
    Ok(Solid::Quadric(q))
}

fn go<const K: usize>(a: &Args) -> CliResult {
    let s = solid::<K>(a)?;
    let sample = if a.corner {
        Sample::Corner
    } else {
        Sample::Centre
    };
    if is_tree_file(&a.out.out) {
        // Straight to a tree: the rays are made slab by slab as the cells are stacked, never held whole
        // (across MPI ranks, each rank makes the rays of its own slabs only).
        let source = SolidSource::new(&s, a.level, sample).map_err(CliError::caused)?;
        let built = TreeOutput::new(&a.out.out, &a.build).write(&source, None)?;
        if let Some(built) = built {
            outln!("{}", built.summary(None));
        }
        return Ok(());
    }
    if !crate::distributed::ranks().is_root() {
        // A ray file is written by rank 0 alone.
        return Ok(());
    }
    // A ray file, written slab by slab: one slab's runs held at a time, no cap on their number.
    let source = SolidSource::new(&s, a.level, sample).map_err(CliError::caused)?;
    let bar = crate::common::progress::progress_bar(a.build.progress, "writing slabs");
    let progress = |done: u64, total: u64| {
        if let Some(bar) = &bar {
            bar.set_length(total);
            bar.set_position(done);
        }
    };
    let mut written = (0, 0);
    let depth = default_split_depth(K, a.level);
    write_atomic_with(&a.out.out, |w| {
        written = write_rays_source(w, &source, depth, &progress)?;
        Ok(())
    })
    .map_err(CliError::caused)?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    outln!(
        "{}: K = {K}, L = {}, {} rays, {} voxels",
        a.out.out.display(),
        a.level,
        written.0,
        written.1
    );
    Ok(())
}

/// Builds the solid's rays and writes them.
pub fn run(args: Args) -> CliResult {
    match args.dim {
        1 => go::<1>(&args),
        2 => go::<2>(&args),
        3 => go::<3>(&args),
        4 => go::<4>(&args),
        k => Err(format!("--dim {k}: K must be 1, 2, 3 or 4").into()),
    }
}
