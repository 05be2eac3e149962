//! Prompts over time. `prompt "…"` is the program's prompt for the whole motion;
//! `prompt 0s..8s "…"` is one span of the program's timeline, and `prompt a 0s..8s "…"` one
//! span of person `a`'s (`people a "…"` or `prompt a "…"` gives `a` one prompt for the
//! whole motion). A person with no prompt of their own takes the program's. Spans are time
//! positions (`time.rs`), resolved to frames at the declared length; a span ending at `end`
//! (the last frame) covers that frame.
//!
//! The rules, each a `mprog::bad_timeline`: a span is at least 1 s long, inside the motion
//! and has words; spans are written in time order and together cover the motion from 0 s
//! to `end` without gaps; consecutive spans may overlap (the model blends one prompt into
//! the next) by at most half of either, never one inside another nor three at once; and one
//! owner (the program, or a person) has either one prompt for the whole motion or a
//! timeline, not both.

use super::Checker;
use super::values::Cx;
use crate::lang::codes::{BAD_TIMELINE, UNKNOWN_PERSON};
use crate::lang::diag::did_you_mean;
use crate::lang::syntax::ast::{Expr, Ident, Item, Module, Span};
use crate::skeleton::FPS;

/// One prompt of a person's timeline: the frames it covers at the declared length.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TimedPrompt {
    /// First frame it covers.
    pub from: usize,
    /// One past the last frame it covers (half-open `[from, to)`).
    pub to: usize,
    /// The prompt.
    pub text: String,
}

/// Shortest span of a timeline, in frames (1 s): the model needs that long to do anything.
const MIN_SPAN: i64 = FPS as i64;

/// Whose prompts: the program's (lines naming no person) or one person's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Owner {
    Program,
    Person(usize),
}

/// A prompt as written: a `prompt` line, or a person's prompt on the `people` line.
struct Line<'a> {
    owner: Owner,
    range: Option<&'a (Expr, Expr)>,
    text: &'a str,
    /// The whole line.
    span: Span,
    /// On the `people` line.
    people_line: bool,
    /// It names its person.
    named: bool,
}

/// A span in frames (`to` exclusive), with the line it is on.
#[derive(Clone, Copy)]
struct Frames {
    from: i64,
    to: i64,
    span: Span,
}

impl Frames {
    fn len(self) -> i64 {
        self.to - self.from
    }
}

/// Frames as seconds, for messages: `8 s`, `0.35 s`.
fn secs(frames: i64) -> String {
    let s = frames as f64 / f64::from(FPS);
    format!("{} s", (s * 100.0).round() / 100.0 + 0.0)
}

fn range_text(from: i64, to: i64) -> String {
    format!("{}..{}", secs(from), secs(to))
}

impl<'a> Checker<'a> {
    /// Reads every prompt into the people's timelines (`PersonInfo::timeline`), the
    /// program's prompt and each person's first prompt. `length_ok`: the `length` line is
    /// right, so spans can be checked against it.
    pub(super) fn declare_timelines(&mut self, module: &'a Module, length_ok: bool, cx: &Cx) {
        let (lines, all_read) = self.prompt_lines(module, cx);
        let owners: Vec<Owner> = std::iter::once(Owner::Program)
            .chain((0..self.header.people.len()).map(Owner::Person))
            .collect();
        let mut timelines = Vec::with_capacity(owners.len());
        for owner in owners {
            let mine: Vec<&Line<'a>> = lines.iter().filter(|l| l.owner == owner).collect();
            timelines.push(self.owner_timeline(owner, &mine, length_ok, all_read, cx));
        }
        let program = timelines[0].clone();
        if let Some(first) = program.first() {
            self.header.prompt = Some(first.text.clone());
        }
        let default_prompt = self.header.prompt.clone();
        for (person, own) in self.header.people.iter_mut().zip(&timelines[1..]) {
            if person.name == "me" {
                // The one person of a program without a `people` line: the program's.
                person.prompt = default_prompt.clone();
            } else if let Some(first) = own.first() {
                person.prompt = Some(first.text.clone());
            }
            person.timeline = if own.is_empty() {
                program.clone()
            } else {
                own.clone()
            };
        }
    }

    /// Every prompt of the program with its owner, and whether every one was read (a
    /// prompt naming no person is reported and left out).
    fn prompt_lines(&mut self, module: &'a Module, cx: &Cx) -> (Vec<Line<'a>>, bool) {
        // The one person of a program without a `people` line is the program's.
        let implicit_me = self.header.people.len() == 1 && self.header.people[0].name == "me";
        let position = |c: &Checker, n: &str| c.header.people.iter().position(|p| p.name == n);
        let mut out = Vec::new();
        let mut people_seen = false;
        let mut all_read = true;
        for item in &module.items {
            match item {
                // A second `people` line is a `mprog::duplicate` and is not read.
                Item::People { people, span } if !people_seen => {
                    people_seen = true;
                    let mut seen = Vec::new();
                    for p in people {
                        let name = p.name.name.as_str();
                        if seen.contains(&name) {
                            continue;
                        }
                        seen.push(name);
                        let (Some(text), Some(i)) = (&p.prompt, position(self, name)) else {
                            continue;
                        };
                        out.push(Line {
                            owner: Owner::Person(i),
                            range: None,
                            text,
                            span: *span,
                            people_line: true,
                            named: true,
                        });
                    }
                }
                Item::Prompt {
                    person,
                    range,
                    text,
                    span,
                } => {
                    let owner = match person {
                        None => Owner::Program,
                        Some(id) => match position(self, &id.name) {
                            Some(_) if implicit_me => Owner::Program,
                            Some(i) => Owner::Person(i),
                            None => {
                                self.unknown_prompt_person(id, range.is_some(), implicit_me, cx);
                                all_read = false;
                                continue;
                            }
                        },
                    };
                    out.push(Line {
                        owner,
                        range: range.as_ref(),
                        text,
                        span: *span,
                        people_line: false,
                        named: person.is_some(),
                    });
                }
                _ => {}
            }
        }
        (out, all_read)
    }

    fn unknown_prompt_person(&mut self, id: &Ident, spanned: bool, implicit_me: bool, cx: &Cx) {
        let n = id.name.as_str();
        let people: Vec<&str> = self.header.people.iter().map(|p| p.name.as_str()).collect();
        let mut help = if implicit_me {
            "this program has one person: leave the name out, `prompt 0s..8s \"…\"`, or \
             declare the people first, `people a, b`"
                .to_string()
        } else {
            match did_you_mean(n, people.iter().copied()) {
                Some(s) => format!("did you mean `{s}`? the people are: {}", people.join(", ")),
                None => format!("the people are: {}", people.join(", ")),
            }
        };
        if spanned && self.header.params.iter().any(|p| p.name == n) {
            help.push_str(&format!(
                "; if the parameter `{n}` begins the span, put it in brackets: `prompt ({n} - 1s)..end \"…\"`"
            ));
        }
        self.error(
            cx,
            UNKNOWN_PERSON,
            id.span,
            format!("no person named `{n}`"),
        )
        .label("not declared in `people`")
        .help(help);
    }

    /// One owner's timeline, after checking its prompts. `all_read`: no prompt was left
    /// out, so the spans can be checked together (gaps, order, blends).
    fn owner_timeline(
        &mut self,
        owner: Owner,
        lines: &[&Line<'a>],
        length_ok: bool,
        all_read: bool,
        cx: &Cx,
    ) -> Vec<TimedPrompt> {
        let len = self.header.length;
        let who = match owner {
            Owner::Program => "the program".to_string(),
            Owner::Person(i) => format!("`{}`", self.header.people[i].name),
        };
        let (whole, spanned): (Vec<&Line>, Vec<&Line>) =
            lines.iter().partition(|l| l.range.is_none());
        // Two prompts for the whole motion (two unnamed `prompt` lines are a
        // `mprog::duplicate`, reported with the header).
        if let Some(first) = whole.first() {
            let line = self.line_of(first.span.start);
            for extra in &whole[1..] {
                if !(extra.named || first.named) {
                    continue;
                }
                self.error(
                    cx,
                    BAD_TIMELINE,
                    extra.span,
                    format!("{who} already has a prompt for the whole motion, on line {line}"),
                )
                .label("second prompt")
                .help(
                    "keep one prompt for the whole motion, or split the motion into spans: \
                     `prompt 0s..8s \"…\"`, `prompt 8s..end \"…\"`",
                );
            }
        }
        let mixed = !whole.is_empty() && !spanned.is_empty();
        if mixed {
            let (w, s) = (whole[0], spanned[0]);
            let line = self.line_of(w.span.start);
            let help = if w.people_line {
                format!(
                    "give {who} either the prompt on the `people` line or a timeline: remove the \
                     text after `{}` on the `people` line, or these spans",
                    match owner {
                        Owner::Person(i) => self.header.people[i].name.as_str(),
                        Owner::Program => "",
                    }
                )
            } else {
                "a prompt without a span already covers the whole motion: give it a span too \
                 (`prompt 0s..8s \"…\"`), or remove it"
                    .to_string()
            };
            self.error(
                cx,
                BAD_TIMELINE,
                s.span,
                format!(
                    "{who} has both a prompt for the whole motion (line {line}) and a timeline"
                ),
            )
            .label("a timeline prompt")
            .help(help);
        }
        let mut spans = Vec::new();
        let mut all_ok = true;
        for l in &spanned {
            let Some((a, b)) = l.range else { continue };
            if l.text.trim().is_empty() {
                self.error(cx, BAD_TIMELINE, l.span, "this timeline prompt has no words")
                    .label("empty prompt")
                    .help(
                        "say what happens in this span, e.g. `prompt 0s..8s \"a person walks forward\"`",
                    );
            }
            let (pa, pb) = (self.time_point(a, &None, cx), self.time_point(b, &None, cx));
            let (Some(pa), Some(pb)) = (pa, pb) else {
                all_ok = false;
                continue;
            };
            if !length_ok {
                all_ok = false;
                continue;
            }
            let from = pa.frame_unclamped(len) as i64;
            let mut to = pb.frame_unclamped(len) as i64;
            // `end` is the last frame: a span to `end` covers it.
            if to == len as i64 - 1 {
                to = len as i64;
            }
            let f = Frames {
                from,
                to,
                span: l.span,
            };
            if self.check_span(f, cx) {
                spans.push((f, l.text));
            } else {
                all_ok = false;
            }
        }
        if all_ok && all_read && !mixed && !spans.is_empty() {
            let frames: Vec<Frames> = spans.iter().map(|(f, _)| *f).collect();
            self.check_sequence(&frames, cx);
        }
        if let Some(w) = whole.first() {
            return vec![TimedPrompt {
                from: 0,
                to: len,
                text: w.text.to_string(),
            }];
        }
        spans
            .into_iter()
            .map(|(f, text)| TimedPrompt {
                from: f.from.max(0) as usize,
                to: f.to.max(0) as usize,
                text: text.to_string(),
            })
            .collect()
    }

    /// One span: not empty, inside the motion, at least 1 s long.
    fn check_span(&mut self, f: Frames, cx: &Cx) -> bool {
        let len = self.header.length as i64;
        let range = range_text(f.from, f.to);
        if f.from >= f.to {
            let how = if f.from == f.to {
                "ends where it starts"
            } else {
                "ends before it starts"
            };
            self.error(
                cx,
                BAD_TIMELINE,
                f.span,
                format!("the span {range} is empty: it {how}"),
            )
            .label("empty span")
            .help(
                "write the span's start, then its end at least 1 s later: `prompt 8s..14s \"…\"`",
            );
            return false;
        }
        if f.from < 0 || f.to > len {
            let what = if f.from < 0 {
                "starts before the motion"
            } else {
                "goes past the end of the motion"
            };
            self.error(
                cx,
                BAD_TIMELINE,
                f.span,
                format!(
                    "the span {range} {what}, which is {} long (`length`)",
                    secs(len)
                ),
            )
            .label("outside the motion")
            .help(format!(
                "spans lie within 0 s..{}: end the last one at `end`, or make the `length` longer",
                secs(len)
            ));
            return false;
        }
        if f.len() < MIN_SPAN {
            self.error(
                cx,
                BAD_TIMELINE,
                f.span,
                format!(
                    "the span {range} is {} long; the model needs at least 1 s to do anything",
                    secs(f.len())
                ),
            )
            .label("too short")
            .help("make the span at least 1 s long, or fold its words into the prompt before or after it");
            return false;
        }
        true
    }

    /// Spans together: in time order, from 0 s to `end`, no gap, overlaps only as blends.
    fn check_sequence(&mut self, spans: &[Frames], cx: &Cx) {
        let len = self.header.length as i64;
        // Out of order, the other rules would only repeat it.
        let mut ordered = true;
        for pair in spans.windows(2) {
            let (prev, cur) = (pair[0], pair[1]);
            if cur.from > prev.from {
                continue;
            }
            ordered = false;
            let when = if cur.from == prev.from {
                "at the same time as"
            } else {
                "before"
            };
            let prev_line = self.line_of(prev.span.start);
            self.error(
                cx,
                BAD_TIMELINE,
                cur.span,
                format!(
                    "spans must be written in time order: {} starts {when} {} (line {prev_line})",
                    range_text(cur.from, cur.to),
                    range_text(prev.from, prev.to)
                ),
            )
            .label("out of order")
            .help("write the prompts in the order they happen, each starting after the one before it starts");
        }
        if !ordered {
            return;
        }
        let first = spans[0];
        if first.from > 0 {
            self.error(
                cx,
                BAD_TIMELINE,
                first.span,
                format!(
                    "no prompt from 0 s to {}: the first span must start at 0 s",
                    secs(first.from)
                ),
            )
            .label("gap before this span")
            .help("start the first span at `0s` (or `start`)");
        }
        // The spans that continue the timeline (one inside another does not).
        let mut kept: Vec<Frames> = vec![first];
        for &cur in &spans[1..] {
            let prev = kept[kept.len() - 1];
            let (p, c) = (range_text(prev.from, prev.to), range_text(cur.from, cur.to));
            let prev_line = self.line_of(prev.span.start);
            if cur.to <= prev.to {
                self.error(
                    cx,
                    BAD_TIMELINE,
                    cur.span,
                    format!(
                        "the span {c} lies inside {p} (line {prev_line}): overlapping spans without blend"
                    ),
                )
                .label("inside the span before")
                .help(format!(
                    "spans follow each other, overlapping at most to blend one prompt into the next: \
                     end this one after {}, or split the span before around it",
                    secs(prev.to)
                ));
                continue;
            }
            kept.push(cur);
            if let Some(&before) = kept.len().checked_sub(3).and_then(|k| kept.get(k))
                && cur.from < before.to
            {
                self.error(
                    cx,
                    BAD_TIMELINE,
                    cur.span,
                    format!(
                        "three prompts at once from {} to {} ({}, {p} and {c}): overlapping spans without blend",
                        secs(cur.from),
                        secs(before.to),
                        range_text(before.from, before.to)
                    ),
                )
                .label("a third prompt at once")
                .help(format!(
                    "only two consecutive spans may overlap: start this one at {} or later",
                    secs(before.to)
                ));
                continue;
            }
            let overlap = prev.to - cur.from;
            let shorter = prev.len().min(cur.len());
            if 2 * overlap > shorter {
                self.error(
                    cx,
                    BAD_TIMELINE,
                    cur.span,
                    format!(
                        "the span {c} overlaps {p} by {}, more than half of the shorter span ({}): \
                         overlapping spans without blend",
                        secs(overlap),
                        secs(shorter)
                    ),
                )
                .label("overlap too long")
                .help(format!(
                    "a blend overlaps at most half of each span: start this one at {} or later, \
                     or shorten the one before",
                    secs(prev.to - shorter / 2)
                ));
                continue;
            }
            if cur.from > prev.to {
                self.error(
                    cx,
                    BAD_TIMELINE,
                    cur.span,
                    format!(
                        "no prompt from {} to {}: a gap between {p} and {c}",
                        secs(prev.to),
                        secs(cur.from)
                    ),
                )
                .label("gap before this span")
                .help(format!(
                    "start this span at {}, where the one before ends, or end that one at {}",
                    secs(prev.to),
                    secs(cur.from)
                ));
            }
        }
        let last = kept[kept.len() - 1];
        if last.to < len {
            self.error(
                cx,
                BAD_TIMELINE,
                last.span,
                format!(
                    "no prompt from {} to the end ({}): the last span must reach `end`",
                    secs(last.to),
                    secs(len)
                ),
            )
            .label("gap after this span")
            .help("end the last span at `end`");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::TimedPrompt;
    use crate::lang::compile;

    fn tp(from: usize, to: usize, text: &str) -> TimedPrompt {
        TimedPrompt {
            from,
            to,
            text: text.into(),
        }
    }

    fn timelines(src: &str) -> Vec<Vec<TimedPrompt>> {
        let p = compile(src, "t.mprog", &[]).unwrap_or_else(|d| panic!("{}", d.render_plain()));
        assert!(
            p.warnings().items.is_empty(),
            "{}",
            p.warnings().render_plain()
        );
        p.timelines()
    }

    fn codes(src: &str) -> Vec<&'static str> {
        crate::lang::check_source(src, "t.mprog", &[])
            .items
            .iter()
            .map(|d| d.code)
            .collect()
    }

    #[test]
    fn one_prompt_covers_the_whole_motion() {
        let src = "prompt \"a person walks\"\nlength 4s\nalways { head.y > 1 m }\n";
        assert_eq!(timelines(src), [[tp(0, 80, "a person walks")]]);
        let p = compile(src, "t.mprog", &[]).unwrap();
        assert_eq!(p.prompts(), [Some("a person walks".to_string())]);
        // No prompt at all: an empty timeline.
        assert_eq!(
            timelines("length 4s\nalways { head.y > 1 m }\n"),
            [Vec::<TimedPrompt>::new()]
        );
    }

    #[test]
    fn a_three_span_timeline_in_frames() {
        let src = "length 20s\n\
            prompt 0s..8s \"a person walks forward\"\n\
            prompt 8s..14s \"a person jogs in a circle\"\n\
            prompt 14s..end \"a person sits down\"\n\
            always { head.y > 0.5 m }\n";
        assert_eq!(
            timelines(src),
            [[
                tp(0, 160, "a person walks forward"),
                tp(160, 280, "a person jogs in a circle"),
                tp(280, 400, "a person sits down"),
            ]]
        );
        let p = compile(src, "t.mprog", &[]).unwrap();
        assert_eq!(p.prompts(), [Some("a person walks forward".to_string())]);
        assert_eq!(p.prompt(), Some("a person walks forward"));
        let prompts: Vec<String> = crate::lang::prompts_of(src)
            .into_iter()
            .map(|(t, _)| t)
            .collect();
        assert_eq!(
            prompts,
            [
                "a person walks forward",
                "a person jogs in a circle",
                "a person sits down"
            ]
        );
    }

    #[test]
    fn consecutive_spans_may_overlap_as_a_blend() {
        let src = "length 20s\n\
            prompt 0s..8s \"a person walks forward\"\n\
            prompt 8s..14s \"a person jogs in a circle\"\n\
            prompt 13s..end \"a person sits down\"\n\
            always { head.y > 0.5 m }\n";
        assert_eq!(
            timelines(src)[0],
            [
                tp(0, 160, "a person walks forward"),
                tp(160, 280, "a person jogs in a circle"),
                tp(260, 400, "a person sits down"),
            ]
        );
        // Half of the shorter span is the most a blend may take; more is an error.
        let at = |start: &str| {
            format!(
                "length 10s\nprompt 0s..4s \"a\"\nprompt {start}..end \"b\"\nalways {{ head.y > 0.5 m }}\n"
            )
        };
        assert!(codes(&at("2s")).is_empty());
        assert_eq!(codes(&at("1.9s")), ["mprog::bad_timeline"]);
    }

    #[test]
    fn two_people_with_their_own_timelines() {
        let src = "length 10s\n\
            people a, b \"a person waves\", c\n\
            prompt a 0s..4s \"a person walks forward\"\n\
            prompt a 4s..end \"a person sits down\"\n\
            prompt c 0s..50% \"a person jumps\"\n\
            prompt c 50%..end \"a person kneels\"\n\
            always { separation(a, b, 0.4 m) }\n";
        assert_eq!(
            timelines(src),
            [
                vec![
                    tp(0, 80, "a person walks forward"),
                    tp(80, 200, "a person sits down")
                ],
                vec![tp(0, 200, "a person waves")],
                vec![
                    tp(0, 100, "a person jumps"),
                    tp(100, 200, "a person kneels")
                ],
            ]
        );
        let p = compile(src, "t.mprog", &[]).unwrap();
        assert_eq!(
            p.prompts(),
            [
                Some("a person walks forward".to_string()),
                Some("a person waves".to_string()),
                Some("a person jumps".to_string())
            ]
        );
        // The program's prompt is everyone's without one of their own; none: empty.
        let src = "length 4s\npeople a, b \"b's\", c\nprompt \"everyone\"\nprompt c 0s..end \"c's\"\n\
            always { separation(a, b, 0.4 m) }\n";
        assert_eq!(
            timelines(src),
            [
                vec![tp(0, 80, "everyone")],
                vec![tp(0, 80, "b's")],
                vec![tp(0, 80, "c's")]
            ]
        );
        assert_eq!(
            timelines("length 4s\npeople a, b\nalways { separation(a, b, 0.4 m) }\n"),
            [vec![], vec![]]
        );
    }

    #[test]
    fn percent_end_and_arithmetic_spans() {
        // 201 frames: 50% is frame 100, `end` the last frame (200), covered.
        let src = "length 201 frames\n\
            prompt start..50% \"a person walks\"\n\
            prompt 50% - 1s..end \"a person runs\"\n\
            always { head.y > 0.5 m }\n";
        assert_eq!(
            timelines(src),
            [[tp(0, 100, "a person walks"), tp(80, 201, "a person runs")]]
        );
        let src = "length 6s\nparam cut = 2s\n\
            prompt 0..cut \"a person walks\"\n\
            prompt (cut)..6s \"a person runs\"\n\
            always { head.y > 0.5 m }\n";
        assert_eq!(
            timelines(src),
            [[tp(0, 40, "a person walks"), tp(40, 120, "a person runs")]]
        );
    }

    #[test]
    fn long_motions_are_no_longer_warned_of() {
        let src = "prompt \"a person walks\"\nlength 30s\nalways { head.y > 1 m }\n";
        assert!(codes(src).is_empty(), "{:?}", codes(src));
    }

    #[test]
    fn each_rule_has_its_diagnostic() {
        let bad = |body: &str| {
            let constraint = if body.contains("people") {
                "separation(a, b, 0.4 m)"
            } else {
                "pelvis.y > 0.5 m"
            };
            let src = format!("length 20s\n{body}\nalways {{ {constraint} }}\n");
            let d = crate::lang::check_source(&src, "t.mprog", &[]);
            assert!(d.has_errors(), "{body}");
            for i in &d.items {
                assert!(i.help.is_some(), "{body}: {} has no hint", i.code);
            }
            let mut codes: Vec<&str> = d.items.iter().map(|i| i.code).collect();
            codes.dedup();
            codes
        };
        let timeline = ["mprog::bad_timeline"];
        for body in [
            "prompt 0s..8s \"a\"\nprompt 8s..8s \"b\"\nprompt 8s..end \"c\"",
            "prompt 0s..14s \"a\"\nprompt 14s..25s \"b\"",
            "prompt 0s..8s \"a\"\nprompt 8s..8.5s \"b\"\nprompt 8.5s..end \"c\"",
            "prompt 8s..end \"a\"\nprompt 0s..8s \"b\"",
            "prompt 0s..8s \"a\"\nprompt 9s..end \"b\"",
            "prompt 1s..end \"a\"",
            "prompt 0s..15s \"a\"",
            "prompt 0s..12s \"a\"\nprompt 4s..10s \"b\"\nprompt 10s..end \"c\"",
            "prompt 0s..10s \"a\"\nprompt 4s..14s \"b\"\nprompt 8s..end \"c\"",
            "prompt 0s..10s \"a\"\nprompt 2s..end \"b\"",
            "prompt 0s..8s \"a\"\nprompt 8s..end \"  \"",
            "prompt \"a\"\nprompt 0s..end \"b\"",
        ] {
            assert_eq!(bad(body), timeline, "{body}");
        }
        assert_eq!(
            bad("people a, b\nprompt c 0s..end \"a\""),
            ["mprog::unknown_person"]
        );
        assert_eq!(bad("prompt 0m..end \"a\""), ["mprog::not_a_time"]);
        assert_eq!(bad("people a \"x\", b\nprompt a 0s..end \"a\""), timeline);
        assert_eq!(bad("people a \"x\", b\nprompt a \"y\""), timeline);
        // Two whole-motion `prompt` lines stay a `mprog::duplicate`.
        assert_eq!(bad("prompt \"a\"\nprompt \"b\""), ["mprog::duplicate"]);
    }
}
