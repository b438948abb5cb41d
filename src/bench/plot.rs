//! The bench's plot: time per frame against error, log-log, drawn with the
//! `plotters` crate into an RGB buffer and written as PNG.
//!
//! One row of two panels per image size: on the left the error against
//! the ray caster on the same field (algorithm error), on the right against
//! the `native` field (algorithm plus model error). One series per (source,
//! mode), with its own colour and marker in every panel and one legend
//! beside the panels: its points are the mode's settings in order (coarse
//! to fine), joined by a line; a point's time is the median over the views
//! of the rows' median times, its error the largest over the views. Errors
//! below [`ERROR_FLOOR`] (an exact match) are drawn on the floor. Text uses
//! the Ubuntu Light font embedded by `epaint_default_fonts`, registered
//! with plotters' `ab_glyph` text backend, so no system font is needed.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;
use plotters::style::FontStyle;

use super::{BenchError, Row};

/// Errors below this are drawn at it (log axes cannot show 0).
pub const ERROR_FLOOR: f64 = 1e-6;

/// One line of the plot.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub label: String,
    /// `WxH` of its rows.
    pub size: String,
    /// `(seconds, algorithm error, native error)` per setting, in order.
    pub points: Vec<(f64, Option<f64>, Option<f64>)>,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn max_opt(v: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    v.flatten()
        .fold(None, |m, x| Some(m.map_or(x, |m: f64| m.max(x))))
}

/// One setting's rows in a series: its rank, label and rows (one per view).
type Setting<'a> = (f64, String, Vec<&'a Row>);

/// The series of `rows` (failed rows left out), in first-seen order.
pub fn series(rows: &[Row]) -> Vec<Series> {
    // (source, mode, size) -> setting -> rows
    let mut order: Vec<(String, String, String)> = Vec::new();
    let mut groups: BTreeMap<(String, String, String), Vec<Setting<'_>>> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.error.is_none()) {
        let key = (r.source.clone(), r.mode.clone(), r.size.clone());
        if !groups.contains_key(&key) {
            order.push(key.clone());
        }
        let g = groups.entry(key).or_default();
        match g.iter_mut().find(|(_, s, _)| *s == r.setting) {
            Some((_, _, v)) => v.push(r),
            None => g.push((r.rank, r.setting.clone(), vec![r])),
        }
    }
    order
        .into_iter()
        .map(|key| {
            let mut settings = groups.remove(&key).unwrap_or_default();
            settings.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (source, mode, size) = key;
            let label = if source == "zoovr" {
                mode
            } else {
                format!("{source} {mode}")
            };
            let points = settings
                .into_iter()
                .map(|(_, _, rs)| {
                    (
                        median(rs.iter().map(|r| r.total_s).collect()),
                        max_opt(rs.iter().map(|r| r.max_err)),
                        max_opt(rs.iter().map(|r| r.native_max_err)),
                    )
                })
                .collect();
            Series {
                label,
                size,
                points,
            }
        })
        .collect()
}

fn register_font() -> Result<(), BenchError> {
    static ONCE: Once = Once::new();
    let mut ok = true;
    ONCE.call_once(|| {
        ok = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        )
        .is_ok();
    });
    if ok {
        Ok(())
    } else {
        Err(BenchError::Write {
            path: "(plot font)".into(),
            msg: "the embedded font did not load".into(),
        })
    }
}

const COLOURS: [RGBColor; 14] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 0),
    RGBColor(0, 0, 128),
    RGBColor(128, 128, 0),
    RGBColor(0, 128, 128),
];

/// Height of one row of panels (one image size), in pixels.
const ROW_HEIGHT: u32 = 440;
/// Width of the figure and of its legend column.
const WIDTH: u32 = 1400;
const LEGEND_WIDTH: u32 = 210;

/// The size of the plot of `rows`: one row of panels per image size.
pub fn plot_size(rows: &[Row]) -> (u32, u32) {
    let sizes = distinct(series(rows).iter().map(|s| s.size.clone()));
    (WIDTH, 40 + ROW_HEIGHT * sizes.len().max(1) as u32)
}

fn distinct(v: impl Iterator<Item = String>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for x in v {
        if !out.contains(&x) {
            out.push(x);
        }
    }
    out
}

/// Draws the points `pts` on `chart` with marker `shape` (the same four
/// shapes as the legend).
macro_rules! markers {
    ($chart:expr, $pts:expr, $shape:expr, $colour:expr) => {
        match $shape % 4 {
            0 => $chart.draw_series($pts.iter().map(|&p| Circle::new(p, 4, $colour.filled()))),
            1 => $chart.draw_series(
                $pts.iter()
                    .map(|&p| TriangleMarker::new(p, 5, $colour.filled())),
            ),
            2 => $chart.draw_series(
                $pts.iter()
                    .map(|&p| Cross::new(p, 5, $colour.stroke_width(2))),
            ),
            _ => $chart.draw_series($pts.iter().map(|&p| {
                EmptyElement::at(p) + Rectangle::new([(-4, -4), (4, 4)], $colour.filled())
            })),
        }
    };
}

/// Writes the plot of `rows` as a PNG of [`plot_size`].
pub fn write_plot(path: &Path, rows: &[Row], title: &str) -> Result<(), BenchError> {
    let err = |e: &dyn std::fmt::Display| BenchError::Write {
        path: path.display().to_string(),
        msg: e.to_string(),
    };
    register_font()?;
    let all = series(rows);
    let sizes = distinct(all.iter().map(|s| s.size.clone()));
    let labels = distinct(all.iter().map(|s| s.label.clone()));
    let style_of = |label: &str| labels.iter().position(|l| l == label).unwrap_or(0);
    let (width, height) = plot_size(rows);
    let mut buf = vec![255u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let (top, body) = root.split_vertically(40);
        top.titled(title, ("sans-serif", 20)).map_err(|e| err(&e))?;
        let (plots, legend) = body.split_horizontally(width - LEGEND_WIDTH);
        // The legend: one line per series label, its marker and colour.
        for (i, label) in labels.iter().enumerate() {
            let colour = COLOURS[i % COLOURS.len()];
            let y = 60 + 20 * i as i32;
            legend
                .draw(&PathElement::new(
                    vec![(8, y), (36, y)],
                    colour.stroke_width(2),
                ))
                .map_err(|e| err(&e))?;
            let p = (22, y);
            match (i / COLOURS.len() + i) % 4 {
                0 => legend.draw(&Circle::new(p, 4, colour.filled())),
                1 => legend.draw(&TriangleMarker::new(p, 5, colour.filled())),
                2 => legend.draw(&Cross::new(p, 5, colour.stroke_width(2))),
                _ => legend.draw(&Rectangle::new(
                    [(p.0 - 4, p.1 - 4), (p.0 + 4, p.1 + 4)],
                    colour.filled(),
                )),
            }
            .map_err(|e| err(&e))?;
            legend
                .draw(&Text::new(label.clone(), (44, y - 7), ("sans-serif", 14)))
                .map_err(|e| err(&e))?;
        }
        let panels = plots.split_evenly((sizes.len().max(1), 2));
        let times: Vec<f64> = all
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0))
            .filter(|t| t.is_finite() && *t > 0.0)
            .collect();
        let (tmin, tmax) = bounds(&times, 1e-3);
        for (n, panel) in panels.iter().enumerate() {
            let (row, k) = (n / 2, n % 2);
            let Some(size) = sizes.get(row) else { continue };
            let pick = |p: &(f64, Option<f64>, Option<f64>)| if k == 0 { p.1 } else { p.2 };
            let errors: Vec<f64> = all
                .iter()
                .flat_map(|s| s.points.iter().filter_map(pick))
                .map(|e| e.max(ERROR_FLOOR))
                .collect();
            let (emin, emax) = bounds(&errors, ERROR_FLOOR);
            let caption = if k == 0 {
                format!("{size}: error against the ray caster, same field")
            } else {
                format!("{size}: error against the ray caster, native field")
            };
            let mut chart = ChartBuilder::on(panel)
                .caption(caption, ("sans-serif", 16))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(64)
                .build_cartesian_2d((tmin..tmax).log_scale(), (emin..emax).log_scale())
                .map_err(|e| err(&e))?;
            chart
                .configure_mesh()
                .x_desc("time per frame, s (median)")
                .y_desc("max abs error, display values (1e-6: at most)")
                .x_label_formatter(&|v| format!("{v:.0e}"))
                .y_label_formatter(&|v| format!("{v:.0e}"))
                .label_style(("sans-serif", 12))
                .draw()
                .map_err(|e| err(&e))?;
            for s in all.iter().filter(|s| &s.size == size) {
                let i = style_of(&s.label);
                let colour = COLOURS[i % COLOURS.len()];
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .filter_map(|p| pick(p).map(|e| (p.0, e.max(ERROR_FLOOR))))
                    .filter(|p| p.0 > 0.0 && p.0.is_finite())
                    .collect();
                chart
                    .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                    .map_err(|e| err(&e))?;
                let shape = i / COLOURS.len() + i;
                markers!(chart, pts, shape, colour).map_err(|e| err(&e))?;
            }
        }
        root.present().map_err(|e| err(&e))?;
    }
    let img =
        image::RgbImage::from_raw(width, height, buf).ok_or_else(|| err(&"plot buffer size"))?;
    img.save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| err(&e))
}

/// A log axis range around `v` (a decade of margin), `floor` when empty.
fn bounds(v: &[f64], floor: f64) -> (f64, f64) {
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() || !hi.is_finite() {
        return (floor, floor * 10.0);
    }
    let lo = 10f64.powf(lo.log10().floor());
    let hi = 10f64.powf(hi.log10().ceil().max(lo.log10() + 1.0));
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(mode: &str, setting: &str, rank: f64, view: usize, t: f64, e: f64) -> Row {
        Row {
            source: "zoovr".into(),
            mode: mode.into(),
            setting: setting.into(),
            size: "64x64".into(),
            view,
            rank,
            total_s: t,
            max_err: Some(e),
            native_max_err: Some(e * 2.0),
            ..Default::default()
        }
    }

    #[test]
    fn series_join_settings_in_order_over_views() {
        let rows = vec![
            row("preint3d", "table=64", 64.0, 0, 0.2, 0.01),
            row("preint3d", "table=32", 32.0, 0, 0.1, 0.05),
            row("preint3d", "table=32", 32.0, 1, 0.3, 0.02),
            row("exact", "default", 0.0, 0, 0.5, 0.0),
        ];
        let s = series(&rows);
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].label, "preint3d");
        assert_eq!(s[0].size, "64x64");
        // table=32 first (coarser), its time the median of 0.1 and 0.3,
        // its error the larger of the two views.
        assert_eq!(s[0].points[0], (0.2, Some(0.05), Some(0.1)));
        assert_eq!(s[0].points[1], (0.2, Some(0.01), Some(0.02)));
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("p.png");
        write_plot(&png, &rows, "test").unwrap();
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (WIDTH, 40 + ROW_HEIGHT));
        // Something besides white was drawn (axes, text, markers).
        let dark = img
            .pixels()
            .filter(|p| p.0.iter().all(|&c| c < 100))
            .count();
        assert!(dark > 1000, "{dark} dark pixels");
    }
}
