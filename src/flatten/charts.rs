//! Flattening of a segmented smooth surface: every chart of [`Surface::charts`] becomes one
//! island, laid flat by [`super::param::parameterize`] (LSCM / ABF++, scaled so that its 2D
//! area equals its 3D area), and [`flatten`] picks between that and the exact polyhedral
//! [`super::unfold`] for the CLI.
//!
//! The [`Flat`] it builds is the one the pattern stage already reads: `face_2d` per face
//! corner, counter-clockwise (a chart laid out mirrored is mirrored back); `joined` for the
//! edges inside a chart (their two copies coincide, the parameterisation being per vertex);
//! `dihedral` the signed bend of every interior edge, as [`super::unfold`] computes it.
//!
//! After the thesis' §5.3 ("overlaps cut away", "a piece over the material's tolerance"), a
//! chart is split in two and both halves laid flat again when
//! - its layout overlaps itself deeper than the unfolder's tolerance (a global overlap, or a
//!   gusset folding over): split between the two overlapping faces
//!   ([`crate::surface::dcharts::split_between`]: each face goes with the nearer of the two,
//!   through the chart), so the overlapping parts end up in different pieces;
//!
//! and along the bisector of its two most distant faces ([`crate::surface::dcharts::bisect`])
//! when
//! - it has a flipped triangle,
//! - the parameteriser refuses it (not a disk),
//! - or its L2 stretch is over [`FlattenOptions::tolerance`] — at most
//!   [`FlattenOptions::max_splits`] times per chart; what is still over it then is reported
//!   (a warning on the surface, and the stretch of every piece in `report.json`).
//!
//! Material tolerances on the L2 stretch of a piece ([`material_tolerance`]), chosen here:
//! paper 1.003 (paper does not stretch; 0.3 % is taken up by folding and gluing without a
//! visible wrinkle), metal 1.001 (a blank must develop, 0.1 % is within a plotter's accuracy
//! on a 1 m piece), fabric 1.03 (woven cloth gives a few percent on the bias, and stuffing
//! takes up more). L∞ is reported but not used: one sliver triangle makes it large without a
//! visible fault.

use super::distortion::{self, Stretch};
use super::param::{self, ParamMethod};
use super::{unfold, Flat, FlattenError, UnfoldOptions};
use crate::geom::mesh::Topology;
use crate::geom::polygon;
use crate::spec::MaterialKind;
use crate::surface::dcharts::{bisect, split_between, Graph};
use crate::surface::Surface;
use glam::DVec2;

/// How a surface is laid flat.
#[derive(Debug, Clone, PartialEq)]
pub struct FlattenOptions {
    /// The exact unfolding's options (surfaces without charts).
    pub unfold: UnfoldOptions,
    /// Parameterisation of charts.
    pub method: ParamMethod,
    /// Largest L2 stretch of a piece before it is split (see [`material_tolerance`]).
    pub tolerance: f64,
    /// Times a chart may be split for being over the tolerance (overlaps and flips are always
    /// split, down to single faces).
    pub max_splits: usize,
}

impl Default for FlattenOptions {
    fn default() -> Self {
        FlattenOptions {
            unfold: UnfoldOptions::default(),
            method: ParamMethod::default(),
            tolerance: material_tolerance(MaterialKind::Paper),
            max_splits: 3,
        }
    }
}

impl FlattenOptions {
    /// Defaults for a material.
    pub fn for_material(kind: MaterialKind) -> Self {
        FlattenOptions {
            tolerance: material_tolerance(kind),
            ..Default::default()
        }
    }
}

/// Largest L2 stretch of a piece, by material (see the module doc).
pub fn material_tolerance(kind: MaterialKind) -> f64 {
    match kind {
        MaterialKind::Paper => 1.003,
        MaterialKind::Fabric => 1.03,
        MaterialKind::Metal => 1.001,
    }
}

/// Lay a surface flat: its charts parameterised when it has them, else unfolded exactly.
pub fn flatten(surface: Surface, opts: &FlattenOptions) -> Result<Flat, FlattenError> {
    if surface.charts.is_some() {
        charts(surface, opts)
    } else {
        unfold(surface, &opts.unfold)
    }
}

/// A chart laid flat.
struct Laid {
    faces: Vec<usize>,
    uv: Vec<Vec<DVec2>>,
    stretch: Stretch,
    splits: usize,
}

/// Lay each chart flat as one island (splitting where needed, see the module doc).
pub fn charts(mut surface: Surface, opts: &FlattenOptions) -> Result<Flat, FlattenError> {
    let mesh = &surface.mesh;
    let nf = mesh.faces.len();
    let chart_of = match &surface.charts {
        Some(c) if c.len() == nf => c.clone(),
        _ => vec![0; nf],
    };
    let topology = mesh.topology();
    let graph = Graph::new(mesh, &topology);
    let count = chart_of.iter().copied().max().map_or(0, |m| m + 1);
    let mut groups: Vec<Vec<usize>> = vec![Vec::new(); count];
    for (f, &c) in chart_of.iter().enumerate() {
        groups[c].push(f);
    }
    let mut todo: Vec<(Vec<usize>, usize)> = groups
        .into_iter()
        .filter(|g| !g.is_empty())
        .map(|g| (g, 0))
        .collect();
    todo.reverse();
    let mut done: Vec<Laid> = Vec::new();
    // Overlaps shallower than the unfolder's tolerance count as touching, as in `unfold`.
    let mean_edge = topology
        .edges
        .iter()
        .map(|e| mesh.vertices[e.verts[0]].distance(mesh.vertices[e.verts[1]]))
        .sum::<f64>()
        / topology.edges.len().max(1) as f64;
    let overlap_eps = opts.unfold.tolerance.min(0.01 * mean_edge);
    let mut over: Vec<(usize, f64)> = Vec::new();
    let degenerate = |f: usize| FlattenError::Degenerate {
        surface: surface.name.clone(),
        face: f + 1,
        line: mesh.faces[f].line,
    };
    while let Some((faces, splits)) = todo.pop() {
        let laid = param::parameterize(mesh, &faces, opts.method);
        let split_it = |todo: &mut Vec<(Vec<usize>, usize)>, faces: &[usize], splits: usize| {
            let (a, b) = bisect(&graph, faces);
            if a.is_empty() || b.is_empty() {
                return false;
            }
            todo.push((b, splits));
            todo.push((a, splits));
            true
        };
        let p = match laid {
            Ok(p) => p,
            // A sliver triangle cannot be laid flat in any chart: say which.
            Err(param::ParamError::Degenerate { face, .. }) => {
                return Err(degenerate(face.min(nf - 1)))
            }
            Err(_) => {
                if faces.len() == 1 || !split_it(&mut todo, &faces, splits) {
                    return Err(degenerate(faces[0]));
                }
                continue;
            }
        };
        let mut uv = p.uv;
        if uv.iter().any(|c| c.iter().any(|q| !q.is_finite())) {
            if faces.len() == 1 || !split_it(&mut todo, &faces, splits) {
                return Err(degenerate(faces[0]));
            }
            continue;
        }
        // Counter-clockwise, as the pattern stage expects.
        let total: f64 = uv.iter().map(|c| polygon::signed_area(c)).sum();
        let stretch = if total < 0.0 {
            for c in uv.iter_mut() {
                for q in c.iter_mut() {
                    q.x = -q.x;
                }
            }
            distortion::stretch(mesh, &faces, &uv)
        } else {
            p.stretch
        };
        if faces.len() > 1 {
            // Overlapping parts go to different pieces: split between the two faces.
            if let Some((x, y)) = self_overlap(&uv, overlap_eps) {
                let (a, b) = split_between(&graph, &faces, faces[x], faces[y]);
                if !a.is_empty() && !b.is_empty() {
                    todo.push((b, splits));
                    todo.push((a, splits));
                    continue;
                }
            }
            if stretch.flipped > 0 && split_it(&mut todo, &faces, splits) {
                continue;
            }
        }
        if stretch.l2 > opts.tolerance
            && splits < opts.max_splits
            && faces.len() >= 8
            && split_it(&mut todo, &faces, splits + 1)
        {
            continue;
        }
        done.push(Laid {
            faces,
            uv,
            stretch,
            splits,
        });
    }

    // Islands numbered by smallest face.
    done.sort_by_key(|l| l.faces.iter().copied().min().unwrap_or(0));
    let mut face_2d: Vec<Vec<DVec2>> = vec![Vec::new(); nf];
    let mut face_island = vec![0; nf];
    let mut islands = Vec::with_capacity(done.len());
    for (k, l) in done.iter().enumerate() {
        if l.stretch.l2 > opts.tolerance {
            over.push((k, l.stretch.l2));
        }
        let _ = l.splits;
        for (f, c) in l.faces.iter().zip(&l.uv) {
            face_2d[*f] = c.clone();
            face_island[*f] = k;
        }
        let mut faces = l.faces.clone();
        faces.sort_unstable();
        islands.push(faces);
    }
    let ne = topology.edges.len();
    let mut joined = vec![false; ne];
    let mut dihedral = vec![0.0; ne];
    let mut lengths = 0.0;
    for (e, edge) in topology.edges.iter().enumerate() {
        lengths += mesh.vertices[edge.verts[0]].distance(mesh.vertices[edge.verts[1]]);
        let [(f, i), (g, j)] = edge.uses[..] else {
            continue;
        };
        dihedral[e] = bend(mesh, f, i, g);
        if face_island[f] == face_island[g] {
            let (p, q) = (face_2d[f][i], face_2d[f][(i + 1) % face_2d[f].len()]);
            let (q0, p0) = (face_2d[g][j], face_2d[g][(j + 1) % face_2d[g].len()]);
            let tol = 1e-9 * (1.0 + p.length().max(q.length()));
            joined[e] = p.distance(p0) <= tol && q.distance(q0) <= tol;
        }
    }
    let mean = lengths / ne.max(1) as f64;
    for (k, l2) in over {
        surface.warnings.push(format!(
            "surface `{}`: piece {} stretches by L2 {:.5}, over the material's {:.4}: expect wrinkles or gaps",
            surface.name,
            k + 1,
            l2,
            opts.tolerance
        ));
    }
    surface.charts = Some(face_island.clone());
    Ok(Flat {
        surface,
        topology,
        face_2d,
        face_island,
        islands,
        joined,
        dihedral,
        tolerance: opts.unfold.tolerance.min(0.01 * mean),
    })
}

/// Stretch of each island of a flat, and of the whole (area-weighted), from its layout.
pub fn stretch(flat: &Flat) -> (Vec<Stretch>, Stretch) {
    let per: Vec<Stretch> = flat
        .islands
        .iter()
        .map(|faces| {
            let uv: Vec<Vec<DVec2>> = faces.iter().map(|&f| flat.face_2d[f].clone()).collect();
            distortion::stretch(&flat.surface.mesh, faces, &uv)
        })
        .collect();
    let whole = distortion::combine(&per);
    (per, whole)
}

/// Signed bend angle at the edge of corner `i` of face `f` shared with face `g` (as
/// [`super::unfold`] has it: positive where convex).
fn bend(mesh: &crate::geom::mesh::Mesh, f: usize, i: usize, g: usize) -> f64 {
    let nf = mesh.face_normal(f);
    let ng = mesh.face_normal(g);
    let (a, b) = Topology::corner_verts(mesh, f, i);
    let dir = mesh.vertices[b] - mesh.vertices[a];
    let angle = nf.angle_between(ng);
    if !angle.is_finite() {
        return 0.0;
    }
    if nf.cross(ng).dot(dir) >= 0.0 {
        angle
    } else {
        -angle
    }
}

/// Two faces (indices into `uv`) of one chart's layout that overlap deeper than `eps`, if
/// any: a sweep over x of the triangles' boxes.
fn self_overlap(uv: &[Vec<DVec2>], eps: f64) -> Option<(usize, usize)> {
    let mut tris: Vec<([DVec2; 3], usize)> = Vec::new();
    for (k, c) in uv.iter().enumerate() {
        for t in polygon::triangulate(c) {
            tris.push(([c[t[0]], c[t[1]], c[t[2]]], k));
        }
    }
    let mut boxes: Vec<(f64, f64, usize)> = tris
        .iter()
        .enumerate()
        .filter_map(|(i, (t, _))| {
            polygon::bounds(t.iter().copied()).map(|(lo, hi)| (lo.x, hi.x, i))
        })
        .collect();
    boxes.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
    for (k, &(_, hx, i)) in boxes.iter().enumerate() {
        for &(lx, _, j) in &boxes[k + 1..] {
            if lx >= hx - eps {
                break;
            }
            if tris[i].1 == tris[j].1 {
                continue;
            }
            if polygon::triangles_overlap(&tris[i].0, &tris[j].0, eps) {
                return Some((tris[i].1, tris[j].1));
            }
        }
    }
    None
}
