//! DXF output for sheet-metal shops (issue 4, item 6): one ASCII DXF per sheet of a nested
//! [`Layout`], 1:1 in millimetres (`$INSUNITS` 4), sheet frame as in the rest of flatcut (x
//! right, y up, origin at the sheet's lower-left corner).
//!
//! Written by hand (DXF is text) as AutoCAD R2000 (`$ACADVER` AC1015) or later, because
//! LWPOLYLINE does not exist in R12 and readers drop it from files that say R12. Layers:
//!
//! - `CUT`: piece outlines and holes, closed LWPOLYLINEs;
//! - `BEND_UP` / `BEND_DOWN`: bend (fold) lines as LINEs. Seen from the printed side, which faces
//!   the viewer, a valley fold brings the flanges up toward the viewer (`BEND_UP`) and a mountain
//!   fold takes them down (`BEND_DOWN`); fittings print their outside, so a cone's bends are all
//!   `BEND_DOWN`;
//! - `MARK`: edge ids beside cut edges, open LWPOLYLINEs (single-stroke font);
//! - `TEXT`: piece labels as strokes, and one TEXT entity per bend line giving its angle
//!   (`12.5° DOWN`) where the pattern wrote the bend's note (beside the line, clear of the
//!   other lines and texts: `pattern::legible`), at the note's height, reading left to right;
//!   a bend whose note was left out for want of room gets it at the middle of the line, along
//!   it (CAD and brake software still read every angle).
//!
//! Choices: every entity has a handle and its subclass markers, the tables hold the layers and
//! the CONTINUOUS line type only; coordinates have 4 decimals (0.1 µm).

use crate::nest::Layout;
use crate::pattern::FoldKind;
use glam::DVec2;
use std::fmt::Write;

/// Layer names.
pub(crate) const LAYERS: [(&str, u8); 5] = [
    ("CUT", 7),
    ("BEND_UP", 1),
    ("BEND_DOWN", 5),
    ("MARK", 3),
    ("TEXT", 8),
];

struct Dxf {
    out: String,
    handle: u32,
}

impl Dxf {
    fn pair(&mut self, code: i32, value: impl std::fmt::Display) {
        let _ = write!(self.out, "{code}\n{value}\n");
    }
    fn num(&mut self, code: i32, v: f64) {
        let v = if v.is_finite() { v } else { 0.0 };
        self.pair(code, format!("{v:.4}"));
    }
    fn handle(&mut self) {
        self.handle += 1;
        let h = format!("{:X}", self.handle);
        self.pair(5, h);
    }
    /// `0 SECTION`, `2 name`.
    fn section(&mut self, name: &str) {
        self.pair(0, "SECTION");
        self.pair(2, name);
    }
    /// A symbol table's header: its name, handle and number of entries.
    fn table(&mut self, name: &str, entries: usize) {
        self.pair(0, "TABLE");
        self.pair(2, name);
        self.handle();
        self.pair(100, "AcDbSymbolTable");
        self.pair(70, entries);
    }
    /// The start of one record of a symbol table: `kind`, its handle and subclass markers.
    fn record(&mut self, kind: &str, subclass: &str) {
        self.pair(0, kind);
        self.handle();
        self.pair(100, "AcDbSymbolTableRecord");
        self.pair(100, subclass);
    }
    fn entity(&mut self, kind: &str, layer: &str, subclass: &str) {
        self.pair(0, kind);
        self.handle();
        self.pair(100, "AcDbEntity");
        self.pair(8, layer);
        self.pair(100, subclass);
    }
    fn polyline(&mut self, layer: &str, pts: &[DVec2], closed: bool) {
        if pts.len() < 2 {
            return;
        }
        self.entity("LWPOLYLINE", layer, "AcDbPolyline");
        self.pair(90, pts.len());
        self.pair(70, if closed { 1 } else { 0 });
        for p in pts {
            self.num(10, p.x);
            self.num(20, p.y);
        }
    }
    fn line(&mut self, layer: &str, a: DVec2, b: DVec2) {
        self.entity("LINE", layer, "AcDbLine");
        for (c, p) in [(10, a), (11, b)] {
            self.num(c, p.x);
            self.num(c + 10, p.y);
            self.num(c + 20, 0.0);
        }
    }
    fn text(&mut self, layer: &str, at: DVec2, height: f64, angle_deg: f64, s: &str) {
        self.entity("TEXT", layer, "AcDbText");
        self.num(10, at.x);
        self.num(20, at.y);
        self.num(30, 0.0);
        self.num(40, height);
        self.pair(1, s);
        self.num(50, angle_deg);
        self.pair(100, "AcDbText");
    }
}

/// A bend note's box on the sheet as a DXF TEXT takes it: the baseline's left end, the height
/// and the angle (degrees) of the reading direction, turned to read left to right.
fn note_box(t: &crate::pattern::Text, place: &crate::nest::Placement) -> Option<(DVec2, f64, f64)> {
    let r = t.dir?;
    let o = t.points().next()?;
    let mut e1 = (place.apply(o + r) - place.apply(o)).try_normalize()?;
    if e1.x < -1e-9 || (e1.x.abs() <= 1e-9 && e1.y < 0.0) {
        e1 = -e1;
    }
    let e2 = e1.perp();
    let (lo, hi) = crate::geom::polygon::bounds(t.points().map(|q| {
        let s = place.apply(q);
        DVec2::new(s.dot(e1), s.dot(e2))
    }))?;
    let h = hi.y - lo.y;
    (h > 0.0).then_some((e1 * lo.x + e2 * lo.y, h, e1.y.atan2(e1.x).to_degrees()))
}

/// The DXF text of one sheet of a layout.
pub fn render(layout: &Layout, sheet: usize) -> String {
    let mut d = Dxf {
        out: String::new(),
        handle: 0x10,
    };
    d.section("HEADER");
    d.pair(9, "$ACADVER");
    d.pair(1, "AC1015");
    d.pair(9, "$INSUNITS");
    d.pair(70, 4);
    d.pair(9, "$MEASUREMENT");
    d.pair(70, 1);
    d.pair(0, "ENDSEC");

    d.section("TABLES");
    d.table("LTYPE", 1);
    d.record("LTYPE", "AcDbLinetypeTableRecord");
    d.pair(2, "CONTINUOUS");
    d.pair(70, 0);
    d.pair(3, "Solid line");
    d.pair(72, 65);
    d.pair(73, 0);
    d.num(40, 0.0);
    d.pair(0, "ENDTAB");
    d.table("LAYER", LAYERS.len());
    for (name, color) in LAYERS {
        d.record("LAYER", "AcDbLayerTableRecord");
        d.pair(2, name);
        d.pair(70, 0);
        d.pair(62, color);
        d.pair(6, "CONTINUOUS");
    }
    d.pair(0, "ENDTAB");
    d.pair(0, "ENDSEC");

    d.section("ENTITIES");
    if let Some(sh) = layout.sheets.get(sheet) {
        for &k in &sh.pieces {
            let (piece, place) = (&layout.pieces[k], &layout.placements[k]);
            let map =
                |pts: &[DVec2]| -> Vec<DVec2> { pts.iter().map(|p| place.apply(*p)).collect() };
            for ring in &piece.outline {
                d.polyline("CUT", &map(ring), true);
            }
            for n in &piece.notches {
                d.polyline(if n.cut { "CUT" } else { "MARK" }, &map(&n.stroke), false);
            }
            for (i, f) in piece.folds.iter().enumerate() {
                let (a, b) = (place.apply(f.a), place.apply(f.b));
                let (layer, word) = match f.kind {
                    FoldKind::Valley => ("BEND_UP", "UP"),
                    FoldKind::Mountain => ("BEND_DOWN", "DOWN"),
                };
                d.line(layer, a, b);
                if f.tab {
                    continue;
                }
                let words = format!("{:.1}%%d {word}", f.angle.to_degrees());
                // Where the pattern wrote the bend's note, clear of the lines and the other
                // texts; a bend whose note was left out gets its text on the line's middle.
                let note = piece
                    .note_folds
                    .iter()
                    .position(|&k| k == i)
                    .and_then(|j| piece.notes.get(j))
                    .and_then(|t| note_box(t, place));
                match note {
                    Some((at, h, ang)) => d.text("TEXT", at, h, ang, &words),
                    None => {
                        let dir = b - a;
                        let mut ang = dir.y.atan2(dir.x).to_degrees();
                        if !(-90.0..=90.0).contains(&ang) {
                            ang += 180.0;
                        }
                        let h = (0.04 * a.distance(b)).clamp(1.0, 3.0);
                        d.text("TEXT", 0.5 * (a + b), h, ang, &words);
                    }
                }
            }
            for m in &piece.marks {
                for s in &m.text.strokes {
                    d.polyline("MARK", &map(s), false);
                }
            }
            for s in piece.seam_line.iter() {
                d.polyline("MARK", &map(s), true);
            }
            for s in piece.grain_line.iter() {
                d.polyline("MARK", &map(s), false);
            }
            for s in &piece.label.strokes {
                d.polyline("TEXT", &map(s), false);
            }
        }
    }
    d.pair(0, "ENDSEC");
    d.pair(0, "EOF");
    d.out
}
