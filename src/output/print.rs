//! Tiled printing for home printers (`--print a4|letter|a3|…`): each sheet of a [`Job`] split
//! into printer pages, 1:1, that are trimmed and taped together into the sheet, with an
//! assembly map page per sheet. The sheets' drawing is the 1:1 PDF's ([`super::pdf`]), so the
//! layers, colours and stroke widths are the same.
//!
//! Choices (no paper to follow; what sewing-pattern PDFs do):
//! - The printer cannot print within `margin_mm` of a page edge (6.35 mm, ¼ in, by default:
//!   what most home inkjet and laser printers leave). The printable rectangle of a page shows
//!   a window of the sheet; neighbouring windows overlap by `overlap_mm` (10.16 mm by default).
//! - Every length of the tiling (margin, overlap, window, step) is a whole number of
//!   [`GRID_MM`] = 0.254 mm (1/100 in): a whole number of pixels at 300, 600 and 1200 dpi and
//!   of 0.001 mm, the PDF's rounding. Two pages showing the same part of a sheet then draw it
//!   at the same sub-pixel phase, so their overlap strips rasterise to the same pixels. The
//!   margin is rounded up and the printable size down to that grid; the overlap to the
//!   nearest step of it.
//! - Rows are lettered from the top of the sheet (A, B, …, Z, AA, …), columns numbered from
//!   the left (1, 2, …): page `B3` is the second row, third column; with several sheets the
//!   label starts with the sheet (`2-B3`). Each sheet is printed in the orientation that needs
//!   fewer pages (portrait on a tie).
//! - A page whose window meets no stroke of the sheet is left out (its label is shown on the
//!   map as blank); the map page of each sheet comes before its pages.
//! - Alignment: the middle of every overlap strip carries a grey dashed match line across the
//!   whole sheet with a filled rhombus ("diamond") every [`DIAMOND_STEP_MM`]; both pages that share the
//!   strip draw it in the sheet's frame, under the pattern, so it lands on the same pixels
//!   of the sheet and hides no line. Page labels stay out of the overlap strips.
//! - Text (labels, the map's title and notes) is drawn in the single-stroke font and also
//!   written as invisible text (render mode 3, base-14 Helvetica, nothing embedded), so a
//!   viewer can search it and `pdftotext` reads it.
//! - The map page holds the 50 mm and 2 in test squares, to check that the printer printed at
//!   100 %.

use glam::DVec2;
use pdf_writer::types::TextRenderingMode;
use pdf_writer::{Content, Name, Pdf, Ref, Str};
use serde::Serialize;

use super::pdf::{self, Frame, Layer, TestSquare, PT_PER_MM, TEST_SQUARE_SIDES_MM};
use super::texture::{Paint, TexturedFace};
use super::OutputError;
use crate::surface::texture::Image;
use crate::toolpath::{Job, SheetJob, StrokeRole};

/// The grid every length of the tiling is rounded to, mm (1/100 in).
pub const GRID_MM: f64 = 0.254;

/// Spacing of the alignment diamonds along a match line, mm.
pub const DIAMOND_STEP_MM: f64 = 40.0;

/// Half diagonal of an alignment diamond, mm.
const DIAMOND_MM: f64 = 2.0;

/// Cap height of a page label, mm.
const LABEL_MM: f64 = 6.0;

/// How far the sheet sits off the pixel grid, mm: the window's corner is drawn this much
/// inside the margin, so that lengths on [`GRID_MM`] (the sheet's origin, the match lines)
/// fall neither on pixel nor on sub-pixel boundaries at 300, 600 or 1200 dpi, where a
/// renderer's rounding can differ between two pages for the same edge.
const PHASE_MM: f64 = 0.01;

/// Smallest step between windows (printable side less overlap), mm: less is no useful page.
const MIN_STEP_MM: f64 = 20.0;

/// Most pages a document may have: more is a mistake of units, not a print job.
pub const MAX_PAGES: usize = 2000;

/// Printer pages, portrait (width × height, mm).
pub const PAPERS: [(&str, f64, f64); 5] = [
    ("a4", 210.0, 297.0),
    ("a3", 297.0, 420.0),
    ("letter", 215.9, 279.4),
    ("legal", 215.9, 355.6),
    ("tabloid", 279.4, 431.8),
];

/// What to print on: the paper (portrait, mm), the printer's unprintable margin and the
/// overlap of neighbouring pages.
#[derive(Debug, Clone, PartialEq)]
pub struct PrintOptions {
    /// Name of the paper, as given (`a4`, `letter`, `200x250`).
    pub paper: String,
    pub width: f64,
    pub height: f64,
    /// The printer's unprintable margin at every edge, mm.
    pub margin_mm: f64,
    /// Overlap of neighbouring pages, mm.
    pub overlap_mm: f64,
}

impl Default for PrintOptions {
    fn default() -> Self {
        PrintOptions {
            paper: "a4".into(),
            width: 210.0,
            height: 297.0,
            margin_mm: 6.35,
            overlap_mm: 10.16,
        }
    }
}

/// One printed page of a sheet.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tile {
    /// 1-based page number in the document.
    pub page: usize,
    /// `B3`, or `2-B3` with several sheets.
    pub label: String,
    /// 0-based row (from the top of the sheet) and column (from the left).
    pub row: usize,
    pub col: usize,
    /// The part of the sheet the page shows, mm: lower-left and upper-right corners.
    pub window_mm: [f64; 4],
    /// Where the window's lower-left corner lies on the page, mm from the page's lower-left.
    pub at_mm: [f64; 2],
}

/// How one sheet is printed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SheetTiling {
    /// 1-based sheet number.
    pub sheet: usize,
    pub landscape: bool,
    /// Page size, mm (as printed: landscape is wider than high).
    pub page_mm: [f64; 2],
    pub rows: usize,
    pub cols: usize,
    /// 1-based page number of the sheet's assembly map.
    pub map_page: usize,
    /// The pages printed, row by row.
    pub tiles: Vec<Tile>,
    /// Labels of the pages left out, with nothing on them.
    pub blank: Vec<String>,
    /// The part of the sheet a page shows (w, h) and how far apart neighbouring pages' parts
    /// start (the window less the overlap), mm.
    #[serde(skip)]
    pub window: DVec2,
    #[serde(skip)]
    pub step: DVec2,
}

impl SheetTiling {
    /// Lower-left corner (sheet mm) of the window of row `r`, column `c` on a sheet `h` high.
    fn cell(&self, r: usize, c: usize, h: f64) -> DVec2 {
        cell_lo(self.window, self.step, h, r, c)
    }
}

/// Lower-left corner of the window of row `r` (from the top), column `c` on a sheet `h` high.
fn cell_lo(win: DVec2, step: DVec2, h: f64, r: usize, c: usize) -> DVec2 {
    DVec2::new(c as f64 * step.x, h - r as f64 * step.y - win.y)
}

/// The label of page row `r`, column `c` of sheet `i` (0-based) of `n`: `B3`, or `2-B3`.
fn page_label(i: usize, n: usize, r: usize, c: usize) -> String {
    let rc = format!("{}{}", row_name(r), c + 1);
    if n > 1 {
        format!("{}-{rc}", i + 1)
    } else {
        rc
    }
}

/// The whole tiled document's plan (written to report.json as `print`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tiling {
    pub paper: String,
    pub margin_mm: f64,
    pub overlap_mm: f64,
    pub pages: usize,
    pub sheets: Vec<SheetTiling>,
}

/// `v` rounded down (`-1`), to the nearest (`0`) or up (`1`) to the grid.
fn snap(v: f64, way: i8) -> f64 {
    let k = v / GRID_MM;
    let k = match way {
        -1 => (k + 1e-9).floor(),
        1 => (k - 1e-9).ceil(),
        _ => k.round(),
    };
    k * GRID_MM
}

/// Row letters: A … Z, AA, AB, …
fn row_name(mut r: usize) -> String {
    let mut s = Vec::new();
    loop {
        s.push(b'A' + (r % 26) as u8);
        if r < 26 {
            break;
        }
        r = r / 26 - 1;
    }
    s.reverse();
    String::from_utf8_lossy(&s).into_owned()
}

/// The grid of one orientation: printable window (w, h), steps, rows and columns, and the
/// windows (row, col, lower-left) that meet a stroke.
struct Grid {
    win: DVec2,
    step: DVec2,
    rows: usize,
    cols: usize,
    used: Vec<(usize, usize, DVec2)>,
    blank: Vec<(usize, usize)>,
}

fn grid(sheet: &SheetJob, page: DVec2, margin: f64, overlap: f64) -> Grid {
    let win = DVec2::new(
        snap(page.x - 2.0 * margin - PHASE_MM, -1),
        snap(page.y - 2.0 * margin - PHASE_MM, -1),
    );
    let step = win - DVec2::splat(overlap);
    let (w, h) = pdf::page_size_mm(sheet);
    let count = |extent: f64, step: f64| -> usize {
        (((extent - overlap) / step - 1e-9).ceil().max(1.0) as usize).min(MAX_PAGES + 1)
    };
    let (cols, rows) = (count(w, step.x), count(h, step.y));
    let mut used = Vec::new();
    let mut blank = Vec::new();
    let segments: Vec<(DVec2, DVec2)> = sheet
        .strokes
        .iter()
        .filter_map(pdf::drawable)
        .flat_map(|p| {
            let n = p.len();
            (0..n.max(1)).map(move |k| (p[k], p[(k + 1).min(n - 1)]))
        })
        .collect();
    if rows.saturating_mul(cols) > MAX_PAGES {
        return Grid {
            win,
            step,
            rows,
            cols,
            used,
            blank,
        };
    }
    for r in 0..rows {
        for c in 0..cols {
            let lo = cell_lo(win, step, h, r, c);
            let hi = lo + win;
            if segments
                .iter()
                .any(|&(p, q)| pdf::segment_meets_box(p, q, lo, hi))
            {
                used.push((r, c, lo));
            } else {
                blank.push((r, c));
            }
        }
    }
    Grid {
        win,
        step,
        rows,
        cols,
        used,
        blank,
    }
}

/// Plans the pages of `job` on the paper of `opts`; refused when the paper leaves no room for
/// a useful window or the job would need more than [`MAX_PAGES`] pages.
pub fn plan(job: &Job, opts: &PrintOptions) -> Result<Tiling, OutputError> {
    let bad = |message: String| OutputError::Print {
        paper: opts.paper.clone(),
        message,
    };
    let ok = |v: f64| v.is_finite() && v >= 0.0;
    if !(ok(opts.width) && ok(opts.height) && ok(opts.margin_mm) && ok(opts.overlap_mm)) {
        return Err(bad("sizes must be numbers of 0 mm or more".into()));
    }
    let margin = snap(opts.margin_mm, 1);
    let overlap = snap(opts.overlap_mm, 0);
    let short = opts.width.min(opts.height);
    if short - 2.0 * margin - overlap < MIN_STEP_MM {
        return Err(bad(format!(
            "a {:.1} x {:.1} mm page less a {margin:.2} mm margin at each edge and a {overlap:.2} mm overlap leaves under {MIN_STEP_MM} mm of new sheet per page; use larger paper, --print-margin or --overlap",
            opts.width, opts.height
        )));
    }
    let mut sheets = Vec::new();
    let mut page = 0;
    let n = job.sheets.len();
    for (i, sheet) in job.sheets.iter().enumerate() {
        let portrait = DVec2::new(opts.width.min(opts.height), opts.width.max(opts.height));
        let landscape = DVec2::new(portrait.y, portrait.x);
        let gp = grid(sheet, portrait, margin, overlap);
        let gl = grid(sheet, landscape, margin, overlap);
        let pages = |g: &Grid| (g.rows.saturating_mul(g.cols), g.used.len());
        let (land, g, size) = if pages(&gl).0 <= MAX_PAGES
            && (pages(&gl).1 < pages(&gp).1 || pages(&gp).0 > MAX_PAGES)
        {
            (true, gl, landscape)
        } else {
            (false, gp, portrait)
        };
        if g.rows.saturating_mul(g.cols) > MAX_PAGES || page + g.used.len() + 1 > MAX_PAGES {
            return Err(bad(format!(
                "sheet {} ({:.0} x {:.0} mm) needs over {MAX_PAGES} pages",
                i + 1,
                sheet.width,
                sheet.height
            )));
        }
        let label = |r: usize, c: usize| page_label(i, n, r, c);
        page += 1;
        let map_page = page;
        let tiles = g
            .used
            .iter()
            .map(|&(r, c, lo)| {
                page += 1;
                Tile {
                    page,
                    label: label(r, c),
                    row: r,
                    col: c,
                    window_mm: [lo.x, lo.y, lo.x + g.win.x, lo.y + g.win.y].map(r3),
                    at_mm: [margin + PHASE_MM, margin + PHASE_MM].map(r3),
                }
            })
            .collect();
        sheets.push(SheetTiling {
            sheet: i + 1,
            landscape: land,
            page_mm: [size.x, size.y],
            rows: g.rows,
            cols: g.cols,
            map_page,
            tiles,
            blank: g.blank.iter().map(|&(r, c)| label(r, c)).collect(),
            window: g.win,
            step: g.step,
        });
    }
    Ok(Tiling {
        paper: opts.paper.clone(),
        margin_mm: r3(margin),
        overlap_mm: r3(overlap),
        pages: page,
        sheets,
    })
}

/// `v` rounded to 0.001 mm.
fn r3(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0
}

/// Renders the tiled document planned by `tiling` (from [`plan`] on the same `job`), with the
/// textured faces of `paint` under the strokes.
pub fn render(job: &Job, tiling: &Tiling, paint: Option<&Paint>) -> Vec<u8> {
    let mut layers = pdf::layers_used(job);
    layers.push(Layer::Tiling);
    if paint.is_some_and(|p| !p.is_empty()) {
        layers.push(Layer::Texture);
    }
    layers.sort();
    layers.dedup();
    let catalog_id = Ref::new(1);
    let pages_id = Ref::new(2);
    let font_id = Ref::new(3);
    let layer_ids: Vec<Ref> = (0..layers.len()).map(|k| Ref::new(4 + k as i32)).collect();
    let first_page = 4 + layers.len() as i32;
    let page_ids: Vec<Ref> = (0..tiling.pages)
        .map(|k| Ref::new(first_page + 2 * k as i32))
        .collect();
    let names = pdf::LayerNames::new(&layers);
    let oc_name = |layer: Layer| names.of(layer);

    let mut doc = Pdf::new();
    pdf::write_catalog(&mut doc, catalog_id, pages_id, &layers, &layer_ids);
    doc.pages(pages_id)
        .kids(page_ids.iter().copied())
        .count(page_ids.len() as i32);
    doc.type1_font(font_id)
        .base_font(Name(b"Helvetica"))
        .encoding_predefined(Name(b"WinAnsiEncoding"));

    let image_ids = paint.map_or(Vec::new(), |p| {
        pdf::pdf_images(&mut doc, p, first_page + 2 * tiling.pages as i32)
    });
    let images: Vec<&Image> = paint.map_or(Vec::new(), |p| p.images().collect());
    let mut contents: Vec<(DVec2, Vec<u8>)> = Vec::new();
    for st in &tiling.sheets {
        let Some(sheet) = job.sheets.get(st.sheet - 1) else {
            continue;
        };
        let size = DVec2::new(st.page_mm[0], st.page_mm[1]);
        contents.push((size, map_content(job, sheet, st, tiling, &oc_name)));
        let faces = paint.map_or(&[][..], |p| p.sheet(st.sheet - 1));
        for t in &st.tiles {
            let drawing = (sheet, faces, &images[..]);
            contents.push((size, tile_content(drawing, st, t, tiling, &oc_name)));
        }
    }
    for ((size, content), &page_id) in contents.iter().zip(&page_ids) {
        let content_id = Ref::new(page_id.get() + 1);
        let refs = pdf::PageRefs {
            page: page_id,
            pages: pages_id,
            content: content_id,
        };
        let resources = pdf::PageResources {
            layers: (&layers, &layer_ids, &names),
            font: Some(font_id),
            images: &image_ids,
        };
        pdf::write_page(&mut doc, refs, (size.x, size.y), &resources);
        doc.stream(content_id, content);
    }
    doc.finish()
}

/// Text in the single-stroke font with its lower-left at `at`, `height` mm cap height, and the
/// same text invisible for search and extraction.
fn text(c: &mut Content, s: &str, at: DVec2, height: f64) {
    let (glyphs, _) = crate::geom::font::text_strokes(s, height);
    for g in glyphs {
        let pts: Vec<DVec2> = g.iter().map(|q| at + *q).collect();
        pdf::path(c, &pts, false);
    }
    c.stroke();
    c.begin_text();
    c.set_text_rendering_mode(TextRenderingMode::Invisible);
    c.set_font(Name(b"F1"), (height * 1.4) as f32);
    c.set_text_matrix([1.0, 0.0, 0.0, 1.0, pdf::mm(at.x), pdf::mm(at.y)]);
    let bytes: Vec<u8> = s
        .chars()
        .map(|ch| if ch.is_ascii() { ch as u8 } else { b'?' })
        .collect();
    c.show(Str(&bytes));
    c.end_text();
}

/// The match lines and diamonds of a sheet's tiling, in sheet mm written in `frame` (see the
/// module doc).
fn alignment(c: &mut Content, sheet: &SheetJob, st: &SheetTiling, tiling: &Tiling, frame: Frame) {
    let (w, h) = pdf::page_size_mm(sheet);
    let (ov, step) = (tiling.overlap_mm, st.step);
    let mut lines = Vec::new();
    for c in 1..st.cols {
        let x = c as f64 * step.x + ov / 2.0;
        lines.push((DVec2::new(x, 0.0), DVec2::new(x, h)));
    }
    for r in 1..st.rows {
        // The strip between row r-1 (above) and row r: row r's window top is h - r·step.
        let y = h - r as f64 * step.y - ov / 2.0;
        lines.push((DVec2::new(0.0, y), DVec2::new(w, y)));
    }
    c.save_state();
    c.set_stroke_rgb(0.55, 0.55, 0.55);
    c.set_fill_rgb(0.7, 0.7, 0.7);
    c.set_line_width(frame.len(0.2));
    c.set_dash_pattern([frame.len(1.0), frame.len(1.0)], 0.0);
    for (a, b) in &lines {
        pdf::path_in(c, &[*a, *b], false, frame);
    }
    c.stroke();
    for (a, b) in &lines {
        let len = a.distance(*b);
        let dir = (*b - *a) / len.max(1e-9);
        let n = (len / DIAMOND_STEP_MM).floor() as usize;
        for k in 1..=n {
            let p = *a + dir * (k as f64 * DIAMOND_STEP_MM);
            if p.distance(*b) < DIAMOND_MM {
                continue;
            }
            // A rhombus, long along the line: no edge at 45°, which a renderer's sub-pixel
            // grid meets at many points at once.
            let (along, across) = (dir * DIAMOND_MM, dir.perp() * DIAMOND_MM * 0.8);
            let pts = [p + along, p + across, p - along, p - across];
            pdf::path_in(c, &pts, true, frame);
        }
    }
    c.fill_nonzero();
    c.restore_state();
}

/// One printed page: the sheet's window, clipped to the printable area, and its label. The
/// sheet is written in whole micrometres shifted by whole micrometres (see [`Frame`]).
fn tile_content<'a>(
    (sheet, faces, images): (&SheetJob, &[TexturedFace], &[&Image]),
    st: &SheetTiling,
    t: &Tile,
    tiling: &Tiling,
    oc_name: &dyn Fn(Layer) -> &'a [u8],
) -> Vec<u8> {
    let mut c = Content::new();
    let k = PT_PER_MM as f32;
    c.transform([k, 0.0, 0.0, k, 0.0, 0.0]);
    let lo = DVec2::new(t.window_mm[0], t.window_mm[1]);
    let hi = DVec2::new(t.window_mm[2], t.window_mm[3]);
    let at = DVec2::new(t.at_mm[0], t.at_mm[1]);
    let size = hi - lo;
    c.save_state();
    c.transform([0.001, 0.0, 0.0, 0.001, 0.0, 0.0]);
    let um = |v: f64| (v * 1000.0).round();
    let frame = Frame {
        micrometres: Some((um(at.x) - um(lo.x), um(at.y) - um(lo.y))),
    };
    let (x0, y0) = Frame {
        micrometres: Some((0.0, 0.0)),
    }
    .at(at);
    c.rect(x0, y0, um(size.x) as f32, um(size.y) as f32);
    c.clip_nonzero();
    c.end_path();
    // The textured faces whose bounds meet the window (grown by the bleed and more), the
    // match lines over them and under the pattern, then the strokes that come within 2 mm of
    // the window (their width and caps reach past it).
    let (glo, ghi) = (lo - DVec2::splat(2.0), hi + DVec2::splat(2.0));
    let near: Vec<TexturedFace> = faces
        .iter()
        .filter(|f| {
            crate::geom::polygon::bounds(f.pts.iter().copied())
                .is_some_and(|(a, b)| a.cmple(ghi).all() && b.cmpge(glo).all())
        })
        .cloned()
        .collect();
    pdf::draw_faces(&mut c, &near, images, oc_name, frame);
    begin_layer(&mut c, oc_name(Layer::Tiling));
    alignment(&mut c, sheet, st, tiling, frame);
    c.end_marked_content();
    pdf::draw_strokes(
        &mut c,
        sheet,
        oc_name,
        &|pts: &[DVec2]| {
            let n = pts.len();
            (0..n).any(|k| pdf::segment_meets_box(pts[k], pts[(k + 1) % n], glo, ghi))
        },
        frame,
    );
    c.restore_state();
    // The label, inside the printable area and out of the overlap strips.
    begin_layer(&mut c, oc_name(Layer::Tiling));
    c.save_state();
    c.set_stroke_rgb(0.35, 0.35, 0.35);
    c.set_line_width(0.35);
    let ov = tiling.overlap_mm;
    let corner = DVec2::new(at.x + ov + 2.0, at.y + size.y - ov - 2.0 - LABEL_MM);
    text(&mut c, &t.label, corner, LABEL_MM);
    let note = format!("page {} of {}", t.page, tiling.pages);
    text(&mut c, &note, corner - DVec2::new(0.0, 2.0 + 2.5), 2.5);
    c.restore_state();
    c.end_marked_content();
    c.finish().to_vec()
}

fn begin_layer(c: &mut Content, oc: &[u8]) {
    c.begin_marked_content_with_properties(Name(b"OC"))
        .properties_named(Name(oc));
}

/// The assembly map of a sheet: title, how to print and join, the sheet scaled down with its
/// pages labelled (blank ones dashed), and the test squares.
fn map_content<'a>(
    job: &Job,
    sheet: &SheetJob,
    st: &SheetTiling,
    tiling: &Tiling,
    oc_name: &dyn Fn(Layer) -> &'a [u8],
) -> Vec<u8> {
    let mut c = Content::new();
    let k = PT_PER_MM as f32;
    c.transform([k, 0.0, 0.0, k, 0.0, 0.0]);
    let page = DVec2::new(st.page_mm[0], st.page_mm[1]);
    let m = tiling.margin_mm + 4.0;
    begin_layer(&mut c, oc_name(Layer::Tiling));
    c.save_state();
    c.set_line_cap(pdf_writer::types::LineCapStyle::RoundCap);
    c.set_line_join(pdf_writer::types::LineJoinStyle::RoundJoin);
    c.set_stroke_rgb(0.0, 0.0, 0.0);
    c.set_line_width(0.3);
    let y = map_header(&mut c, job, sheet, st, tiling, page.y - m - 5.0, m);
    // The map: the sheet's extent of pages, scaled into the room left above the squares.
    let squares_h = TEST_SQUARE_SIDES_MM[1] + 6.0;
    let room_lo = DVec2::new(m, m + squares_h);
    let room_hi = DVec2::new(page.x - m, y - 8.0);
    if st.tiles.is_empty() {
        c.restore_state();
        c.end_marked_content();
        squares(&mut c, page, m, oc_name);
        return c.finish().to_vec();
    }
    let (win, step) = (st.window, st.step);
    let (_, h) = pdf::page_size_mm(sheet);
    // Sheet coordinates of the grid's outer corners.
    let g_lo = DVec2::new(0.0, h - (st.rows - 1) as f64 * step.y - win.y);
    let g_hi = DVec2::new((st.cols - 1) as f64 * step.x + win.x, h);
    let ext = g_hi - g_lo;
    let room = room_hi - room_lo;
    let s = (room.x / ext.x).min(room.y / ext.y).max(1e-6);
    let origin = room_lo + DVec2::new((room.x - ext.x * s) / 2.0, room.y - ext.y * s);
    let to_map = |p: DVec2| origin + (p - g_lo) * s;
    // The pieces' cuts, thin.
    c.set_stroke_rgb(0.45, 0.45, 0.45);
    c.set_line_width(0.15);
    for stroke in sheet.strokes.iter().filter(|s| s.role == StrokeRole::Cut) {
        if let Some(pts) = pdf::drawable(stroke) {
            let pts: Vec<DVec2> = pts.iter().map(|p| to_map(*p)).collect();
            pdf::path(&mut c, &pts, stroke.closed);
        }
    }
    c.stroke();
    // The sheet's edge.
    c.set_stroke_rgb(0.0, 0.0, 0.0);
    c.set_line_width(0.3);
    let (w, _) = pdf::page_size_mm(sheet);
    let (a, b) = (to_map(DVec2::ZERO), to_map(DVec2::new(w, h)));
    c.rect(
        pdf::mm(a.x),
        pdf::mm(a.y),
        pdf::mm(b.x - a.x),
        pdf::mm(b.y - a.y),
    );
    c.stroke();
    // Every page of the grid, with its label; blank ones dashed.
    let cell = |r: usize, col: usize| {
        let lo = st.cell(r, col, h);
        (to_map(lo), to_map(lo + win))
    };
    let label_h = (step.x.min(step.y) * s / 4.0).clamp(1.5, 8.0);
    for (r, col, name, printed) in st
        .tiles
        .iter()
        .map(|t| (t.row, t.col, t.label.clone(), true))
        .chain(
            (0..st.rows)
                .flat_map(|r| (0..st.cols).map(move |col| (r, col)))
                .filter_map(|(r, col)| {
                    let printed = st.tiles.iter().any(|t| (t.row, t.col) == (r, col));
                    let label = page_label(st.sheet - 1, job.sheets.len(), r, col);
                    (!printed).then_some((r, col, label, false))
                }),
        )
    {
        let (lo, hi) = cell(r, col);
        c.save_state();
        if printed {
            c.set_stroke_rgb(0.0, 0.3, 0.8);
            c.set_line_width(0.25);
        } else {
            c.set_stroke_rgb(0.6, 0.6, 0.6);
            c.set_line_width(0.15);
            c.set_dash_pattern([1.0f32, 1.0], 0.0);
        }
        c.rect(
            pdf::mm(lo.x),
            pdf::mm(lo.y),
            pdf::mm(hi.x - lo.x),
            pdf::mm(hi.y - lo.y),
        );
        c.stroke();
        c.restore_state();
        // The label in the middle of the cell's own part (out of the overlaps).
        let shown = if printed {
            name.clone()
        } else {
            format!("({name})")
        };
        let tw = crate::geom::font::text_width(&shown, label_h);
        let mid = (cell(r, col).0 + cell(r, col).1) / 2.0;
        c.save_state();
        c.set_stroke_rgb(0.0, 0.3, 0.8);
        c.set_line_width((label_h / 12.0).max(0.15) as f32);
        text(
            &mut c,
            &shown,
            mid - DVec2::new(tw / 2.0, label_h / 2.0),
            label_h,
        );
        c.restore_state();
    }
    c.restore_state();
    c.end_marked_content();
    squares(&mut c, page, m, oc_name);
    c.finish().to_vec()
}

/// The map page's title and notes from `top` down, `m` from the left; returns the last
/// line's height on the page.
fn map_header(
    c: &mut Content,
    job: &Job,
    sheet: &SheetJob,
    st: &SheetTiling,
    tiling: &Tiling,
    top: f64,
    m: f64,
) -> f64 {
    let mut y = top;
    let title = format!(
        "{} - sheet {} of {}: assembly map",
        job.name,
        st.sheet,
        job.sheets.len()
    );
    text(c, &title, DVec2::new(m, y), 5.0);
    c.set_line_width(0.2);
    let notes = [
        format!(
            "{:.0} x {:.0} mm on {} {}: {} rows x {} columns, {} pages printed ({} blank left out).",
            sheet.width,
            sheet.height,
            tiling.paper.to_uppercase(),
            if st.landscape { "landscape" } else { "portrait" },
            st.rows,
            st.cols,
            st.tiles.len(),
            st.blank.len()
        ),
        "Print at actual size (100 percent, no fit to page): the squares below must measure 50 mm and 2 in."
            .to_string(),
        format!(
            "Pages overlap by {:.1} mm: trim a page on its grey match line where it has a neighbour",
            tiling.overlap_mm
        ),
        "to the left or above, lay it over that neighbour with the diamonds on each other, and tape."
            .to_string(),
    ];
    for n in &notes {
        y -= 6.0;
        text(c, n, DVec2::new(m, y), 2.8);
    }
    y
}

/// The test squares at the bottom left of a map page.
fn squares<'a>(c: &mut Content, page: DVec2, m: f64, oc_name: &dyn Fn(Layer) -> &'a [u8]) {
    let [a, b] = TEST_SQUARE_SIDES_MM;
    if page.x - 2.0 * m < a + b + 4.0 {
        return;
    }
    let sq = [
        TestSquare {
            corner: DVec2::new(m, m),
            side: a,
        },
        TestSquare {
            corner: DVec2::new(m + a + 4.0, m),
            side: b,
        },
    ];
    pdf::draw_test_squares(c, &sq, oc_name(Layer::TestSquares));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::fixtures::{sheet, stroke};

    fn job_of(w: f64, h: f64, strokes: Vec<crate::toolpath::Stroke>) -> Job {
        let mut s = sheet(strokes);
        s.width = w;
        s.height = h;
        Job {
            name: "t".into(),
            sheets: vec![s],
        }
    }

    #[test]
    fn rows_are_lettered() {
        assert_eq!(row_name(0), "A");
        assert_eq!(row_name(25), "Z");
        assert_eq!(row_name(26), "AA");
        assert_eq!(row_name(27), "AB");
        assert_eq!(page_label(0, 1, 1, 2), "B3");
        assert_eq!(page_label(1, 2, 26, 11), "2-AA12");
    }

    #[test]
    fn a_610_by_900_sheet_on_a4() {
        // A stroke in the top-left and one in the bottom-right corner only.
        let job = job_of(
            610.0,
            900.0,
            vec![
                stroke(StrokeRole::Cut, &[(10.0, 880.0), (50.0, 890.0)]),
                stroke(StrokeRole::Cut, &[(560.0, 10.0), (600.0, 20.0)]),
            ],
        );
        let t = plan(&job, &PrintOptions::default()).unwrap();
        let st = &t.sheets[0];
        // Portrait: 4 x 4 pages, the second stroke across columns 3 and 4 (3 printed);
        // landscape: 5 rows x 3 columns, each stroke on one page (2 printed).
        assert_eq!((st.rows, st.cols), (5, 3));
        assert!(st.landscape);
        assert_eq!(st.page_mm, [297.0, 210.0]);
        assert_eq!(st.tiles.len(), 2);
        assert_eq!(st.tiles[0].label, "A1");
        assert_eq!(st.tiles[1].label, "E3");
        assert_eq!(st.blank.len(), 13);
        assert_eq!(t.pages, 3);
        // Everything on the 0.254 mm grid.
        let on_grid = |v: f64| ((v / GRID_MM) - (v / GRID_MM).round()).abs() < 1e-6;
        assert!(on_grid(t.margin_mm) && on_grid(t.overlap_mm));
        let w = st.tiles[0].window_mm;
        assert!(on_grid(w[2] - w[0]) && on_grid(w[3] - w[1]));
        assert!(w[2] - w[0] <= 297.0 - 2.0 * 6.35 + 1e-9);
        assert!(st.tiles[0].at_mm[0] + (w[2] - w[0]) <= 297.0 - 6.35);
        // Neighbouring windows overlap by the overlap.
        let step = (w[2] - w[0]) - t.overlap_mm;
        assert!(on_grid(step));
        let doc = render(&job, &t, None);
        let text = String::from_utf8_lossy(&doc);
        assert!(text.contains("/Count 3"));
        assert!(text.contains("(E3) Tj"), "invisible label");
        assert!(text.contains("/BaseFont /Helvetica"));
        assert_eq!(render(&job, &t, None), doc, "deterministic");
    }

    #[test]
    fn too_small_paper_is_refused() {
        let job = job_of(100.0, 100.0, vec![]);
        let o = PrintOptions {
            paper: "40x40".into(),
            width: 40.0,
            height: 40.0,
            ..Default::default()
        };
        let e = plan(&job, &o).unwrap_err().to_string();
        assert!(e.contains("40x40"), "{e}");
        let o = PrintOptions {
            margin_mm: f64::NAN,
            ..Default::default()
        };
        assert!(plan(&job, &o).is_err());
        // A sheet of 10 km needs too many pages.
        let job = job_of(1e7, 1e7, vec![]);
        let e = plan(&job, &PrintOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("pages"), "{e}");
    }
}
