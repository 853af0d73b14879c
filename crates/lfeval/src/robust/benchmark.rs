//! `lfeval robustness`: every method scored on every corrupted copy `lfeval corrupt` wrote,
//! as tables (`robustness.md`, `robustness.json`) and a plot of BadPix(0.07) against each
//! corruption's strength (`robustness.png`).

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use lfdata::font;
use lfdata::prediction::Method;
use lfdata::scene_eval::EvalConfig;
use lfformat::dataset::discover;
use plotters::prelude::*;
use serde::Serialize;

use super::corruption::{BENCHMARK, Corruption};
use crate::pipeline::{EvalOptions, evaluate_dataset};
use crate::report::chart::{colour, plot_error, render};
use crate::report::table::Table;

/// A method's scores on one corrupted copy (front-most surface, the report's reference).
#[derive(Clone, Debug, Serialize)]
pub struct Score {
    /// BadPix(0.07), %.
    pub badpix_007: Option<f64>,
    /// MSE × 100.
    pub mse_x100: Option<f64>,
}

/// One corrupted copy and every method's scores on it.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub name: String,
    pub corruption: Corruption,
    /// Scores in the order of [`Robustness::methods`].
    pub scores: Vec<Score>,
}

/// The whole benchmark.
#[derive(Clone, Debug, Serialize)]
pub struct Robustness {
    pub methods: Vec<String>,
    pub rows: Vec<Row>,
}

/// Scores `method_roots` (each a folder holding one prediction folder per corrupted copy,
/// named as the copy) on every copy under `corrupted` that is there.
pub fn score(corrupted: &Path, method_roots: &[PathBuf], quiet: bool) -> Result<Robustness> {
    let methods: Vec<Method> = method_roots
        .iter()
        .map(|p| Method::new(p))
        .collect::<Result<_>>()?;
    let present: Vec<&Corruption> = BENCHMARK
        .iter()
        .filter(|c| corrupted.join(c.name()).is_dir())
        .collect();
    if present.is_empty() {
        bail!(
            "{}: no corrupted copy (clean, noise_1, …) inside; write them with lfeval corrupt",
            corrupted.display()
        );
    }
    let opts = EvalOptions {
        config: EvalConfig::default(),
        quiet,
        ..EvalOptions::default()
    };
    let mut rows = Vec::new();
    for c in present {
        let data = corrupted.join(c.name());
        let per_copy = methods
            .iter()
            .map(|m| {
                let dir = m.dir.join(c.name());
                Method::new(&dir).map(|found| Method {
                    name: m.name.clone(),
                    ..found
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let eval = evaluate_dataset(&data, discover(&data, &[])?, per_copy, &opts)?;
        let scores = (eval.methods.iter())
            .map(|m| {
                let s = &m.summary.unimodal[opts.config.reference.name()];
                Score {
                    badpix_007: s.badpix_007,
                    mse_x100: s.mse_x100,
                }
            })
            .collect();
        rows.push(Row {
            name: c.name(),
            corruption: *c,
            scores,
        });
    }
    let methods = methods.into_iter().map(|m| m.name).collect();
    Ok(Robustness { methods, rows })
}

impl Robustness {
    /// The table of one measure: a row per corrupted copy, a column per method, and the mean
    /// over the corrupted copies (the clean one left out).
    pub fn table(&self, title: &str, pick: fn(&Score) -> Option<f64>) -> Table {
        let mut rows: Vec<(String, Vec<Option<f64>>)> = (self.rows.iter())
            .map(|r| (r.name.clone(), r.scores.iter().map(pick).collect()))
            .collect();
        let corrupted: Vec<&Row> = (self.rows.iter())
            .filter(|r| r.corruption != Corruption::Clean)
            .collect();
        let mean = (0..self.methods.len())
            .map(|m| {
                let values: Option<Vec<f64>> =
                    corrupted.iter().map(|r| pick(&r.scores[m])).collect();
                values
                    .filter(|v| !v.is_empty())
                    .map(|v| v.iter().sum::<f64>() / v.len() as f64)
            })
            .collect();
        rows.push(("mean of the corrupted".into(), mean));
        let mut header = vec!["corruption".to_string()];
        header.extend(self.methods.iter().cloned());
        Table {
            title: title.into(),
            header,
            rows,
            note: String::new(),
            best_per_row: true,
        }
    }

    /// `robustness.md`, `robustness.json` and `robustness.png` in `out`.
    pub fn write(&self, out: &Path) -> Result<()> {
        std::fs::create_dir_all(out)
            .map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", out.display()))?;
        let md = self.table("BadPix(0.07) %", |s| s.badpix_007).to_markdown()
            + &self.table("MSE×100", |s| s.mse_x100).to_markdown();
        lfformat::files::write_atomic(&out.join("robustness.md"), md.as_bytes())?;
        let json = serde_json::to_string_pretty(self)? + "\n";
        lfformat::files::write_atomic(&out.join("robustness.json"), json.as_bytes())?;
        self.plot(&out.join("robustness.png"))
    }

    /// One panel per corruption family: each method's BadPix(0.07) against the strength, the
    /// clean score at strength 0.
    fn plot(&self, path: &Path) -> Result<()> {
        let mut families: Vec<(&str, &str)> = Vec::new();
        for r in &self.rows {
            let f = r.corruption.family();
            if f.0 != "clean" && !families.contains(&f) {
                families.push(f);
            }
        }
        let clean = self.rows.iter().find(|r| r.corruption == Corruption::Clean);
        let y_max = (self.rows.iter())
            .flat_map(|r| r.scores.iter().filter_map(|s| s.badpix_007))
            .fold(1.0f64, f64::max)
            * 1.05;
        let width = 360 * families.len().max(1) as u32;
        render(path, (width, 400), |root| {
            let panels = root.split_evenly((1, families.len().max(1)));
            for (panel, &(family, axis)) in panels.iter().zip(&families) {
                let points = |m: usize| -> Vec<(f64, f64)> {
                    let rows = (clean.into_iter()).chain(
                        self.rows
                            .iter()
                            .filter(|r| r.corruption.family().0 == family),
                    );
                    rows.filter_map(|r| Some((r.corruption.strength(), r.scores[m].badpix_007?)))
                        .collect()
                };
                let x_max = (0..self.methods.len())
                    .flat_map(points)
                    .map(|p| p.0)
                    .fold(0.0f64, f64::max)
                    .max(1e-9);
                let mut chart = ChartBuilder::on(panel)
                    .caption(family, (font::FAMILY, 18))
                    .margin(10)
                    .x_label_area_size(36)
                    .y_label_area_size(48)
                    .build_cartesian_2d(0.0..x_max * 1.05, 0.0..y_max)
                    .map_err(plot_error)?;
                chart
                    .configure_mesh()
                    .x_desc(axis)
                    .y_desc("BadPix(0.07) %")
                    .label_style((font::FAMILY, 12))
                    .draw()
                    .map_err(plot_error)?;
                for (m, name) in self.methods.iter().enumerate() {
                    let style = colour(m).stroke_width(2);
                    let dots = points(m)
                        .into_iter()
                        .map(|p| Circle::new(p, 3, style.filled()));
                    chart.draw_series(dots).map_err(plot_error)?;
                    chart
                        .draw_series(LineSeries::new(points(m), style))
                        .map_err(plot_error)?
                        .label(name.as_str())
                        .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], style));
                }
                chart
                    .configure_series_labels()
                    .label_font((font::FAMILY, 12))
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .position(SeriesLabelPosition::LowerRight)
                    .draw()
                    .map_err(plot_error)?;
            }
            Ok(())
        })
    }
}
