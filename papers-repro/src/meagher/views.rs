//! Views of the machined milling scene (Fig. 11–13, M7): hidden-surface images from the top, front, side, an
//! orthographic isometric-like direction and in perspective, and a line drawing with hidden lines removed,
//! all with `ktree::display`.

use std::fmt::Write as _;
use std::time::Instant;

use super::Out;
use ktree::display::{
    default_camera, line_drawing, png, render, svg, DisplayError, HiddenLineMethod, RenderOptions,
    ISO_TOWARD_EYE,
};
use ktree::tree::Octree;

/// Side of the hidden-surface images, pixels.
pub const VIEW_SIZE: u32 = 512;

/// The views: file name, description, direction from the scene towards the eye, perspective field of view.
const VIEWS: [(&str, &str, [f64; 3], Option<f64>); 5] = [
    (
        "views_top.png",
        "top (looking down z)",
        [0.0, 0.0, 1.0],
        None,
    ),
    (
        "views_front.png",
        "front (looking along +y)",
        [0.0, -1.0, 0.0],
        None,
    ),
    (
        "views_side.png",
        "side (looking along −x)",
        [1.0, 0.0, 0.0],
        None,
    ),
    (
        "views_iso.png",
        "orthographic, isometric-like",
        ISO_TOWARD_EYE,
        None,
    ),
    (
        "views_perspective.png",
        "perspective, 35° field of view",
        ISO_TOWARD_EYE,
        Some(35.0),
    ),
];

fn err(e: DisplayError) -> String {
    e.to_string()
}

/// Darkens each painted pixel with its depth (near: as shaded, far: 45 % darker), so that faces with the
/// same orientation at different depths — the channel's floor and the workpiece's top seen from above —
/// stay apart.
fn depth_cue(rgb: &mut [u8], depth: &[f32]) {
    let finite = depth.iter().copied().filter(|d| d.is_finite());
    let (lo, hi) = finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), d| {
        (a.min(d), b.max(d))
    });
    let span = (hi - lo).max(1e-6);
    for (px, &d) in rgb.chunks_exact_mut(3).zip(depth) {
        if d.is_finite() {
            let k = 1.0 - 0.45 * f64::from((d - lo) / span);
            for c in px {
                *c = (f64::from(*c) * k).round() as u8;
            }
        }
    }
}

/// Renders `scene` (the machined workpiece, clamp and tool, one tree) and writes the images; returns the
/// README section.
pub fn views(out: &Out, scene: &Octree, what: &str) -> Result<String, String> {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "### (f) Views of the scene (Fig. 11–13, M7)\n\n{what}, {} nodes, rendered with `ktree::display::render` \
         (front-to-back traversal with a screen coverage mask: Meagher's hidden-surface display, M7). \
         Shading is by face orientation with a light from above left of the viewer, darkened with depth so \
         that parallel faces at different depths (the channel's floor and the workpiece's top seen from \
         above) stay apart. Each camera frames the scene's full leaves. {VIEW_SIZE}×{VIEW_SIZE} pixels.\n\n\
         | view | file | nodes visited | culled (covered) | leaves drawn | time (s) |\n|---|---|---:|---:|---:|---:|",
        scene.node_count()
    );
    let mut images = String::new();
    for (file, name, toward, fov) in VIEWS {
        let camera = default_camera(scene, toward, fov, VIEW_SIZE, VIEW_SIZE).map_err(err)?;
        let options = RenderOptions {
            width: VIEW_SIZE,
            height: VIEW_SIZE,
            depth: true,
            ..Default::default()
        };
        let t = Instant::now();
        let mut image = render(scene, &camera, &options).map_err(err)?;
        let secs = t.elapsed().as_secs_f64();
        if image.stats.painted == 0 {
            return Err(format!("{name}: the rendered view is empty"));
        }
        if let Some(depth) = &image.depth {
            depth_cue(&mut image.rgb, depth);
        }
        png::write_rgb_png(&out.path(file), VIEW_SIZE, VIEW_SIZE, &image.rgb).map_err(err)?;
        let s = image.stats;
        let _ = writeln!(
            md,
            "| {name} | [`{file}`]({file}) | {} | {} | {} | {secs:.3} |",
            s.nodes_visited, s.culled, s.leaves_drawn
        );
        let _ = write!(images, "![{name}]({file}) ");
    }
    let t = Instant::now();
    let d = line_drawing(scene, ISO_TOWARD_EYE, HiddenLineMethod::Bucketed).map_err(err)?;
    let secs = t.elapsed().as_secs_f64();
    let segs = d.segments_2d();
    if segs.is_empty() {
        return Err("the line drawing has no lines".into());
    }
    out.write("views_lines.svg", &svg::lines_svg(&segs, 900, 900, 0.8))?;
    png::lines_canvas(&segs, 900, 900)
        .and_then(|c| c.write_png(&out.path("views_lines.png")))
        .map_err(err)?;
    let s = d.stats;
    let _ = writeln!(
        md,
        "\n{images}\n\nLine drawing with hidden lines removed (Veenstra & Ahuja's method, bucketed; \
         parallel projection from the isometric-like direction): [`views_lines.svg`](views_lines.svg), \
         [`views_lines.png`](views_lines.png) — {} graphics nodes, {} segments, {} lines after joining, \
         {secs:.2} s.\n\n![line drawing](views_lines.png)\n\n\
         Differences from the paper: Meagher's Fig. 12–13 are photographs of a raster display at the \
         resolution of 1982; ours are computed images of our own scene (see (a)), so only the kinds of view \
         compare.",
        s.graphics_nodes, s.segments, s.lines
    );
    Ok(md)
}
