//! `--plot FILE.svg`: the run's timeline as one SVG chart (plotters' SVG backend) — p50 and p99
//! latency per second on the left axis, requests and errors per second on the right.

use std::path::Path;

use plotters::prelude::*;
use serde_json::Value;

/// Series colours: p50, p99, throughput, errors.
const P50: RGBColor = RGBColor(31, 119, 180);
const P99: RGBColor = RGBColor(214, 39, 40);
const RATE: RGBColor = RGBColor(44, 160, 44);
const ERRORS: RGBColor = RGBColor(255, 127, 14);

/// Draw `timeline` (the report's per-second rows) to `path`, titled `title`; written whole.
pub fn write(path: &Path, title: &str, timeline: &[Value]) -> Result<(), String> {
    let mut svg = String::new();
    draw(&mut svg, title, timeline).map_err(|e| format!("{}: drawing the plot: {e}", path.display()))?;
    textile_core::files::write_atomic(path, svg.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))
}

fn draw(svg: &mut String, title: &str, timeline: &[Value]) -> Result<(), Box<dyn std::error::Error>> {
    let col = |k: &str| -> Vec<(f64, f64)> {
        timeline.iter().filter_map(|t| Some((t["second"].as_f64()? + 0.5, t[k].as_f64()?))).collect()
    };
    let (p50, p99, rate, errors) = (col("p50_ms"), col("p99_ms"), col("requests"), col("errors"));
    let seconds = timeline.len().max(1) as f64;
    let top_ms = p99.iter().map(|p| p.1).fold(1.0, f64::max) * 1.1;
    let top_rate = rate.iter().map(|p| p.1).fold(1.0, f64::max) * 1.1;
    {
        let root = SVGBackend::with_string(svg, (960, 480)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .right_y_label_area_size(60)
            .build_cartesian_2d(0.0..seconds, 0.0..top_ms)?
            .set_secondary_coord(0.0..seconds, 0.0..top_rate);
        chart.configure_mesh().x_desc("seconds").y_desc("latency (ms)").draw()?;
        chart.configure_secondary_axes().y_desc("requests per second").draw()?;
        chart
            .draw_series(LineSeries::new(p50, P50.stroke_width(2)))?
            .label("p50 latency (ms)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], P50.stroke_width(2)));
        chart
            .draw_series(LineSeries::new(p99, P99.stroke_width(2)))?
            .label("p99 latency (ms)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], P99.stroke_width(2)));
        chart
            .draw_secondary_series(LineSeries::new(rate, RATE.stroke_width(2)))?
            .label("requests/s")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], RATE.stroke_width(2)));
        chart
            .draw_secondary_series(LineSeries::new(errors, ERRORS.stroke_width(2)))?
            .label("errors/s")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], ERRORS.stroke_width(2)));
        chart.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(BLACK).draw()?;
        root.present()?;
    }
    Ok(())
}
