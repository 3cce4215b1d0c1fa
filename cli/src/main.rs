//! `ktree`: the command-line tool. Thin: parses arguments, calls the library, reports. Each subcommand lives
//! in its own module here.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use common::error::CliError;

mod build;
mod collide;
mod common;
mod convert;
mod convert_values;
mod distance;
mod distributed;
mod lines;
mod map;
mod mass;
mod op;
mod project;
mod query;
mod rays;
mod render;
#[cfg(feature = "repro")]
mod repro;
mod shape;
mod stats;
mod table;
mod transform;
mod values;
mod view;
mod voxelize;

/// k-trees (bintrees, quadtrees, octrees, 4-D trees) from rays by stacking.
#[derive(Debug, Parser)]
#[command(name = "ktree", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    #[command(flatten)]
    format: common::tree_file::FormatArgs,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Stack a ray file into a .ktree file.
    Build(build::Args),
    /// Print node counts (K, L, rays, full, empty, partial, nodes, per level) of a tree or a ray file.
    Stats(stats::Args),
    /// Boolean operation on tree files: union, intersect, diff, xor (two inputs) or not (one).
    Op(op::Args),
    /// Translate, rotate, scale or apply a matrix to a tree file.
    Transform(transform::Args),
    /// Interference detection: do two tree files overlap, where, and (with --time-axis) when first.
    Collide(collide::Args),
    /// Volume, centroid, second moments; with --tolerance, Meagher's progressive bounds.
    Mass(mass::Args),
    /// Draw a hidden-surface image of a tree (octree; quadtree picture; 4-D strip of time slices) as PNG.
    Render(render::Args),
    /// Draw an octree as lines with hidden lines removed (SVG or PNG).
    Lines(lines::Args),
    /// An interactive 3-D view of a tree in one self-contained HTML page (WebGL2, no network).
    View(view::Args),
    /// Regenerate the paper reproductions into results/ (all of them by default).
    #[cfg(feature = "repro")]
    Repro(repro::Args),
    /// An analytic solid (ball, ellipsoid, paraboloid, cylinder, cone, half-space, box, quadric) to rays.
    Rays(rays::Args),
    /// A triangle mesh (OBJ, STL, PLY), a volume (raw + JSON, NIfTI) or a point cloud (PLY, PCD, XYZ/CSV, LAS/LAZ) to rays or a .ktree.
    Voxelize(voxelize::Args),
    /// The voxels of one value, or of a range of values, of a tree with values: a tree without values.
    Select(values::SelectArgs),
    /// An occupancy map (OctoMap's semantics) from range scans: .ot, .bt or .ktree.
    Map(map::MapArgs),
    /// The union of a tree's slices along an axis over a range: a tree of one dimension fewer (or a .png occupancy grid with its .yaml); for a map (.ot, .bt), its plane between two heights.
    Project(project::ProjectArgs),
    /// A tree's slice at one position along an axis: a tree of one dimension fewer (or a .png occupancy grid).
    Slice(project::SliceArgs),
    /// Point queries on a tree file: inside or not, with --distance and --nearest the nearest full voxel.
    Query(query::QueryArgs),
    /// Cast rays (origin, direction) into a tree file: the first full voxel each enters.
    Raycast(query::RaycastArgs),
    /// Convert between .ktree, .rays, .binvox, OctoMap .bt and OpenVDB .vdb; meshes (voxelized in, the boundary out: .ply, .obj, .stl, .glb, .svg), VTK out (.vtu, .htg, .pvd), volumes in.
    Convert(convert::Args),
    /// Dilate, erode, open or close a tree file by a ball, box or cross of any radius.
    Morph(shape::MorphArgs),
    /// Connected components of a tree file: count, sizes, each as its own file.
    Components(shape::ComponentsArgs),
    /// Signed distances of an octree file: the narrow band as an OpenVDB level set (FloatGrid).
    Distance(distance::DistanceArgs),
}

/// Writes a line to standard output, returning from the enclosing function with a [`CliError`] if that
/// fails (`ktree stats A | head` closes the pipe early: that ends the command quietly, not in a panic).
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout(), $($arg)*)
            .map_err(crate::common::error::CliError::from_output)?;
    }};
}
pub(crate) use outln;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // A bad value (a vector that is not three numbers, …) is a one-line error like any other bad input.
        Err(e) if e.kind() == clap::error::ErrorKind::ValueValidation => {
            let text = e.render().to_string();
            let line = text.lines().next().unwrap_or_default();
            eprintln!("ktree: {}", line.strip_prefix("error: ").unwrap_or(line));
            return ExitCode::from(2);
        }
        Err(e) => e.exit(),
    };
    let _mpi = distributed::init();
    common::tree_file::set(&cli.format);
    let outcome = match cli.command {
        Command::Build(args) => build::run(args),
        Command::Stats(args) => stats::run(args),
        Command::Op(args) => op::run(args),
        Command::Transform(args) => transform::run(args),
        Command::Collide(args) => collide::run(args),
        Command::Mass(args) => mass::run(args),
        Command::Render(args) => render::run(args),
        Command::Lines(args) => lines::run(args),
        Command::View(args) => view::run(args),
        #[cfg(feature = "repro")]
        Command::Repro(args) => repro::run(args),
        Command::Rays(args) => rays::run(args),
        Command::Voxelize(args) => voxelize::run(args),
        Command::Convert(args) => convert::run(args),
        Command::Morph(args) => shape::run_morph(args),
        Command::Components(args) => shape::run_components(args),
        Command::Distance(args) => distance::run(args),
        Command::Select(args) => values::run_select(args),
        Command::Map(args) => map::run_map(args),
        Command::Project(args) => project::run_project(args),
        Command::Slice(args) => project::run_slice(args),
        Command::Query(args) => query::run_query(args),
        Command::Raycast(args) => query::run_raycast(args),
    };
    match outcome {
        Ok(()) | Err(CliError::OutputClosed) => ExitCode::SUCCESS,
        Err(e) => {
            distributed::report_failure(&e.to_string());
            ExitCode::FAILURE
        }
    }
}
