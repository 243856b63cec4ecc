//! PDF output: a vector document of a [`Job`], 1:1 in millimetres, one page per sheet, written
//! with `pdf-writer` (no system packages, no fonts).
//!
//! Choices:
//! - Units: each page's `MediaBox` is the sheet, in points (1 mm = 72/25.4 pt); the content
//!   stream starts with a `cm` of that factor, so every coordinate in it is the job's own
//!   millimetres, x right, y up, origin at the sheet's lower-left corner — the job's frame,
//!   with no flip. Coordinates are rounded once to 0.001 mm. A sheet whose size is zero,
//!   negative or not a number gets a 1 mm side so that the page stays valid. No `UserUnit`:
//!   a page over 5080 mm (14 400 pt, a roll longer than 5 m) is read by poppler but beyond
//!   what Acrobat shows; tiling (issue 25, item 2) is the way to print such a sheet.
//! - Layers: the stroke roles are grouped into optional content groups (`/OCProperties` in the
//!   catalog, all on, the viewer's layer panel opened with `/PageMode /UseOC`) that a viewer
//!   or printer can switch: `Cut` (cuts and notches), `Folds` (mountain and valley), `Marks`,
//!   `Labels`, `Seams`, `Grain`, `Weed`, and `Test squares`. A group exists only if the job
//!   has a stroke of it (the test squares always). Each role's strokes on a page are one
//!   `/OC /ocN BDC … EMC` section, drawn in `DRAW_ORDER` (cuts on top), with the SVG's
//!   colours, widths and dash patterns (in mm). Labels and edge ids are the single-stroke
//!   font's strokes already in the job, so no font is embedded.
//! - Test squares: a 50 mm and a 2 in (50.8 mm) square, outlined 0.2 mm black, with "50 mm" and
//!   "2 in" inside in the single-stroke font ([`crate::geom::font`]). A spot is free if it is
//!   `SQUARE_INSET_MM` inside the page's edges, keeps `SQUARE_CLEARANCE_MM` from every stroke
//!   and is not inside a piece; the squares go, `SQUARE_GAP_MM` apart, side by side into the
//!   first free corner (top left, top right, bottom right, bottom left) or else the first free
//!   spot of a grid over the page; failing that stacked, the same way; failing that each on
//!   its own. With no free spot at all they go into the top-left corner over the pieces: they
//!   are in their own layer, so they can be switched off ([`test_squares`] says which).
//! - Content streams are not compressed: the files stay readable and diffable, and the
//!   tests read the coordinates back. Output is a pure function of the job: no dates, no file
//!   id, fixed object numbers.

use glam::DVec2;
use pdf_writer::types::{LineCapStyle, LineJoinStyle, PageMode};
use pdf_writer::{Content, Finish, Name, Pdf, Rect, Ref, TextStr};

use super::{role_style, DRAW_ORDER};
use crate::toolpath::{Job, SheetJob, Stroke, StrokeRole};

/// Points per millimetre.
pub const PT_PER_MM: f64 = 72.0 / 25.4;

/// The sides of the test squares, mm: 50 mm and 2 in.
pub const TEST_SQUARE_SIDES_MM: [f64; 2] = [50.0, 50.8];

/// Gap between the two test squares, mm.
const SQUARE_GAP_MM: f64 = 4.0;

/// Distance of the test squares from the page's edges, mm.
pub const SQUARE_INSET_MM: f64 = 5.0;

/// Smallest distance from the test squares to any stroke, mm.
pub const SQUARE_CLEARANCE_MM: f64 = 3.0;

/// Outline width of the test squares, mm.
const SQUARE_LINE_MM: f64 = 0.2;

/// Cap height of the test squares' captions, mm.
const CAPTION_MM: f64 = 3.0;

/// A switchable layer of the document (an optional content group).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Layer {
    Cut,
    Folds,
    Marks,
    Labels,
    Seams,
    Grain,
    Weed,
    TestSquares,
}

impl Layer {
    /// Every layer, in the order of the viewer's layer panel.
    pub const ALL: [Layer; 8] = [
        Layer::Cut,
        Layer::Folds,
        Layer::Marks,
        Layer::Labels,
        Layer::Seams,
        Layer::Grain,
        Layer::Weed,
        Layer::TestSquares,
    ];

    /// The layer a stroke of `role` is drawn in.
    pub fn of(role: StrokeRole) -> Layer {
        match role {
            StrokeRole::Cut | StrokeRole::Notch => Layer::Cut,
            StrokeRole::FoldMountain | StrokeRole::FoldValley => Layer::Folds,
            StrokeRole::Mark | StrokeRole::Register => Layer::Marks,
            StrokeRole::Label => Layer::Labels,
            StrokeRole::Seam => Layer::Seams,
            StrokeRole::Grain => Layer::Grain,
            StrokeRole::Weed => Layer::Weed,
        }
    }

    /// The name a viewer shows.
    pub fn name(self) -> &'static str {
        match self {
            Layer::Cut => "Cut",
            Layer::Folds => "Folds",
            Layer::Marks => "Marks",
            Layer::Labels => "Labels",
            Layer::Seams => "Seams",
            Layer::Grain => "Grain",
            Layer::Weed => "Weed",
            Layer::TestSquares => "Test squares",
        }
    }
}

/// One test square: its lower-left corner on the sheet and its side, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TestSquare {
    pub corner: DVec2,
    pub side: f64,
}

/// Where the test squares of a sheet go (see the module doc), and whether that spot is free
/// (`false`: no free spot was found and they lie over the pieces).
pub fn test_squares(sheet: &SheetJob) -> (Vec<TestSquare>, bool) {
    let (w, h) = page_size_mm(sheet);
    let [a, b] = TEST_SQUARE_SIDES_MM;
    let step = a + SQUARE_GAP_MM;
    let mut obstacles = Obstacles::of(sheet);
    let square = |at: DVec2, side: f64| TestSquare { corner: at, side };
    // Side by side, then stacked.
    if let Some(at) = find_spot(&obstacles, w, h, step + b, b) {
        return (vec![square(at, a), square(at + DVec2::X * step, b)], true);
    }
    if let Some(at) = find_spot(&obstacles, w, h, b, step + b) {
        return (vec![square(at, a), square(at + DVec2::Y * step, b)], true);
    }
    // Each where it finds room, the second clear of the first.
    if let Some(at_a) = find_spot(&obstacles, w, h, a, a) {
        obstacles.boxes.push((at_a, at_a + DVec2::splat(a)));
        if let Some(at_b) = find_spot(&obstacles, w, h, b, b) {
            return (vec![square(at_a, a), square(at_b, b)], true);
        }
    }
    let i = SQUARE_INSET_MM;
    if step + b + 2.0 * i > w && b + 2.0 * i <= w {
        // Stacked, if only that fits across the page.
        let at = DVec2::new(i, h - i - step - b);
        return (vec![square(at, a), square(at + DVec2::Y * step, b)], false);
    }
    let at = DVec2::new(i, h - i - b);
    (vec![square(at, a), square(at + DVec2::X * step, b)], false)
}

/// The first free spot (lower-left corner) for a `bw` × `bh` block on a `w` × `h` page,
/// `SQUARE_INSET_MM` inside its edges: a corner (top left, top right, bottom right, bottom
/// left), else the first of a grid of at most 41 × 41 spots, top to bottom, left to right.
fn find_spot(obstacles: &Obstacles, w: f64, h: f64, bw: f64, bh: f64) -> Option<DVec2> {
    let i = SQUARE_INSET_MM;
    let (room_x, room_y) = (w - 2.0 * i - bw, h - 2.0 * i - bh);
    if room_x < 0.0 || room_y < 0.0 {
        return None;
    }
    let corners = [
        DVec2::new(i, i + room_y),
        DVec2::new(i + room_x, i + room_y),
        DVec2::new(i + room_x, i),
        DVec2::new(i, i),
    ];
    let grid = (0..=40).flat_map(|r| {
        (0..=40).map(move |c| {
            DVec2::new(
                i + room_x * f64::from(c) / 40.0,
                i + room_y * (1.0 - f64::from(r) / 40.0),
            )
        })
    });
    corners
        .into_iter()
        .chain(grid)
        .find(|&at| obstacles.free(at, bw, bh))
}

/// The strokes of a sheet as segments with their bounds, and the closed cut outlines (the
/// pieces), for [`test_squares`].
struct Obstacles {
    segments: Vec<(DVec2, DVec2)>,
    outlines: Vec<Vec<DVec2>>,
    /// Squares placed already (lower-left, upper-right corners).
    boxes: Vec<(DVec2, DVec2)>,
}

impl Obstacles {
    fn of(sheet: &SheetJob) -> Self {
        let mut segments = Vec::new();
        let mut outlines = Vec::new();
        for s in &sheet.strokes {
            let Some(pts) = drawable(s) else { continue };
            segments.extend(pts.windows(2).map(|w| (w[0], w[1])));
            if s.closed {
                if let (Some(&a), Some(&b)) = (pts.last(), pts.first()) {
                    segments.push((a, b));
                }
                if s.role == StrokeRole::Cut {
                    outlines.push(pts);
                }
            } else if pts.len() == 1 {
                segments.push((pts[0], pts[0]));
            }
        }
        Obstacles {
            segments,
            outlines,
            boxes: Vec::new(),
        }
    }

    /// Whether the block at `at` (lower-left), `bw` × `bh`, grown by the clearance, touches no
    /// stroke and does not lie inside a piece.
    fn free(&self, at: DVec2, bw: f64, bh: f64) -> bool {
        let c = SQUARE_CLEARANCE_MM;
        let lo = at - DVec2::splat(c);
        let hi = at + DVec2::new(bw + c, bh + c);
        if self
            .segments
            .iter()
            .any(|&(p, q)| segment_meets_box(p, q, lo, hi))
        {
            return false;
        }
        let centre = (lo + hi) / 2.0;
        !self.outlines.iter().any(|o| inside(centre, o))
    }
}

/// Whether segment `p`–`q` meets the box `lo`..`hi` (Liang–Barsky clipping).
fn segment_meets_box(p: DVec2, q: DVec2, lo: DVec2, hi: DVec2) -> bool {
    let d = q - p;
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for (dp, lo_gap, hi_gap) in [(d.x, p.x - lo.x, hi.x - p.x), (d.y, p.y - lo.y, hi.y - p.y)] {
        // Inside the slab: −dp·t ≤ lo_gap and dp·t ≤ hi_gap.
        for (a, b) in [(-dp, lo_gap), (dp, hi_gap)] {
            if a == 0.0 {
                if b < 0.0 {
                    return false;
                }
            } else {
                let t = b / a;
                if a < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
            }
        }
    }
    t0 <= t1
}

/// Even-odd point in polygon.
fn inside(p: DVec2, poly: &[DVec2]) -> bool {
    let mut inside = false;
    let n = poly.len();
    for k in 0..n {
        let (a, b) = (poly[k], poly[(k + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

/// Largest coordinate drawn, mm (10 km): beyond it f32 loses the 0.001 mm and, far beyond,
/// the number itself.
const MAX_COORD_MM: f64 = 1e7;

/// The points of a stroke to draw: none with a non-finite coordinate or one beyond
/// `MAX_COORD_MM`, a closed stroke without its repeated end point; `None` for a stroke with
/// nothing to draw.
fn drawable(s: &Stroke) -> Option<Vec<DVec2>> {
    let bad = |p: &DVec2| !(p.x.abs() <= MAX_COORD_MM && p.y.abs() <= MAX_COORD_MM);
    if s.points.is_empty() || s.points.iter().any(bad) {
        return None;
    }
    let mut pts = s.points.clone();
    if s.closed && pts.len() > 2 && pts[0].distance(pts[pts.len() - 1]) <= 1e-9 {
        pts.pop();
    }
    Some(pts)
}

/// The page size of a sheet, mm: its own, or 1 mm for a side that is not a positive number
/// up to `MAX_COORD_MM`.
fn page_size_mm(sheet: &SheetJob) -> (f64, f64) {
    let ok = |v: f64| if v > 0.0 && v <= MAX_COORD_MM { v } else { 1.0 };
    (ok(sheet.width), ok(sheet.height))
}

/// A coordinate in mm, rounded to 0.001 mm, for the content stream.
fn mm(v: f64) -> f32 {
    ((v * 1000.0).round() / 1000.0) as f32
}

/// The layers the job uses, in panel order: those of its strokes' roles and the test squares.
fn layers_used(job: &Job) -> Vec<Layer> {
    let mut used: Vec<Layer> = job
        .sheets
        .iter()
        .flat_map(|s| &s.strokes)
        .filter(|s| drawable(s).is_some())
        .map(|s| Layer::of(s.role))
        .chain([Layer::TestSquares])
        .collect();
    used.sort();
    used.dedup();
    used
}

/// Renders the whole job as one PDF document, a page per sheet.
pub fn render(job: &Job) -> Vec<u8> {
    let layers = layers_used(job);
    let catalog_id = Ref::new(1);
    let pages_id = Ref::new(2);
    let layer_ids: Vec<Ref> = (0..layers.len()).map(|k| Ref::new(3 + k as i32)).collect();
    let first_page = 3 + layers.len() as i32;
    // Per sheet: its page, then its content stream.
    let page_ids: Vec<Ref> = (0..job.sheets.len())
        .map(|k| Ref::new(first_page + 2 * k as i32))
        .collect();
    // Resource names of the layers in the pages: /oc1, /oc2, …
    let oc_names: Vec<String> = (1..=layers.len()).map(|k| format!("oc{k}")).collect();
    let oc_name = |layer: Layer| -> &[u8] {
        let k = layers.iter().position(|l| *l == layer).unwrap_or(0);
        oc_names.get(k).map_or(b"oc1", |s| s.as_bytes())
    };

    let mut pdf = Pdf::new();
    let mut catalog = pdf.catalog(catalog_id);
    catalog.pages(pages_id).page_mode(PageMode::UseOC);
    let mut props = catalog.insert(Name(b"OCProperties")).dict();
    props
        .insert(Name(b"OCGs"))
        .array()
        .items(layer_ids.iter().copied());
    let mut config = props.insert(Name(b"D")).dict();
    config.pair(Name(b"Name"), TextStr("Layers"));
    config.pair(Name(b"BaseState"), Name(b"ON"));
    config
        .insert(Name(b"Order"))
        .array()
        .items(layer_ids.iter().copied());
    config.finish();
    props.finish();
    catalog.finish();

    pdf.pages(pages_id)
        .kids(page_ids.iter().copied())
        .count(page_ids.len() as i32);
    for (layer, id) in layers.iter().zip(&layer_ids) {
        pdf.indirect(*id)
            .dict()
            .pair(Name(b"Type"), Name(b"OCG"))
            .pair(Name(b"Name"), TextStr(layer.name()));
    }

    for (sheet, &page_id) in job.sheets.iter().zip(&page_ids) {
        let content_id = Ref::new(page_id.get() + 1);
        let (w, h) = page_size_mm(sheet);
        let mut page = pdf.page(page_id);
        page.parent(pages_id)
            .media_box(Rect::new(
                0.0,
                0.0,
                (w * PT_PER_MM) as f32,
                (h * PT_PER_MM) as f32,
            ))
            .contents(content_id);
        let mut resources = page.resources();
        let mut named = resources.insert(Name(b"Properties")).dict();
        for (layer, id) in layers.iter().zip(&layer_ids) {
            named.pair(Name(oc_name(*layer)), *id);
        }
        named.finish();
        resources.finish();
        page.finish();
        let content = page_content(sheet, &oc_name);
        pdf.stream(content_id, &content);
    }
    pdf.finish()
}

/// The content stream of one sheet's page; `oc_name` gives the resource name of a layer.
fn page_content<'a>(sheet: &SheetJob, oc_name: &dyn Fn(Layer) -> &'a [u8]) -> Vec<u8> {
    let mut c = Content::new();
    let k = PT_PER_MM as f32;
    c.transform([k, 0.0, 0.0, k, 0.0, 0.0]);
    c.set_line_cap(LineCapStyle::RoundCap);
    c.set_line_join(LineJoinStyle::RoundJoin);
    for role in DRAW_ORDER {
        let strokes: Vec<(Vec<DVec2>, bool)> = sheet
            .strokes
            .iter()
            .filter(|s| s.role == role)
            .filter_map(|s| drawable(s).map(|p| (p, s.closed)))
            .collect();
        if strokes.is_empty() {
            continue;
        }
        let style = role_style(role);
        let [r, g, b] = style.rgb.map(|v| f32::from(v) / 255.0);
        c.begin_marked_content_with_properties(Name(b"OC"))
            .properties_named(Name(oc_name(Layer::of(role))));
        c.save_state();
        c.set_stroke_rgb(r, g, b);
        c.set_line_width(super::svg::stroke_width_mm(role) as f32);
        if !style.dash_mm.is_empty() {
            c.set_dash_pattern(style.dash_mm.iter().map(|&d| d as f32), 0.0);
        }
        for (pts, closed) in &strokes {
            path(&mut c, pts, *closed);
        }
        c.stroke();
        c.restore_state();
        c.end_marked_content();
    }

    let (squares, _) = test_squares(sheet);
    c.begin_marked_content_with_properties(Name(b"OC"))
        .properties_named(Name(oc_name(Layer::TestSquares)));
    c.save_state();
    c.set_stroke_rgb(0.0, 0.0, 0.0);
    c.set_line_width(SQUARE_LINE_MM as f32);
    for sq in &squares {
        let p = sq.corner;
        c.rect(mm(p.x), mm(p.y), mm(sq.side), mm(sq.side));
        let text = if sq.side == TEST_SQUARE_SIDES_MM[0] {
            "50 mm"
        } else {
            "2 in"
        };
        let (glyphs, _) = crate::geom::font::text_strokes(text, CAPTION_MM);
        let at = p + DVec2::splat(CAPTION_MM);
        for g in glyphs {
            let pts: Vec<DVec2> = g.iter().map(|q| at + *q).collect();
            path(&mut c, &pts, false);
        }
    }
    c.stroke();
    c.restore_state();
    c.end_marked_content();
    c.finish().to_vec()
}

/// Appends one subpath through `pts` (a dot for a single point), closed with `h` if `closed`.
fn path(c: &mut Content, pts: &[DVec2], closed: bool) {
    let Some(first) = pts.first() else { return };
    c.move_to(mm(first.x), mm(first.y));
    if pts.len() == 1 {
        c.line_to(mm(first.x), mm(first.y));
    }
    for p in &pts[1..] {
        c.line_to(mm(p.x), mm(p.y));
    }
    if closed {
        c.close_path();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::fixtures::{sheet, stroke};

    fn job(sheets: Vec<SheetJob>) -> Job {
        Job {
            name: "t".into(),
            sheets,
        }
    }

    /// The content streams of a document, as text, page by page.
    fn contents(pdf: &[u8]) -> Vec<String> {
        let text = String::from_utf8_lossy(pdf).into_owned();
        text.split(">>\nstream\n")
            .skip(1)
            .filter_map(|s| s.split("endstream").next())
            .map(str::to_string)
            .collect()
    }

    #[test]
    fn pages_layers_and_coordinates() {
        let mut big = sheet(vec![
            stroke(
                StrokeRole::Cut,
                &[(60.0, 10.0), (90.0, 10.0), (90.0, 40.0), (60.0, 10.0)],
            ),
            stroke(StrokeRole::FoldValley, &[(61.0, 20.0), (80.5, 20.25)]),
        ]);
        big.width = 300.0;
        big.height = 200.0;
        let doc = render(&job(vec![big, sheet(vec![])]));
        let text = String::from_utf8_lossy(&doc).into_owned();
        assert!(text.starts_with("%PDF-1.7"));
        assert!(text.contains("/Count 2"));
        // 300 × 200 mm in points.
        assert!(
            text.contains("/MediaBox [0 0 850.3937 566.92914]"),
            "{text}"
        );
        assert!(text.contains("/MediaBox [0 0 283.46457 283.46457]"));
        // Layers: only those used, and the test squares.
        for name in ["(Cut)", "(Folds)", "(Test squares)"] {
            assert!(
                text.contains(&format!("/Type /OCG\n  /Name {name}")),
                "{name}"
            );
        }
        assert!(!text.contains("(Marks)"));
        assert!(text.contains("/OCProperties"));
        let pages = contents(&doc);
        assert_eq!(pages.len(), 2);
        let p = &pages[0];
        assert!(p.starts_with("2.8346457 0 0 2.8346457 0 0 cm"), "{p}");
        // The cut, closed without its repeated end, in mm; the fold in its own section.
        assert!(p.contains("/OC /oc1 BDC"), "{p}");
        assert!(p.contains("60 10 m\n90 10 l\n90 40 l\nh\n"), "{p}");
        assert!(p.contains("61 20 m\n80.5 20.25 l\n"), "{p}");
        assert!(p.contains("[2 1] 0 d"), "valley dashes: {p}");
        assert_eq!(p.matches("BDC").count(), p.matches("EMC").count());
        // Two test squares on each page.
        for p in &pages {
            assert_eq!(p.matches(" re").count(), 2, "{p}");
        }
    }

    #[test]
    fn squares_keep_clear_of_the_pieces() {
        // A piece in the top-left corner: the squares go to the top right.
        let mut s = sheet(vec![stroke(
            StrokeRole::Cut,
            &[(0.0, 100.0), (100.0, 100.0), (100.0, 300.0), (0.0, 100.0)],
        )]);
        s.width = 300.0;
        s.height = 300.0;
        let (sq, free) = test_squares(&s);
        assert!(free);
        assert_eq!(sq.len(), 2);
        assert_eq!(
            sq[0].corner,
            DVec2::new(300.0 - 5.0 - 104.8, 300.0 - 5.0 - 50.8)
        );
        assert_eq!((sq[0].side, sq[1].side), (50.0, 50.8));
        assert!((sq[1].corner.x - sq[0].corner.x - 54.0).abs() < 1e-9);
        // A piece covering the whole page, its outline outside the squares' reach: inside a
        // piece is not free, so they lie over it and say so.
        let mut s = sheet(vec![stroke(
            StrokeRole::Cut,
            &[
                (1.0, 1.0),
                (299.0, 1.0),
                (299.0, 299.0),
                (1.0, 299.0),
                (1.0, 1.0),
            ],
        )]);
        s.width = 300.0;
        s.height = 300.0;
        let (sq, free) = test_squares(&s);
        assert!(!free);
        assert_eq!(sq[0].corner, DVec2::new(5.0, 300.0 - 5.0 - 50.8));
        // An empty narrow sheet: stacked.
        let mut s = sheet(vec![]);
        s.width = 70.0;
        s.height = 300.0;
        let (sq, free) = test_squares(&s);
        assert!(free);
        assert_eq!(sq[0].corner.x, sq[1].corner.x);
    }

    #[test]
    fn boxes_and_segments() {
        let (lo, hi) = (DVec2::ZERO, DVec2::new(10.0, 10.0));
        let seg = |a: (f64, f64), b: (f64, f64)| {
            segment_meets_box(DVec2::new(a.0, a.1), DVec2::new(b.0, b.1), lo, hi)
        };
        assert!(seg((-5.0, 5.0), (15.0, 5.0)));
        assert!(seg((2.0, 2.0), (3.0, 3.0)));
        assert!(seg((-1.0, 5.0), (5.0, -1.0)));
        assert!(!seg((-5.0, 11.0), (15.0, 11.0)));
        assert!(!seg((-5.0, 5.0), (3.0, 15.0)));
        assert!(seg((5.0, 5.0), (5.0, 5.0)));
        assert!(!seg((11.0, 5.0), (11.0, 5.0)));
    }

    #[test]
    fn bad_input_does_not_panic_and_output_is_stable() {
        let mut s = sheet(vec![
            stroke(StrokeRole::Cut, &[(f64::NAN, 1.0), (2.0, 2.0)]),
            stroke(StrokeRole::Label, &[]),
            stroke(StrokeRole::Mark, &[(1e300, 3.0), (4.0, 3.0)]),
            stroke(StrokeRole::Grain, &[(5.0, 5.0)]),
        ]);
        s.width = f64::NAN;
        s.height = -3.0;
        let doc = render(&job(vec![s.clone()]));
        let text = String::from_utf8_lossy(&doc).into_owned();
        assert!(
            text.contains("/MediaBox [0 0 2.8346457 2.8346457]"),
            "{text}"
        );
        assert!(!text.contains("NaN") && !text.contains("inf"));
        assert!(!text.contains("(Cut)"), "a stroke with NaN is not drawn");
        assert_eq!(render(&job(vec![s])), doc);
        let empty = render(&job(vec![]));
        assert!(String::from_utf8_lossy(&empty).contains("/Count 0"));
    }
}
