//! The exact stage's run time against error (`orthosim bench --sweep`, the report's sweep): per
//! tolerance, the µs per pair query (left panel) and the largest gap or penetration left at a
//! reported contact beside the tolerance itself (right panel), both on log scales.

use std::path::Path;

use plotters::{coord::Shift, prelude::*};

use super::{AnalysisError, plot::font};
use crate::collision::bench::ParetoPoint;

const TIME: RGBColor = RGBColor(33, 102, 172);
const ERROR: RGBColor = RGBColor(214, 96, 77);

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    points: &[ParetoPoint],
) -> Result<(), AnalysisError>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| AnalysisError::Plot(e.to_string());
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, (font(), 20)).map_err(err)?;
    let (left, right) = root.split_horizontally(root.dim_in_pixel().0 / 2);
    let tol: Vec<f64> = points.iter().map(|p| p.tolerance_mm).collect();
    let range = |v: &[f64]| {
        let lo = v
            .iter()
            .copied()
            .filter(|x| *x > 0.0)
            .fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(0.0, f64::max);
        if lo.is_finite() && hi > lo {
            (lo / 1.5, hi * 1.5)
        } else if lo.is_finite() {
            (lo / 2.0, lo * 2.0)
        } else {
            (1e-4, 1.0)
        }
    };
    let (x_lo, x_hi) = range(&tol);
    let panels: [(&DrawingArea<DB, Shift>, &str, RGBColor); 2] = [
        (&left, "µs per near-contact pair query", TIME),
        (&right, "largest error at a contact (mm)", ERROR),
    ];
    for (k, (area, y_desc, colour)) in panels.into_iter().enumerate() {
        let values: Vec<f64> = points
            .iter()
            .map(|p| {
                if k == 0 {
                    p.us_per_pair
                } else {
                    p.max_error_mm
                }
            })
            .collect();
        let (mut lo, mut hi) = range(&values);
        if k == 1 {
            lo = lo.min(x_lo);
            hi = hi.max(x_hi);
        }
        let line: Vec<(f64, f64)> = tol
            .iter()
            .zip(&values)
            .filter(|(_, v)| **v > 0.0)
            .map(|(t, v)| (*t, *v))
            .collect();
        // The two panels' charts differ in type (linear and log time axis), so the drawing
        // common to both is written once here.
        macro_rules! finish {
            ($chart:ident, $y_fmt:expr) => {
                $chart
                    .configure_mesh()
                    .x_desc("tolerance (mm)")
                    .y_desc(y_desc)
                    .x_label_formatter(&|x| format!("{x}"))
                    .y_label_formatter(&$y_fmt)
                    .label_style((font(), 12))
                    .axis_desc_style((font(), 13))
                    .draw()
                    .map_err(err)?;
                if k == 1 {
                    $chart
                        .draw_series(LineSeries::new(
                            [(x_lo, x_lo), (x_hi, x_hi)],
                            BLACK.stroke_width(1),
                        ))
                        .map_err(err)?
                        .label("error = tolerance")
                        .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK));
                }
                $chart
                    .draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))
                    .map_err(err)?
                    .label(if k == 0 { "run time" } else { "max error" })
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], colour));
                $chart
                    .draw_series(line.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                    .map_err(err)?;
                $chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperRight)
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .label_font((font(), 12))
                    .draw()
                    .map_err(err)?;
            };
        }
        let mut builder = ChartBuilder::on(area);
        builder
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(64);
        if k == 0 {
            // Run times span less than a decade: a linear axis from 0 labels them.
            let mut chart = builder
                .build_cartesian_2d((x_lo..x_hi).log_scale(), 0.0..hi / 1.5 * 1.15)
                .map_err(err)?;
            finish!(chart, |y: &f64| format!("{y:.0}"));
        } else {
            let mut chart = builder
                .build_cartesian_2d((x_lo..x_hi).log_scale(), (lo..hi).log_scale())
                .map_err(err)?;
            finish!(chart, |y: &f64| format!("{y:.3}"));
        }
    }
    root.present().map_err(err)
}

/// The plot as SVG text.
///
/// # Errors
/// [`AnalysisError::Plot`] when it cannot be drawn.
pub fn pareto_svg(title: &str, points: &[ParetoPoint]) -> Result<String, AnalysisError> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (1100, 480)).into_drawing_area();
        draw(root, title, points)?;
    }
    Ok(out)
}

/// The plot as a PNG file at `path` (drawn beside it, then renamed into place).
///
/// # Errors
/// [`AnalysisError::Plot`] when it cannot be drawn, [`AnalysisError::Output`] when it cannot be
/// moved into place.
pub fn pareto_png(path: &Path, title: &str, points: &[ParetoPoint]) -> Result<(), AnalysisError> {
    super::plot::write_png(path, (1100, 480), |root| draw(root, title, points))
}
