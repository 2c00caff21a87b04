//! Log-log relMSE-versus-time plots (SVG through plotters; no font files needed: text is written
//! as SVG `<text>` and laid out by the viewer).

use std::path::Path;

use plotters::prelude::*;

use crate::error::BenchError;

/// One configuration's curve.
pub(crate) struct Series {
    /// Legend text.
    pub label: String,
    /// `(median seconds, median relMSE, min relMSE, max relMSE)` per budget, by time.
    pub medians: Vec<(f64, f64, f64, f64)>,
    /// Every run's `(seconds, relMSE)`.
    pub points: Vec<(f64, f64)>,
}

const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

fn usable(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// Lower and upper ends of a log axis holding `values`, widened a little.
fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| usable(*v))
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (0.1, 10.0);
    }
    // Whole decades, so that the log axes always have labelled ticks.
    let lo = 10f64.powf(lo.log10().floor());
    let hi = 10f64.powf(hi.log10().ceil()).max(lo * 10.0);
    (lo, hi)
}

/// `0.5`, `1`, `10`: a tick value without trailing zeros.
fn short(x: f64) -> String {
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Writes the plot of `series` to `path` (SVG); `reference_noise` draws a grey horizontal line.
pub(crate) fn relmse_plot(
    path: &Path,
    title: &str,
    series: &[Series],
    reference_noise: Option<f64>,
) -> Result<(), BenchError> {
    draw(path, title, series, reference_noise).map_err(|e| BenchError::Plot {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

fn draw(
    path: &Path,
    title: &str,
    series: &[Series],
    reference_noise: Option<f64>,
) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (760, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let (xmin, xmax) = log_range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let (ymin, ymax) = log_range(
        series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1))
            .chain(reference_noise),
    );
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .margin_right(28)
        .x_label_area_size(45)
        .y_label_area_size(75)
        .build_cartesian_2d((xmin..xmax).log_scale(), (ymin..ymax).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("render time (s)")
        .y_desc("relMSE")
        .x_label_formatter(&|x| short(*x))
        .y_label_formatter(&|y| format!("{y:.1e}"))
        .draw()?;
    for (i, s) in series.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let line: Vec<(f64, f64)> = s
            .medians
            .iter()
            .filter(|m| usable(m.0) && usable(m.1))
            .map(|m| (m.0, m.1))
            .collect();
        chart
            .draw_series(LineSeries::new(line, color.stroke_width(2)))?
            .label(s.label.as_str())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], color.stroke_width(2))
            });
        // Min–max over seeds as a vertical bar at the median time.
        chart.draw_series(
            s.medians
                .iter()
                .filter(|m| usable(m.0) && usable(m.2) && usable(m.3))
                .map(|m| PathElement::new(vec![(m.0, m.2), (m.0, m.3)], color.stroke_width(1))),
        )?;
        chart.draw_series(
            s.points
                .iter()
                .filter(|p| usable(p.0) && usable(p.1))
                .map(|&p| Circle::new(p, 2, color.mix(0.6).filled())),
        )?;
    }
    if let Some(noise) = reference_noise.filter(|n| usable(*n)) {
        let grey = RGBColor(120, 120, 120);
        chart
            .draw_series(LineSeries::new(
                vec![(xmin, noise), (xmax, noise)],
                grey.stroke_width(1),
            ))?
            .label("reference's own relMSE (est.)")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], grey.stroke_width(1))
            });
    }
    chart
        .configure_series_labels()
        // Error falls with time: the lower left is the emptiest corner.
        .position(SeriesLabelPosition::LowerLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

/// One configuration's relMSE per frame of a sequence.
pub(crate) struct FrameSeries {
    /// Legend text.
    pub label: String,
    /// `(frame, relMSE)` by frame.
    pub points: Vec<(u32, f64)>,
}

/// Writes the per-frame relMSE plot of a sequence to `path` (SVG): frames on a linear axis,
/// relMSE on a log axis, one line with dots per configuration.
pub(crate) fn frame_plot(
    path: &Path,
    title: &str,
    series: &[FrameSeries],
) -> Result<(), BenchError> {
    draw_frames(path, title, series).map_err(|e| BenchError::Plot {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

fn draw_frames(
    path: &Path,
    title: &str,
    series: &[FrameSeries],
) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (760, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let frames = series.iter().flat_map(|s| s.points.iter().map(|p| p.0));
    let (first, last) = frames.fold((u32::MAX, 0), |(a, b), f| (a.min(f), b.max(f)));
    let (first, last) = if first > last {
        (0, 1)
    } else {
        (first, last.max(first + 1))
    };
    let (ymin, ymax) = log_range(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .margin_right(28)
        .x_label_area_size(45)
        .y_label_area_size(75)
        .build_cartesian_2d(
            f64::from(first) - 0.5..f64::from(last) + 0.5,
            (ymin..ymax).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("frame")
        .y_desc("relMSE")
        .x_label_formatter(&|x| short(x.round()))
        .y_label_formatter(&|y| format!("{y:.1e}"))
        .draw()?;
    for (i, s) in series.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter(|p| usable(p.1))
            .map(|&(f, e)| (f64::from(f), e))
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))?
            .label(s.label.as_str())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], color.stroke_width(2))
            });
        chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_span_whole_decades() {
        let close = |(a, b): (f64, f64), (c, d): (f64, f64)| {
            assert!(
                (a / c - 1.0).abs() < 1e-9 && (b / d - 1.0).abs() < 1e-9,
                "{a} {b}"
            );
        };
        close(log_range([0.5, 8.0].into_iter()), (0.1, 10.0));
        close(log_range([2e-3, 3e-3].into_iter()), (1e-3, 1e-2));
        close(log_range(std::iter::empty()), (0.1, 10.0));
        assert_eq!(short(10.0), "10");
        assert_eq!(short(0.5), "0.5");
    }
}
