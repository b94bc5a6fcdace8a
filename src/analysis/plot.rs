//! Plots like the paper's Figures 3–5: per adjacent pair of teeth, the centre distance and the
//! surface gap under each algorithm, with the 1 mm clinical line, as SVG and PNG (plotters, with a
//! bundled font so no system font library is needed).

use std::{path::Path, sync::OnceLock};

use plotters::{coord::Shift, prelude::*, style::FontStyle};

use super::{AnalysisError, measures::GAP_FLAG_MM};
use crate::io::OutputError;

/// One algorithm's values per pair.
pub struct Series<'a> {
    /// Algorithm name.
    pub name: &'a str,
    /// Centre distance per pair (mm).
    pub centre: Vec<f32>,
    /// Surface gap per pair (mm).
    pub gap: Vec<f32>,
}

const COLOURS: [RGBColor; 4] = [
    RGBColor(214, 96, 77),
    RGBColor(67, 147, 195),
    RGBColor(33, 102, 172),
    RGBColor(27, 120, 55),
];

pub(super) fn font() -> &'static str {
    static DONE: OnceLock<()> = OnceLock::new();
    DONE.get_or_init(|| {
        // The font is a valid TrueType file bundled by the crate; failure would be a build error.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        );
    });
    "sans-serif"
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    labels: &[String],
    series: &[Series],
) -> Result<(), AnalysisError>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| AnalysisError::Plot(e.to_string());
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, (font(), 22)).map_err(err)?;
    let (top, bottom) = root.split_vertically(root.dim_in_pixel().1 / 2);
    let n = labels.len().max(1);
    let label = |x: &f64| {
        let i = x.round();
        if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < labels.len() {
            labels[i as usize].clone()
        } else {
            String::new()
        }
    };
    let panels: [(&DrawingArea<DB, Shift>, &str, bool); 2] = [
        (&top, "centre distance in the x–z plane (mm)", false),
        (&bottom, "surface gap (mm), 1 mm line", true),
    ];
    for (area, y_desc, gap) in panels {
        let values = |s: &Series| if gap { s.gap.clone() } else { s.centre.clone() };
        let all: Vec<f32> = series
            .iter()
            .flat_map(values)
            .filter(|v| v.is_finite())
            .collect();
        let lo = all.iter().copied().fold(f32::INFINITY, f32::min).min(0.0) as f64;
        let mut hi = all.iter().copied().fold(f32::NEG_INFINITY, f32::max) as f64;
        if gap {
            hi = hi.max(GAP_FLAG_MM as f64 * 1.2);
        }
        if !hi.is_finite() || hi <= lo {
            hi = lo + 1.0;
        }
        let mut chart = ChartBuilder::on(area)
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(-0.5f64..(n as f64 - 0.5), lo..hi * 1.05)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_labels(n)
            .x_label_formatter(&label)
            .x_label_style((font(), 11))
            .y_label_style((font(), 12))
            .y_desc(y_desc)
            .axis_desc_style((font(), 13))
            .draw()
            .map_err(err)?;
        if gap {
            chart
                .draw_series(LineSeries::new(
                    [
                        (-0.5, GAP_FLAG_MM as f64),
                        (n as f64 - 0.5, GAP_FLAG_MM as f64),
                    ],
                    BLACK.stroke_width(1),
                ))
                .map_err(err)?
                .label("1 mm")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK));
        }
        for (k, s) in series.iter().enumerate() {
            let colour = COLOURS[k % COLOURS.len()];
            let points: Vec<(f64, f64)> = values(s)
                .iter()
                .enumerate()
                .map(|(i, v)| (i as f64, *v as f64))
                .collect();
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(err)?
                .label(s.name)
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], colour));
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                .map_err(err)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font((font(), 12))
            .draw()
            .map_err(err)?;
    }
    root.present().map_err(err)
}

/// The plot as SVG text.
///
/// # Errors
/// [`AnalysisError::Plot`] when the plot cannot be drawn.
pub fn svg(title: &str, labels: &[String], series: &[Series]) -> Result<String, AnalysisError> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (1100, 760)).into_drawing_area();
        draw(root, title, labels, series)?;
    }
    Ok(out)
}

/// The plot as a PNG file at `path` (drawn beside it, then renamed, so no half file is left).
///
/// # Errors
/// [`AnalysisError::Plot`] when the plot cannot be drawn, [`AnalysisError::Output`] when it cannot
/// be moved into place.
pub fn png(
    path: &Path,
    title: &str,
    labels: &[String],
    series: &[Series],
) -> Result<(), AnalysisError> {
    write_png(path, (1100, 760), |root| draw(root, title, labels, series))
}

/// Draws a `size` picture with `draw` into a PNG beside `path`, then renames it into place, so
/// no half-written file is ever left at `path`.
pub(super) fn write_png(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), AnalysisError>,
) -> Result<(), AnalysisError> {
    let name = path
        .file_name()
        .map_or_else(|| "plot".into(), |n| n.to_string_lossy().into_owned());
    let tmp = path.with_file_name(format!(".{name}.tmp-{}.png", std::process::id()));
    draw(BitMapBackend::new(&tmp, size).into_drawing_area())?;
    std::fs::rename(&tmp, path).map_err(|source| {
        let _ = std::fs::remove_file(&tmp);
        AnalysisError::Output(OutputError::Write {
            path: path.to_owned(),
            source,
        })
    })
}
