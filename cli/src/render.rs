//! `ktree render FILE.ktree [--camera VIEW] [--perspective FOV] [--size WxH] [--out img.png]`: a
//! hidden-surface image of an octree; a quadtree is drawn as a picture of its cells, a 4-D tree as a strip
//! of time slices; a tree with values (K = 2, 3 or 4) in its values' colours.

use crate::common::error::{read_error, CliError, CliResult};
use crate::outln;

use std::path::{Path, PathBuf};

use indicatif::ProgressBar;

use crate::common::picture::{parse_size, parse_view};
use crate::common::progress::progress_bar;
use crate::common::vector::vector;
use ktree::display::{
    default_camera, object_bounds, plane, png, render_with_progress, slices, Camera, Paint,
    Projection, RenderOptions,
};
use ktree::io::{read_rays_file, AnyMappedTree, FileTree};
use ktree::space::Cell;
use ktree::tree::storage::TreeStorage;
use ktree::tree::valued::BinaryValues;
use ktree::{AnyRaySet, AnyTree};

/// Arguments of `ktree render`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A `.ktree` file, version 2 read in place, or any format `ktree convert` reads (K = 3:
    /// hidden-surface image; K = 2: picture of the cells; K = 4: strip of slices; a tree with values in
    /// its values' colours).
    file: PathBuf,
    /// Where the camera looks from: iso, top, bottom, front, back, left, right, or a direction X,Y,Z from
    /// the object towards the eye. The camera frames the object.
    #[arg(
        long,
        default_value = "iso",
        value_name = "VIEW|X,Y,Z",
        allow_hyphen_values = true
    )]
    camera: String,
    /// Perspective projection with this vertical field of view in degrees (default: orthographic).
    #[arg(long, value_name = "FOV")]
    perspective: Option<f64>,
    /// Put the eye at this point X,Y,Z (voxel coordinates) instead of framing automatically.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = vector::<f64, 3>)]
    eye: Option<[f64; 3]>,
    /// The point looked at with --eye (default: the object's centre).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = vector::<f64, 3>)]
    target: Option<[f64; 3]>,
    /// The up direction (default: z, or y when looking along z).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = vector::<f64, 3>)]
    up: Option<[f64; 3]>,
    /// Image size in pixels (for a 4-D tree: the size of each frame).
    #[arg(long, default_value = "800x800", value_name = "WxH")]
    size: String,
    /// Output PNG (default: the input's name with .png).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Also write the depth image (near = light) to this PNG.
    #[arg(long, value_name = "PNG")]
    depth: Option<PathBuf>,
    /// 4-D trees: the axis sliced (time).
    #[arg(long, default_value_t = 3)]
    time_axis: usize,
    /// 4-D trees: the number of frames in the strip.
    #[arg(long, default_value_t = 6)]
    frames: usize,
    /// 4-D trees: also write each frame as FRAMES_DIR/frame_NNN.png (an animated sequence).
    #[arg(long, value_name = "DIR")]
    frames_dir: Option<PathBuf>,
    /// Shade with the surface normals carried by this ray file (the rays the octree was built from).
    #[arg(long, value_name = "FILE")]
    rays: Option<PathBuf>,
    /// The object's colour: `value` (a tree with values: a palette for labels, a colour ramp from the
    /// smallest to the largest float, colours as they are; the default for such a tree) or R,G,B.
    #[arg(long, value_name = "value|R,G,B", allow_hyphen_values = true)]
    colour: Option<String>,
    /// Show a progress bar.
    #[arg(long)]
    progress: bool,
}

/// The colour asked for: by value (`None`) or one colour.
fn parse_colour(text: Option<&str>) -> Result<Option<[u8; 3]>, String> {
    match text {
        None | Some("value") => Ok(None),
        Some(t) => {
            let parts: Vec<_> = t.split(',').map(|p| p.trim().parse::<u8>()).collect();
            match parts.as_slice() {
                [Ok(r), Ok(g), Ok(b)] => Ok(Some([*r, *g, *b])),
                _ => Err(format!(
                    "--colour '{t}': expected value or R,G,B (0 to 255 each)"
                )),
            }
        }
    }
}

fn default_out(file: &Path) -> PathBuf {
    file.with_extension("png")
}

/// Renders the file.
pub fn run(args: Args) -> CliResult {
    let (w, h) = parse_size(&args.size)?;
    let out = args.out.clone().unwrap_or_else(|| default_out(&args.file));
    let bar = progress_bar(args.progress, "render");
    let mut tick = |done: u64, total: u64| {
        if let Some(b) = &bar {
            b.set_length(total.max(1));
            b.set_position(done);
        }
    };
    let colour = parse_colour(args.colour.as_deref())?;
    if crate::values::is_valued(&args.file) {
        let (k, dtype) = crate::values::file_dtype(&args.file)?;
        let dtype = dtype.ok_or("a valued file has a value type")?;
        return match k {
            2 => ktree::with_valued!(2, dtype, KK, V => {
                render_valued_quadtree::<V>(&args, &out, w.min(h), colour)
            }, else unreachable!("every value type has an arm")),
            3 => ktree::with_valued!(3, dtype, KK, V => {
                render_valued::<V>(&args, &out, w, h, colour, bar.as_ref(), &mut tick)
            }, else unreachable!("every value type has an arm")),
            4 => ktree::with_valued!(4, dtype, KK, V => {
                render_valued_strip::<V>(&args, &out, h, colour)
            }, else unreachable!("every value type has an arm")),
            _ => Err(format!(
                "{}: a bintree (K = {k}) has no picture; render needs K = 2, 3 or 4",
                args.file.display()
            )
            .into()),
        };
    }
    if args.colour.as_deref() == Some("value") {
        return Err(format!(
            "{}: --colour value colours a tree with values; this tree holds none",
            args.file.display()
        )
        .into());
    }
    // A version 2 file is drawn from its memory map, whatever its size.
    let file = ktree::input::open_tree(&args.file, &ktree::io::ReadOptions::default())
        .map_err(CliError::caused)?;
    match &file {
        FileTree::Memory(AnyTree::K3(t)) => render_octree(
            t,
            &args,
            &out,
            (w, h),
            (colour, None),
            bar.as_ref(),
            &mut tick,
        ),
        FileTree::Mapped(AnyMappedTree::K3(t)) => render_octree(
            t,
            &args,
            &out,
            (w, h),
            (colour, None),
            bar.as_ref(),
            &mut tick,
        ),
        FileTree::Memory(AnyTree::K2(t)) => render_quadtree(t, &out, w.min(h), colour),
        FileTree::Mapped(AnyMappedTree::K2(t)) => render_quadtree(t, &out, w.min(h), colour),
        FileTree::Memory(AnyTree::K4(t)) => render_strip(t, &args, &out, h, colour),
        FileTree::Mapped(AnyMappedTree::K4(t)) => render_strip(t, &args, &out, h, colour),
        FileTree::Memory(AnyTree::K1(_)) | FileTree::Mapped(AnyMappedTree::K1(_)) => {
            Err("a bintree (K = 1) has no picture; render needs K = 2, 3 or 4".into())
        }
    }
}

/// Draws a quadtree's cells, `size` pixels square, to the PNG `out` (full cells in `colour` if given).
fn render_quadtree<T: TreeStorage<2>>(
    tree: &T,
    out: &Path,
    size: u32,
    colour: Option<[u8; 3]>,
) -> CliResult {
    let canvas = match colour {
        None => plane::quadtree_canvas(tree, size),
        Some(c) => plane::values_canvas(&BinaryValues(tree), size, |()| c),
    }
    .map_err(CliError::caused)?;
    canvas.write_png(out).map_err(CliError::caused)?;
    // Every leaf is full or empty: the counts say how many there are, without a walk.
    let counts = tree.counts();
    outln!(
        "wrote {} (quadtree, {} leaves)",
        out.display(),
        counts.full + counts.empty
    );
    Ok(())
}

/// Draws a quadtree with values, `size` pixels square, each leaf in its value's colour (or `colour`), to
/// the PNG `out`.
fn render_valued_quadtree<V: ktree::value::Value>(
    args: &Args,
    out: &Path,
    size: u32,
    colour: Option<[u8; 3]>,
) -> CliResult {
    let (tree, _, _) = crate::convert_values::read_noted::<2, V>(&args.file)?;
    let of_value = ktree::display::palette::value_colours(&tree);
    let canvas = plane::values_canvas(&tree, size, |v| colour.unwrap_or_else(|| of_value(v)))
        .map_err(CliError::caused)?;
    canvas.write_png(out).map_err(CliError::caused)?;
    let leaves = tree.value_leaves().count();
    let values = tree.value_leaves().filter(|(_, v)| v.is_some()).count();
    outln!(
        "wrote {} (quadtree with values, {leaves} leaves, {values} of them holding a value)",
        out.display()
    );
    Ok(())
}

/// Draws a strip of a 4-D tree with values, each leaf in its value's colour (or `colour`).
fn render_valued_strip<V: ktree::value::Value>(
    args: &Args,
    out: &Path,
    size: u32,
    colour: Option<[u8; 3]>,
) -> CliResult {
    let (tree, _, _) = crate::convert_values::read_noted::<4, V>(&args.file)?;
    let of_value = ktree::display::palette::value_colours(&tree);
    let strip = slices::time_strip_values(&tree, args.time_axis, args.frames, size, |v| {
        colour.unwrap_or_else(|| of_value(v))
    })
    .map_err(CliError::caused)?;
    write_strip(strip, args, out)
}

/// Draws a strip of a 4-D tree's slices, frames `size` pixels square, to the PNG `out` (and each frame
/// to the frames' folder if asked), in `colour` if given.
fn render_strip<T: TreeStorage<4>>(
    tree: &T,
    args: &Args,
    out: &Path,
    size: u32,
    colour: Option<[u8; 3]>,
) -> CliResult {
    let strip = match colour {
        None => slices::time_strip(tree, args.time_axis, args.frames, size),
        Some(c) => slices::time_strip_values(
            &BinaryValues(tree),
            args.time_axis,
            args.frames,
            size,
            |()| c,
        ),
    }
    .map_err(CliError::caused)?;
    write_strip(strip, args, out)
}

/// Writes a strip to the PNG `out` (and each frame to the frames' folder if asked).
fn write_strip(strip: slices::Strip, args: &Args, out: &Path) -> CliResult {
    let (strip, frames) = strip;
    strip.write_png(out).map_err(CliError::caused)?;
    if let Some(dir) = &args.frames_dir {
        for (i, (_, frame)) in frames.iter().enumerate() {
            let path = dir.join(format!("frame_{i:03}.png"));
            png::write_rgb_png(&path, frame.width, frame.height, &frame.rgb)
                .map_err(CliError::caused)?;
        }
    }
    let positions: Vec<String> = frames.iter().map(|(p, _)| p.to_string()).collect();
    outln!(
        "wrote {} ({} frames of the slices at {} on axis {})",
        out.display(),
        frames.len(),
        positions.join(", "),
        args.time_axis
    );
    Ok(())
}

/// Draws an octree with values, each leaf in its value's colour (or `colour`).
fn render_valued<V: ktree::value::Value>(
    args: &Args,
    out: &Path,
    w: u32,
    h: u32,
    colour: Option<[u8; 3]>,
    bar: Option<&ProgressBar>,
    tick: &mut dyn FnMut(u64, u64),
) -> CliResult {
    let (tree, _, _) = crate::convert_values::read_noted::<3, V>(&args.file)?;
    let of_value = ktree::display::palette::value_colours(&tree);
    let paint = |cell: &Cell<3>| {
        colour.unwrap_or_else(|| tree.value_at(cell.origin()).map_or([0; 3], &of_value))
    };
    let view = ktree::tree::valued::LeavesOfValues(&tree);
    render_octree(
        &view,
        args,
        out,
        (w, h),
        (None, Some(Paint(&paint))),
        bar,
        tick,
    )
}

/// Renders an octree, in memory or memory-mapped, to the PNG `out` (and the depth image if asked).
fn render_octree<T: TreeStorage<3>>(
    tree: &T,
    args: &Args,
    out: &Path,
    (w, h): (u32, u32),
    (colour, paint): (Option<[u8; 3]>, Option<Paint<'_>>),
    bar: Option<&ProgressBar>,
    tick: &mut dyn FnMut(u64, u64),
) -> CliResult {
    let toward = parse_view(&args.camera)?;
    let mut camera =
        default_camera(tree, toward, args.perspective, w, h).map_err(CliError::caused)?;
    if let Some(eye) = &args.eye {
        camera.eye = *eye;
        let side = tree.universe().side() as f64;
        let (lo, hi) = object_bounds(tree)
            .map_err(read_error)?
            .unwrap_or(([0.0; 3], [side; 3]));
        camera.target = match &args.target {
            Some(t) => *t,
            None => [0, 1, 2].map(|i| (lo[i] + hi[i]) / 2.0),
        };
        if let Projection::Orthographic { .. } = camera.projection {
            let diag =
                ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2))
                    .sqrt();
            camera.projection = Projection::Orthographic {
                height: diag.max(1.0) * 1.05,
            };
        }
    }
    if let Some(up) = &args.up {
        camera.up = *up;
    }
    let camera: Camera = camera;
    camera.check().map_err(CliError::caused)?;
    let options = RenderOptions {
        width: w,
        height: h,
        depth: args.depth.is_some(),
        colour: colour.unwrap_or(RenderOptions::default().colour),
        ..Default::default()
    };
    let rays = match &args.rays {
        None => None,
        Some(path) => match read_rays_file(path).map_err(CliError::caused)? {
            AnyRaySet::K3(r) if r.level() != tree.level() => {
                return Err(format!(
                    "{}: level {} does not match the tree's level {}",
                    path.display(),
                    r.level(),
                    tree.level()
                )
                .into())
            }
            AnyRaySet::K3(r) if r.has_normals() => Some(r),
            AnyRaySet::K3(_) => {
                return Err(format!(
                    "{}: the rays carry no normals to shade with",
                    path.display()
                )
                .into())
            }
            _ => {
                return Err(format!(
                    "{}: normals for an octree need a K = 3 ray file",
                    path.display()
                )
                .into())
            }
        },
    };
    let image = render_with_progress(
        tree,
        &camera,
        &RenderOptions {
            normals: rays.as_ref(),
            paint,
            ..options
        },
        tick,
    )
    .map_err(CliError::caused)?;
    png::write_rgb_png(out, w, h, &image.rgb).map_err(CliError::caused)?;
    if let (Some(path), Some(grey)) = (&args.depth, image.depth_grey()) {
        png::write_grey_png(path, w, h, &grey).map_err(CliError::caused)?;
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    outln!(
        "wrote {} ({w}x{h}, {} pixels of the object, {} nodes visited, {} culled)",
        out.display(),
        image.stats.painted,
        image.stats.nodes_visited,
        image.stats.culled
    );
    Ok(())
}
