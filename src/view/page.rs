//! Assembles the page: HTML skeleton + `viewer.css` + the data block (as
//! `<script type="application/json" id="mprog-data">`) + `viewer.js`, all inline.

use serde_json::Value;

const CSS: &str = include_str!("viewer.css");
const JS: &str = include_str!("viewer.js");

/// The whole page.
pub(crate) fn page(title: &str, data: &Value) -> String {
    let title = escape_html(title);
    let data = embed_json(data);
    format!(
        r#"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="mprog {version}">
<title>{title}</title>
<style>
{CSS}</style>
</head>
<body>
<header>
  <h1 id="title">{title}</h1>
  <div id="legend"></div>
</header>
<div id="stage"><canvas id="view" tabindex="0" aria-label="3-D view of the motion"></canvas><div id="hud"></div></div>
<div id="controls">
  <button id="play" type="button" title="play / pause (space)">&#9654;</button>
  <input id="slider" type="range" min="0" max="0" value="0" step="1" aria-label="frame">
  <span id="counter" class="mono"></span>
  <span id="prompt" title="the prompt at this frame"></span>
  <label>speed <select id="speed" title="speed (up / down arrows)">
    <option value="0.25">0.25&times;</option><option value="0.5">0.5&times;</option>
    <option value="1" selected>1&times;</option><option value="2">2&times;</option>
    <option value="4">4&times;</option></select></label>
  <button id="reset" type="button" title="reset the camera (R)">reset view</button>
</div>
<div id="timeline"></div>
<div id="charts"></div>
<footer>drag: orbit &middot; shift-drag: pan &middot; wheel: zoom &middot; space: play/pause &middot;
&larr; &rarr;: step (shift: 10) &middot; &uarr; &darr;: speed &middot; Home/End &middot; R: reset view
&middot; link to a frame with <span class="mono">#frame=40</span></footer>
<script type="application/json" id="mprog-data">{data}</script>
<script>
{JS}</script>
</body>
</html>
"#,
        version = env!("CARGO_PKG_VERSION"),
    )
}

/// Text safe inside HTML elements and attributes.
pub(crate) fn escape_html(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// JSON that cannot end its `<script>` element: every `<` becomes `\u003c` (still the
/// same JSON), so `</script>` or `<!--` in a title or label stays text.
pub(crate) fn embed_json(v: &Value) -> String {
    v.to_string().replace('<', "\\u003c")
}
