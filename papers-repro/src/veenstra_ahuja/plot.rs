//! Fig. 12's plot: line-drawing time against the number of octree nodes, both hidden-line methods, as
//! SVG and PNG (plotters). Text needs a font; the first common system font found is registered at run
//! time (shared with the Meagher reproduction's plots), and without one the plot is skipped (the CSV and table still hold the numbers).

use plotters::coord::Shift;
use plotters::prelude::*;

/// The font registration is the Meagher reproduction's (one list of system fonts for both).
pub use crate::common::font_available;

/// The two series: (nodes, seconds) for the pairwise and the bucketed method.
pub struct Fig12<'a> {
    /// The paper's method.
    pub pairwise: &'a [(f64, f64)],
    /// Ours.
    pub bucketed: &'a [(f64, f64)],
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, data: &Fig12) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let all = data.pairwise.iter().chain(data.bucketed);
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for &(x, y) in all {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y.max(1e-6));
        y1 = y1.max(y);
    }
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Line drawing time vs octree nodes (Fig. 12)",
            ("sans-serif", 22),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (x0 / 1.5..x1 * 1.5).log_scale(),
            (y0 / 2.0..y1 * 2.0).log_scale(),
        )
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc("nodes in the octree")
        .y_desc("seconds (one core)")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| err(&e))?;
    chart
        .draw_series(
            data.pairwise
                .iter()
                .map(|&(x, y)| Circle::new((x, y), 4, RED.filled())),
        )
        .map_err(|e| err(&e))?
        .label("pairwise hidden-line removal (the paper's, quadratic)")
        .legend(|(x, y)| Circle::new((x, y), 4, RED.filled()));
    chart
        .draw_series(
            data.bucketed
                .iter()
                .map(|&(x, y)| Cross::new((x, y), 5, BLUE.stroke_width(2))),
        )
        .map_err(|e| err(&e))?
        .label("bucketed (ours): screen grid of earlier graphics nodes")
        .legend(|(x, y)| Cross::new((x, y), 5, BLUE.stroke_width(2)));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// The plot as an SVG document and as RGB pixels (`w × h`), `None` without a font.
///
/// # Errors
/// A message if drawing fails.
pub fn fig12(data: &Fig12, w: u32, h: u32) -> Result<Option<(String, Vec<u8>)>, String> {
    if !font_available() {
        return Ok(None);
    }
    let mut svg = String::new();
    draw(
        SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area(),
        data,
    )?;
    let mut rgb = vec![255u8; 3 * w as usize * h as usize];
    draw(
        BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area(),
        data,
    )?;
    Ok(Some((svg, rgb)))
}
