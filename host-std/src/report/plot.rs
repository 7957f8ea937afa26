//! The log-log plot of relMSE against render time.

use crate::report::{Measurement, Series};
use std::path::Path;

static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// The log-log plot of relMSE against time, one line per series (method, and K where the
/// report sweeps it), as SVG and PNG.
pub fn plot(path_svg: &Path, path_png: &Path, title: &str, measurements: &[Measurement]) -> Result<(), String> {
    use plotters::prelude::*;
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    let (mut t0, mut t1, mut e0, mut e1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for m in measurements.iter().filter(|m| m.seconds > 0.0 && m.relmse > 0.0) {
        (t0, t1, e0, e1) = (t0.min(m.seconds), t1.max(m.seconds), e0.min(m.relmse), e1.max(m.relmse));
    }
    if !(t0 < t1 && e0 < e1) {
        (t0, t1, e0, e1) = (t0.min(1e-3), t1.max(1.0), e0.min(1e-6), e1.max(1.0));
    }
    // In order of first appearance (bracketing renders come last).
    let mut series: Vec<Series> = Vec::new();
    for m in measurements {
        if !series.contains(&m.series()) {
            series.push(m.series());
        }
    }
    fn draw<DB: DrawingBackend>(
        root: DrawingArea<DB, plotters::coord::Shift>,
        title: &str,
        ranges: (f64, f64, f64, f64),
        series: &[Series],
        measurements: &[Measurement],
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let (t0, t1, e0, e1) = ranges;
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d((t0 / 1.3..t1 * 1.3).log_scale(), (e0 / 1.5..e1 * 1.5).log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("render time (s)")
            .y_desc("relMSE")
            .x_label_formatter(&|x| format!("{x:.3}"))
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| e.to_string())?;
        for (k, &line) in series.iter().enumerate() {
            let colour = Palette99::pick(k).to_rgba();
            let mut pts: Vec<(f64, f64)> = measurements
                .iter()
                .filter(|m| m.series() == line && m.seconds > 0.0 && m.relmse > 0.0)
                .map(|m| (m.seconds, m.relmse))
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            chart
                .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(line.to_string())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled()))).map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())
    }
    let ranges = (t0, t1, e0, e1);
    draw(SVGBackend::new(path_svg, (900, 600)).into_drawing_area(), title, ranges, &series, measurements)?;
    draw(BitMapBackend::new(path_png, (900, 600)).into_drawing_area(), title, ranges, &series, measurements)?;
    Ok(())
}
