//! Plots as SVG and PNG with plotters. PNG text needs a TrueType font: the DejaVu Sans of the system
//! (`/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf`, Debian's fonts-dejavu-core) is registered once when
//! present (plotters' `ab_glyph` text needs it for both backends, as it measures text with the font); without
//! it the plots are drawn without any text and the report says so.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

/// One series: a name, points, and whether to join them with a line.
pub struct Series {
    /// Legend name.
    pub name: String,
    /// Points.
    pub points: Vec<(f64, f64)>,
    /// Draw a line (else markers).
    pub line: bool,
    /// Colour index.
    pub colour: usize,
}

/// A 2-D plot.
pub struct Plot {
    /// Caption.
    pub title: String,
    /// X axis label.
    pub x_label: String,
    /// Y axis label.
    pub y_label: String,
    /// Logarithmic axes.
    pub log: bool,
    /// The series.
    pub series: Vec<Series>,
}

fn colour(i: usize) -> RGBColor {
    [
        BLUE,
        RED,
        RGBColor(0, 150, 0),
        MAGENTA,
        BLACK,
        RGBColor(200, 120, 0),
    ][i % 6]
}

impl Plot {
    fn bounds(&self) -> (f64, f64, f64, f64) {
        let pts = self.series.iter().flat_map(|s| s.points.iter());
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &(x, y) in pts {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        if self.log {
            (x0 / 2.0, x1 * 2.0, y0 / 2.0, y1 * 2.0)
        } else {
            let (dx, dy) = ((x1 - x0).max(1e-9) * 0.05, (y1 - y0).max(1e-9) * 0.05);
            (x0.min(0.0), x1 + dx, y0.min(0.0), y1 + dy)
        }
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
        text: bool,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(e)?;
        let (x0, x1, y0, y1) = self.bounds();
        let mut b = ChartBuilder::on(&root);
        b.margin(20);
        if text {
            b.caption(&self.title, ("sans-serif", 22))
                .x_label_area_size(50)
                .y_label_area_size(80);
        } else {
            b.x_label_area_size(5).y_label_area_size(5);
        }
        macro_rules! body {
            ($chart:expr) => {{
                let mut chart = $chart;
                let mut mesh = chart.configure_mesh();
                if text {
                    mesh.x_desc(self.x_label.as_str())
                        .y_desc(self.y_label.as_str());
                } else {
                    mesh.disable_x_axis().disable_y_axis();
                }
                mesh.draw().map_err(e)?;
                for s in &self.series {
                    let c = colour(s.colour);
                    let drawn = if s.line {
                        chart
                            .draw_series(LineSeries::new(
                                s.points.iter().copied(),
                                c.stroke_width(2),
                            ))
                            .map_err(e)?
                    } else {
                        chart
                            .draw_series(s.points.iter().map(|&p| Circle::new(p, 5, c.filled())))
                            .map_err(e)?
                    };
                    if text {
                        drawn.label(s.name.as_str()).legend(move |(x, y)| {
                            Rectangle::new([(x, y - 4), (x + 14, y + 4)], c.filled())
                        });
                    }
                }
                if text {
                    chart
                        .configure_series_labels()
                        .background_style(WHITE.mix(0.85))
                        .border_style(BLACK)
                        .position(SeriesLabelPosition::UpperLeft)
                        .draw()
                        .map_err(e)?;
                }
            }};
        }
        if self.log {
            body!(b
                .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
                .map_err(e)?);
        } else {
            body!(b.build_cartesian_2d(x0..x1, y0..y1).map_err(e)?);
        }
        root.present().map_err(e)?;
        Ok(())
    }

    /// Writes `base.svg` and `base.png`.
    pub fn write(&self, base: &Path) -> Result<(), String> {
        if let Some(dir) = base.parent() {
            std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
        }
        let svg = base.with_extension("svg");
        let png = base.with_extension("png");
        let mut text = String::new();
        {
            let root = SVGBackend::with_string(&mut text, (900, 600)).into_drawing_area();
            self.draw(root, crate::common::font_available())?;
        }
        ktree::fs::write_atomic(&svg, text.as_bytes()).map_err(|e| e.to_string())?;
        let mut pixels = vec![0u8; 900 * 600 * 3];
        {
            let root = BitMapBackend::with_buffer(&mut pixels, (900, 600)).into_drawing_area();
            self.draw(root, crate::common::font_available())?;
        }
        ktree::display::png::write_rgb_png(&png, 900, 600, &pixels).map_err(|e| e.to_string())
    }
}
