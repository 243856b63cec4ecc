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
//!   or printer can switch: `Texture` (a textured model's faces, [`super::texture`], under
//!   everything), `Cut` (cuts and notches), `Folds` (mountain and valley), `Marks`,
//!   `Labels`, `Seams`, `Grain`, `Weed`, and `Test squares` (and `Tiling` in the tiled
//!   document, [`super::print`]). A group exists only if the job
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

use crate::geom::grid::Grid;
use glam::DVec2;
use pdf_writer::types::{LineCapStyle, LineJoinStyle, PageMode};
use pdf_writer::{Content, Finish, Name, Pdf, Rect, Ref, TextStr};

use super::texture::{Paint, TexturedFace};
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
    /// The faces' texture (textured papercraft), under everything else.
    Texture,
    Cut,
    Folds,
    Marks,
    Labels,
    Seams,
    Grain,
    Weed,
    TestSquares,
    /// Tiled printing's match lines, diamonds and page labels ([`super::print`]).
    Tiling,
}

impl Layer {
    /// Every layer, in the order of the viewer's layer panel.
    pub const ALL: [Layer; 10] = [
        Layer::Texture,
        Layer::Cut,
        Layer::Folds,
        Layer::Marks,
        Layer::Labels,
        Layer::Seams,
        Layer::Grain,
        Layer::Weed,
        Layer::TestSquares,
        Layer::Tiling,
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
            Layer::Texture => "Texture",
            Layer::Cut => "Cut",
            Layer::Folds => "Folds",
            Layer::Marks => "Marks",
            Layer::Labels => "Labels",
            Layer::Seams => "Seams",
            Layer::Grain => "Grain",
            Layer::Weed => "Weed",
            Layer::TestSquares => "Test squares",
            Layer::Tiling => "Tiling",
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

/// The strokes of a sheet as segments on a grid over the page, and the closed cut outlines
/// (the pieces) with their boxes, for [`test_squares`].
struct Obstacles {
    segments: Vec<(DVec2, DVec2)>,
    grid: Grid,
    outlines: Vec<(Vec<DVec2>, DVec2, DVec2)>,
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
                    let lo = pts.iter().copied().fold(DVec2::INFINITY, DVec2::min);
                    let hi = pts.iter().copied().fold(DVec2::NEG_INFINITY, DVec2::max);
                    outlines.push((pts, lo, hi));
                }
            } else if pts.len() == 1 {
                segments.push((pts[0], pts[0]));
            }
        }
        let (w, h) = page_size_mm(sheet);
        let mut grid = Grid::new(DVec2::ZERO, DVec2::new(w, h));
        for (k, &(p, q)) in segments.iter().enumerate() {
            grid.insert_segment(p, q, k as u32);
        }
        Obstacles {
            segments,
            grid,
            outlines,
            boxes: Vec::new(),
        }
    }

    /// Whether the block at `at` (lower-left), `bw` × `bh`, grown by the clearance, touches no
    /// stroke and no square placed, and does not lie inside a piece.
    fn free(&self, at: DVec2, bw: f64, bh: f64) -> bool {
        let c = SQUARE_CLEARANCE_MM;
        let lo = at - DVec2::splat(c);
        let hi = at + DVec2::new(bw + c, bh + c);
        if self.grid.any(lo, hi, |k| {
            let (p, q) = self.segments[k as usize];
            segment_meets_box(p, q, lo, hi)
        }) {
            return false;
        }
        if self
            .boxes
            .iter()
            .any(|&(a, b)| a.x < hi.x && b.x > lo.x && a.y < hi.y && b.y > lo.y)
        {
            return false;
        }
        let centre = (lo + hi) / 2.0;
        !self.outlines.iter().any(|(o, olo, ohi)| {
            centre.cmpge(*olo).all() && centre.cmple(*ohi).all() && inside(centre, o)
        })
    }
}

/// Whether segment `p`–`q` meets the box `lo`..`hi` (Liang–Barsky clipping).
pub(crate) fn segment_meets_box(p: DVec2, q: DVec2, lo: DVec2, hi: DVec2) -> bool {
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
pub(crate) fn drawable(s: &Stroke) -> Option<Vec<DVec2>> {
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
pub(crate) fn page_size_mm(sheet: &SheetJob) -> (f64, f64) {
    let ok = |v: f64| if v > 0.0 && v <= MAX_COORD_MM { v } else { 1.0 };
    (ok(sheet.width), ok(sheet.height))
}

/// A coordinate in mm, rounded to 0.001 mm, for the content stream.
pub(crate) fn mm(v: f64) -> f32 {
    ((v * 1000.0).round() / 1000.0) as f32
}

/// The layers the job uses, in panel order: those of its strokes' roles and the test squares.
pub(crate) fn layers_used(job: &Job) -> Vec<Layer> {
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
    render_painted(job, None)
}

/// [`render`] with the textured faces of `paint` under the strokes of each sheet.
pub fn render_painted(job: &Job, paint: Option<&Paint>) -> Vec<u8> {
    let mut layers = layers_used(job);
    if paint.is_some_and(|p| !p.is_empty()) {
        layers.insert(0, Layer::Texture);
    }
    let catalog_id = Ref::new(1);
    let pages_id = Ref::new(2);
    let layer_ids: Vec<Ref> = (0..layers.len()).map(|k| Ref::new(3 + k as i32)).collect();
    let first_page = 3 + layers.len() as i32;
    // Per sheet: its page, then its content stream.
    let page_ids: Vec<Ref> = (0..job.sheets.len())
        .map(|k| Ref::new(first_page + 2 * k as i32))
        .collect();
    let names = LayerNames::new(&layers);
    let oc_name = |layer: Layer| names.of(layer);

    let mut pdf = Pdf::new();
    write_catalog(&mut pdf, catalog_id, pages_id, &layers, &layer_ids);
    pdf.pages(pages_id)
        .kids(page_ids.iter().copied())
        .count(page_ids.len() as i32);
    let image_ids = paint.map_or(Vec::new(), |p| {
        pdf_images(&mut pdf, p, first_page + 2 * job.sheets.len() as i32)
    });
    let images: Vec<&crate::surface::texture::Image> =
        paint.map_or(Vec::new(), |p| p.images().collect());
    for (k, (sheet, &page_id)) in job.sheets.iter().zip(&page_ids).enumerate() {
        let content_id = Ref::new(page_id.get() + 1);
        let (w, h) = page_size_mm(sheet);
        let page = PageRefs {
            page: page_id,
            pages: pages_id,
            content: content_id,
        };
        let resources = PageResources {
            layers: (&layers, &layer_ids, &names),
            font: None,
            images: &image_ids,
        };
        write_page(&mut pdf, page, (w, h), &resources);
        let faces = paint.map_or(&[][..], |p| p.sheet(k));
        let content = page_content(sheet, &oc_name, faces, &images);
        pdf.stream(content_id, &content);
    }
    pdf.finish()
}

/// Resource names of the layers in the pages: `/oc1`, `/oc2`, … in the order of `layers`.
pub(crate) struct LayerNames {
    layers: Vec<Layer>,
    names: Vec<String>,
}

impl LayerNames {
    pub fn new(layers: &[Layer]) -> LayerNames {
        LayerNames {
            layers: layers.to_vec(),
            names: (1..=layers.len()).map(|k| format!("oc{k}")).collect(),
        }
    }

    /// The resource name of `layer` (the first layer's for one not in the list).
    pub fn of(&self, layer: Layer) -> &[u8] {
        let k = self.layers.iter().position(|l| *l == layer).unwrap_or(0);
        self.names.get(k).map_or(b"oc1", |s| s.as_bytes())
    }
}

/// The catalog with the layers (optional content groups `layer_ids`, all on, the viewer's
/// layer panel open) and the layers' dictionaries.
pub(crate) fn write_catalog(
    pdf: &mut Pdf,
    catalog_id: Ref,
    pages_id: Ref,
    layers: &[Layer],
    layer_ids: &[Ref],
) {
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
    for (layer, id) in layers.iter().zip(layer_ids) {
        pdf.indirect(*id)
            .dict()
            .pair(Name(b"Type"), Name(b"OCG"))
            .pair(Name(b"Name"), TextStr(layer.name()));
    }
}

/// A page's object, its parent and its content stream.
pub(crate) struct PageRefs {
    pub page: Ref,
    pub pages: Ref,
    pub content: Ref,
}

/// What a page's resources name: the layers (with their objects and names), a font as `/F1`,
/// the texture images.
pub(crate) struct PageResources<'a> {
    pub layers: (&'a [Layer], &'a [Ref], &'a LayerNames),
    pub font: Option<Ref>,
    pub images: &'a [Ref],
}

/// Writes a page of `size` mm (w, h) with its resources.
pub(crate) fn write_page(pdf: &mut Pdf, refs: PageRefs, size: (f64, f64), res: &PageResources) {
    let mut page = pdf.page(refs.page);
    page.parent(refs.pages)
        .media_box(Rect::new(
            0.0,
            0.0,
            (size.0 * PT_PER_MM) as f32,
            (size.1 * PT_PER_MM) as f32,
        ))
        .contents(refs.content);
    let mut resources = page.resources();
    let mut named = resources.insert(Name(b"Properties")).dict();
    let (layers, ids, names) = res.layers;
    for (layer, id) in layers.iter().zip(ids) {
        named.pair(Name(names.of(*layer)), *id);
    }
    named.finish();
    if let Some(font) = res.font {
        resources.fonts().pair(Name(b"F1"), font);
    }
    image_resources(&mut resources, res.images);
    resources.finish();
    page.finish();
}

/// The page resources naming the texture images `/Tx1`, `/Tx2`, … (none: no entry).
pub(crate) fn image_resources(resources: &mut pdf_writer::writers::Resources, ids: &[Ref]) {
    if ids.is_empty() {
        return;
    }
    let mut x = resources.x_objects();
    for (k, id) in ids.iter().enumerate() {
        let name = format!("Tx{}", k + 1);
        x.pair(Name(name.as_bytes()), *id);
    }
    x.finish();
}

/// Draws textured faces in the texture layer (nothing for none).
pub(crate) fn draw_faces<'a>(
    c: &mut Content,
    faces: &[TexturedFace],
    images: &[&crate::surface::texture::Image],
    oc_name: &dyn Fn(Layer) -> &'a [u8],
    frame: Frame,
) {
    if faces.is_empty() {
        return;
    }
    c.begin_marked_content_with_properties(Name(b"OC"))
        .properties_named(Name(oc_name(Layer::Texture)));
    pdf_faces(c, faces, images, frame);
    c.end_marked_content();
}

/// Draws the textured faces of a sheet into a PDF content stream, in `frame`; image `k` of
/// the paint is the XObject `/Tx{k+1}`.
fn pdf_faces(
    c: &mut pdf_writer::Content,
    faces: &[TexturedFace],
    images: &[&crate::surface::texture::Image],
    frame: Frame,
) {
    use pdf_writer::Name;
    let s = f64::from(frame.len(1.0));
    let (sx, sy) = frame.micrometres.unwrap_or((0.0, 0.0));
    for face in faces {
        for t in super::texture::triangles(face, images) {
            c.save_state();
            path_in(c, &t.clip, true, frame);
            match t.fill {
                super::texture::Fill::Map([a, b, cc, d, e, f]) => {
                    c.clip_nonzero();
                    c.end_path();
                    c.transform([
                        (a * s) as f32,
                        (b * s) as f32,
                        (cc * s) as f32,
                        (d * s) as f32,
                        (e * s + sx) as f32,
                        (f * s + sy) as f32,
                    ]);
                    let name = format!("Tx{}", t.image + 1);
                    c.x_object(Name(name.as_bytes()));
                }
                super::texture::Fill::Colour([r, g, b]) => {
                    c.set_fill_rgb(
                        f32::from(r) / 255.0,
                        f32::from(g) / 255.0,
                        f32::from(b) / 255.0,
                    );
                    c.fill_nonzero();
                }
            }
            c.restore_state();
        }
    }
}

/// Writes the paint's images as image XObjects with ids from `first` on; returns the ids.
pub(crate) fn pdf_images(
    pdf: &mut pdf_writer::Pdf,
    paint: &Paint,
    first: i32,
) -> Vec<pdf_writer::Ref> {
    let mut ids = Vec::new();
    for (k, img) in paint.images().enumerate() {
        let id = pdf_writer::Ref::new(first + k as i32);
        let data =
            miniz_oxide::deflate::compress_to_vec_zlib(&super::texture::rgb_over_white(img), 6);
        let mut x = pdf.image_xobject(id, &data);
        x.filter(pdf_writer::Filter::FlateDecode);
        x.width(img.width as i32);
        x.height(img.height as i32);
        x.color_space().device_rgb();
        x.bits_per_component(8);
        x.interpolate(true);
        drop(x);
        ids.push(id);
    }
    ids
}

/// The content stream of one sheet's page; `oc_name` gives the resource name of a layer.
fn page_content<'a>(
    sheet: &SheetJob,
    oc_name: &dyn Fn(Layer) -> &'a [u8],
    faces: &[TexturedFace],
    images: &[&crate::surface::texture::Image],
) -> Vec<u8> {
    let mut c = Content::new();
    let k = PT_PER_MM as f32;
    c.transform([k, 0.0, 0.0, k, 0.0, 0.0]);
    draw_faces(&mut c, faces, images, oc_name, Frame::MM);
    draw_strokes(&mut c, sheet, oc_name, &|_| true, Frame::MM);
    let (squares, _) = test_squares(sheet);
    draw_test_squares(&mut c, &squares, oc_name(Layer::TestSquares));
    c.finish().to_vec()
}

/// How sheet millimetres are written into a content stream.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Frame {
    /// Whole micrometres (the user space is µm), shifted by this many µm; else millimetres
    /// rounded to 0.001 mm. f32 holds every whole number of µm up to 16 m exactly, so a
    /// point written on two pages with whole-µm shifts lands at the same sub-pixel phase on
    /// both ([`super::print`]).
    pub micrometres: Option<(f64, f64)>,
}

impl Frame {
    /// Millimetres, unshifted.
    pub const MM: Frame = Frame { micrometres: None };

    /// A point as written.
    pub fn at(self, p: DVec2) -> (f32, f32) {
        match self.micrometres {
            Some((sx, sy)) => (
                ((p.x * 1000.0).round() + sx) as f32,
                ((p.y * 1000.0).round() + sy) as f32,
            ),
            None => (mm(p.x), mm(p.y)),
        }
    }

    /// A length in mm as written (line widths, dashes).
    pub fn len(self, v: f64) -> f32 {
        match self.micrometres {
            Some(_) => (v * 1000.0).round() as f32,
            None => v as f32,
        }
    }
}

/// Draws the strokes of a sheet for which `keep` holds (given their drawable points), in
/// `frame`, each role in its layer (`oc_name`) and style, in `DRAW_ORDER`; sets round caps and
/// joins.
pub(crate) fn draw_strokes<'a>(
    c: &mut Content,
    sheet: &SheetJob,
    oc_name: &dyn Fn(Layer) -> &'a [u8],
    keep: &dyn Fn(&[DVec2]) -> bool,
    frame: Frame,
) {
    c.set_line_cap(LineCapStyle::RoundCap);
    c.set_line_join(LineJoinStyle::RoundJoin);
    for role in DRAW_ORDER {
        let strokes: Vec<(Vec<DVec2>, bool)> = sheet
            .strokes
            .iter()
            .filter(|s| s.role == role)
            .filter_map(|s| drawable(s).map(|p| (p, s.closed)))
            .filter(|(p, _)| keep(p))
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
        c.set_line_width(frame.len(super::svg::stroke_width_mm(role)));
        if !style.dash_mm.is_empty() {
            c.set_dash_pattern(style.dash_mm.iter().map(|&d| frame.len(d)), 0.0);
        }
        for (pts, closed) in &strokes {
            path_in(c, pts, *closed, frame);
        }
        c.stroke();
        c.restore_state();
        c.end_marked_content();
    }
}

/// Draws the test squares with their captions in the layer named `oc`.
pub(crate) fn draw_test_squares(c: &mut Content, squares: &[TestSquare], oc: &[u8]) {
    c.begin_marked_content_with_properties(Name(b"OC"))
        .properties_named(Name(oc));
    c.save_state();
    c.set_stroke_rgb(0.0, 0.0, 0.0);
    c.set_line_width(SQUARE_LINE_MM as f32);
    for sq in squares {
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
            path(c, &pts, false);
        }
    }
    c.stroke();
    c.restore_state();
    c.end_marked_content();
}

/// Appends one subpath through `pts` (a dot for a single point), closed with `h` if `closed`.
pub(crate) fn path(c: &mut Content, pts: &[DVec2], closed: bool) {
    path_in(c, pts, closed, Frame::MM);
}

/// [`path`] in `frame`.
pub(crate) fn path_in(c: &mut Content, pts: &[DVec2], closed: bool, frame: Frame) {
    let Some(first) = pts.first() else { return };
    let (x, y) = frame.at(*first);
    c.move_to(x, y);
    if pts.len() == 1 {
        c.line_to(x, y);
    }
    for p in &pts[1..] {
        let (x, y) = frame.at(*p);
        c.line_to(x, y);
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
    fn squares_placed_apart_do_not_overlap_each_other() {
        // Lines every 70 mm: no room for the two squares together, room for each alone in a
        // cell; the second goes to another cell than the first (it used to take the same).
        let mut strokes = Vec::new();
        for k in 0..=4 {
            let v = 70.0 * k as f64;
            strokes.push(stroke(StrokeRole::Mark, &[(v, 0.0), (v, 300.0)]));
            strokes.push(stroke(StrokeRole::Mark, &[(0.0, v), (300.0, v)]));
        }
        let mut s = sheet(strokes);
        s.width = 300.0;
        s.height = 300.0;
        let (sq, free) = test_squares(&s);
        assert!(free);
        let (a, b) = (sq[0], sq[1]);
        let apart = a.corner.x + a.side <= b.corner.x
            || b.corner.x + b.side <= a.corner.x
            || a.corner.y + a.side <= b.corner.y
            || b.corner.y + b.side <= a.corner.y;
        assert!(apart, "{a:?} and {b:?} overlap");
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
