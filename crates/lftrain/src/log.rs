//! The run's log: `log.csv` (one row per step, appended as training goes, so it can be followed
//! with `tail -f`), `log.json` (all records, rewritten at checkpoints; `--resume` reads it) and
//! `loss.png` (training loss and validation BadPix over steps).

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use lfdata::font;
use plotters::prelude::*;
use serde::{Deserialize, Serialize};

use crate::validate::ValScores;

/// One logged step.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// Optimiser step (1-based).
    pub step: usize,
    /// Training loss of the step's batch.
    pub loss: f64,
    /// Training throughput over the step (samples per second).
    pub samples_per_s: f64,
    /// Seconds since the run started (resumed runs continue the count).
    pub elapsed_s: f64,
    /// Validation scores, at validation steps.
    pub val_mse_x100: Option<f64>,
    /// Validation BadPix(0.07) %.
    pub val_badpix_007: Option<f64>,
    /// Validation KLD.
    pub val_kld: Option<f64>,
}

impl Record {
    /// Attaches validation scores.
    pub fn with_val(mut self, v: ValScores) -> Self {
        self.val_mse_x100 = v.mse_x100;
        self.val_badpix_007 = v.badpix_007;
        self.val_kld = v.kld;
        self
    }
}

const CSV_HEADER: &str = "step,loss,samples_per_s,elapsed_s,val_mse_x100,val_badpix_007,val_kld";

/// The log files of a run.
pub struct TrainLog {
    dir: PathBuf,
    csv: File,
    /// Every record so far.
    pub records: Vec<Record>,
}

impl TrainLog {
    /// Opens the log in `dir`; with `resume`, earlier records up to `step` are kept.
    pub fn open(dir: &Path, resume: bool, step: usize) -> Result<Self> {
        let mut records: Vec<Record> = Vec::new();
        let json = dir.join("log.json");
        if resume && json.exists() {
            let text = lfformat::read::text(&json)?;
            records = serde_json::from_str(&text)
                .with_context(|| format!("{}: invalid log", json.display()))?;
            records.retain(|r| r.step <= step);
        }
        let path = dir.join("log.csv");
        let mut csv = OpenOptions::new()
            .create(true)
            .write(true)
            .truncate(true)
            .open(&path)
            .with_context(|| format!("{}: cannot create", path.display()))?;
        writeln!(csv, "{CSV_HEADER}")?;
        for r in &records {
            write_row(&mut csv, r)?;
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            csv,
            records,
        })
    }

    /// Appends a record to the CSV (and to memory).
    pub fn push(&mut self, r: Record) -> Result<()> {
        write_row(&mut self.csv, &r)
            .with_context(|| format!("{}: cannot write", self.dir.join("log.csv").display()))?;
        self.records.push(r);
        Ok(())
    }

    /// Rewrites `log.json` and `loss.png`.
    pub fn flush(&mut self) -> Result<()> {
        self.csv.flush()?;
        let json = self.dir.join("log.json");
        let text = serde_json::to_string_pretty(&self.records)?;
        lfformat::files::write_atomic(&json, text.as_bytes())?;
        plot(&self.records, &self.dir.join("loss.png"))
    }
}

/// One CSV row; absent scores are empty fields.
fn write_row(f: &mut File, r: &Record) -> std::io::Result<()> {
    let opt = |v: Option<f64>| v.map(|v| format!("{v:.6}")).unwrap_or_default();
    writeln!(
        f,
        "{},{:.6},{:.3},{:.3},{},{},{}",
        r.step,
        r.loss,
        r.samples_per_s,
        r.elapsed_s,
        opt(r.val_mse_x100),
        opt(r.val_badpix_007),
        opt(r.val_kld)
    )
}

/// Training loss (left) and validation BadPix(0.07) (right) over steps.
pub fn plot(records: &[Record], path: &Path) -> Result<()> {
    font::register()?;
    let (w, h) = (1000u32, 400u32);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let (left, right) = root.split_horizontally(w / 2);
        let loss: Vec<(f64, f64)> = records.iter().map(|r| (r.step as f64, r.loss)).collect();
        let val: Vec<(f64, f64)> = records
            .iter()
            .filter_map(|r| r.val_badpix_007.map(|b| (r.step as f64, b)))
            .collect();
        series(&left, "training loss", &loss, &BLUE)?;
        series(&right, "validation BadPix(0.07) %", &val, &RED)?;
        root.present().map_err(plot_error)?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).context("plot buffer size")?;
    Ok(lfformat::png::write_png(path, &img)?)
}

/// One line chart with its own axes.
fn series<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    points: &[(f64, f64)],
    colour: &RGBColor,
) -> Result<()> {
    let x_max = points.iter().map(|p| p.0).fold(1.0, f64::max);
    let (y_min, y_max) = points
        .iter()
        .map(|p| p.1)
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    let (y_min, y_max) = if y_min < y_max {
        (y_min, y_max)
    } else {
        (y_min.min(0.0) - 1.0, y_max.max(0.0) + 1.0)
    };
    let mut chart = ChartBuilder::on(area)
        .caption(title, (font::FAMILY, 18))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..x_max, y_min..y_max)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc("step")
        .label_style((font::FAMILY, 12))
        .draw()
        .map_err(plot_error)?;
    chart
        .draw_series(LineSeries::new(points.iter().copied(), colour))
        .map_err(plot_error)?;
    Ok(())
}

fn plot_error(e: impl std::fmt::Debug) -> anyhow::Error {
    anyhow!("plotting failed: {e:?}")
}
