//! The bench's rows as a table on stdout, CSV and JSON.
//!
//! CSV: one header line, then one line per row, the columns of
//! [`super::Row`] in order (empty where a figure does not exist; `inf` for
//! the PSNR of identical images), written by the `csv` crate. JSON: one
//! object, `{"file", "adapter", "config", "rows": [...]}`, with `null`
//! where the CSV is empty.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use super::{BenchError, Row};

/// What the JSON report says about the run besides the rows.
#[derive(Clone, Debug, Serialize)]
pub struct RunInfo {
    pub file: String,
    pub cells: usize,
    pub points: usize,
    /// The GPU adapter the projected modes drew on, if any opened.
    pub adapter: Option<String>,
    pub warmup: usize,
    pub repeats: usize,
    pub zoovr_version: &'static str,
}

fn write_err(path: &Path, e: impl ToString) -> BenchError {
    BenchError::Write {
        path: path.display().to_string(),
        msg: e.to_string(),
    }
}

/// Writes the rows as CSV.
pub fn write_csv(path: &Path, rows: &[Row]) -> Result<(), BenchError> {
    let mut w = csv::Writer::from_path(path).map_err(|e| write_err(path, e))?;
    for r in rows {
        w.serialize(r).map_err(|e| write_err(path, e))?;
    }
    w.flush().map_err(|e| write_err(path, e))
}

/// Writes the rows and the run's description as one JSON object.
pub fn write_json(path: &Path, info: &RunInfo, rows: &[Row]) -> Result<(), BenchError> {
    #[derive(Serialize)]
    struct Report<'a> {
        #[serde(flatten)]
        info: &'a RunInfo,
        rows: &'a [Row],
    }
    let text =
        serde_json::to_string_pretty(&Report { info, rows }).map_err(|e| write_err(path, e))?;
    std::fs::write(path, text + "\n").map_err(|e| write_err(path, e))
}

fn opt(v: Option<f64>, f: impl Fn(f64) -> String) -> String {
    v.map_or_else(|| "-".into(), f)
}

fn sci(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.2e}")
    }
}

fn psnr(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.1}")
    } else {
        "inf".into()
    }
}

/// The rows as a fixed-width table (what `zoovr bench` prints).
pub fn table(rows: &[Row]) -> String {
    let head = [
        "source",
        "mode",
        "setting",
        "size",
        "view",
        "total s",
        "spread",
        "first s",
        "setup",
        "sort",
        "project",
        "tables",
        "gpu",
        "readback",
        "triangles",
        "peak MiB",
        "ref",
        "max err",
        "rms err",
        "psnr",
        "native max",
        "native rms",
    ];
    let mut cells: Vec<Vec<String>> = vec![head.iter().map(|s| s.to_string()).collect()];
    for r in rows {
        let mut line = vec![
            r.source.clone(),
            r.mode.clone(),
            r.setting.clone(),
            r.size.clone(),
            r.view.to_string(),
        ];
        if let Some(e) = &r.error {
            line.push(format!("failed: {e}"));
            cells.push(line);
            continue;
        }
        let spread = if r.total_s > 0.0 {
            format!(
                "{:.0}%",
                100.0 * (r.total_max_s - r.total_min_s) / r.total_s
            )
        } else {
            "-".into()
        };
        line.extend([
            format!("{:.3}", r.total_s),
            spread,
            format!("{:.3}", r.first_s),
            format!("{:.3}", r.setup_s),
            format!("{:.3}", r.sort_s),
            format!("{:.3}", r.project_s),
            format!("{:.3}", r.tables_s),
            format!("{:.3}", r.gpu_s),
            format!("{:.3}", r.readback_s),
            r.triangles.to_string(),
            opt(r.peak_rss_mb, |v| format!("{v:.0}")),
            r.reference.clone(),
            opt(r.max_err, sci),
            opt(r.rms_err, sci),
            opt(r.psnr, psnr),
            opt(r.native_max_err, sci),
            opt(r.native_rms_err, sci),
        ]);
        cells.push(line);
    }
    let cols = head.len();
    let width: Vec<usize> = (0..cols)
        .map(|c| {
            cells
                .iter()
                .filter(|row| row.len() == cols)
                .map(|row| row[c].chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut out = String::new();
    for row in &cells {
        let mut line = String::new();
        for (c, v) in row.iter().enumerate() {
            if row.len() == cols {
                // Text left, figures right.
                if c < 5 && c != 4 || c == 16 {
                    let _ = write!(line, "{v:<w$}  ", w = width[c]);
                } else {
                    let _ = write!(line, "{v:>w$}  ", w = width[c]);
                }
            } else {
                let w = if c + 1 < row.len() { width[c] } else { 0 };
                let _ = write!(line, "{v:<w$}  ");
            }
        }
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(mode: &str, total: f64, err: Option<f64>) -> Row {
        Row {
            source: "zoovr".into(),
            mode: mode.into(),
            setting: "default".into(),
            size: "64x64".into(),
            width: 64,
            height: 64,
            total_s: total,
            total_min_s: total * 0.9,
            total_max_s: total * 1.1,
            max_err: err,
            rms_err: err.map(|e| e / 10.0),
            psnr: err.map(|_| f64::INFINITY),
            reference: "faces".into(),
            ..Default::default()
        }
    }

    #[test]
    fn csv_and_json_hold_every_row_and_the_columns() {
        let dir = tempfile::tempdir().unwrap();
        let rows = vec![row("exact", 0.5, Some(0.01)), row("raycast", 2.0, None)];
        let csv = dir.path().join("b.csv");
        write_csv(&csv, &rows).unwrap();
        let text = std::fs::read_to_string(&csv).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3, "{text}");
        let head: Vec<&str> = lines[0].split(',').collect();
        for c in [
            "mode",
            "size",
            "view",
            "setting",
            "load_s",
            "setup_s",
            "sort_s",
            "project_s",
            "tables_s",
            "gpu_s",
            "readback_s",
            "total_s",
            "max_err",
            "rms_err",
            "psnr",
        ] {
            assert!(head.contains(&c), "{c} missing: {}", lines[0]);
        }
        let psnr_col = head.iter().position(|c| *c == "psnr").unwrap();
        assert_eq!(lines[1].split(',').nth(psnr_col), Some("inf"));
        assert_eq!(lines[2].split(',').nth(psnr_col), Some(""));
        let json = dir.path().join("b.json");
        let info = RunInfo {
            file: "f.vtu".into(),
            cells: 1,
            points: 8,
            adapter: None,
            warmup: 1,
            repeats: 3,
            zoovr_version: "0",
        };
        write_json(&json, &info, &rows).unwrap();
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        assert_eq!(v["rows"].as_array().unwrap().len(), 2);
        assert_eq!(v["rows"][0]["max_err"], 0.01);
        assert!(v["rows"][1]["max_err"].is_null());
        assert_eq!(v["file"], "f.vtu");
        let t = table(&rows);
        assert_eq!(t.lines().count(), 3, "{t}");
        assert!(t.contains("exact") && t.contains("1.00e-2"), "{t}");
    }
}
