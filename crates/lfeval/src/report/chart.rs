//! Charts drawn with plotters: sparsification curves of all methods (thesis Fig. 5.5) and
//! posteriors at single pixels against the true modes (thesis Fig. 5.1).
//!
//! Text uses DejaVu Sans embedded in the binary, so charts look the same on machines
//! without fonts; pixels are drawn into a buffer and encoded with the `image` crate.

use std::path::Path;

use anyhow::{Result, anyhow};
use lfdata::bins::Bins;
use lfdata::font;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::Evaluation;
use super::samples::PosteriorSample;
use crate::summary::{CurveSummary, SparsificationSummary};

/// The two error measures that have sparsification curves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Measure {
    /// BadPix(0.07) in %.
    BadPix,
    /// MSE×100.
    Mse,
}

impl Measure {
    /// Both, in the order of [`super::SPARSIFICATION_PLOTS`].
    pub const ALL: [Measure; 2] = [Measure::BadPix, Measure::Mse];

    fn label(self) -> &'static str {
        match self {
            Measure::BadPix => "BadPix(0.07) %",
            Measure::Mse => "MSE×100",
        }
    }

    fn pick(self, s: &SparsificationSummary) -> &CurveSummary {
        match self {
            Measure::BadPix => &s.badpix_007,
            Measure::Mse => &s.mse_x100,
        }
    }
}

/// Any plotting error as an `anyhow` error.
pub(crate) fn plot_error(e: impl std::fmt::Debug) -> anyhow::Error {
    anyhow!("drawing failed: {e:?}")
}

/// Draws with `draw` on a white `w × h` canvas and writes it to `path` as PNG.
pub(crate) fn render(
    path: &Path,
    (w, h): (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend, Shift>) -> Result<()>,
) -> Result<()> {
    font::register()?;
    let mut buffer = vec![255u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (w, h)).into_drawing_area();
        draw(&root)?;
        root.present().map_err(plot_error)?;
    }
    let img = image::RgbImage::from_raw(w, h, buffer).expect("the canvas is w × h RGB");
    Ok(lfformat::png::write_png(path, &img)?)
}

/// Colour of method `i` (colour-blind-friendly Okabe–Ito order).
pub(crate) fn colour(i: usize) -> RGBColor {
    const COLOURS: [RGBColor; 7] = [
        RGBColor(0, 114, 178),
        RGBColor(213, 94, 0),
        RGBColor(0, 158, 115),
        RGBColor(204, 121, 167),
        RGBColor(230, 159, 0),
        RGBColor(86, 180, 233),
        RGBColor(120, 120, 120),
    ];
    COLOURS[i % COLOURS.len()]
}

/// `sparsification_*.png`: left, every method's curve (solid) and Oracle (dashed); right,
/// the sparsification errors. Methods without uncertainty are left out.
pub fn sparsification(eval: &Evaluation, measure: Measure, path: &Path) -> Result<()> {
    let series: Vec<(usize, &str, &SparsificationSummary)> = eval
        .methods
        .iter()
        .enumerate()
        .filter_map(|(i, m)| {
            Some((
                i,
                m.method.name.as_str(),
                m.summary.sparsification.as_ref()?,
            ))
        })
        .collect();
    render(path, (1400, 560), |root| {
        let panels = root.split_evenly((1, 2));
        let curves: Vec<_> = series
            .iter()
            .map(|&(i, name, s)| (i, name, s, measure.pick(s)))
            .collect();
        let lines = |c: &CurveSummary| vec![c.curve.clone(), c.oracle.clone()];
        draw_curves(
            &panels[0],
            &format!("Sparsification, {}", measure.label()),
            &curves,
            lines,
        )?;
        draw_curves(
            &panels[1],
            "Sparsification error (curve − Oracle)",
            &curves,
            |c| vec![c.error.clone()],
        )
    })
}

/// One panel: for each method the lines `lines(curve)` over the removed fraction, the
/// first solid and labelled with its AuSE, the others dashed (the Oracle).
fn draw_curves(
    area: &DrawingArea<BitMapBackend, Shift>,
    title: &str,
    curves: &[(usize, &str, &SparsificationSummary, &CurveSummary)],
    lines: impl Fn(&CurveSummary) -> Vec<Vec<f64>>,
) -> Result<()> {
    let y_max = curves
        .iter()
        .flat_map(|c| lines(c.3).into_iter().flatten())
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let y_max = if y_max > 0.0 { y_max * 1.05 } else { 1.0 };
    let mut chart = ChartBuilder::on(area)
        .caption(title, (font::FAMILY, 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..1.0, 0.0..y_max)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc("fraction of pixels removed")
        .label_style((font::FAMILY, 14))
        .draw()
        .map_err(plot_error)?;
    for &(i, name, s, c) in curves {
        let style = colour(i).stroke_width(2);
        for (k, values) in lines(c).into_iter().enumerate() {
            let points = s.fractions.iter().copied().zip(values);
            if k == 0 {
                let label = format!(
                    "{name} (AuSE {})",
                    c.ause.map_or("–".into(), |a| format!("{a:.3}"))
                );
                chart
                    .draw_series(LineSeries::new(points, style))
                    .map_err(plot_error)?
                    .label(label)
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style));
            } else {
                chart
                    .draw_series(DashedLineSeries::new(
                        points,
                        6,
                        4,
                        colour(i).stroke_width(1),
                    ))
                    .map_err(plot_error)?;
            }
        }
    }
    if !curves.is_empty() {
        chart
            .configure_series_labels()
            .label_font((font::FAMILY, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(plot_error)?;
    }
    Ok(())
}

/// `posteriors/<scene>_x<X>_y<Y>.png`: each method's probability per bin as a step line,
/// and the true modes as black stems of height `η`.
pub fn posterior(sample: &PosteriorSample, bins: &Bins, path: &Path) -> Result<()> {
    let y_max = sample
        .methods
        .iter()
        .flat_map(|m| m.masses.iter().copied())
        .chain(sample.modes.iter().map(|m| m.1))
        .fold(0.0f64, f64::max)
        .clamp(0.05, 1.0)
        * 1.08;
    render(path, (900, 520), |root| {
        let title = format!(
            "{} pixel ({}, {}): posterior vs true modes",
            sample.scene, sample.x, sample.y
        );
        let mut chart = ChartBuilder::on(root)
            .caption(title, (font::FAMILY, 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(bins.min..bins.max, 0.0..y_max)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("disparity (px)")
            .y_desc("probability per bin / η")
            .label_style((font::FAMILY, 14))
            .draw()
            .map_err(plot_error)?;
        for (i, m) in sample.methods.iter().enumerate() {
            let steps = m
                .masses
                .iter()
                .enumerate()
                .flat_map(|(k, &p)| [(bins.edge(k), p), (bins.edge(k + 1), p)]);
            let style = colour(i).stroke_width(2);
            chart
                .draw_series(LineSeries::new(steps, style))
                .map_err(plot_error)?
                .label(format!("{} (estimate {:.3})", m.method, m.disparity))
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style));
        }
        let stems = sample
            .modes
            .iter()
            .map(|&(d, eta)| PathElement::new([(d, 0.0), (d, eta)], BLACK.stroke_width(3)));
        chart
            .draw_series(stems)
            .map_err(plot_error)?
            .label("true modes (height η)")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.stroke_width(3)));
        chart
            .configure_series_labels()
            .label_font((font::FAMILY, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(plot_error)
    })
}
