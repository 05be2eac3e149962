//! Line plots to PNG: named series of (x, y) points drawn with axes, ticks, axis labels, a
//! title and a legend, on a linear or logarithmic y axis — training loss curves and a
//! program's per-statement error over time, the latter with the prompt timeline's spans
//! as labelled bands ([`PlotOptions::bands`]).

use super::draw::{disc, line, polyline, render_rgb, text, veil};
use super::encode::encode_png;
use super::error::{RenderError, draw_err};
use super::font::{FAMILY, ensure_fonts, fit_text};
use super::timeline::SPAN_COLORS;
use crate::fsutil::write_bytes_atomic;
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use std::ops::Range;
use std::path::Path;

/// One named line.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// Points in drawing order.
    pub points: Vec<(f32, f32)>,
}

/// Plot appearance.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotOptions {
    /// Picture size in pixels (width, height).
    pub size: (u32, u32),
    /// Logarithmic y axis (points with y ≤ 0 are left out).
    pub log_y: bool,
    /// Shaded x ranges drawn behind the lines, each labelled at its top left (a prompt
    /// timeline's spans on an error-over-time plot); a band outside the points' range is
    /// cut to it.
    pub bands: Vec<Band>,
}

/// A labelled x range of a plot.
#[derive(Clone, Debug, PartialEq)]
pub struct Band {
    /// Where it starts (x units).
    pub from: f32,
    /// Where it ends.
    pub to: f32,
    /// Its label (a prompt).
    pub label: String,
}

impl Default for PlotOptions {
    fn default() -> Self {
        PlotOptions {
            size: (800, 480),
            log_y: false,
            bands: Vec::new(),
        }
    }
}

/// Series colours (Tableau 10), cycled.
const COLORS: [RGBColor; 10] = [
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
];

/// Series with at most this many points also get a dot at each point.
const MARK_POINTS_UP_TO: usize = 40;

/// Draws `series` as a PNG line plot at `path` (which must end in `.png`).
///
/// Non-finite points (a diverged loss) and, with `log_y`, points with y ≤ 0 are left out
/// of the drawing; it is an error when no point remains. Nothing is written on error.
pub fn plot_lines(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    opts: &PlotOptions,
) -> Result<(), RenderError> {
    let is_png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png {
        return Err(RenderError::UnknownFormat(path.to_path_buf()));
    }
    let bytes = plot_png(title, x_label, y_label, series, opts)?;
    write_bytes_atomic(path, &bytes).map_err(|source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// The plot's PNG bytes.
pub(crate) fn plot_png(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    opts: &PlotOptions,
) -> Result<Vec<u8>, RenderError> {
    let (w, h) = opts.size;
    if w < 200 || h < 150 {
        return Err(RenderError::BadOption(format!(
            "plot size {w}x{h} is too small (min 200x150)"
        )));
    }
    let kept: Vec<Vec<(f32, f32)>> = series
        .iter()
        .map(|s| {
            let keep =
                |&&(x, y): &&(f32, f32)| x.is_finite() && y.is_finite() && (!opts.log_y || y > 0.0);
            s.points.iter().filter(keep).copied().collect()
        })
        .collect();
    let all: Vec<(f32, f32)> = kept.iter().flatten().copied().collect();
    if all.is_empty() {
        let why = if opts.log_y {
            "no finite positive points for a log-scale plot"
        } else {
            "no finite points"
        };
        return Err(RenderError::BadPlot(why.into()));
    }
    if let Some(b) = opts
        .bands
        .iter()
        .find(|b| !(b.from.is_finite() && b.to.is_finite() && b.from < b.to))
    {
        return Err(RenderError::BadPlot(format!(
            "band {}..{} (\"{}\") is empty or not finite",
            b.from, b.to, b.label
        )));
    }
    let xr = padded(all.iter().map(|p| p.0), false);
    let yr = padded(all.iter().map(|p| p.1), opts.log_y);
    ensure_fonts()?;
    let labels = Labels {
        title,
        x: x_label,
        y: y_label,
        bands: &opts.bands,
        y_any: yr.start,
    };
    let rgb = render_rgb(w, h, |area| {
        area.fill(&WHITE).map_err(draw_err)?;
        if opts.log_y {
            chart(
                area,
                &labels,
                xr,
                yr.clone().log_scale(),
                Some(yr),
                series,
                &kept,
            )
        } else {
            chart(area, &labels, xr, yr, None, series, &kept)
        }
    })?;
    encode_png(&rgb, w, h)
}

struct Labels<'a> {
    title: &'a str,
    x: &'a str,
    y: &'a str,
    bands: &'a [Band],
    /// A y value on the axis, for mapping x values to pixels.
    y_any: f32,
}

/// Data range with a 5 % margin (multiplicative on a log axis); a single value gets a
/// unit-wide (or factor-of-two) range around it.
fn padded(values: impl Iterator<Item = f32>, log: bool) -> Range<f32> {
    let (lo, hi) = values.fold((f32::MAX, f32::MIN), |(a, b), v| (a.min(v), b.max(v)));
    if log {
        if hi <= lo * 1.0001 {
            return lo / 2.0..hi * 2.0;
        }
        let f = (hi / lo).powf(0.05);
        return lo / f..hi * f;
    }
    if hi - lo <= f32::EPSILON * hi.abs().max(1.0) {
        return lo - 0.5..hi + 0.5;
    }
    let m = (hi - lo) * 0.05;
    lo - m..hi + m
}

/// Tick text: plain for ordinary magnitudes, scientific for tiny or huge ones.
fn tick(v: f32) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        format!("{v:.1e}")
    } else {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// Tick values for a log axis over `[lo, hi]`: decades, or 1-2-5, or 1…9 steps per
/// decade, whichever first gives at least four ticks (at most ~12 kept); a range too
/// narrow even for that gets five geometrically spaced ticks.
fn log_ticks(lo: f32, hi: f32) -> Vec<f32> {
    let (e0, e1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let steps: [&[f32]; 3] = [
        &[1.0],
        &[1.0, 2.0, 5.0],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    ];
    for mults in steps {
        let ticks: Vec<f32> = (e0..=e1)
            .flat_map(|e| mults.iter().map(move |m| m * 10f32.powi(e)))
            // Tolerate rounding at the ends (9 × 0.1 is not exactly 0.9 in f32).
            .filter(|v| (lo * (1.0 - 1e-5)..=hi * (1.0 + 1e-5)).contains(v))
            .collect();
        if ticks.len() >= 4 {
            let keep_every = ticks.len().div_ceil(12);
            return ticks.into_iter().step_by(keep_every).collect();
        }
    }
    (0..5)
        .map(|i| lo * (hi / lo).powf(i as f32 / 4.0))
        .collect()
}

fn chart<'a, Y>(
    area: &DrawingArea<BitMapBackend<'a>, Shift>,
    labels: &Labels,
    xr: Range<f32>,
    yr: Y,
    log_ticks_in: Option<Range<f32>>,
    series: &[Series],
    kept: &[Vec<(f32, f32)>],
) -> Result<(), RenderError>
where
    Y: AsRangedCoord<Value = f32>,
    Y::CoordDescType: ValueFormatter<f32>,
{
    let x0 = xr.start;
    let (x_lo, x_hi) = (xr.start, xr.end);
    let mut chart = ChartBuilder::on(area)
        .caption(labels.title, (FAMILY, 18))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(64)
        .build_cartesian_2d(xr, yr)
        .map_err(draw_err)?;
    // Plotters labels a log axis only at powers of ten; its labels are blanked and the
    // ticks drawn below instead.
    let log = log_ticks_in.is_some();
    let y_labels = if log { 0 } else { 8 };
    chart
        .configure_mesh()
        .x_desc(labels.x)
        .y_desc(labels.y)
        .x_labels(8)
        .y_labels(y_labels)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| if log { String::new() } else { tick(*v) })
        .label_style((FAMILY, 12))
        .axis_desc_style((FAMILY, 14))
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(draw_err)?;
    if let Some(range) = log_ticks_in {
        let right = chart.plotting_area().get_pixel_range().0.end;
        for v in log_ticks(range.start, range.end) {
            let (x, y) = chart.backend_coord(&(x0, v));
            line(area, (x + 1, y), (right - 1, y), RGBColor(215, 215, 215), 1)?;
            line(area, (x - 5, y), (x, y), RGBColor(0, 0, 0), 1)?;
            text(
                area,
                &tick(v),
                (x - 8, y),
                12.0,
                RGBColor(0, 0, 0),
                (HPos::Right, VPos::Center),
            )?;
        }
    }
    let (_, rows) = chart.plotting_area().get_pixel_range();
    for (i, band) in labels.bands.iter().enumerate() {
        let (from, to) = (band.from.max(x_lo), band.to.min(x_hi));
        if from >= to {
            continue;
        }
        let color = SPAN_COLORS[i % SPAN_COLORS.len()];
        let a = chart.backend_coord(&(from, labels.y_any)).0;
        let b = chart.backend_coord(&(to, labels.y_any)).0;
        let (top, bottom) = (rows.start, rows.end - 1);
        veil(
            area,
            vec![(a, top), (b, top), (b, bottom), (a, bottom)],
            color,
            0.10,
        )?;
        if band.from >= x_lo {
            line(area, (a, top), (a, bottom), color, 1)?;
        }
        let room = f64::from(b - a - 8);
        if room > 16.0 {
            text(
                area,
                &fit_text(&band.label, 12.0, room),
                (a + 4, top + 4),
                12.0,
                color,
                (HPos::Left, VPos::Top),
            )?;
        }
    }
    for (i, (s, pts)) in series.iter().zip(kept).enumerate() {
        let color = COLORS[i % COLORS.len()];
        let px: Vec<(i32, i32)> = pts.iter().map(|p| chart.backend_coord(p)).collect();
        // Drawn with the picture helpers: plotters' thick paths come out jagged.
        polyline(area, px.clone(), color, 2)?;
        if pts.len() <= MARK_POINTS_UP_TO {
            for p in px {
                disc(area, p, 3, color)?;
            }
        }
        let style = color.stroke_width(2);
        chart
            .draw_series(std::iter::empty::<PathElement<(f32, f32)>>())
            .map_err(draw_err)?
            .label(s.name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(170, 170, 170))
        .label_font((FAMILY, 13))
        .draw()
        .map_err(draw_err)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::test_util::{decode_png, dir_entries, pixels_of};

    #[test]
    fn ranges_and_ticks() {
        assert_eq!(padded([2.0, 2.0].into_iter(), false), 1.5..2.5);
        let r = padded([0.0, 10.0].into_iter(), false);
        assert!((r.start + 0.5).abs() < 1e-6 && (r.end - 10.5).abs() < 1e-6);
        let l = padded([1e-3, 10.0].into_iter(), true);
        assert!(l.start < 1e-3 && l.start > 0.0 && l.end > 10.0);
        assert_eq!(tick(0.25), "0.25");
        assert_eq!(tick(3.0), "3");
        assert_eq!(tick(0.0), "0");
        assert_eq!(tick(1.5e-5), "1.5e-5");
        let close = |a: &[f32], b: &[f32]| {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x / y - 1.0).abs() < 1e-5)
        };
        assert!(close(&log_ticks(1e-4, 2.0), &[1e-4, 1e-3, 1e-2, 1e-1, 1.0]));
        assert!(close(&log_ticks(0.13, 3.2), &[0.2, 0.5, 1.0, 2.0]));
        assert!(close(
            &log_ticks(0.13, 0.9),
            &[0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]
        ));
        assert!(log_ticks(1e-20, 1e20).len() <= 12);
        let narrow = log_ticks(0.55, 0.6);
        assert_eq!(narrow.len(), 5);
        assert!((narrow[0] - 0.55).abs() < 1e-6 && (narrow[4] - 0.6).abs() < 1e-5);
    }

    #[test]
    fn plot_lines_writes_a_png_and_rejects_bad_input() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("loss.png");
        let train = Series {
            name: "train".into(),
            points: (1..200).map(|i| (i as f32, 5.0 / i as f32)).collect(),
        };
        let mut val_pts: Vec<(f32, f32)> = (1..20)
            .map(|i| ((i * 10) as f32, 6.0 / (i * 10) as f32))
            .collect();
        val_pts.push((200.0, f32::NAN));
        let val = Series {
            name: "val".into(),
            points: val_pts,
        };
        let opts = PlotOptions {
            log_y: true,
            ..PlotOptions::default()
        };
        plot_lines(&path, "loss", "step", "loss", &[train.clone(), val], &opts).unwrap();
        let (w, h, rgb) = decode_png(&path);
        assert_eq!((w, h), (800, 480));
        // Both series are drawn in their colours.
        assert!(pixels_of(&rgb, w, RGBColor(31, 119, 180)).len() > 200);
        assert!(pixels_of(&rgb, w, RGBColor(255, 127, 14)).len() > 50);

        let nan_only = Series {
            name: "nan".into(),
            points: vec![(0.0, f32::NAN)],
        };
        let bad = dir.path().join("bad.png");
        assert!(matches!(
            plot_lines(&bad, "t", "x", "y", &[nan_only], &PlotOptions::default()),
            Err(RenderError::BadPlot(_))
        ));
        let negative = Series {
            name: "neg".into(),
            points: vec![(0.0, -1.0), (1.0, 0.0)],
        };
        assert!(plot_lines(&bad, "t", "x", "y", &[negative], &opts).is_err());
        assert!(plot_lines(&dir.path().join("loss.gif"), "t", "x", "y", &[train], &opts).is_err());
        assert!(!bad.exists());
        assert_eq!(dir_entries(dir.path()), 1);
    }

    #[test]
    fn bands_shade_and_label_the_prompt_spans() {
        let errors = Series {
            name: "line 3".into(),
            points: (0..600)
                .map(|f| (f as f32 / 20.0, (f as f32 / 50.0).sin()))
                .collect(),
        };
        let band = |from: f32, to: f32, label: &str| Band {
            from,
            to,
            label: label.into(),
        };
        let opts = PlotOptions {
            bands: vec![
                band(0.0, 12.0, "a person walks forward"),
                band(12.0, 20.0, "a person jogs"),
                band(20.0, 30.0, "a person sits down"),
            ],
            ..PlotOptions::default()
        };
        let plain = plot_png(
            "t",
            "time (s)",
            "error",
            std::slice::from_ref(&errors),
            &PlotOptions::default(),
        )
        .unwrap();
        let png = plot_png(
            "t",
            "time (s)",
            "error",
            std::slice::from_ref(&errors),
            &opts,
        )
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
        std::fs::write(&a, plain).unwrap();
        std::fs::write(&b, png).unwrap();
        let (w, _, rgb) = decode_png(&b);
        let (_, _, rgb0) = decode_png(&a);
        // Each band's edge line and label are in its colour; none without bands.
        for c in &SPAN_COLORS[1..3] {
            assert!(pixels_of(&rgb, w, *c).len() > 100, "{c:?}");
            assert!(pixels_of(&rgb0, w, *c).is_empty());
        }
        // The second band's edge is a vertical line at 12 s, left of the third's at 20 s.
        let x_of = |c: RGBColor| {
            let px = pixels_of(&rgb, w, c);
            let mut xs: Vec<usize> = px.iter().map(|p| p.0).collect();
            xs.sort_unstable();
            xs[0]
        };
        assert!(x_of(SPAN_COLORS[1]) + 100 < x_of(SPAN_COLORS[2]));
        let empty = PlotOptions {
            bands: vec![band(3.0, 3.0, "x")],
            ..PlotOptions::default()
        };
        assert!(matches!(
            plot_png("t", "x", "y", &[errors], &empty),
            Err(RenderError::BadPlot(_))
        ));
    }
}
