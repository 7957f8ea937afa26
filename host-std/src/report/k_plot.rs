//! The K sweep's figure: relMSE at equal time against K (log₂ across), one panel per region,
//! one line per method at its own equal time, extrapolated points hollow.

use crate::report::{KCurve, KSweep};
use std::path::Path;

static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// Panels per row.
const COLUMNS: usize = 3;

/// Draws `sweep` as SVG and PNG: K across (log₂), relMSE (log) up, a panel per region.
pub fn plot_k(path_svg: &Path, path_png: &Path, title: &str, sweep: &KSweep) -> Result<(), String> {
    use plotters::prelude::*;
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    let mut regions: Vec<&str> = Vec::new();
    for c in &sweep.curves {
        if !regions.contains(&c.region.as_str()) {
            regions.push(&c.region);
        }
    }
    let rows = regions.len().div_ceil(COLUMNS).max(1);
    let columns = regions.len().clamp(1, COLUMNS);
    let size = (460 * columns as u32, 40 + 360 * rows as u32);
    draw_all(SVGBackend::new(path_svg, size).into_drawing_area(), title, sweep, &regions, (rows, columns))?;
    draw_all(BitMapBackend::new(path_png, size).into_drawing_area(), title, sweep, &regions, (rows, columns))
}

/// The title and every region's panel on `root`, `grid` (rows, columns) of them.
fn draw_all<DB: plotters::prelude::DrawingBackend>(
    root: plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    sweep: &KSweep,
    regions: &[&str],
    grid: (usize, usize),
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    use plotters::prelude::*;
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(|e| e.to_string())?;
    for (panel, region) in root.split_evenly(grid).iter().zip(regions) {
        let curves: Vec<&KCurve> = sweep.curves.iter().filter(|c| c.region == *region).collect();
        draw_panel(panel, region, sweep, &curves)?;
    }
    root.present().map_err(|e| e.to_string())
}

/// One region's panel.
fn draw_panel<DB: plotters::prelude::DrawingBackend>(
    area: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    region: &str,
    sweep: &KSweep,
    curves: &[&KCurve],
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    use plotters::prelude::*;
    // log₂ K across, so that the axis is labelled at the powers of two.
    let log2 = |k: usize| (k.max(1) as f64).log2();
    let k0 = log2(sweep.ks.first().copied().unwrap_or(1));
    let k1 = log2(sweep.ks.last().copied().unwrap_or(1));
    let (mut e0, mut e1) = (f64::INFINITY, 0.0f64);
    for p in curves.iter().flat_map(|c| &c.points).filter(|p| p.relmse > 0.0) {
        (e0, e1) = (e0.min(p.relmse), e1.max(p.relmse));
    }
    if e0.partial_cmp(&e1) != Some(std::cmp::Ordering::Less) {
        (e0, e1) = (e0.min(1e-6), e1.max(1.0));
    }
    let name = if region == "all" { "whole image" } else { region };
    let mut chart = ChartBuilder::on(area)
        .caption(name, ("sans-serif", 16))
        .margin(8)
        .x_label_area_size(36)
        .y_label_area_size(64)
        .build_cartesian_2d(k0 - 0.3..k1 + 0.3, (e0 / 1.5..e1 * 1.5).log_scale())
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("BRDF samples K")
        .y_desc("relMSE at equal time")
        .x_labels((k1 - k0) as usize + 2)
        .max_light_lines(2)
        .x_label_formatter(&|x| format!("{:.0}", x.exp2()))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .label_style(("sans-serif", 12))
        .draw()
        .map_err(|e| e.to_string())?;
    for (k, c) in curves.iter().enumerate() {
        let colour = Palette99::pick(k).to_rgba();
        let style = colour.stroke_width(2);
        let pts: Vec<(f64, f64)> =
            c.points.iter().filter(|p| p.relmse > 0.0).map(|p| (log2(p.brdf_samples), p.relmse)).collect();
        chart
            .draw_series(LineSeries::new(pts, style))
            .map_err(|e| e.to_string())?
            .label(format!("{} ({:.2} s)", c.method, c.seconds))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
        // Extrapolated points hollow.
        let marks = c.points.iter().filter(|p| p.relmse > 0.0).map(|p| {
            let at = (log2(p.brdf_samples), p.relmse);
            Circle::new(at, 3, if p.extrapolated { style } else { colour.filled() })
        });
        chart.draw_series(marks).map_err(|e| e.to_string())?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 12))
        .draw()
        .map_err(|e| e.to_string())
}
