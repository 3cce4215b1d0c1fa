//! `ktree lines FILE.ktree [--view VIEW] [--out drawing.svg]`: a line drawing of an octree with hidden
//! lines removed (Veenstra & Ahuja), as SVG (vector) or PNG (by the output's extension).

use crate::common::error::{CliError, CliResult};
use crate::outln;

use std::path::PathBuf;

use ktree::display::{line_drawing_with_progress, png, svg, HiddenLineMethod, LineDrawing};
use ktree::io::{AnyMappedTree, FileTree};
use ktree::tree::storage::TreeStorage;
use ktree::AnyTree;

use crate::common::picture::{parse_size, parse_view};
use crate::common::progress::progress_bar;

/// Arguments of `ktree lines`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// An octree (K = 3): a `.ktree` file (version 2 is read in place) or any format `ktree convert`
    /// reads.
    file: PathBuf,
    /// Where the viewer looks from (parallel projection): iso, top, bottom, front, back, left, right, or a
    /// direction X,Y,Z from the object towards the viewer.
    #[arg(
        long,
        default_value = "iso",
        value_name = "VIEW|X,Y,Z",
        allow_hyphen_values = true
    )]
    view: String,
    /// Output file: .svg (vector lines) or .png (default: the input's name with .svg).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Drawing size in pixels.
    #[arg(long, default_value = "800x800", value_name = "WxH")]
    size: String,
    /// Hidden-line method: bucketed (fast) or pairwise (the paper's, quadratic).
    #[arg(long, default_value = "bucketed")]
    method: String,
    /// Line width in pixels (SVG).
    #[arg(long, default_value_t = 1.0)]
    stroke: f64,
    /// Show a progress bar.
    #[arg(long)]
    progress: bool,
}

/// Draws the file.
pub fn run(args: Args) -> CliResult {
    let (w, h) = parse_size(&args.size)?;
    let toward = parse_view(&args.view)?;
    let method = match args.method.as_str() {
        "bucketed" => HiddenLineMethod::Bucketed,
        "pairwise" => HiddenLineMethod::Pairwise,
        other => return Err(format!("method '{other}' must be bucketed or pairwise").into()),
    };
    if !(args.stroke.is_finite() && args.stroke > 0.0) {
        return Err("--stroke must be a positive number".into());
    }
    // A version 2 file is drawn from its memory map, whatever its size.
    let file = ktree::input::open_tree(&args.file, &ktree::io::ReadOptions::default())
        .map_err(CliError::caused)?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| args.file.with_extension("svg"));
    let bar = progress_bar(args.progress, "hidden lines");
    let mut tick = |done: u64, total: u64| {
        if let Some(b) = &bar {
            b.set_length(total.max(1));
            b.set_position(done);
        }
    };
    let drawing = match &file {
        FileTree::Memory(AnyTree::K3(t)) => draw(t, toward, method, &mut tick)?,
        FileTree::Mapped(AnyMappedTree::K3(t)) => draw(t, toward, method, &mut tick)?,
        other => {
            return Err(format!(
                "line drawings need an octree (K = 3); {} is a K = {} tree (try ktree render)",
                args.file.display(),
                other.k()
            )
            .into())
        }
    };
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let segments = drawing.segments_2d();
    let is_png = out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if is_png {
        png::lines_canvas(&segments, w, h)
            .and_then(|c| c.write_png(&out))
            .map_err(CliError::caused)?;
    } else {
        svg::write_svg(&out, &svg::lines_svg(&segments, w, h, args.stroke))
            .map_err(CliError::caused)?;
    }
    let s = drawing.stats;
    outln!(
        "wrote {} ({} lines; {} full leaves, {} surrounded skipped, {} graphics nodes, {} segments tested)",
        out.display(),
        s.lines,
        s.full_leaves,
        s.surrounded,
        s.graphics_nodes,
        s.segments
    );
    Ok(())
}

/// The line drawing of an octree, in memory or memory-mapped.
fn draw<T: TreeStorage<3>>(
    tree: &T,
    toward: [f64; 3],
    method: HiddenLineMethod,
    tick: &mut dyn FnMut(u64, u64),
) -> CliResult<LineDrawing> {
    line_drawing_with_progress(tree, toward, method, tick).map_err(CliError::caused)
}
