//! The prompt timeline in pictures: which prompt is active at a frame (for captions), a bar
//! of the spans (one row per person with a timeline) with the current frame or the strip's
//! numbered frames marked on it, and strip frames moved so that every span gets a cell.
//!
//! Drawn only when some person has more than one prompt: one prompt over the whole clip
//! is already the title.

use super::camera::Rect;
use super::draw::{Area, CENTRE, line, polygon, text};
use super::error::RenderError;
use super::font::{fit_text, text_width};
use super::options::{RenderOptions, TimelineSpan};
use super::style::{SUBTLE, TEXT, fade};
use super::views::label_height;
use plotters::style::RGBColor;
use plotters::style::text_anchor::{HPos, VPos};
use std::ops::Range;

/// Span colours, cycled along a row (and along a plot's bands).
pub(crate) const SPAN_COLORS: [RGBColor; 6] = [
    RGBColor(66, 133, 244),
    RGBColor(52, 168, 83),
    RGBColor(245, 124, 0),
    RGBColor(171, 71, 188),
    RGBColor(0, 150, 170),
    RGBColor(211, 47, 47),
];
/// The current frame's cursor.
const CURSOR: RGBColor = RGBColor(192, 38, 45);

/// What the bar marks besides the spans.
pub(crate) enum BarMarks<'f> {
    /// A cursor at this frame; the spans active there are drawn stronger.
    Cursor(usize),
    /// Numbered ticks (1, 2, …) at these frames, numbers above the bar.
    Numbered(&'f [usize]),
}

/// The timelines to draw, checked against the clip.
pub(crate) struct Timeline {
    /// (person index, spans clipped to the clip), for every person with a span.
    rows: Vec<(usize, Vec<TimelineSpan>)>,
    /// Frames of the clip.
    len: usize,
}

impl Timeline {
    /// The timeline of `opts` for a clip of `len` frames, or `None` when no person has
    /// more than one prompt. A span that is empty or starts past the clip is an error; one
    /// that ends past it is cut at the clip's end.
    pub fn new(opts: &RenderOptions, len: usize) -> Result<Option<Timeline>, RenderError> {
        let mut rows = Vec::new();
        for (person, spans) in opts.timeline.iter().enumerate() {
            let mut kept = Vec::with_capacity(spans.len());
            for s in spans {
                if s.from >= s.to || s.from >= len {
                    return Err(RenderError::BadOption(format!(
                        "timeline of person {}: span {}..{} (\"{}\") is empty or starts past the clip's {len} frames",
                        person + 1,
                        s.from,
                        s.to,
                        s.prompt
                    )));
                }
                kept.push(TimelineSpan {
                    to: s.to.min(len),
                    ..s.clone()
                });
            }
            if !kept.is_empty() {
                rows.push((person, kept));
            }
        }
        if rows.iter().all(|(_, spans)| spans.len() < 2) {
            return Ok(None);
        }
        Ok(Some(Timeline { rows, len }))
    }

    /// Every span of every row, as frame ranges.
    pub fn spans(&self) -> impl Iterator<Item = Range<usize>> + '_ {
        self.rows
            .iter()
            .flat_map(|(_, spans)| spans.iter().map(|s| s.from..s.to))
    }

    /// The prompts active at `frame`: `"a person walks"`, `"walks" → "sits"` where two
    /// spans blend, and `p1: "…" · p2: "…"` with several people.
    pub fn caption(&self, frame: usize) -> String {
        let of_row = |spans: &[TimelineSpan]| {
            let on: Vec<String> = spans
                .iter()
                .filter(|s| (s.from..s.to).contains(&frame))
                .map(|s| format!("\"{}\"", s.prompt))
                .collect();
            if on.is_empty() {
                "–".to_string()
            } else {
                on.join(" → ")
            }
        };
        match self.rows.as_slice() {
            [(_, spans)] => of_row(spans),
            rows => rows
                .iter()
                .map(|(p, spans)| format!("p{}: {}", p + 1, of_row(spans)))
                .collect::<Vec<_>>()
                .join(" · "),
        }
    }

    /// Height of one row of the bar for text of `size` pixels.
    fn row_height(size: f64) -> f32 {
        label_height(size) + 4.0
    }

    /// Height of the bar drawn with `marks` for text of `size` pixels.
    pub fn bar_height(&self, size: f64, numbered: bool) -> f32 {
        let ticks = if numbered {
            label_height(size * 0.85)
        } else {
            0.0
        };
        ticks + self.rows.len() as f32 * Self::row_height(size) + 6.0
    }

    /// Draws the bar into `rect` (as tall as [`Timeline::bar_height`]).
    pub fn draw_bar(
        &self,
        area: &Area,
        rect: Rect,
        marks: &BarMarks,
        size: f64,
    ) -> Result<(), RenderError> {
        let numbered = matches!(marks, BarMarks::Numbered(_));
        let tick_h = if numbered {
            label_height(size * 0.85)
        } else {
            0.0
        };
        let names = self.rows.len() > 1;
        let name_w = if names {
            text_width(&format!("p{}", self.rows.len()), size) as f32 + 10.0
        } else {
            0.0
        };
        let (x0, x1) = (rect.x + 6.0 + name_w, rect.x + rect.w - 6.0);
        let x = |f: f32| x0 + (x1 - x0) * f / self.len.max(1) as f32;
        let row_h = Self::row_height(size);
        let top = rect.y + 3.0 + tick_h;
        let current = match marks {
            BarMarks::Cursor(f) => Some(*f),
            BarMarks::Numbered(_) => None,
        };
        for (r, (person, spans)) in self.rows.iter().enumerate() {
            let (y0, y1) = (top + r as f32 * row_h, top + (r + 1) as f32 * row_h - 2.0);
            if names {
                text(
                    area,
                    &format!("p{}", person + 1),
                    (rect.x as i32 + 6, ((y0 + y1) / 2.0) as i32),
                    size,
                    SUBTLE,
                    (HPos::Left, VPos::Center),
                )?;
            }
            let color = |i: usize, s: &TimelineSpan| {
                let c = SPAN_COLORS[i % SPAN_COLORS.len()];
                let on = current.is_some_and(|f| (s.from..s.to).contains(&f));
                (c, fade(c, if on { 0.35 } else { 0.72 }))
            };
            for (i, s) in spans.iter().enumerate() {
                let (edge, fill) = color(i, s);
                fill_rect(area, x(s.from as f32), y0, x(s.to as f32), y1, fill)?;
                // Where this span blends with the one before, each fills half the row.
                if i > 0 && spans[i - 1].to > s.from {
                    let (_, before) = color(i - 1, &spans[i - 1]);
                    let mid = (y0 + y1) / 2.0;
                    let end = spans[i - 1].to.min(s.to) as f32;
                    fill_rect(area, x(s.from as f32), y0, x(end), mid, before)?;
                }
                line(
                    area,
                    (x(s.from as f32) as i32, y0 as i32),
                    (x(s.from as f32) as i32, y1 as i32),
                    edge,
                    1,
                )?;
            }
            for (i, s) in spans.iter().enumerate() {
                // The label sits in the part no neighbour blends into.
                let from = if i > 0 {
                    s.from.max(spans[i - 1].to)
                } else {
                    s.from
                };
                let to = spans.get(i + 1).map_or(s.to, |n| s.to.min(n.from));
                let (a, b) = (x(from as f32) + 4.0, x(to.max(from) as f32) - 3.0);
                let label = fit_text(&s.prompt, size, f64::from(b - a));
                if label != "…" {
                    text(
                        area,
                        &label,
                        (a as i32, ((y0 + y1) / 2.0) as i32),
                        size,
                        TEXT,
                        (HPos::Left, VPos::Center),
                    )?;
                }
            }
        }
        let bottom = top + self.rows.len() as f32 * row_h - 2.0;
        match marks {
            BarMarks::Cursor(f) => {
                let cx = x(*f as f32 + 0.5) as i32;
                line(
                    area,
                    (cx, (top - 2.0) as i32),
                    (cx, (bottom + 2.0) as i32),
                    CURSOR,
                    2,
                )?;
            }
            BarMarks::Numbered(frames) => {
                for (k, &f) in frames.iter().enumerate() {
                    // Notches on the bar's edges, so that labels stay readable.
                    let cx = x(f as f32 + 0.5) as i32;
                    let (t, b) = (top as i32, bottom as i32);
                    line(area, (cx, t - 3), (cx, t + 4), TEXT, 2)?;
                    line(area, (cx, b - 4), (cx, b + 2), TEXT, 2)?;
                    text(
                        area,
                        &format!("{}", k + 1),
                        (cx, (rect.y + 2.0 + tick_h / 2.0) as i32),
                        size * 0.85,
                        TEXT,
                        CENTRE,
                    )?;
                }
            }
        }
        Ok(())
    }
}

fn fill_rect(
    area: &Area,
    x0: f32,
    y0: f32,
    x1: f32,
    y1: f32,
    color: RGBColor,
) -> Result<(), RenderError> {
    let (x0, y0, x1, y1) = (
        x0 as i32,
        y0 as i32,
        (x1 as i32).max(x0 as i32 + 1),
        y1 as i32,
    );
    polygon(area, vec![(x0, y0), (x1, y0), (x1, y1), (x0, y1)], color)
}

/// Moves strip frames so that every span of `spans` (within `range`) holds one when it
/// can: for each span without a frame, the frame nearest its middle whose removal leaves
/// no span without one moves to the middle. The count stays the same; the order is
/// ascending.
pub(crate) fn cover_spans(
    mut frames: Vec<usize>,
    spans: &[Range<usize>],
    range: &Range<usize>,
) -> Vec<usize> {
    let spans: Vec<Range<usize>> = spans
        .iter()
        .map(|s| s.start.max(range.start)..s.end.min(range.end))
        .filter(|s| !s.is_empty())
        .collect();
    for s in &spans {
        if frames.iter().any(|f| s.contains(f)) {
            continue;
        }
        let want = s.start + (s.len() - 1) / 2;
        let movable = |i: usize| {
            spans.iter().filter(|t| t.contains(&frames[i])).all(|t| {
                frames
                    .iter()
                    .enumerate()
                    .any(|(j, g)| j != i && t.contains(g))
            })
        };
        if let Some(i) = (0..frames.len())
            .filter(|&i| movable(i))
            .min_by_key(|&i| frames[i].abs_diff(want))
        {
            frames[i] = want;
            frames.sort_unstable();
        }
    }
    frames
}

#[cfg(test)]
mod tests {
    use super::*;

    fn span(from: usize, to: usize, prompt: &str) -> TimelineSpan {
        TimelineSpan {
            from,
            to,
            prompt: prompt.into(),
        }
    }

    fn opts(timeline: Vec<Vec<TimelineSpan>>) -> RenderOptions {
        RenderOptions {
            timeline,
            ..RenderOptions::default()
        }
    }

    #[test]
    fn captions_name_the_active_prompts() {
        let one = opts(vec![vec![span(0, 100, "walks")]]);
        assert!(Timeline::new(&one, 100).unwrap().is_none(), "one prompt");
        let t = Timeline::new(
            &opts(vec![vec![span(0, 60, "walks"), span(50, 130, "sits down")]]),
            100,
        )
        .unwrap()
        .unwrap();
        assert_eq!(t.caption(10), "\"walks\"");
        assert_eq!(t.caption(55), "\"walks\" → \"sits down\"");
        assert_eq!(t.caption(99), "\"sits down\"");
        assert_eq!(t.spans().collect::<Vec<_>>(), vec![0..60, 50..100]);
        let two = Timeline::new(
            &opts(vec![
                vec![span(0, 50, "walks"), span(50, 100, "sits")],
                vec![span(0, 100, "waves")],
            ]),
            100,
        )
        .unwrap()
        .unwrap();
        assert_eq!(two.caption(70), "p1: \"sits\" · p2: \"waves\"");
        let bad = opts(vec![vec![span(0, 50, "a"), span(120, 130, "b")]]);
        assert!(Timeline::new(&bad, 100).is_err());
    }

    #[test]
    fn strip_frames_give_every_span_a_cell() {
        // 30 s, 8 evenly spaced frames; a 1 s span at 10 s holds none of them.
        let even = vec![0, 86, 171, 257, 342, 428, 513, 599];
        let spans = [0..200, 200..220, 220..600];
        let got = cover_spans(even.clone(), &spans, &(0..600));
        assert_eq!(got, vec![0, 86, 209, 257, 342, 428, 513, 599]);
        for s in &spans {
            assert!(got.iter().any(|f| s.contains(f)), "{s:?}");
        }
        // Covered already: unchanged. More spans than frames: as many as can be.
        assert_eq!(
            cover_spans(even.clone(), &[0..300, 300..600], &(0..600)),
            even
        );
        let many: Vec<Range<usize>> = (0..10).map(|i| i * 60..(i + 1) * 60).collect();
        let got = cover_spans(vec![0, 599], &many, &(0..600));
        assert_eq!(got.len(), 2);
        // Spans outside the range are left out.
        assert_eq!(
            cover_spans(vec![10, 20], &[200..300, 500..600], &(0..100)),
            vec![10, 20]
        );
    }
}
