//! `report.html`: the conformance report as one self-contained page (issue 52 item 8), opened
//! from disk with no network and no files beside it. Per scene, the reference and each
//! technique's visibility, signed error, shaded image and FLIP map side by side, and a log-log
//! time-error plot (the reference's curve, each technique's point); above them one table of
//! every case (RMSE, penumbra RMSE, FLIP, time, speed-up, status), sortable by any column.
//!
//! Images are embedded as `data:` URIs. A script at the top of the page counts console errors,
//! uncaught errors and images that fail to load, and writes the counts on `<body>` as
//! `data-console-errors`, `data-images` and `data-images-loaded`, which the headless-browser
//! test reads back from the rendered DOM.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use base64::Engine;

/// One image of a case or of the reference: a caption and a PNG file.
pub struct Picture {
    /// Caption under the image.
    pub caption: String,
    /// The PNG on disk (embedded when the page is written).
    pub path: PathBuf,
}

/// One (technique, scene) case.
pub struct Case {
    /// Preset name.
    pub technique: String,
    /// `ok`, `fail`, `unsupported` or `failed`, with the reason when not `ok`.
    pub status: String,
    /// RMSE against the reference on the same view.
    pub rmse: Option<f64>,
    /// Penumbra RMSE.
    pub penumbra_rmse: Option<f64>,
    /// Mean FLIP of the shaded image against the reference's.
    pub flip: Option<f64>,
    /// Seconds (prepare and estimate).
    pub seconds: Option<f64>,
    /// RMSE against the independent reference (the plot's y).
    pub independent_rmse: Option<f64>,
    /// Speed-up against the reference at equal error, as the text table prints it.
    pub speedup: String,
    /// Visibility, error, shaded, FLIP map.
    pub pictures: Vec<Picture>,
}

/// One scene: the reference's pictures and curve, and its cases.
pub struct Scene {
    /// Scene name.
    pub name: String,
    /// The reference's visibility and shaded image.
    pub reference: Vec<Picture>,
    /// The reference's (seconds, RMSE against the independent reference) at each sample count.
    pub curve: Vec<(f64, f64)>,
    /// Every case run on it.
    pub cases: Vec<Case>,
}

/// Writes the page to `path`.
///
/// # Errors
/// When an image cannot be read or the page cannot be written.
pub fn write_report(path: &Path, title: &str, intro: &str, scenes: &[Scene]) -> Result<(), String> {
    let mut h = String::new();
    writeln!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>",
        esc(title)
    )
    .ok();
    h.push_str(CHECK_SCRIPT);
    h.push_str(STYLE);
    writeln!(
        h,
        "</head>\n<body>\n<h1>{}</h1>\n<p>{}</p>",
        esc(title),
        esc(intro)
    )
    .ok();
    summary_table(&mut h, scenes);
    for s in scenes {
        writeln!(h, "<section id=\"scene-{0}\">\n<h2>{0}</h2>", esc(&s.name)).ok();
        h.push_str(&time_error_svg(s));
        h.push_str("<div class=\"grid\">\n");
        row(&mut h, "reference", "", &s.reference)?;
        for c in &s.cases {
            let label = match (c.rmse, c.flip) {
                (Some(r), Some(f)) => format!("RMSE {r:.4}, FLIP {f:.4}, {}", c.status),
                _ => c.status.clone(),
            };
            row(&mut h, &c.technique, &label, &c.pictures)?;
        }
        h.push_str("</div>\n</section>\n");
    }
    h.push_str(SORT_SCRIPT);
    h.push_str("</body>\n</html>\n");
    std::fs::write(path, h).map_err(|e| format!("writing {}: {e}", path.display()))
}

fn summary_table(h: &mut String, scenes: &[Scene]) {
    h.push_str("<table id=\"cases\">\n<thead><tr>");
    for (k, col) in [
        "technique",
        "scene",
        "RMSE",
        "penumbra RMSE",
        "FLIP",
        "seconds",
        "speed-up",
        "status",
    ]
    .iter()
    .enumerate()
    {
        write!(h, "<th data-col=\"{k}\">{col}</th>").ok();
    }
    h.push_str("</tr></thead>\n<tbody>\n");
    let num = |v: Option<f64>, digits: usize| v.map_or(String::new(), |v| format!("{v:.digits$}"));
    for s in scenes {
        for c in &s.cases {
            let (tech, scene) = (esc(&c.technique), esc(&s.name));
            writeln!(
                h,
                "<tr><td>{tech}</td><td><a href=\"#scene-{scene}\">{scene}</a></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                num(c.rmse, 4),
                num(c.penumbra_rmse, 4),
                num(c.flip, 4),
                num(c.seconds, 3),
                esc(&c.speedup),
                esc(&c.status)
            )
            .ok();
        }
    }
    h.push_str("</tbody>\n</table>\n");
}

fn row(h: &mut String, name: &str, label: &str, pictures: &[Picture]) -> Result<(), String> {
    writeln!(
        h,
        "<div class=\"row\"><div class=\"name\"><b>{}</b><br>{}</div>",
        esc(name),
        esc(label)
    )
    .ok();
    for p in pictures {
        let bytes =
            std::fs::read(&p.path).map_err(|e| format!("reading {}: {e}", p.path.display()))?;
        let b64 = base64::engine::general_purpose::STANDARD.encode(bytes);
        writeln!(
            h,
            "<figure><img alt=\"{0} {1}\" src=\"data:image/png;base64,{2}\"><figcaption>{1}</figcaption></figure>",
            esc(name),
            esc(&p.caption),
            b64
        )
        .ok();
    }
    h.push_str("</div>\n");
    Ok(())
}

/// A log-log plot of time against RMSE: the reference's curve and each technique's point.
fn time_error_svg(s: &Scene) -> String {
    let pos = |v: f64| v.is_finite() && v > 0.0;
    let points: Vec<(&str, f64, f64)> = s
        .cases
        .iter()
        .filter_map(|c| match (c.seconds, c.independent_rmse) {
            (Some(t), Some(e)) if pos(t) && pos(e) => Some((c.technique.as_str(), t, e)),
            _ => None,
        })
        .collect();
    let curve: Vec<(f64, f64)> = s
        .curve
        .iter()
        .copied()
        .filter(|(t, e)| pos(*t) && pos(*e))
        .collect();
    let all = curve
        .iter()
        .copied()
        .chain(points.iter().map(|p| (p.1, p.2)));
    let (mut t0, mut t1, mut e0, mut e1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (t, e) in all {
        (t0, t1, e0, e1) = (t0.min(t), t1.max(t), e0.min(e), e1.max(e));
    }
    if t0 > t1 {
        return "<p>(no timed case to plot)</p>\n".into();
    }
    // Whole decades around the data.
    let (lt0, lt1) = (
        t0.log10().floor(),
        t1.log10().ceil().max(t0.log10().floor() + 1.0),
    );
    let (le0, le1) = (
        e0.log10().floor(),
        e1.log10().ceil().max(e0.log10().floor() + 1.0),
    );
    let (w, hgt, m) = (640.0, 360.0, 56.0);
    let x = |t: f64| m + (t.log10() - lt0) / (lt1 - lt0) * (w - 2.0 * m);
    let y = |e: f64| hgt - m - (e.log10() - le0) / (le1 - le0) * (hgt - 2.0 * m);
    let mut svg = format!(
        "<svg class=\"plot\" xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{hgt}\" viewBox=\"0 0 {w} {hgt}\" role=\"img\" aria-label=\"time against error on {}\">\n",
        esc(&s.name)
    );
    for d in lt0 as i32..=lt1 as i32 {
        let px = x(10f64.powi(d));
        writeln!(svg, "<line x1=\"{px:.1}\" y1=\"{m}\" x2=\"{px:.1}\" y2=\"{:.1}\" class=\"grid\"/><text x=\"{px:.1}\" y=\"{:.1}\" text-anchor=\"middle\">1e{d}</text>", hgt - m, hgt - m + 16.0).ok();
    }
    for d in le0 as i32..=le1 as i32 {
        let py = y(10f64.powi(d));
        writeln!(svg, "<line x1=\"{m}\" y1=\"{py:.1}\" x2=\"{:.1}\" y2=\"{py:.1}\" class=\"grid\"/><text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">1e{d}</text>", w - m, m - 6.0, py + 4.0).ok();
    }
    writeln!(svg, "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">seconds (prepare + estimate)</text><text x=\"14\" y=\"{:.1}\" transform=\"rotate(-90 14 {:.1})\" text-anchor=\"middle\">RMSE against the independent reference</text>", w / 2.0, hgt - 12.0, hgt / 2.0, hgt / 2.0).ok();
    if !curve.is_empty() {
        let pts: Vec<String> = curve
            .iter()
            .map(|(t, e)| format!("{:.1},{:.1}", x(*t), y(*e)))
            .collect();
        writeln!(
            svg,
            "<polyline class=\"ref\" points=\"{}\"><title>reference</title></polyline>",
            pts.join(" ")
        )
        .ok();
    }
    for (name, t, e) in &points {
        writeln!(svg, "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\"><title>{}: {t:.3} s, RMSE {e:.4}</title></circle><text class=\"pt\" x=\"{:.1}\" y=\"{:.1}\">{}</text>", x(*t), y(*e), esc(name), x(*t) + 6.0, y(*e) - 4.0, esc(name)).ok();
    }
    svg.push_str("</svg>\n");
    svg
}

/// HTML-escapes text for element content and attribute values.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// First in `<head>`: counts console errors, uncaught errors and images that fail, and once the
/// page has loaded writes them on `<body>` for the browser test.
const CHECK_SCRIPT: &str = r#"<script>
(function () {
  var errors = 0;
  var original = console.error;
  console.error = function () { errors += 1; return original.apply(console, arguments); };
  window.addEventListener("error", function () { errors += 1; }, true);
  window.addEventListener("load", function () {
    var imgs = document.images, loaded = 0;
    for (var i = 0; i < imgs.length; i++) {
      if (imgs[i].complete && imgs[i].naturalWidth > 0) { loaded += 1; }
    }
    document.body.setAttribute("data-images", String(imgs.length));
    document.body.setAttribute("data-images-loaded", String(loaded));
    document.body.setAttribute("data-console-errors", String(errors));
  });
})();
</script>
"#;

const STYLE: &str = r#"<style>
body { font-family: sans-serif; margin: 1.5em; color: #222; }
table { border-collapse: collapse; font-size: 0.85em; }
th, td { border: 1px solid #ccc; padding: 2px 6px; text-align: right; }
td:nth-child(1), td:nth-child(2), td:nth-child(8) { text-align: left; }
th { cursor: pointer; background: #eee; }
.grid .row { display: flex; align-items: flex-start; gap: 6px; margin: 4px 0; }
.grid .name { width: 16em; font-size: 0.8em; }
figure { margin: 0; font-size: 0.7em; text-align: center; }
img { image-rendering: pixelated; width: 192px; display: block; }
svg.plot { font-size: 11px; }
svg.plot line.grid { stroke: #ddd; }
svg.plot polyline.ref { fill: none; stroke: #333; stroke-width: 2; }
svg.plot circle { fill: #c33; }
svg.plot text.pt { font-size: 9px; fill: #733; }
</style>
"#;

/// Sorts the case table by the clicked column (numbers as numbers, blanks last).
const SORT_SCRIPT: &str = r#"<script>
(function () {
  var table = document.getElementById("cases");
  var heads = table.tHead.rows[0].cells;
  for (var k = 0; k < heads.length; k++) {
    heads[k].addEventListener("click", (function (col) {
      var ascending = true;
      return function () {
        var body = table.tBodies[0];
        var rows = Array.prototype.slice.call(body.rows);
        var key = function (r) {
          var t = r.cells[col].textContent.replace(/^[>x]+|x$/g, "");
          var v = parseFloat(t);
          return isNaN(v) ? t : v;
        };
        rows.sort(function (a, b) {
          var x = key(a), y = key(b);
          if (x === "" || y === "") { return x === "" ? 1 : -1; }
          if (typeof x === typeof y) { return (x < y ? -1 : x > y ? 1 : 0) * (ascending ? 1 : -1); }
          return typeof x === "number" ? -1 : 1;
        });
        rows.forEach(function (r) { body.appendChild(r); });
        ascending = !ascending;
      };
    })(k));
  }
})();
</script>
"#;
