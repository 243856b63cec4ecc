//! Pattern stage: turns each island of a [`Flat`] into a [`Piece`] a person can cut and
//! assemble: the cut outline (outer contour and any holes), fold lines where joined faces meet
//! at a bend above the threshold (mountain or valley, with the angle), the same edge id written
//! beside both copies of every cut edge, and a label naming the piece.
//!
//! Conventions: pieces are drawn as seen from the printed side, which is the outside of a
//! closed mesh; a convex edge therefore folds away from the viewer and is a mountain fold, a
//! concave edge a valley fold. Text is set in the single-stroke font of [`crate::geom::font`]
//! so a pen can draw it or a knife score it.
//!
//! Choices where the issue is silent: edge ids are numbered 1, 2, … over the whole job in the
//! order of the surfaces and of their mesh edges; an edge id is set along its edge, inside the
//! face, reading left to right (never upside down), at a height of at most 3 mm, 30 % of the
//! edge length and 35 % of the face's depth behind the edge; the piece label goes in the
//! incircle of the piece's largest triangle, at most 8 mm high.

pub mod bends;

use crate::flatten::Flat;
use crate::geom::{font, polygon};
use glam::DVec2;
use serde::Serialize;

/// Options of the pattern stage.
#[derive(Debug, Clone, PartialEq)]
pub struct PatternOptions {
    /// Joined edges bending by more than this (degrees) become fold lines.
    pub fold_threshold_deg: f64,
    /// Largest height of edge ids (mm).
    pub max_mark_height: f64,
    /// Largest height of piece labels (mm).
    pub max_label_height: f64,
}

impl Default for PatternOptions {
    fn default() -> Self {
        PatternOptions {
            fold_threshold_deg: 1.0,
            max_mark_height: 3.0,
            max_label_height: 8.0,
        }
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
    /// Bend angle in degrees (0 = flat).
    pub angle_deg: f64,
    /// Mesh edge it comes from.
    pub edge: usize,
}

/// The id of a cut edge written beside one of its two copies.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeMark {
    /// The number written (the same on both copies).
    pub id: usize,
    /// Mesh edge.
    pub edge: usize,
    /// This copy of the edge on the piece.
    pub a: DVec2,
    pub b: DVec2,
    /// Pen strokes of the number.
    pub strokes: Vec<Vec<DVec2>>,
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
    /// (counter-clockwise), then holes (clockwise).
    pub outline: Vec<Vec<DVec2>>,
    /// Mesh edge of each outline segment (segment `k` runs from point `k` to `k + 1`).
    pub outline_edges: Vec<Vec<usize>>,
    pub folds: Vec<Fold>,
    pub marks: Vec<EdgeMark>,
    /// Pen strokes of the label.
    pub label: Vec<Vec<DVec2>>,
    /// Area in mm² (equal in 3D and flat: the unfolding is isometric).
    pub area: f64,
    /// Direction of the grain line in the piece's frame (radians from +x), for materials with
    /// a grain (fabric). The nest stage keeps it parallel to the roll (sheet y axis), either way.
    pub grain: Option<f64>,
}

impl Piece {
    /// Total length of the cut contours (mm).
    pub fn cut_length(&self) -> f64 {
        self.outline.iter().map(|l| polygon::perimeter(l)).sum()
    }
    /// Total length of the fold lines (mm).
    pub fn fold_length(&self) -> f64 {
        self.folds.iter().map(|f| f.a.distance(f.b)).sum()
    }
    /// Every point of the piece's geometry (outline, folds, marks, label).
    pub fn points(&self) -> impl Iterator<Item = DVec2> + '_ {
        self.outline
            .iter()
            .flatten()
            .copied()
            .chain(self.folds.iter().flat_map(|f| [f.a, f.b]))
            .chain(
                self.marks
                    .iter()
                    .flat_map(|m| m.strokes.iter().flatten().copied()),
            )
            .chain(self.label.iter().flatten().copied())
    }
}

/// Errors of the pattern stage.
#[derive(Debug, thiserror::Error)]
pub enum PatternError {
    #[error("surface `{surface}`, piece {piece}: its outline could not be traced (flatcut bug)")]
    Outline { surface: String, piece: String },
}

/// Build the pieces of every flattened surface, numbering pieces and edge ids across the job.
pub fn build(flats: &[Flat], opts: &PatternOptions) -> Result<Vec<Piece>, PatternError> {
    let mut pieces = Vec::new();
    let mut next_edge_id = 1;
    let multi = flats.len() > 1;
    for flat in flats {
        let ids = edge_ids(flat, &mut next_edge_id);
        for (k, faces) in flat.islands.iter().enumerate() {
            let id = pieces.len() + 1;
            let name = if multi {
                format!("{}-{}", flat.surface.name, k + 1)
            } else {
                format!("{}", k + 1)
            };
            pieces.push(piece(flat, faces, &ids, id, name, opts)?);
        }
    }
    Ok(pieces)
}

/// Number the cut edges that have two copies.
fn edge_ids(flat: &Flat, next: &mut usize) -> Vec<Option<usize>> {
    flat.topology
        .edges
        .iter()
        .enumerate()
        .map(|(e, edge)| {
            if edge.uses.len() == 2 && !flat.joined[e] {
                *next += 1;
                Some(*next - 1)
            } else {
                None
            }
        })
        .collect()
}

fn is_boundary(flat: &Flat, f: usize, i: usize) -> bool {
    !flat.joined[flat.topology.face_edges[f][i]]
}

fn piece(
    flat: &Flat,
    faces: &[usize],
    ids: &[Option<usize>],
    id: usize,
    name: String,
    opts: &PatternOptions,
) -> Result<Piece, PatternError> {
    let topo = &flat.topology;
    let mesh = &flat.surface.mesh;
    let fail = || PatternError::Outline {
        surface: flat.surface.name.clone(),
        piece: name.clone(),
    };

    // Outline: walk boundary half-edges around the island, turning about each vertex through
    // joined edges.
    let mut visited: std::collections::HashSet<(usize, usize)> = Default::default();
    let total_corners: usize = faces.iter().map(|&f| mesh.faces[f].verts.len()).sum();
    let mut loops: Vec<(Vec<DVec2>, Vec<usize>)> = Vec::new();
    for &f0 in faces {
        for i0 in 0..mesh.faces[f0].verts.len() {
            if !is_boundary(flat, f0, i0) || visited.contains(&(f0, i0)) {
                continue;
            }
            let (mut pts, mut edges) = (Vec::new(), Vec::new());
            let (mut f, mut i) = (f0, i0);
            loop {
                visited.insert((f, i));
                pts.push(flat.face_2d[f][i]);
                edges.push(topo.face_edges[f][i]);
                // Next boundary half-edge around the end vertex.
                let mut steps = 0;
                let (mut g, mut j) = (f, (i + 1) % mesh.faces[f].verts.len());
                while !is_boundary(flat, g, j) {
                    let e = topo.face_edges[g][j];
                    let &(h, k) = topo.edges[e]
                        .uses
                        .iter()
                        .find(|u| **u != (g, j))
                        .ok_or_else(fail)?;
                    g = h;
                    j = (k + 1) % mesh.faces[h].verts.len();
                    steps += 1;
                    if steps > total_corners {
                        return Err(fail());
                    }
                }
                (f, i) = (g, j);
                if (f, i) == (f0, i0) {
                    break;
                }
                if pts.len() > total_corners {
                    return Err(fail());
                }
            }
            loops.push((pts, edges));
        }
    }
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
    let (outline, outline_edges): (Vec<_>, Vec<_>) = loops.into_iter().unzip();

    // Folds and edge ids.
    let fold_at = bends::fold_angles(flat, opts.fold_threshold_deg.to_radians());
    let mut folds = Vec::new();
    let mut marks = Vec::new();
    for &f in faces {
        for (i, &e) in topo.face_edges[f].iter().enumerate() {
            let (a, b) = flat.corner_edge(f, i);
            if flat.joined[e] {
                // Each fold once: from the face listed first on the edge.
                if let (true, Some(d)) = (topo.edges[e].uses[0] == (f, i), fold_at[e]) {
                    folds.push(Fold {
                        a,
                        b,
                        kind: if d > 0.0 {
                            FoldKind::Mountain
                        } else {
                            FoldKind::Valley
                        },
                        angle_deg: d.abs().to_degrees(),
                        edge: e,
                    });
                }
            } else if let Some(n) = ids[e] {
                let depth = 2.0 * mesh.face_area(f) / a.distance(b).max(f64::MIN_POSITIVE);
                marks.push(EdgeMark {
                    id: n,
                    edge: e,
                    a,
                    b,
                    strokes: edge_text(&n.to_string(), a, b, depth, opts.max_mark_height),
                });
            }
        }
    }

    let label = piece_label(flat, faces, &name, opts.max_label_height);
    let area = faces.iter().map(|&f| mesh.face_area(f)).sum();
    Ok(Piece {
        id,
        name,
        surface: flat.surface.name.clone(),
        faces: faces.to_vec(),
        outline,
        outline_edges,
        folds,
        marks,
        label,
        area,
        grain: None,
    })
}

/// Strokes of `text` set along the edge `a → b` (interior on its left), inside the face.
fn edge_text(text: &str, a: DVec2, b: DVec2, depth: f64, max_h: f64) -> Vec<Vec<DVec2>> {
    let len = a.distance(b);
    if len <= 0.0 {
        return Vec::new();
    }
    let d = (b - a) / len;
    let inward = d.perp();
    let mut h = max_h.min(0.3 * len).min(0.35 * depth);
    let w1 = font::text_width(text, 1.0);
    if w1 * h > 0.8 * len {
        h = 0.8 * len / w1;
    }
    if h.is_nan() || h <= 0.0 {
        return Vec::new();
    }
    let w = w1 * h;
    let gap = 0.25 * h;
    // Read left to right: run along +x (or +y for vertical edges).
    let upright = d.x > 1e-9 || (d.x.abs() <= 1e-9 && d.y > 0.0);
    let (r, base) = if upright {
        (d, 0.5 * (a + b) - d * (0.5 * w) + inward * gap)
    } else {
        (-d, 0.5 * (a + b) + d * (0.5 * w) + inward * (gap + h))
    };
    let up = r.perp();
    let (strokes, _) = font::text_strokes(text, h);
    strokes
        .into_iter()
        .map(|s| s.into_iter().map(|p| base + r * p.x + up * p.y).collect())
        .collect()
}

/// The piece name, centred in the incircle of the piece's largest triangle.
fn piece_label(flat: &Flat, faces: &[usize], text: &str, max_h: f64) -> Vec<Vec<DVec2>> {
    let mut best: Option<(f64, DVec2)> = None; // (inradius, incenter)
    for &f in faces {
        let p = &flat.face_2d[f];
        for t in polygon::triangulate(p) {
            let (a, b, c) = (p[t[0]], p[t[1]], p[t[2]]);
            let (la, lb, lc) = (b.distance(c), c.distance(a), a.distance(b));
            let per = la + lb + lc;
            if per <= 0.0 {
                continue;
            }
            let area = polygon::signed_area(&[a, b, c]).abs();
            let r = 2.0 * area / per;
            if best.is_none_or(|(br, _)| r > br) {
                best = Some((r, (a * la + b * lb + c * lc) / per));
            }
        }
    }
    let Some((r, center)) = best else {
        return Vec::new();
    };
    let k = font::text_width(text, 1.0);
    let h = (1.6 * r / (k * k + 1.0).sqrt()).min(max_h);
    if h.is_nan() || h <= 0.0 {
        return Vec::new();
    }
    let (strokes, w) = font::text_strokes(text, h);
    let origin = center - DVec2::new(0.5 * w, 0.5 * h);
    strokes
        .into_iter()
        .map(|s| s.into_iter().map(|p| p + origin).collect())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flatten::{unfold, UnfoldOptions};

    #[test]
    fn cube_piece_has_folds_marks_and_a_simple_outline() {
        let flat = unfold(
            crate::flatten::unfold::tests::cube(100.0),
            &UnfoldOptions::default(),
        )
        .unwrap();
        let pieces = build(&[flat], &PatternOptions::default()).unwrap();
        assert_eq!(pieces.len(), 1);
        let p = &pieces[0];
        assert_eq!(p.outline.len(), 1);
        assert_eq!(p.outline[0].len(), 14);
        assert!((p.cut_length() - 1400.0).abs() < 1e-9);
        assert!((p.fold_length() - 500.0).abs() < 1e-9);
        assert!(p.folds.iter().all(|f| f.kind == FoldKind::Mountain));
        assert!(p.folds.iter().all(|f| (f.angle_deg - 90.0).abs() < 1e-9));
        assert!((p.area - 60000.0).abs() < 1e-6);
        assert!(polygon::signed_area(&p.outline[0]) > 0.0);
        assert!(polygon::is_simple_ring(&p.outline[0]));
        // Seven cut edges, each id written twice, inside the piece.
        assert_eq!(p.marks.len(), 14);
        for id in 1..=7 {
            assert_eq!(p.marks.iter().filter(|m| m.id == id).count(), 2);
        }
        for m in &p.marks {
            assert!(!m.strokes.is_empty());
            for q in m.strokes.iter().flatten() {
                assert!(polygon::contains(&p.outline[0], *q), "mark {} at {q}", m.id);
            }
        }
        assert!(!p.label.is_empty());
        for q in p.label.iter().flatten() {
            assert!(polygon::contains(&p.outline[0], *q));
        }
    }
}
