//! SVG output: one document holding every sheet of a [`Job`], for checking a job by eye and for
//! editing it in Inkscape.
//!
//! Choices:
//! - Units are millimetres: `width`/`height` carry `mm` and the `viewBox` is in mm, so one user
//!   unit is one mm and coordinates are the job's own numbers (printed by [`fmt_mm`]).
//! - Sheets sit left to right with a `SHEET_GAP_MM` gap, tops aligned; the document is as
//!   high as the highest sheet. The y axis is flipped per sheet: `y_svg = sheet.height - y`.
//! - One Inkscape layer per role, always all of them even when empty, in the order `sheet`
//!   (outlines, locked), then `DRAW_ORDER`: `label`, `mark`, `fold-valley`, `fold-mountain`,
//!   `cut`, so cuts are drawn on top. Styles are presentation attributes on the layer group;
//!   paths carry only geometry, `data-sheet` and, when known, `data-piece`.
//! - Each stroke is one `<path>` (`M x y L x y …`); a closed stroke drops its repeated end point
//!   and ends with `Z`. A stroke without points is left out.
//! - Output is a pure function of the job: no timestamps, no hash maps, fixed number format.

use std::fmt::Write as _;

use super::{fmt_mm, role_style, DRAW_ORDER};
use crate::toolpath::{Job, Stroke, StrokeRole};

/// Horizontal gap between neighbouring sheets in the document, mm.
pub(crate) const SHEET_GAP_MM: f64 = 20.0;

/// Stroke width of the sheet outlines, mm.
const SHEET_OUTLINE_MM: f64 = 0.1;

/// Stroke width per role, mm.
pub(crate) fn stroke_width_mm(role: StrokeRole) -> f64 {
    match role {
        StrokeRole::Cut | StrokeRole::Notch | StrokeRole::Weed => 0.25,
        StrokeRole::FoldMountain | StrokeRole::FoldValley => 0.2,
        StrokeRole::Mark | StrokeRole::Label | StrokeRole::Seam | StrokeRole::Grain => 0.15,
        StrokeRole::Register => crate::toolpath::registration::SIZE_STROKE_MM,
    }
}

/// Renders the whole job as one SVG document (UTF-8 text, ends with a newline).
pub fn render(job: &Job) -> String {
    // Left edge of each sheet in the document.
    let mut offsets = Vec::with_capacity(job.sheets.len());
    let mut x = 0.0;
    for (i, sheet) in job.sheets.iter().enumerate() {
        if i > 0 {
            x += SHEET_GAP_MM;
        }
        offsets.push(x);
        x += finite_or_zero(sheet.width);
    }
    let doc_w = x;
    let doc_h = job
        .sheets
        .iter()
        .map(|s| finite_or_zero(s.height))
        .fold(0.0, f64::max);
    let (w, h) = (fmt_mm(doc_w), fmt_mm(doc_h));

    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n");
    out.push_str(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" \
         xmlns:inkscape=\"http://www.inkscape.org/namespaces/inkscape\" \
         xmlns:sodipodi=\"http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd\" ",
    );
    let _ = writeln!(
        out,
        "version=\"1.1\" width=\"{w}mm\" height=\"{h}mm\" viewBox=\"0 0 {w} {h}\">"
    );
    let _ = writeln!(out, "  <title>{}</title>", escape(&job.name));
    out.push_str("  <sodipodi:namedview id=\"namedview\" inkscape:document-units=\"mm\"/>\n");

    // Sheet outlines, locked so that they are not moved by accident.
    let _ = writeln!(
        out,
        "  <g inkscape:groupmode=\"layer\" id=\"layer-sheet\" inkscape:label=\"sheet\" \
         sodipodi:insensitive=\"true\" fill=\"none\" stroke=\"#a0a0a0\" stroke-width=\"{}\">",
        fmt_mm(SHEET_OUTLINE_MM)
    );
    for (i, (sheet, &x0)) in job.sheets.iter().zip(&offsets).enumerate() {
        let _ = writeln!(
            out,
            "    <rect data-sheet=\"{i}\" x=\"{}\" y=\"0\" width=\"{}\" height=\"{}\"/>",
            fmt_mm(x0),
            fmt_mm(sheet.width),
            fmt_mm(sheet.height)
        );
    }
    out.push_str("  </g>\n");

    for role in DRAW_ORDER {
        let style = role_style(role);
        let name = role.name();
        let _ = write!(
            out,
            "  <g inkscape:groupmode=\"layer\" id=\"layer-{name}\" inkscape:label=\"{name}\" \
             fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linecap=\"round\" \
             stroke-linejoin=\"round\"",
            style.hex(),
            fmt_mm(stroke_width_mm(role))
        );
        if !style.dash_mm.is_empty() {
            let dash: Vec<String> = style.dash_mm.iter().map(|&d| fmt_mm(d)).collect();
            let _ = write!(out, " stroke-dasharray=\"{}\"", dash.join(" "));
        }
        out.push_str(">\n");
        for (i, (sheet, &x0)) in job.sheets.iter().zip(&offsets).enumerate() {
            for stroke in sheet.strokes.iter().filter(|s| s.role == role) {
                write_path(&mut out, stroke, i, x0, sheet.height);
            }
        }
        out.push_str("  </g>\n");
    }
    out.push_str("</svg>\n");
    out
}

/// Appends one `<path>` for `stroke` of sheet `sheet`, whose left edge is at `x0` and whose
/// height is `height` (for the y flip). Nothing for a stroke without points.
fn write_path(out: &mut String, stroke: &Stroke, sheet: usize, x0: f64, height: f64) {
    let mut pts = stroke.points.as_slice();
    if stroke.closed && pts.len() > 2 {
        if let (Some(first), Some(last)) = (pts.first(), pts.last()) {
            if first.distance(*last) <= 1e-9 {
                pts = &pts[..pts.len() - 1];
            }
        }
    }
    if pts.is_empty() {
        return;
    }
    let mut d = String::new();
    for (k, p) in pts.iter().enumerate() {
        let cmd = if k == 0 { "M" } else { " L" };
        let _ = write!(d, "{cmd} {} {}", fmt_mm(x0 + p.x), fmt_mm(height - p.y));
    }
    if stroke.closed {
        d.push_str(" Z");
    }
    let _ = write!(out, "    <path data-sheet=\"{sheet}\"");
    if let Some(piece) = stroke.piece {
        let _ = write!(out, " data-piece=\"{piece}\"");
    }
    let _ = writeln!(out, " d=\"{d}\"/>");
}

fn finite_or_zero(v: f64) -> f64 {
    if v.is_finite() {
        v.max(0.0)
    } else {
        0.0
    }
}

/// Escapes text for XML character data and attribute values.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // Control characters other than tab/newline are not allowed in XML 1.0.
            c if c.is_control() && c != '\t' && c != '\n' && c != '\r' => out.push('\u{fffd}'),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::toolpath::SheetJob;
    use glam::DVec2;

    /// The layers every document has, bottom to top.
    const LAYERS: [&str; 6] = [
        "sheet",
        "label",
        "mark",
        "fold-valley",
        "fold-mountain",
        "cut",
    ];

    fn stroke(role: StrokeRole, pts: &[(f64, f64)], closed: bool, piece: Option<usize>) -> Stroke {
        Stroke {
            role,
            points: pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
            closed,
            piece,
            outer: false,
        }
    }

    fn two_sheet_job() -> Job {
        let square = [
            (10.0, 0.0),
            (30.0, 0.0),
            (30.0, 20.0),
            (10.0, 20.0),
            (10.0, 0.0),
        ];
        Job {
            name: "test <job> & \"co\"".to_string(),
            sheets: vec![
                SheetJob {
                    width: 200.0,
                    height: 100.0,
                    strokes: vec![
                        stroke(StrokeRole::Label, &[(1.0, 1.0), (2.0, 2.0)], false, Some(0)),
                        stroke(StrokeRole::Mark, &[(3.0, 3.0), (4.0, 3.0)], false, Some(0)),
                        stroke(
                            StrokeRole::FoldMountain,
                            &[(10.0, 10.0), (30.0, 10.0)],
                            false,
                            Some(0),
                        ),
                        stroke(
                            StrokeRole::FoldValley,
                            &[(20.0, 0.0), (20.0, 20.0)],
                            false,
                            Some(0),
                        ),
                        stroke(StrokeRole::Cut, &square, true, Some(0)),
                    ],
                },
                SheetJob {
                    width: 150.0,
                    height: 120.0,
                    strokes: vec![
                        stroke(StrokeRole::Cut, &square, true, Some(1)),
                        stroke(StrokeRole::Cut, &[(0.0, 0.0), (5.0, 5.0)], false, None),
                        stroke(
                            StrokeRole::FoldMountain,
                            &[(1.5, 2.25), (3.0, 4.0)],
                            false,
                            Some(1),
                        ),
                    ],
                },
            ],
        }
    }

    /// Contents of the layer group `name`, between its opening tag and its `</g>`.
    fn layer<'a>(svg: &'a str, name: &str) -> &'a str {
        let open = format!("id=\"layer-{name}\"");
        let start = svg.find(&open).expect("layer present");
        let end = start + svg[start..].find("</g>").expect("layer closed");
        &svg[start..end]
    }

    /// Minimal well-formedness check: every start tag is closed by a matching end tag in
    /// nesting order, there is one root, and attribute quotes are balanced.
    fn check_well_formed(svg: &str) {
        let mut stack: Vec<String> = Vec::new();
        let mut roots = 0;
        let mut rest = svg;
        while let Some(lt) = rest.find('<') {
            let gt = rest[lt..].find('>').expect("tag closed") + lt;
            let tag = &rest[lt + 1..gt];
            assert!(!tag.contains('<'), "nested '<' in tag {tag}");
            assert_eq!(
                tag.matches('"').count() % 2,
                0,
                "unbalanced quotes in {tag}"
            );
            let text = &rest[..lt];
            assert!(!text.contains('>'), "stray '>' in text");
            if tag.starts_with('?') {
                assert!(tag.ends_with('?'));
            } else if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(
                    stack.pop().as_deref(),
                    Some(name.trim()),
                    "mismatched end tag"
                );
            } else {
                let name = tag
                    .split_whitespace()
                    .next()
                    .unwrap_or("")
                    .trim_end_matches('/');
                assert!(!name.is_empty());
                if stack.is_empty() {
                    roots += 1;
                }
                if !tag.ends_with('/') {
                    stack.push(name.to_string());
                }
            }
            rest = &rest[gt + 1..];
        }
        assert!(stack.is_empty(), "unclosed tags {stack:?}");
        assert_eq!(roots, 1);
        assert_eq!(svg.matches("<g").count(), svg.matches("</g>").count());
    }

    #[test]
    fn two_sheets_layers_and_paths() {
        let job = two_sheet_job();
        let svg = render(&job);
        check_well_formed(&svg);

        // Document size: 200 + 20 + 150 wide, highest sheet high.
        assert!(svg.contains("width=\"370mm\" height=\"120mm\" viewBox=\"0 0 370 120\""));
        assert!(svg.contains("xmlns:inkscape="));
        assert!(svg.contains("xmlns:sodipodi="));
        assert!(svg.contains("<title>test &lt;job&gt; &amp; &quot;co&quot;</title>"));

        // Layer order.
        let pos: Vec<usize> = LAYERS
            .iter()
            .map(|n| svg.find(&format!("id=\"layer-{n}\"")).expect("layer"))
            .collect();
        assert!(pos.windows(2).all(|w| w[0] < w[1]), "layer order {pos:?}");
        for n in LAYERS {
            assert!(svg.contains(&format!("inkscape:label=\"{n}\"")));
        }
        assert!(layer(&svg, "sheet").contains("sodipodi:insensitive=\"true\""));
        assert_eq!(layer(&svg, "sheet").matches("<rect").count(), 2);

        // Exactly one path per stroke, in the layer of its role.
        let total: usize = job.sheets.iter().map(|s| s.strokes.len()).sum();
        assert_eq!(svg.matches("<path").count(), total);
        for role in StrokeRole::ALL {
            let n: usize = job
                .sheets
                .iter()
                .flat_map(|s| &s.strokes)
                .filter(|s| s.role == role)
                .count();
            assert_eq!(
                layer(&svg, role.name()).matches("<path").count(),
                n,
                "{role:?}"
            );
        }

        // Styles on the groups.
        let cut = layer(&svg, "cut");
        assert!(cut.contains("stroke=\"#000000\" stroke-width=\"0.25\""));
        assert!(cut.contains("fill=\"none\""));
        let mountain = layer(&svg, "fold-mountain");
        assert!(mountain.contains("stroke=\"#d00000\""));
        assert!(mountain.contains("stroke-dasharray=\"3 1 0.5 1\""));
        let valley = layer(&svg, "fold-valley");
        assert!(valley.contains("stroke=\"#0050d0\""));
        assert!(valley.contains("stroke-dasharray=\"2 1\""));
        assert!(layer(&svg, "mark").contains("stroke=\"#008000\" stroke-width=\"0.15\""));
        assert!(layer(&svg, "label").contains("stroke=\"#006000\" stroke-width=\"0.15\""));
        assert!(!svg.contains("<path style"));

        // Closed squares: y flipped, closing duplicate dropped, Z at the end.
        assert!(cut.contains(
            "<path data-sheet=\"0\" data-piece=\"0\" d=\"M 10 100 L 30 100 L 30 80 L 10 80 Z\"/>"
        ));
        // Second sheet: offset by 200 + 20, flipped by its own height 120.
        assert!(cut.contains(
            "<path data-sheet=\"1\" data-piece=\"1\" d=\"M 230 120 L 250 120 L 250 100 L 230 100 Z\"/>"
        ));
        // Open stroke without piece: no Z, no data-piece.
        assert!(cut.contains("<path data-sheet=\"1\" d=\"M 220 120 L 225 115\"/>"));
        assert!(mountain.contains("d=\"M 221.5 117.75 L 223 116\""));
        for line in svg.lines().filter(|l| l.contains("<path")) {
            let closed = line.contains("Z\"");
            assert_eq!(
                closed,
                line.contains("d=\"M 10 100") || line.contains("d=\"M 230 120")
            );
        }
    }

    #[test]
    fn deterministic() {
        let job = two_sheet_job();
        assert_eq!(render(&job).as_bytes(), render(&job.clone()).as_bytes());
    }

    #[test]
    fn empty_job_has_all_layers() {
        let svg = render(&Job {
            name: String::new(),
            sheets: Vec::new(),
        });
        check_well_formed(&svg);
        for n in LAYERS {
            assert!(svg.contains(&format!("id=\"layer-{n}\"")));
        }
        assert_eq!(svg.matches("<path").count(), 0);
    }
}
