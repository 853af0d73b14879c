//! The comparison tables, as Markdown (`report.md`) and HTML (`report.html`).
//!
//! The main table has the columns of thesis Table 5.1 (unimodal MSE and BadPix, KLD over
//! unimodal / multimodal / all pixels, AuSE, runtime), one row per method; further tables
//! give every HCI score against each reference and BadPix per scene. Every score is
//! lower-is-better, so the best value of each column is set in bold.

use std::fmt::Write;
use std::path::Path;

use anyhow::Result;
use lfdata::metrics::hci::SCORE_NAMES;
use lfdata::metrics::region::{REGION_SCORE_NAMES, Resolution};
use lfdata::scene_eval::EvalConfig;
use lfdata::truth::Reference;

use super::{
    Evaluation, POSTERIOR_PLOT_DIR, SPARSIFICATION_PLOTS, posterior_plot_name, write_text,
};

/// A table of optional numbers with row labels.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Heading above the table.
    pub title: String,
    /// Column titles (the first is the label column's).
    pub header: Vec<String>,
    /// Label and values per row.
    pub rows: Vec<(String, Vec<Option<f64>>)>,
    /// Explanation below the table.
    pub note: String,
    /// Whether methods are the columns (best value per row) rather than the rows.
    pub best_per_row: bool,
}

impl Table {
    /// The cells as text, the best (lowest) value of each column, or of each row when
    /// [`Table::best_per_row`], wrapped by `bold`.
    fn cells(&self, bold: impl Fn(&str) -> String) -> Vec<Vec<String>> {
        let lowest = |values: &mut dyn Iterator<Item = Option<f64>>| {
            values
                .flatten()
                .filter(|x| x.is_finite())
                .min_by(f64::total_cmp)
        };
        let columns = self.header.len() - 1;
        let column_best: Vec<Option<f64>> = (0..columns)
            .map(|c| lowest(&mut self.rows.iter().map(|(_, v)| v[c])))
            .collect();
        let competitors = if self.best_per_row {
            columns
        } else {
            self.rows.len()
        };
        self.rows
            .iter()
            .map(|(label, values)| {
                let row_best = lowest(&mut values.iter().copied());
                let mut row = vec![label.clone()];
                row.extend(values.iter().zip(&column_best).map(|(v, col_best)| {
                    let best = if self.best_per_row {
                        row_best
                    } else {
                        *col_best
                    };
                    match v {
                        Some(x) if competitors > 1 && Some(*x) == best => bold(&format_value(*x)),
                        Some(x) => format_value(*x),
                        None => "–".into(),
                    }
                }));
                row
            })
            .collect()
    }

    /// GitHub-flavoured Markdown.
    pub fn to_markdown(&self) -> String {
        let mut s = format!("### {}\n\n| {} |\n", self.title, self.header.join(" | "));
        s += &format!("|{}\n", ":--|".repeat(self.header.len()));
        for row in self.cells(|v| format!("**{v}**")) {
            s += &format!("| {} |\n", row.join(" | "));
        }
        if !self.note.is_empty() {
            s += &format!("\n{}\n", self.note);
        }
        s + "\n"
    }

    /// An HTML `<table>` with its heading and note.
    pub fn to_html(&self) -> String {
        let mut s = format!("<h3>{}</h3>\n<table>\n<tr>", escape(&self.title));
        for h in &self.header {
            let _ = write!(s, "<th>{}</th>", escape(h));
        }
        s += "</tr>\n";
        for row in self.cells(|v| format!("<b>{v}</b>")) {
            s += "<tr>";
            for (i, cell) in row.iter().enumerate() {
                // Labels are user text (folder names); values are ours and may hold <b>.
                let cell = if i == 0 { escape(cell) } else { cell.clone() };
                let _ = write!(s, "<td>{cell}</td>");
            }
            s += "</tr>\n";
        }
        s += "</table>\n";
        if !self.note.is_empty() {
            let _ = writeln!(s, "<p>{}</p>", escape(&self.note));
        }
        s
    }
}

/// Three decimals, like thesis Table 5.1.
fn format_value(x: f64) -> String {
    format!("{x:.3}")
}

/// Escapes text for HTML.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The main table in the layout of thesis Table 5.1.
pub fn main_table(eval: &Evaluation) -> Table {
    let r = eval.config.reference.name();
    let header = [
        "Method",
        "MSE×100",
        "BadPix(0.07) %",
        "KLD unimodal",
        "KLD multimodal",
        "KLD overall",
        "AuSE BadPix(0.07)",
        "AuSE MSE×100",
        "Time (s)",
    ];
    let rows = eval
        .methods
        .iter()
        .map(|m| {
            let s = &m.summary;
            let u = s.unimodal[r];
            let sp = s.sparsification.as_ref();
            let values = vec![
                u.mse_x100,
                u.badpix_007,
                s.kld.unimodal,
                s.kld.multimodal,
                s.kld.all,
                sp.and_then(|p| p.badpix_007.ause),
                sp.and_then(|p| p.mse_x100.ause),
                s.runtime_mean_s,
            ];
            (m.method.name.clone(), values)
        })
        .collect();
    let pixels = eval
        .methods
        .first()
        .map(|m| m.summary.kld)
        .unwrap_or_default();
    Table {
        title: format!(
            "Summary over {} scenes (unimodal scores against the {r} mode)",
            eval.scenes.len()
        ),
        header: header.map(String::from).to_vec(),
        rows,
        note: format!(
            "Lower is better. MSE and BadPix: mean over scenes, {}. \
             KLD: nats per pixel over {} bins on [{}, {}], ε = {}, averaged over {} pixels \
             ({} unimodal, {} multimodal = at least two modes with η > 0.3). AuSE: area under \
             the sparsification error over the removed fraction 0..1, ranking by the method's \
             uncertainty (– when it gives none). Time: mean seconds per scene as reported.",
            scored_pixels(&eval.config),
            eval.config.bins.count,
            eval.config.bins.min,
            eval.config.bins.max,
            eval.config.epsilon,
            pixels.pixels_all,
            pixels.pixels_unimodal,
            pixels.pixels_multimodal,
        ),
        best_per_row: false,
    }
}

/// Which pixels of a scene are scored, in words.
fn scored_pixels(cfg: &EvalConfig) -> String {
    let border = format!("{}-px border left out", cfg.border);
    match cfg.crop < 1.0 {
        true => format!(
            "{border}, only the centred {} × {} crop",
            cfg.crop, cfg.crop
        ),
        false => border,
    }
}

/// Every HCI score of every method against `reference`.
pub fn hci_table(eval: &Evaluation, reference: Reference) -> Table {
    let mut header = vec!["Method".to_string()];
    header.extend(SCORE_NAMES.iter().map(|s| s.to_string()));
    header.push("Invalid %".into());
    let rows = eval
        .methods
        .iter()
        .map(|m| {
            let mut values = m.summary.unimodal[reference.name()].to_array().to_vec();
            values.push(m.summary.invalid_percent);
            (m.method.name.clone(), values)
        })
        .collect();
    let what = match reference {
        Reference::Front => "the front-most mode",
        Reference::Dominant => "the dominant (largest-η) mode",
        Reference::Hci => "gt_disp_lowres.pfm (HCI single GT)",
    };
    Table {
        title: format!("HCI scores against {what}"),
        header,
        rows,
        note: "Mean over scenes; masks as in the HCI toolkit. Invalid: NaN/±∞ predictions.".into(),
        best_per_row: false,
    }
}

/// The HCI region scores of every method, when some scene has evaluation masks.
pub fn region_table(eval: &Evaluation) -> Option<Table> {
    let summaries: Vec<_> = eval.methods.iter().map(|m| m.summary.regions).collect();
    let resolution = summaries.iter().flatten().find_map(|r| r.fine_resolution);
    summaries.iter().any(Option::is_some).then(|| {
        let mut header = vec!["Method".to_string()];
        header.extend(REGION_SCORE_NAMES.iter().map(|s| s.to_string()));
        let rows = eval
            .methods
            .iter()
            .zip(&summaries)
            .map(|(m, r)| {
                (
                    m.method.name.clone(),
                    r.map_or(vec![None; 7], |r| r.to_array().to_vec()),
                )
            })
            .collect();
        let fine = match resolution {
            Some(Resolution::High) => "on the high-resolution ground truth",
            _ => "on the low-resolution masks (no high-resolution ground truth)",
        };
        Table {
            title: "HCI region scores against gt_disp_lowres.pfm".into(),
            header,
            rows,
            note: format!(
                "Mean over the scenes with evaluation masks, computed as the HCI toolkit does; \
                 Discont., Fine Fat. and Fine Thin. {fine}."
            ),
            best_per_row: false,
        }
    })
}

/// BadPix(0.07) of every method per scene, against the configured reference.
pub fn scene_table(eval: &Evaluation) -> Table {
    let r = eval.config.reference;
    let mut header = vec!["Scene".to_string()];
    header.extend(eval.methods.iter().map(|m| m.method.name.clone()));
    let rows = eval
        .scenes
        .iter()
        .enumerate()
        .map(|(i, scene)| {
            let values = eval
                .methods
                .iter()
                .map(|m| m.scenes[i].against(r).badpix_007)
                .collect();
            (scene.name.clone(), values)
        })
        .collect();
    Table {
        title: format!("BadPix(0.07) % per scene (against the {} mode)", r.name()),
        header,
        rows,
        note: String::new(),
        best_per_row: true,
    }
}

/// All tables, main table first.
pub fn tables(eval: &Evaluation) -> Vec<Table> {
    let mut t = vec![main_table(eval)];
    t.extend(Reference::ALL.iter().map(|&r| hci_table(eval, r)));
    t.extend(region_table(eval));
    t.push(scene_table(eval));
    t
}

/// The images the reports show, as `(caption, relative path)`.
fn figures(eval: &Evaluation) -> Vec<(String, String)> {
    let mut f: Vec<(String, String)> = SPARSIFICATION_PLOTS
        .iter()
        .map(|p| {
            (
                "Sparsification (left) and sparsification error (right)".into(),
                p.to_string(),
            )
        })
        .collect();
    f.extend(eval.samples.iter().map(|s| {
        (
            format!("Posterior at {} ({}, {})", s.scene, s.x, s.y),
            format!("{POSTERIOR_PLOT_DIR}/{}", posterior_plot_name(s)),
        )
    }));
    f
}

/// Writes `report.md` and `report.html` into `out`.
pub fn write_reports(eval: &Evaluation, out: &Path) -> Result<()> {
    let tables = tables(eval);
    let figures = figures(eval);
    let intro = format!(
        "Dataset `{}`, {} scenes{}; methods: {}. Per-scene BadPix maps are in `error_maps/` \
         (green = good, red = bad, black = no valid comparison).",
        eval.dataset.display(),
        eval.scenes.len(),
        if eval.skipped.is_empty() {
            String::new()
        } else {
            format!(" ({} without ground truth skipped)", eval.skipped.len())
        },
        eval.methods
            .iter()
            .map(|m| m.method.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let mut md = format!("# lfeval report\n\n{intro}\n\n");
    let mut html = format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>lfeval report</title>\n\
         <style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}\
         td,th{{border:1px solid #bbb;padding:3px 8px;text-align:right}}\
         td:first-child,th:first-child{{text-align:left}}img{{max-width:100%}}</style>\n\
         </head><body>\n<h1>lfeval report</h1>\n<p>{}</p>\n",
        escape(&intro)
    );
    for t in &tables {
        md += &t.to_markdown();
        html += &t.to_html();
    }
    for (caption, path) in &figures {
        md += &format!("![{caption}]({path})\n\n");
        html += &format!(
            "<figure><img src=\"{}\" alt=\"{c}\"><figcaption>{c}</figcaption></figure>\n",
            escape(path),
            c = escape(caption)
        );
    }
    html += "</body></html>\n";
    write_text(&out.join("report.md"), &md)?;
    write_text(&out.join("report.html"), &html)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> Table {
        Table {
            title: "T".into(),
            header: vec!["M".into(), "a".into(), "b".into()],
            rows: vec![
                ("x<y".into(), vec![Some(1.0), None]),
                ("z".into(), vec![Some(0.5), Some(2.0)]),
            ],
            note: "n".into(),
            best_per_row: false,
        }
    }

    #[test]
    fn markdown_marks_the_best_value_and_dashes_missing_ones() {
        let md = table().to_markdown();
        assert!(md.contains("| M | a | b |"), "{md}");
        assert!(md.contains("| x<y | 1.000 | – |"), "{md}");
        assert!(md.contains("| z | **0.500** | **2.000** |"), "{md}");
    }

    #[test]
    fn per_row_tables_mark_the_best_method_of_each_row() {
        let t = Table {
            best_per_row: true,
            ..table()
        };
        let md = t.to_markdown();
        assert!(md.contains("| x<y | **1.000** | – |"), "{md}");
        assert!(md.contains("| z | **0.500** | 2.000 |"), "{md}");
    }

    #[test]
    fn html_escapes_labels() {
        let html = table().to_html();
        assert!(html.contains("<td>x&lt;y</td>"), "{html}");
        assert!(html.contains("<td><b>0.500</b></td>"), "{html}");
    }
}
