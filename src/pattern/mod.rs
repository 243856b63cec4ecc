//! Pattern stage: turns each island of a [`Flat`] into a [`Piece`] a person can cut and
//! assemble: the cut outline, fold lines where joined faces meet at a bend above the threshold
//! (mountain or valley, with the angle), seams with the same id written on both sides and
//! notches at equal arc lengths ([`marks`]), a label naming the piece and the side that faces
//! up, a grain line for fabric, bend notes for metal, and the material's finishing: glue tabs
//! for paper, seam allowance for fabric, kerf compensation ([`allowance`]). Pieces laid out
//! from D-Charts have the seams between them simplified first ([`simplify`], thesis §5.3):
//! their borders follow mesh edges and zig-zag; exact unfoldings keep every edge. The folds of
//! a metal mesh are developed as brake bends first ([`develop`]: each wall shorter by half
//! the bend deduction of each of its bends, bend lines on the bend centre lines, corner
//! reliefs), and every later step works on the developed piece.
//!
//! Conventions: pieces are drawn as seen from the printed side, which is the outside of a
//! closed mesh; a convex edge therefore folds away from the viewer and is a mountain fold, a
//! concave edge a valley fold. Text is set in the single-stroke font of [`crate::geom::font`]
//! so a pen can draw it or a knife score it. A piece keeps two boundaries: its `border`, the
//! edges of the surface itself (where seams are matched, where the sewing line runs), and its
//! `outline`, what is cut (the border with tabs, allowance or kerf added).
//!
//! Choices where the issue is silent: materials choose the defaults
//! ([`PatternOptions::for_material`]): paper gets glue tabs on one side of each seam, fabric a
//! 10 mm seam allowance, notches every 50 mm and a grain line, metal its bend notes; the plain
//! [`Default`] adds nothing, for callers that only want the net.

pub mod bends;
pub mod develop;

use crate::flatten::Flat;
use crate::geom::polygon;
use crate::surface::MaterialKind;
use glam::DVec2;
use serde::Serialize;

pub mod allowance;
pub mod legible;
pub mod marks;
pub mod simplify;
pub mod split;

pub use marks::{SeamSide, Text};

/// Where glue tabs go.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Tabs {
    /// No tabs.
    #[default]
    None,
    /// On one side of each seam: the side where the tab comes out larger.
    OneSide,
    /// On both sides of each seam.
    Both,
}

impl Tabs {
    pub fn name(self) -> &'static str {
        match self {
            Tabs::None => "none",
            Tabs::OneSide => "one-side",
            Tabs::Both => "both",
        }
    }
}

/// Options of the pattern stage.
#[derive(Debug, Clone, PartialEq)]
pub struct PatternOptions {
    /// Joined edges bending by more than this (degrees) become fold lines.
    pub fold_threshold_deg: f64,
    /// Largest height of seam ids and bend notes (mm).
    pub max_mark_height: f64,
    /// Largest height of piece labels (mm).
    pub max_label_height: f64,
    /// The material: decides the label's "side up" wording and how notches are made (slits
    /// cut into fabric, ticks drawn on paper and metal).
    pub material: MaterialKind,
    /// Glue tabs.
    pub tabs: Tabs,
    /// Height of a glue tab (mm); smaller where the seam is short or there is no room.
    pub tab_height: f64,
    /// Seam allowance added around the border (mm); 0 for none.
    pub allowance: f64,
    /// Notches along every seam every this many mm; `None` for none.
    pub notches: Option<f64>,
    /// Width of the cut (mm): every cut contour moves half of it away from the piece.
    pub kerf: f64,
    /// Write each bend line's angle and direction beside it.
    pub bend_notes: bool,
    /// Small V notches in the outline where bend lines meet it.
    pub bend_notches: bool,
    /// Draw a grain-line arrow (and keep the grain along the roll when nesting).
    pub grain: bool,
    /// Largest deviation (mm) of a simplified seam from its original chain, for pieces laid
    /// out from D-Charts ([`simplify`], thesis §5.3); 0 leaves them as they are. Other pieces
    /// (exact unfoldings) are never simplified. Default: 0 in the bare net, 0.5 mm for paper
    /// and fabric, 0.1 mm for metal ([`PatternOptions::for_material`]).
    pub simplify: f64,
    /// The spec's `simplify` of single surfaces, by surface name, over [`Self::simplify`].
    pub simplify_surfaces: Vec<(String, f64)>,
    /// Surfaces whose folds are developed as sheet-metal bends ([`develop`]), by name, with
    /// the sheet's thickness, K factor and inside bend radius: the mesh surfaces of a metal
    /// job. Empty in the bare net.
    pub develop: Vec<(String, crate::geom::bend::SheetBend)>,
    /// Largest L2 stretch of a part when a piece laid out from charts is split to fit the
    /// sheet ([`split`]): partitions with fewer parts over it are preferred. `None` in the
    /// bare net; the flatten stage's tolerance of the material otherwise
    /// ([`PatternOptions::for_material`]).
    pub stretch_limit: Option<f64>,
}

impl Default for PatternOptions {
    /// The bare net: folds, seam ids and labels, nothing added to the outline.
    fn default() -> Self {
        PatternOptions {
            fold_threshold_deg: 1.0,
            max_mark_height: 3.0,
            max_label_height: 8.0,
            material: MaterialKind::Paper,
            tabs: Tabs::None,
            tab_height: 5.0,
            allowance: 0.0,
            notches: None,
            kerf: 0.0,
            bend_notes: false,
            bend_notches: false,
            grain: false,
            simplify: 0.0,
            simplify_surfaces: Vec::new(),
            develop: Vec::new(),
            stretch_limit: None,
        }
    }
}

impl PatternOptions {
    /// Defaults of a material: paper gets glue tabs on one side of each seam; fabric a 10 mm
    /// seam allowance, notches every 50 mm and a grain line; metal its bend notes. Seams of
    /// D-Charts pieces are simplified within 0.5 mm on paper and fabric (about what a knife,
    /// scissors or a sewing line follow anyway), 0.1 mm on metal.
    pub fn for_material(kind: MaterialKind) -> Self {
        let bare = PatternOptions {
            material: kind,
            simplify: match kind {
                MaterialKind::Metal => 0.1,
                _ => 0.5,
            },
            stretch_limit: Some(
                crate::flatten::charts::FlattenOptions::for_material(kind).tolerance,
            ),
            ..PatternOptions::default()
        };
        match kind {
            MaterialKind::Paper => PatternOptions {
                tabs: Tabs::OneSide,
                ..bare
            },
            MaterialKind::Fabric => PatternOptions {
                allowance: 10.0,
                notches: Some(50.0),
                grain: true,
                ..bare
            },
            MaterialKind::Metal => PatternOptions {
                bend_notes: true,
                ..bare
            },
        }
    }
}

impl PatternOptions {
    /// The simplification tolerance (mm) for a surface: its own, else the default.
    pub fn simplify_for(&self, surface: &str) -> f64 {
        self.simplify_surfaces
            .iter()
            .find(|(n, _)| n == surface)
            .map_or(self.simplify, |(_, t)| *t)
    }

    /// The sheet a surface's folds are developed in, if they are ([`Self::develop`]).
    pub fn develop_for(&self, surface: &str) -> Option<crate::geom::bend::SheetBend> {
        self.develop
            .iter()
            .find(|(n, _)| n == surface)
            .map(|(_, s)| *s)
    }
}

/// Mountain or valley, seen from the printed side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FoldKind {
    Mountain,
    Valley,
}

/// A fold line on a piece.
#[derive(Debug, Clone, PartialEq)]
pub struct Fold {
    pub a: DVec2,
    pub b: DVec2,
    pub kind: FoldKind,
    /// Bend angle in radians (0 = flat), unsigned: `kind` says which way; printed in
    /// degrees (the fold label, DXF, `report.json`).
    pub angle: f64,
    /// Mesh edge it comes from.
    pub edge: usize,
    /// The fold of a glue tab (along a seam), not of the surface.
    pub tab: bool,
}

/// The id of a seam written beside one of its two sides.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeMark {
    /// The seam id (the same on both sides).
    pub id: usize,
    /// Mesh edge of the border segment it is written along.
    pub edge: usize,
    /// That segment on the piece.
    pub a: DVec2,
    pub b: DVec2,
    pub text: Text,
}

/// A notch: where two seam sides must meet when joined.
#[derive(Debug, Clone, PartialEq)]
pub struct Notch {
    /// Seam id.
    pub seam: usize,
    /// The point on the border.
    pub at: DVec2,
    /// The stroke: a slit cut into the piece or its allowance (`cut`), else a drawn tick.
    pub stroke: Vec<DVec2>,
    pub cut: bool,
}

/// One flat piece, in its own frame (mm).
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// 1-based, unique in the job.
    pub id: usize,
    /// Name written on the piece and used in reports.
    pub name: String,
    /// Surface it came from.
    pub surface: String,
    /// Mesh faces it is made of.
    pub faces: Vec<usize>,
    /// Closed cut contours without the repeated first point: the outer contour first
    /// (counter-clockwise), then holes (clockwise). The border plus tabs, allowance and kerf.
    pub outline: Vec<Vec<DVec2>>,
    /// The piece's edges on the surface, as `outline` (outer first, counter-clockwise).
    pub border: Vec<Vec<DVec2>>,
    /// Mesh edge of each border segment (segment `k` runs from point `k` to `k + 1`), or
    /// [`develop::NO_EDGE`] for a segment of a developed metal piece that is no mesh edge (a
    /// corner relief, the step between two trimmed corners on a bend line).
    pub border_edges: Vec<Vec<usize>>,
    /// Mesh face each border segment belongs to.
    pub border_faces: Vec<Vec<usize>>,
    pub folds: Vec<Fold>,
    /// Seam ids.
    pub marks: Vec<EdgeMark>,
    /// The piece's side of every seam it has.
    pub seams: Vec<SeamSide>,
    pub notches: Vec<Notch>,
    /// Bend notes (metal): angle and direction beside each bend line.
    pub notes: Vec<Text>,
    /// The fold (index into `folds`) each note is written beside, in the order of `notes`.
    pub note_folds: Vec<usize>,
    /// The sewing line, drawn, when the outline carries a seam allowance.
    pub seam_line: Vec<Vec<DVec2>>,
    /// The grain-line arrow (fabric).
    pub grain_line: Vec<Vec<DVec2>>,
    /// Name, id and which side faces up.
    pub label: Text,
    /// Area in mm² of the surface it covers (equal in 3D and flat: the unfolding is isometric).
    pub area: f64,
    /// Direction of the grain line in the piece's frame (radians from +x), for materials with
    /// a grain (fabric). The nest stage keeps it parallel to the roll (sheet y axis), either way.
    pub grain: Option<f64>,
    /// What simplifying its seams did ([`simplify`]); `None` when they were not simplified.
    pub simplified: Option<simplify::Simplified>,
    /// Texts left off for want of a clear place ([`legible`]).
    pub left_out: Vec<legible::LeftOut>,
    /// How a metal mesh piece was developed: each bend's allowance and deduction, its corner
    /// reliefs ([`develop`]); `None` for pieces that are not (paper, fabric, strips, charts).
    pub development: Option<develop::Development>,
}

impl Piece {
    /// How far (mm) a piece's strokes (marks on the border) may lie outside its cut outline:
    /// cleaning the outline closes and drops features narrower than twice this
    /// ([`allowance::CLEAN_MM`]), which can leave a mark's end just outside it.
    pub const OVERHANG_MM: f64 = allowance::CLEAN_MM;

    /// A piece that is only a cut outline (counter-clockwise ring): no folds, seams or text.
    /// For tests and for nesting shapes that come from elsewhere (ESICUP instances).
    pub fn from_outline(id: usize, name: String, ring: Vec<DVec2>) -> Piece {
        let n = ring.len();
        Piece {
            id,
            name,
            surface: String::new(),
            faces: Vec::new(),
            area: polygon::signed_area(&ring).abs(),
            outline: vec![ring.clone()],
            border: vec![ring],
            border_edges: vec![(0..n).collect()],
            border_faces: vec![vec![0; n]],
            folds: Vec::new(),
            marks: Vec::new(),
            seams: Vec::new(),
            notches: Vec::new(),
            notes: Vec::new(),
            note_folds: Vec::new(),
            seam_line: Vec::new(),
            grain_line: Vec::new(),
            label: Text::default(),
            grain: None,
            simplified: None,
            left_out: Vec::new(),
            development: None,
        }
    }

    /// Total length of the cut contours (mm).
    pub fn cut_length(&self) -> f64 {
        self.outline.iter().map(|l| polygon::perimeter(l)).sum()
    }
    /// Total length of the fold lines, tab folds included (mm).
    pub fn fold_length(&self) -> f64 {
        self.folds.iter().map(|f| f.a.distance(f.b)).sum()
    }
    /// Every point of the piece's geometry (outline, folds, marks, label, ...).
    pub fn points(&self) -> impl Iterator<Item = DVec2> + '_ {
        self.outline
            .iter()
            .flatten()
            .copied()
            .chain(self.folds.iter().flat_map(|f| [f.a, f.b]))
            .chain(self.marks.iter().flat_map(|m| m.text.points()))
            .chain(self.notes.iter().flat_map(|t| t.points()))
            .chain(self.notches.iter().flat_map(|n| n.stroke.iter().copied()))
            .chain(self.seam_line.iter().flatten().copied())
            .chain(self.grain_line.iter().flatten().copied())
            .chain(self.label.points())
    }
}

/// Errors of the pattern stage.
#[derive(Debug, thiserror::Error)]
pub enum PatternError {
    #[error("surface `{surface}`, piece {piece}: its outline could not be traced (flatcut bug)")]
    Outline { surface: String, piece: String },
    /// A piece that cannot be split to fit: one face larger than the room ([`split`]).
    #[error("surface `{surface}`, piece {piece}: face {face} alone is {w:.1} × {h:.1} mm and does not fit on the {what} ({uw:.1} × {uh} mm inside the margins), so the piece cannot be split to fit; use a larger sheet or roll, or scale the surface down")]
    TooLarge {
        surface: String,
        piece: String,
        /// 1-based.
        face: usize,
        w: f64,
        h: f64,
        what: &'static str,
        uw: f64,
        uh: String,
    },
}

impl PatternError {
    /// A fault of flatcut itself (exit code 2), not of the input.
    pub fn is_bug(&self) -> bool {
        matches!(self, PatternError::Outline { .. })
    }
}

/// Build the pieces of every flattened surface, numbering pieces and seams across the job.
pub fn build(flats: &[Flat], opts: &PatternOptions) -> Result<Vec<Piece>, PatternError> {
    build_tagged(flats, &[], opts)
}

/// [`build`], naming island `k` of flat `f` by `tags[f][k]` where given instead of `k + 1`
/// (the parts of a split piece: `3a`, `3b`, …).
pub(crate) fn build_tagged(
    flats: &[Flat],
    tags: &[Vec<String>],
    opts: &PatternOptions,
) -> Result<Vec<Piece>, PatternError> {
    let mut pieces: Vec<Piece> = Vec::new();
    let mut next_seam = 1;
    let multi = flats.len() > 1;
    for (fi, flat) in flats.iter().enumerate() {
        // Metal meshes: the faces trimmed to their bend centre lines, the borders with their
        // corner reliefs ([`develop`]); every later step works on the developed flat.
        let developed = develop::develop(flat, opts);
        let flat = developed.as_ref().map_or(flat, |d| &d.flat);
        let first = pieces.len();
        for (k, faces) in flat.islands.iter().enumerate() {
            let id = pieces.len() + 1;
            let tag = tags
                .get(fi)
                .and_then(|t| t.get(k))
                .cloned()
                .unwrap_or_else(|| format!("{}", k + 1));
            let name = if multi {
                format!("{}-{tag}", flat.surface.name)
            } else {
                tag
            };
            let dev = developed.as_ref().and_then(|d| d.islands.get(k));
            pieces.push(net(flat, faces, id, name, opts, dev)?);
        }
        let mine = &mut pieces[first..];
        marks::find(flat, mine, &mut next_seam);
        // Chart boundaries zig-zag along mesh edges: simplified (thesis §5.3) before any mark
        // is placed on them. Exact unfoldings keep their borders.
        let tolerance = opts.simplify_for(&flat.surface.name);
        let simplified = flat.surface.charts.is_some() && tolerance > 0.0;
        if simplified {
            simplify::apply(mine, tolerance);
        }
        marks::place(flat, mine, opts, simplified);
        for p in mine.iter_mut() {
            marks::finish(p, opts);
        }
        allowance::apply(flat, mine, opts);
        // Texts last, once every stroke is final: moved off each other and off the lines.
        let textured = flat.surface.texture.is_some();
        for p in mine.iter_mut() {
            legible::place(p, opts, textured);
        }
    }
    Ok(pieces)
}

/// The bare piece of an island: border, folds, area.
fn net(
    flat: &Flat,
    faces: &[usize],
    id: usize,
    name: String,
    opts: &PatternOptions,
    dev: Option<&develop::Island>,
) -> Result<Piece, PatternError> {
    let topo = &flat.topology;
    let mesh = &flat.surface.mesh;
    let fail = || PatternError::Outline {
        surface: flat.surface.name.clone(),
        piece: name.clone(),
    };

    // Outline: the boundary loops of the island, as laid flat or as developed (metal).
    let mut loops: Vec<Ring> = match dev.and_then(|d| d.rings.clone()) {
        Some(rings) => rings,
        None => walk(flat, faces)
            .ok_or_else(fail)?
            .iter()
            .map(|l| {
                let pts = l.iter().map(|s| flat.face_2d[s.f][s.i]).collect();
                let edges = l.iter().map(|s| s.e).collect();
                let owners = l.iter().map(|s| s.f).collect();
                (pts, edges, owners)
            })
            .collect(),
    };
    if loops.is_empty() {
        return Err(fail());
    }
    // Outer contour first: the loop of largest positive area.
    let outer = (0..loops.len())
        .max_by(|&a, &b| {
            polygon::signed_area(&loops[a].0).total_cmp(&polygon::signed_area(&loops[b].0))
        })
        .unwrap_or(0);
    loops.swap(0, outer);
    let mut border = Vec::new();
    let mut border_edges = Vec::new();
    let mut border_faces = Vec::new();
    for (pts, edges, owners) in loops {
        border.push(pts);
        border_edges.push(edges);
        border_faces.push(owners);
    }

    // Folds: edges whose bend passes the threshold, or the bend lines the surface names.
    let fold_at = bends::fold_angles(flat, opts.fold_threshold_deg.to_radians());
    let mut folds = Vec::new();
    for &f in faces {
        for (i, &e) in topo.face_edges[f].iter().enumerate() {
            // Each fold once: from the face listed first on the edge.
            if !flat.joined[e] || topo.edges[e].uses[0] != (f, i) {
                continue;
            }
            if let Some(d) = fold_at[e] {
                let (a, b) = match dev.filter(|d| d.rings.is_some()) {
                    // Developed: on the bend centre line, within the blank.
                    Some(d) => match d.folds.get(&e) {
                        Some(&ab) => ab,
                        None => continue,
                    },
                    None => flat.corner_edge(f, i),
                };
                folds.push(Fold {
                    a,
                    b,
                    kind: if d > 0.0 {
                        FoldKind::Mountain
                    } else {
                        FoldKind::Valley
                    },
                    angle: d.abs(),
                    edge: e,
                    tab: false,
                });
            }
        }
    }
    let area = faces.iter().map(|&f| mesh.face_area(f)).sum();
    Ok(Piece {
        surface: flat.surface.name.clone(),
        faces: faces.to_vec(),
        outline: border.clone(),
        border,
        border_edges,
        border_faces,
        folds,
        area,
        development: dev.map(|d| d.development.clone()),
        ..Piece::from_outline(id, name, Vec::new())
    })
}

/// A border ring as `net` keeps it: points, the mesh edge of each segment (or
/// [`develop::NO_EDGE`]) and the face it belongs to.
pub(crate) type Ring = (Vec<DVec2>, Vec<usize>, Vec<usize>);

/// One boundary half-edge of an island: corner `i` of face `f` (the edge from corner `i` to
/// `i + 1`), and the joined edges crossed about its end vertex to reach the next one, each
/// with the face entered and that face's corner at the vertex.
#[derive(Debug, Clone)]
pub(crate) struct Step {
    pub f: usize,
    pub i: usize,
    /// The mesh edge of the half-edge.
    pub e: usize,
    pub turn: Vec<(usize, usize, usize)>,
}

/// The boundary loops of an island, in the order they are found: walk boundary half-edges
/// around the island, turning about each vertex through joined edges. `None` when the walk
/// does not close (a flatcut bug).
pub(crate) fn walk(flat: &Flat, faces: &[usize]) -> Option<Vec<Vec<Step>>> {
    let topo = &flat.topology;
    let mesh = &flat.surface.mesh;
    let mut visited: std::collections::HashSet<(usize, usize)> = Default::default();
    let total_corners: usize = faces.iter().map(|&f| mesh.faces[f].verts.len()).sum();
    let mut loops = Vec::new();
    for &f0 in faces {
        for i0 in 0..mesh.faces[f0].verts.len() {
            if !is_boundary(flat, f0, i0) || visited.contains(&(f0, i0)) {
                continue;
            }
            let mut steps: Vec<Step> = Vec::new();
            let (mut f, mut i) = (f0, i0);
            loop {
                visited.insert((f, i));
                let mut turn = Vec::new();
                // Next boundary half-edge around the end vertex.
                let (mut g, mut j) = (f, (i + 1) % mesh.faces[f].verts.len());
                while !is_boundary(flat, g, j) {
                    let e = topo.face_edges[g][j];
                    let &(h, k) = topo.edges[e].uses.iter().find(|u| **u != (g, j))?;
                    g = h;
                    j = (k + 1) % mesh.faces[h].verts.len();
                    turn.push((e, g, j));
                    if turn.len() > total_corners {
                        return None;
                    }
                }
                steps.push(Step {
                    f,
                    i,
                    e: topo.face_edges[f][i],
                    turn,
                });
                (f, i) = (g, j);
                if (f, i) == (f0, i0) {
                    break;
                }
                if steps.len() > total_corners {
                    return None;
                }
            }
            loops.push(steps);
        }
    }
    Some(loops)
}

fn is_boundary(flat: &Flat, f: usize, i: usize) -> bool {
    !flat.joined[flat.topology.face_edges[f][i]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flatten::{unfold, UnfoldOptions};

    #[test]
    fn cube_piece_has_folds_marks_and_a_simple_outline() {
        let cube = crate::surface::Surface {
            name: "cube".into(),
            source: "t.obj".into(),
            mesh: crate::surface::solids::cuboid(100.0, 100.0, 100.0),
            ..Default::default()
        };
        let flat = unfold(cube, &UnfoldOptions::default()).unwrap();
        let pieces = build(&[flat], &PatternOptions::default()).unwrap();
        assert_eq!(pieces.len(), 1);
        let p = &pieces[0];
        assert_eq!(p.outline.len(), 1);
        assert_eq!(p.border[0].len(), 14);
        // The cut outline is the border without its two straight-through vertices.
        assert_eq!(p.outline[0].len(), 12);
        assert!((p.cut_length() - 1400.0).abs() < 1e-6);
        assert!((p.fold_length() - 500.0).abs() < 1e-9);
        assert!(p.folds.iter().all(|f| f.kind == FoldKind::Mountain));
        assert!(p
            .folds
            .iter()
            .all(|f| (f.angle.to_degrees() - 90.0).abs() < 1e-9));
        assert!((p.area - 60000.0).abs() < 1e-6);
        assert!(polygon::signed_area(&p.outline[0]) > 0.0);
        assert!(polygon::is_simple_ring(&p.outline[0]));
        // Seven cut edges in seams: every seam has two sides on this piece, of equal length,
        // together covering the 1400 mm of border once; each id written twice, inside.
        let n = p.seams.len() / 2;
        assert!(
            (1..=7).contains(&n) && p.seams.len() == 2 * n,
            "{}",
            p.seams.len()
        );
        let total: f64 = p.seams.iter().map(|s| s.length).sum();
        assert!((total - 1400.0).abs() < 1e-9);
        assert_eq!(p.marks.len(), 2 * n);
        for id in 1..=n {
            let sides: Vec<_> = p.seams.iter().filter(|s| s.id == id).collect();
            assert_eq!(sides.len(), 2);
            assert!((sides[0].length - sides[1].length).abs() < 1e-9);
            assert_eq!(sides[0].is_a, !sides[1].is_a);
            assert_eq!(p.marks.iter().filter(|m| m.id == id).count(), 2);
        }
        for m in &p.marks {
            assert!(!m.text.is_empty());
            for q in m.text.points() {
                assert!(polygon::contains(&p.outline[0], q), "mark {} at {q}", m.id);
            }
        }
        assert!(!p.label.is_empty());
        for q in p.label.points() {
            assert!(polygon::contains(&p.outline[0], q));
        }
    }
}
