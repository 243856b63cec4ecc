//! Parameterisation of nearly developable disk-topology charts: LSCM (Lévy, Petitjean, Ray,
//! Maillot 2002) and ABF++ (Sheffer, Lévy, Mogilnitsky, Bogomyakov 2005), the unfolding the
//! thesis (seed 001, §6.2 / §6.4) uses for its panels. [`parameterize`] flattens one chart (a
//! set of mesh faces) and measures it with [`distortion::stretch`].
//!
//! **LSCM.** Each triangle, laid in its own plane with corners z₁ z₂ z₃ (complex), asks the
//! flat map U to be conformal: |Σⱼ Wⱼ Uⱼ|² / (2A) = 0 with Wⱼ = z_{j+2} − z_{j+1} (Lévy et al.
//! eq. 8–10, written so that direct similarities cost nothing and mirror images do). Two vertices
//! are pinned and the rest solved by sparse least squares: the normal equations AᵀA x = −Aᵀb
//! (symmetric positive definite once two vertices are pinned) are factored by faer's sparse
//! Cholesky with its fill-reducing ordering, and the solution improved by two steps of
//! iterative refinement (the normal equations square the condition number; refined, an
//! exactly developable chart comes out isometric to ~1e-11 relative).
//!
//! **ABF++** (`abf`): the angles of every triangle solved for, then turned into coordinates
//! by the LSCM energy with each triangle's shape built from its angles, same two pins.
//!
//! Choices where the papers are silent:
//! - **Pins**: the two boundary vertices farthest apart in 3D (ties: the lowest local indices,
//!   local indices being first appearance in `faces` order), placed at (0, 0) and (d, 0), d their
//!   3D distance. Exact over all pairs up to `EXACT_PIN_LIMIT` boundary vertices; beyond it a
//!   double sweep (the vertex farthest from the first boundary vertex, then the one farthest
//!   from that), which is within a factor √2 of the diameter and O(n).
//! - **Output frame**: the layout is scaled so its area equals the chart's 3D area, mirrored if
//!   it came out clockwise (it never should: both energies penalise mirror images), and moved so
//!   its bounding box starts at (0, 0). Counter-clockwise = seen from the side the face normals
//!   point to, like [`super::Flat`].
//! - **Best**: LSCM first. A flip-free LSCM layout that is already isometric (L2 within
//!   `ISOMETRIC` of 1) is returned at once; any other flip-free one is relaxed by free-boundary
//!   L2 stretch minimisation (Sander et al. 2001 §4, the parameterisation the thesis evaluates
//!   its charts with, §5.4) over all vertices at once ([`lbfgs`]), which never raises L2 and
//!   never flips a triangle (a developable chart, already at 1.0, stays as it is). ABF++ runs
//!   only where LSCM fails (a singular system) or flips a triangle: the result with fewer
//!   flipped triangles wins, then the lower L2 stretch (a tie keeps LSCM), and a flip-free
//!   winner is relaxed the same way. If one method fails (ABF++ not converging in
//!   `ABF_MAX_ITER` Newton steps) the other is kept; if both fail, the LSCM error is
//!   returned. ABF++ steps are damped when a full Newton step would take an angle out of
//!   (0, π) (the paper takes full steps). If both results have flipped triangles the one with
//!   fewer is returned and `stretch.flipped` says how many: the caller must split such a
//!   chart (D-Charts does). ABF++'s angles start the minimisation no better than LSCM's
//!   layout: the quasi-Newton steps reach a lower L2 from either than vertex-by-vertex sweeps
//!   reach from the better of the two. `method` names the conformal method the minimisation
//!   started from. It lowers L2 at the cost of conformality (shear) and, on strongly curved
//!   charts, of L∞: `Lscm` and `Abf` give the pure conformal layouts. [`relax_from`] runs the
//!   same minimisation from a given layout (a part of a larger chart, as it lay in the whole)
//!   instead of laying the chart anew.
//! - **Polygon faces** (more than 3 corners) are ear-clipped in their best-fit plane
//!   (`distortion::face_triangles`); their `uv` is still one point per original corner.
//! - **Refused** (a [`ParamError`] naming the face and its OBJ line): no faces, a face index out
//!   of range or repeated, a vertex index out of range or not finite, a triangle with an angle
//!   below `MIN_ANGLE` (1e-3 rad), an edge used by more than two triangles, two faces wound
//!   against each other, a vertex where two boundary fans meet, several connected components,
//!   no boundary (closed), several boundary loops (holes), handles. Nothing is repaired here:
//!   charts come from a segmentation that can cut differently.
//! - Determinism: no hash-map iteration order reaches the result; the solves are sequential.

use super::distortion::{self, corner_angle, face_triangles, Stretch};
use crate::geom::mesh::Mesh;
use crate::geom::sparse::{Cholesky, Pattern};
use crate::geom::unionfind::UnionFind;
use faer::sparse::Triplet;
use glam::{DVec2, DVec3};
use std::collections::HashMap;
use std::sync::OnceLock;

mod abf;
mod lbfgs;
mod seams;
mod solve;
mod stretch;

use abf::abf_angles;
use solve::{spd_solve, Solver};
use stretch::minimise_stretch;

pub use seams::match_seams;

/// Smallest triangle angle accepted (radians).
pub(crate) const MIN_ANGLE: f64 = 1e-3;
/// `Best` keeps an LSCM layout without running ABF++ when its L2 stretch is within this of 1.
pub(crate) const ISOMETRIC: f64 = 1e-9;
/// Boundary size up to which the pins are the exact farthest pair.
pub(crate) const EXACT_PIN_LIMIT: usize = 4000;
/// Newton steps ABF++ may take.
pub(crate) const ABF_MAX_ITER: usize = 50;
/// ABF++ stops when the gradient of the Lagrangian (with the constraint values) is below this
/// times √(triangles), or when it stalls below 1e-7 times √(triangles).
pub(crate) const ABF_TOLERANCE: f64 = 1e-10;

/// Which parameterisation to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ParamMethod {
    Lscm,
    Abf,
    /// Both; keep the one with fewer flipped triangles, then the lower L2 stretch, then
    /// minimise its L2 stretch (see the module doc).
    #[default]
    Best,
}

/// One chart laid flat.
#[derive(Debug, Clone, PartialEq)]
pub struct ChartParam {
    /// The chart's faces (mesh face indices), as given.
    pub faces: Vec<usize>,
    /// Per chart face (same order), per corner: flat position in mm, scaled so the flat area
    /// equals the 3D area.
    pub uv: Vec<Vec<DVec2>>,
    /// The method whose result this is (`Lscm` or `Abf`; for `Best`, the one the stretch
    /// minimisation started from).
    pub method: ParamMethod,
    /// Distortion of `uv`.
    pub stretch: Stretch,
}

fn at(face: usize, line: &Option<usize>) -> String {
    match line {
        Some(l) => format!("face {face} (line {l})"),
        None => format!("face {face}"),
    }
}

/// Why a chart cannot be parameterised. Each message names the face (and its OBJ line).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    #[error("chart has no faces")]
    Empty,
    #[error("chart lists face {face}, but the mesh has {count} faces")]
    FaceOutOfRange { face: usize, count: usize },
    #[error("chart lists {} twice", at(*face, line))]
    DuplicateFace { face: usize, line: Option<usize> },
    #[error("{}: vertex {vertex} is missing or not a finite point", at(*face, line))]
    BadVertex {
        face: usize,
        line: Option<usize>,
        vertex: usize,
    },
    #[error("{}: degenerate triangle (angle {angle:.2e} rad, below 1e-3); remove or remesh it", at(*face, line))]
    Degenerate {
        face: usize,
        line: Option<usize>,
        angle: f64,
    },
    #[error("{}: non-manifold edge {a}-{b}, used by {count} triangles; a chart must be a disk", at(*face, line))]
    NonManifoldEdge {
        face: usize,
        line: Option<usize>,
        a: usize,
        b: usize,
        count: usize,
    },
    #[error("{}: non-manifold vertex {vertex} (two boundary fans meet there); a chart must be a disk", at(*face, line))]
    NonManifoldVertex {
        face: usize,
        line: Option<usize>,
        vertex: usize,
    },
    #[error("{}: wound against its neighbour across edge {a}-{b}; orient the mesh consistently", at(*face, line))]
    Inconsistent {
        face: usize,
        line: Option<usize>,
        a: usize,
        b: usize,
    },
    #[error("chart is not a disk: {count} separate components ({} is not connected to the first face)", at(*face, line))]
    SeveralComponents {
        count: usize,
        face: usize,
        line: Option<usize>,
    },
    #[error("chart is not a disk: it is closed (no boundary, e.g. {}); cut it open", at(*face, line))]
    Closed { face: usize, line: Option<usize> },
    #[error("chart is not a disk: {loops} boundary loops (holes; one runs along {}); cut from each hole to the outer boundary", at(*face, line))]
    Holes {
        loops: usize,
        face: usize,
        line: Option<usize>,
    },
    #[error("chart is not a disk: Euler characteristic {euler} with one boundary loop (handles; e.g. {}); cut the handles", at(*face, line))]
    Handles {
        euler: i64,
        face: usize,
        line: Option<usize>,
    },
    #[error("{method}: {message} (chart of {faces} faces starting at {})", at(*face, line))]
    Solver {
        method: &'static str,
        message: String,
        faces: usize,
        face: usize,
        line: Option<usize>,
    },
}

/// A chart ready to solve: local vertices, triangles over them.
struct Chart {
    /// Local vertex → 3D position.
    pos: Vec<DVec3>,
    /// Triangles over local vertices (face winding).
    tris: Vec<[usize; 3]>,
    /// Per chart face: local vertex of each corner.
    corners: Vec<Vec<usize>>,
    /// Per local vertex: on the boundary.
    boundary: Vec<bool>,
    /// Boundary vertices (local), in loop order.
    boundary_loop: Vec<usize>,
    /// For messages: the first face and its line.
    first: (usize, Option<usize>),
    nfaces: usize,
    /// The symbolic factorisation of the first system over the chart's vertices with the
    /// cotangent Laplacian's structure ([`Chart::vertex_cholesky`]).
    vertex_symbolic: OnceLock<Option<Cholesky>>,
}

impl Chart {
    /// A factorisation for `pattern`, a system over the chart's vertices: made from the
    /// chart's first such system's symbolic factorisation where the two have one structure
    /// (the stretch minimiser's and the seam matching's Laplacians, softly pinned at different
    /// vertices), else anew. Faer orders a structure the same way whichever system it comes
    /// from, so the factors are those each would make alone.
    fn vertex_cholesky(&self, pattern: &Pattern) -> Option<Cholesky> {
        match self.vertex_symbolic.get_or_init(|| Cholesky::new(pattern)) {
            Some(first) => first.for_pattern(pattern),
            None => Cholesky::new(pattern),
        }
    }

    fn solver_error(&self, method: &'static str, message: impl Into<String>) -> ParamError {
        ParamError::Solver {
            method,
            message: message.into(),
            faces: self.nfaces,
            face: self.first.0,
            line: self.first.1,
        }
    }
}

/// The chart of `faces`, checked (see the module doc's "Refused"): its local vertices and
/// triangles, its edges, one component, one boundary loop and a disk's Euler characteristic.
fn build_chart(mesh: &Mesh, faces: &[usize]) -> Result<Chart, ParamError> {
    if faces.is_empty() {
        return Err(ParamError::Empty);
    }
    let line = |f: usize| mesh.faces[f].line;
    let lt = local_triangles(mesh, faces)?;
    let edge_uses = edge_uses(mesh, &lt)?;
    check_components(mesh, &lt, &edge_uses)?;
    let nv = lt.pos.len();
    let mut loops = boundary_loops(mesh, faces, &lt, &edge_uses)?;
    let LocalTriangles {
        pos, tris, corners, ..
    } = lt;
    let euler = nv as i64 - edge_uses.len() as i64 + tris.len() as i64;
    if euler != 1 {
        let f = faces[0];
        return Err(ParamError::Handles {
            euler,
            face: f,
            line: line(f),
        });
    }
    let mut boundary = vec![false; nv];
    for &v in &loops[0] {
        boundary[v] = true;
    }
    Ok(Chart {
        pos,
        tris,
        corners,
        boundary,
        boundary_loop: loops.swap_remove(0),
        first: (faces[0], line(faces[0])),
        nfaces: faces.len(),
        vertex_symbolic: OnceLock::new(),
    })
}

/// Per edge over the triangles: its uses as (triangle, directed a -> b).
type EdgeUses = Vec<Vec<(usize, usize, usize)>>;

/// A chart's faces over local vertices, before its topology is checked.
struct LocalTriangles {
    /// Local vertex → 3D position.
    pos: Vec<DVec3>,
    /// Triangles over local vertices (face winding).
    tris: Vec<[usize; 3]>,
    /// Chart face of each triangle.
    tri_face: Vec<usize>,
    /// Per chart face: local vertex of each corner.
    corners: Vec<Vec<usize>>,
    /// Local vertex → mesh vertex.
    global: Vec<usize>,
}

/// Local vertices (by first appearance in `faces` order) and the faces' triangles over them;
/// refuses a face out of range or repeated, a vertex out of range or not finite, and a
/// triangle with an angle below [`MIN_ANGLE`].
fn local_triangles(mesh: &Mesh, faces: &[usize]) -> Result<LocalTriangles, ParamError> {
    let line = |f: usize| mesh.faces[f].line;
    let mut seen: HashMap<usize, usize> = HashMap::with_capacity(faces.len());
    let mut local: HashMap<usize, usize> = HashMap::new();
    let mut pos: Vec<DVec3> = Vec::new();
    let mut tris: Vec<[usize; 3]> = Vec::new();
    let mut tri_face: Vec<usize> = Vec::new();
    let mut corners: Vec<Vec<usize>> = Vec::with_capacity(faces.len());
    for (k, &f) in faces.iter().enumerate() {
        if f >= mesh.faces.len() {
            return Err(ParamError::FaceOutOfRange {
                face: f,
                count: mesh.faces.len(),
            });
        }
        if seen.insert(f, k).is_some() {
            return Err(ParamError::DuplicateFace {
                face: f,
                line: line(f),
            });
        }
        let face = &mesh.faces[f];
        let mut cs = Vec::with_capacity(face.verts.len());
        for &v in &face.verts {
            let p = mesh.vertices.get(v).copied().unwrap_or(DVec3::NAN);
            if !p.is_finite() {
                return Err(ParamError::BadVertex {
                    face: f,
                    line: line(f),
                    vertex: v,
                });
            }
            let id = *local.entry(v).or_insert_with(|| {
                pos.push(p);
                pos.len() - 1
            });
            cs.push(id);
        }
        let tri_list = face_triangles(mesh, f);
        if tri_list.is_empty() {
            return Err(ParamError::Degenerate {
                face: f,
                line: line(f),
                angle: 0.0,
            });
        }
        for t in tri_list.iter() {
            let lt = t.map(|i| cs[i]);
            let p = lt.map(|i| pos[i]);
            let mut min = f64::INFINITY;
            for c in 0..3 {
                min = min.min(corner_angle(p[c], p[(c + 1) % 3], p[(c + 2) % 3]));
            }
            if lt[0] == lt[1] || lt[1] == lt[2] || lt[0] == lt[2] || min.is_nan() || min < MIN_ANGLE
            {
                return Err(ParamError::Degenerate {
                    face: f,
                    line: line(f),
                    angle: if min.is_nan() { 0.0 } else { min },
                });
            }
            tris.push(lt);
            tri_face.push(f);
        }
        corners.push(cs);
    }
    let global: Vec<usize> = {
        let mut g = vec![0; pos.len()];
        for (&v, &l) in &local {
            g[l] = v;
        }
        g
    };

    Ok(LocalTriangles {
        pos,
        tris,
        tri_face,
        corners,
        global,
    })
}

/// Edges over the triangles, each with its uses as (triangle, directed a -> b), in order of
/// first use; refuses an edge used by more than two triangles.
fn edge_uses(mesh: &Mesh, lt: &LocalTriangles) -> Result<EdgeUses, ParamError> {
    let line = |f: usize| mesh.faces[f].line;
    let (tris, tri_face, global) = (&lt.tris, &lt.tri_face, &lt.global);
    let mut edge_index: HashMap<(usize, usize), usize> = HashMap::with_capacity(tris.len() * 2);
    let mut edge_uses: Vec<Vec<(usize, usize, usize)>> = Vec::new();
    for (t, tri) in tris.iter().enumerate() {
        for c in 0..3 {
            let (a, b) = (tri[c], tri[(c + 1) % 3]);
            let id = *edge_index.entry((a.min(b), a.max(b))).or_insert_with(|| {
                edge_uses.push(Vec::new());
                edge_uses.len() - 1
            });
            let uses = &mut edge_uses[id];
            uses.push((t, a, b));
            if uses.len() > 2 {
                let f = tri_face[t];
                return Err(ParamError::NonManifoldEdge {
                    face: f,
                    line: line(f),
                    a: global[a],
                    b: global[b],
                    count: uses.len(),
                });
            }
        }
    }
    Ok(edge_uses)
}

/// Refuses two faces wound against each other and several connected components (union-find
/// over triangles sharing an edge).
fn check_components(
    mesh: &Mesh,
    lt: &LocalTriangles,
    edge_uses: &[Vec<(usize, usize, usize)>],
) -> Result<(), ParamError> {
    let line = |f: usize| mesh.faces[f].line;
    let (tris, tri_face, global) = (&lt.tris, &lt.tri_face, &lt.global);
    let mut sets = UnionFind::new(tris.len());
    for uses in edge_uses {
        if let [(t, a, b), (u, a2, _)] = uses[..] {
            if a == a2 {
                let f = tri_face[u];
                return Err(ParamError::Inconsistent {
                    face: f,
                    line: line(f),
                    a: global[a],
                    b: global[b],
                });
            }
            sets.union(t, u);
        }
    }
    let root0 = sets.find(0);
    let mut roots = Vec::new();
    let mut other = None;
    for t in 0..tris.len() {
        let r = sets.find(t);
        if r == t {
            roots.push(r);
        }
        if r != root0 && other.is_none() {
            other = Some(t);
        }
    }
    if let Some(t) = other {
        let f = tri_face[t];
        return Err(ParamError::SeveralComponents {
            count: roots.len(),
            face: f,
            line: line(f),
        });
    }
    Ok(())
}

/// The boundary loops (local vertices in loop order): directed edges used once, one out- and
/// one in-edge per boundary vertex; refuses a vertex where two boundary fans meet, a closed
/// chart and several loops (holes).
fn boundary_loops(
    mesh: &Mesh,
    faces: &[usize],
    lt: &LocalTriangles,
    edge_uses: &[Vec<(usize, usize, usize)>],
) -> Result<Vec<Vec<usize>>, ParamError> {
    let line = |f: usize| mesh.faces[f].line;
    let (tri_face, global) = (&lt.tri_face, &lt.global);
    let nv = lt.pos.len();
    let mut next: Vec<Option<usize>> = vec![None; nv];
    let mut has_in = vec![false; nv];
    let mut boundary_face: Vec<usize> = vec![0; nv];
    let mut nb = 0usize;
    for uses in edge_uses {
        if let [(t, a, b)] = uses[..] {
            let f = tri_face[t];
            if next[a].is_some() || has_in[b] {
                let v = if next[a].is_some() { a } else { b };
                return Err(ParamError::NonManifoldVertex {
                    face: f,
                    line: line(f),
                    vertex: global[v],
                });
            }
            next[a] = Some(b);
            has_in[b] = true;
            boundary_face[a] = f;
            nb += 1;
        }
    }
    if nb == 0 {
        let f = faces[0];
        return Err(ParamError::Closed {
            face: f,
            line: line(f),
        });
    }
    let mut visited = vec![false; nv];
    let mut loops: Vec<Vec<usize>> = Vec::new();
    for s in 0..nv {
        if next[s].is_none() || visited[s] {
            continue;
        }
        let mut lp = Vec::new();
        let mut cur = s;
        while !visited[cur] {
            visited[cur] = true;
            lp.push(cur);
            match next[cur] {
                Some(n) => cur = n,
                None => break,
            }
        }
        loops.push(lp);
    }
    if loops.len() > 1 {
        // Name a face on the second loop (the first is usually the outer one).
        let f = boundary_face[loops[1][0]];
        return Err(ParamError::Holes {
            loops: loops.len(),
            face: f,
            line: line(f),
        });
    }
    Ok(loops)
}

/// The two pinned vertices (local ids): the farthest pair of boundary vertices (see the module
/// doc for the rule).
fn pins(chart: &Chart) -> [usize; 2] {
    let b = &chart.boundary_loop;
    let p = &chart.pos;
    let farthest = |from: usize| -> usize {
        let mut best = (f64::NEG_INFINITY, from);
        for &v in b {
            let d = p[v].distance_squared(p[from]);
            if d > best.0 || (d == best.0 && v < best.1) {
                best = (d, v);
            }
        }
        best.1
    };
    if b.len() <= EXACT_PIN_LIMIT {
        let mut sorted = b.clone();
        sorted.sort_unstable();
        let mut best = (f64::NEG_INFINITY, sorted[0], sorted[0]);
        for (i, &u) in sorted.iter().enumerate() {
            for &v in &sorted[i + 1..] {
                let d = p[u].distance_squared(p[v]);
                if d > best.0 {
                    best = (d, u, v);
                }
            }
        }
        [best.1, best.2]
    } else {
        let start = *b.iter().min().unwrap_or(&0);
        let a = farthest(start);
        let c = farthest(a);
        [a.min(c), a.max(c)]
    }
}

/// Shape of each triangle in its own plane: corner 0 at the origin, corner 1 on +x.
fn shapes_from_3d(chart: &Chart) -> Vec<[DVec2; 3]> {
    chart
        .tris
        .iter()
        .map(|t| {
            let (a, b, c) = (chart.pos[t[0]], chart.pos[t[1]], chart.pos[t[2]]);
            let e1 = b - a;
            let e2 = c - a;
            let l1 = e1.length();
            let x = e1 / l1;
            let cx = e2.dot(x);
            let cy = x.cross(e2).length();
            [DVec2::ZERO, DVec2::new(l1, 0.0), DVec2::new(cx, cy)]
        })
        .collect()
}

/// Shape of a triangle from its angles (law of sines), unit-free.
fn shape_from_angles(a: [f64; 3]) -> [DVec2; 3] {
    [
        DVec2::ZERO,
        DVec2::new(a[2].sin(), 0.0),
        DVec2::new(a[0].cos(), a[0].sin()) * a[1].sin(),
    ]
}

/// LSCM with the given triangle shapes and two pins; returns a position per local vertex.
fn lscm_solve(
    chart: &Chart,
    method: &'static str,
    shapes: &[[DVec2; 3]],
    pin: [usize; 2],
    pin_pos: [DVec2; 2],
    solver: &mut Option<Solver>,
) -> Result<Vec<DVec2>, ParamError> {
    let nv = chart.pos.len();
    // Free vertex k has unknowns u = 2k, v = 2k + 1.
    let mut var: Vec<Option<usize>> = vec![None; nv];
    let mut k = 0;
    for (v, slot) in var.iter_mut().enumerate() {
        if v != pin[0] && v != pin[1] {
            *slot = Some(k);
            k += 1;
        }
    }
    let n = 2 * k;
    let fixed = |v: usize| -> DVec2 {
        if v == pin[0] {
            pin_pos[0]
        } else {
            pin_pos[1]
        }
    };
    let mut triplets: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(chart.tris.len() * 21);
    let mut rhs = vec![0.0; n];
    for (t, tri) in chart.tris.iter().enumerate() {
        let s = shapes[t];
        let d = (s[1] - s[0]).perp_dot(s[2] - s[0]);
        if !(d > 0.0 && d.is_finite()) {
            return Err(chart.solver_error(method, "a triangle shape has no area"));
        }
        let w = 1.0 / d.sqrt();
        // Rows (real, imaginary) over the 6 unknowns (u_j, v_j): entries (var or pinned value).
        let mut rows = [[0.0f64; 6]; 2];
        for j in 0..3 {
            let wj = (s[(j + 2) % 3] - s[(j + 1) % 3]) * w;
            rows[0][2 * j] = wj.x;
            rows[0][2 * j + 1] = -wj.y;
            rows[1][2 * j] = wj.y;
            rows[1][2 * j + 1] = wj.x;
        }
        // Local 6x6 block of AᵀA over free unknowns and the pinned part of each row.
        let idx: [Option<usize>; 6] =
            std::array::from_fn(|i| var[tri[i / 2]].map(|kk| 2 * kk + i % 2));
        for row in &rows {
            let mut pinned = 0.0;
            for j in 0..3 {
                if var[tri[j]].is_none() {
                    let p = fixed(tri[j]);
                    pinned += row[2 * j] * p.x + row[2 * j + 1] * p.y;
                }
            }
            for i in 0..6 {
                let Some(ri) = idx[i] else { continue };
                rhs[ri] -= row[i] * pinned;
            }
        }
        for i in 0..6 {
            let Some(ri) = idx[i] else { continue };
            for j in 0..6 {
                let Some(cj) = idx[j] else { continue };
                if ri >= cj {
                    let v = rows[0][i] * rows[0][j] + rows[1][i] * rows[1][j];
                    if v != 0.0 {
                        triplets.push(Triplet::new(ri, cj, v));
                    }
                }
            }
        }
    }
    let x = spd_solve(chart, method, n, &triplets, &rhs, solver, 2)?;
    Ok((0..nv)
        .map(|v| match var[v] {
            Some(kk) => DVec2::new(x[2 * kk], x[2 * kk + 1]),
            None => fixed(v),
        })
        .collect())
}

/// Scale to the 3D area, make counter-clockwise, move to the origin; per chart face corners.
fn finish(
    mesh: &Mesh,
    faces: &[usize],
    chart: &Chart,
    method: ParamMethod,
    mut uv: Vec<DVec2>,
) -> ChartParam {
    let mut a2 = 0.0;
    let mut a3 = 0.0;
    for t in &chart.tris {
        let p = t.map(|v| uv[v]);
        a2 += 0.5 * (p[1] - p[0]).perp_dot(p[2] - p[0]);
        let q = t.map(|v| chart.pos[v]);
        a3 += 0.5 * (q[1] - q[0]).cross(q[2] - q[0]).length();
    }
    if a2 < 0.0 {
        for p in &mut uv {
            p.x = -p.x;
        }
    }
    let k = if a2 != 0.0 && a2.is_finite() {
        (a3 / a2.abs()).sqrt()
    } else {
        1.0
    };
    let mut lo = DVec2::splat(f64::INFINITY);
    for p in &mut uv {
        *p *= k;
        lo = lo.min(*p);
    }
    for p in &mut uv {
        *p -= lo;
    }
    let face_uv: Vec<Vec<DVec2>> = chart
        .corners
        .iter()
        .map(|cs| cs.iter().map(|&v| uv[v]).collect())
        .collect();
    let stretch = distortion::stretch(mesh, faces, &face_uv);
    ChartParam {
        faces: faces.to_vec(),
        uv: face_uv,
        method,
        stretch,
    }
}

fn run_lscm(
    mesh: &Mesh,
    faces: &[usize],
    chart: &Chart,
    pin: [usize; 2],
    solver: &mut Option<Solver>,
) -> Result<ChartParam, ParamError> {
    let d = chart.pos[pin[0]].distance(chart.pos[pin[1]]);
    let uv = lscm_solve(
        chart,
        "LSCM",
        &shapes_from_3d(chart),
        pin,
        [DVec2::ZERO, DVec2::new(d, 0.0)],
        solver,
    )?;
    Ok(finish(mesh, faces, chart, ParamMethod::Lscm, uv))
}

fn run_abf(
    mesh: &Mesh,
    faces: &[usize],
    chart: &Chart,
    pin: [usize; 2],
    solver: &mut Option<Solver>,
) -> Result<ChartParam, ParamError> {
    abf_from(mesh, faces, chart, pin, abf_angles(chart), solver)
}

/// [`run_abf`] from ABF++'s angles (or their error) already found.
fn abf_from(
    mesh: &Mesh,
    faces: &[usize],
    chart: &Chart,
    pin: [usize; 2],
    angles: Result<Vec<[f64; 3]>, ParamError>,
    solver: &mut Option<Solver>,
) -> Result<ChartParam, ParamError> {
    let angles = angles?;
    let shapes: Vec<[DVec2; 3]> = angles.iter().map(|a| shape_from_angles(*a)).collect();
    let d = chart.pos[pin[0]].distance(chart.pos[pin[1]]);
    let uv = lscm_solve(
        chart,
        "ABF++ (angles to coordinates)",
        &shapes,
        pin,
        [DVec2::ZERO, DVec2::new(d, 0.0)],
        solver,
    )?;
    Ok(finish(mesh, faces, chart, ParamMethod::Abf, uv))
}

/// Flatten one disk-topology chart (mesh face indices) with the given method. See the module
/// doc for what is refused and how `Best` chooses.
pub fn parameterize(
    mesh: &Mesh,
    faces: &[usize],
    method: ParamMethod,
) -> Result<ChartParam, ParamError> {
    let chart = build_chart(mesh, faces)?;
    parameterize_chart(mesh, faces, &chart, method)
}

/// [`parameterize`], then the seams matched ([`match_seams`]) when its L2 stretch is at
/// most `match_below`, on one chart built for both.
pub fn parameterize_matched(
    mesh: &Mesh,
    faces: &[usize],
    method: ParamMethod,
    match_below: f64,
) -> Result<ChartParam, ParamError> {
    let chart = build_chart(mesh, faces)?;
    let p = parameterize_chart(mesh, faces, &chart, method)?;
    Ok(matched(mesh, faces, &chart, p, match_below))
}

/// `p` with its seams matched ([`match_seams`]) when its L2 stretch is at most `match_below`.
fn matched(
    mesh: &Mesh,
    faces: &[usize],
    chart: &Chart,
    p: ChartParam,
    match_below: f64,
) -> ChartParam {
    if p.stretch.l2 <= match_below {
        seams::match_seams_of(mesh, faces, chart, &p)
    } else {
        p
    }
}

/// [`parameterize`] on the chart of `faces` already built.
fn parameterize_chart(
    mesh: &Mesh,
    faces: &[usize],
    chart: &Chart,
    method: ParamMethod,
) -> Result<ChartParam, ParamError> {
    let pin = pins(chart);
    // LSCM's system has one pattern whichever shapes it is given: one ordering for both.
    let mut solver = None;
    match method {
        ParamMethod::Lscm => run_lscm(mesh, faces, chart, pin, &mut solver),
        ParamMethod::Abf => run_abf(mesh, faces, chart, pin, &mut solver),
        ParamMethod::Best => {
            let l = run_lscm(mesh, faces, chart, pin, &mut solver);
            let key = |c: &ChartParam| (c.stretch.flipped, c.stretch.l2);
            let kept = match l {
                // Already isometric: nothing can do better.
                Ok(l) if l.stretch.flipped == 0 && l.stretch.l2 - 1.0 < ISOMETRIC => return Ok(l),
                // Flip-free: the stretch minimisation takes it from there.
                Ok(l) if l.stretch.flipped == 0 => l,
                // Flipped or failed: ABF++'s layout where it is better.
                l => match (l, run_abf(mesh, faces, chart, pin, &mut solver)) {
                    (Ok(l), Ok(a)) => {
                        if key(&a) < key(&l) {
                            a
                        } else {
                            l
                        }
                    }
                    (Ok(l), Err(_)) => l,
                    (Err(_), Ok(a)) => a,
                    (Err(e), Err(_)) => return Err(e),
                },
            };
            let refined = refine(mesh, faces, chart, &kept);
            Ok(if key(&refined) < key(&kept) {
                refined
            } else {
                kept
            })
        }
    }
}

/// Steps of the stretch minimisation that `Best` runs on the kept layout ([`lbfgs`]).
pub(crate) const STRETCH_STEPS: usize = 200;
/// The stretch minimisation stops when a step lowers E by less than this share of it.
pub(crate) const STRETCH_GAIN: f64 = 1e-6;

/// The free-boundary stretch minimisation of a flip-free layout `uv` ([`lbfgs::minimise`];
/// where the chart's Laplacian cannot be factored, the sweeps of [`minimise_stretch`]).
fn minimise_free(chart: &Chart, uv: Vec<DVec2>) -> Option<Vec<DVec2>> {
    match lbfgs::minimise(chart, uv.clone(), STRETCH_STEPS, STRETCH_GAIN) {
        Some(uv) => Some(uv),
        None => minimise_stretch(chart, uv, &vec![false; chart.pos.len()], STRETCH_SWEEPS),
    }
}

/// Sweeps of the vertex-by-vertex minimisation where [`lbfgs`] cannot run.
pub(crate) const STRETCH_SWEEPS: usize = 60;

/// Free-boundary L2 stretch minimisation (Sander et al. 2001 §4, [`stretch`]) from a
/// flip-free layout: it stays flip-free, and its L2 stretch never increases.
fn refine(mesh: &Mesh, faces: &[usize], chart: &Chart, start: &ChartParam) -> ChartParam {
    if start.stretch.flipped > 0 {
        return start.clone();
    }
    let uv = vertex_uv(chart, &start.uv);
    match minimise_free(chart, uv) {
        Some(uv) => finish(mesh, faces, chart, start.method, uv),
        None => start.clone(),
    }
}

/// The chart of `faces` laid out from `start` (a position per face corner, counter-clockwise:
/// a larger chart's layout restricted to these faces, or this chart's own) by the stretch
/// minimisation of [`refine`], without laying it anew: the start is already near the chart's
/// optimum, so the minimisation stops early. `None` when `start` is not a layout of this chart (the corners of one
/// vertex apart, a flipped or collapsed triangle) or the chart is refused; the caller then
/// lays it anew ([`parameterize`]).
pub fn relax_from(
    mesh: &Mesh,
    faces: &[usize],
    method: ParamMethod,
    start: &[Vec<DVec2>],
) -> Option<ChartParam> {
    let chart = build_chart(mesh, faces).ok()?;
    relax_chart(mesh, faces, &chart, method, start)
}

/// [`relax_from`], then the seams matched ([`match_seams`]) when its L2 stretch is at most
/// `match_below`, on one chart built for both.
pub fn relax_from_matched(
    mesh: &Mesh,
    faces: &[usize],
    method: ParamMethod,
    start: &[Vec<DVec2>],
    match_below: f64,
) -> Option<ChartParam> {
    let chart = build_chart(mesh, faces).ok()?;
    let p = relax_chart(mesh, faces, &chart, method, start)?;
    Some(matched(mesh, faces, &chart, p, match_below))
}

/// [`relax_from`] on the chart of `faces` already built.
fn relax_chart(
    mesh: &Mesh,
    faces: &[usize],
    chart: &Chart,
    method: ParamMethod,
    start: &[Vec<DVec2>],
) -> Option<ChartParam> {
    if start.len() != chart.corners.len() {
        return None;
    }
    let mut uv: Vec<Option<DVec2>> = vec![None; chart.pos.len()];
    for (cs, pts) in chart.corners.iter().zip(start) {
        if cs.len() != pts.len() {
            return None;
        }
        for (&v, &p) in cs.iter().zip(pts) {
            match uv[v] {
                Some(q) if q.distance(p) > 1e-9 * (1.0 + q.length()) => return None,
                Some(_) => {}
                _ => uv[v] = Some(p),
            }
        }
    }
    let uv: Vec<DVec2> = uv.into_iter().collect::<Option<_>>()?;
    let uv = minimise_free(chart, uv)?;
    Some(finish(mesh, faces, chart, method, uv))
}

/// A layout per chart face corner as one position per local vertex.
fn vertex_uv(chart: &Chart, face_uv: &[Vec<DVec2>]) -> Vec<DVec2> {
    let mut uv = vec![DVec2::ZERO; chart.pos.len()];
    for (cs, pts) in chart.corners.iter().zip(face_uv) {
        for (&v, &p) in cs.iter().zip(pts) {
            uv[v] = p;
        }
    }
    uv
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::mesh::Face;
    use std::f64::consts::PI;

    /// A 6 x 6 grid lifted into a saddle-and-bump: not developable, every interior vertex has
    /// a non-zero angle defect.
    pub(super) fn bumpy_grid() -> Mesh {
        let n = 6;
        let mut vertices = Vec::new();
        for y in 0..=n {
            for x in 0..=n {
                let (u, v) = (x as f64 / n as f64 - 0.5, y as f64 / n as f64 - 0.5);
                vertices.push(DVec3::new(
                    u,
                    v,
                    0.8 * u * v + 0.3 * (-(u * u + v * v) * 8.0).exp(),
                ));
            }
        }
        let id = |x: usize, y: usize| y * (n + 1) + x;
        let mut faces = Vec::new();
        for y in 0..n {
            for x in 0..n {
                for t in [
                    [id(x, y), id(x + 1, y), id(x + 1, y + 1)],
                    [id(x, y), id(x + 1, y + 1), id(x, y + 1)],
                ] {
                    faces.push(Face {
                        verts: t.to_vec(),
                        line: None,
                    });
                }
            }
        }
        Mesh { vertices, faces }
    }

    #[test]
    fn abf_angles_satisfy_all_three_constraint_families() {
        let m = bumpy_grid();
        let faces: Vec<usize> = (0..m.faces.len()).collect();
        let chart = build_chart(&m, &faces).expect("chart");
        let alpha = abf_angles(&chart).expect("abf");
        let nv = chart.pos.len();
        let mut sum = vec![0.0; nv];
        let mut wheel = vec![0.0; nv];
        for (t, tri) in chart.tris.iter().enumerate() {
            let a = alpha[t];
            assert!(
                (a[0] + a[1] + a[2] - PI).abs() < 1e-9,
                "triangle {t}: {a:?}"
            );
            for c in 0..3 {
                assert!(a[c] > 0.0 && a[c] < PI);
                sum[tri[c]] += a[c];
                wheel[tri[c]] += a[(c + 1) % 3].sin().ln() - a[(c + 2) % 3].sin().ln();
            }
        }
        let mut interior = 0;
        for v in 0..nv {
            if !chart.boundary[v] {
                interior += 1;
                assert!((sum[v] - 2.0 * PI).abs() < 1e-9, "vertex {v}: {}", sum[v]);
                assert!(wheel[v].abs() < 1e-9, "vertex {v}: wheel {}", wheel[v]);
            }
        }
        assert_eq!(interior, 25);
        // Angles that satisfy the constraints rebuild a layout whose triangles have exactly
        // those angles (up to round-off): the reconstruction is consistent.
        let p = run_abf(&m, &faces, &chart, pins(&chart), &mut None).expect("layout");
        // One triangle per face, faces in order: triangle t is face t.
        assert_eq!(p.uv.len(), alpha.len());
        for (t, (uv, al)) in p.uv.iter().zip(&alpha).enumerate() {
            for c in 0..3 {
                let (a, b, d) = (uv[c], uv[(c + 1) % 3], uv[(c + 2) % 3]);
                let ang = (b - a).angle_to(d - a);
                assert!((ang - al[c]).abs() < 1e-7, "{t} {c}: {ang} vs {}", al[c]);
            }
        }
    }

    #[test]
    fn pins_are_the_farthest_boundary_pair() {
        let m = bumpy_grid();
        let faces: Vec<usize> = (0..m.faces.len()).collect();
        let chart = build_chart(&m, &faces).expect("chart");
        let [a, b] = pins(&chart);
        let d = chart.pos[a].distance(chart.pos[b]);
        for &u in &chart.boundary_loop {
            for &v in &chart.boundary_loop {
                assert!(chart.pos[u].distance(chart.pos[v]) <= d + 1e-12);
            }
        }
        assert!(chart.boundary[a] && chart.boundary[b]);
    }

    #[test]
    fn best_is_never_worse_than_either_method_and_single_triangles_work() {
        let m = bumpy_grid();
        let faces: Vec<usize> = (0..m.faces.len()).collect();
        let l = parameterize(&m, &faces, ParamMethod::Lscm).expect("lscm");
        let a = parameterize(&m, &faces, ParamMethod::Abf).expect("abf");
        let b = parameterize(&m, &faces, ParamMethod::Best).expect("best");
        assert!(b.stretch.l2 <= l.stretch.l2.min(a.stretch.l2));
        assert_eq!(b.stretch.flipped, 0);
        assert!(b.stretch.l2 > 1.0);
        for method in [ParamMethod::Lscm, ParamMethod::Abf, ParamMethod::Best] {
            let p = parameterize(&m, &[7], method).expect("one triangle");
            assert!((p.stretch.l2 - 1.0).abs() < 1e-12, "{:?}", p.stretch);
        }
    }

    /// A layout resumed from a start: from the chart's own layout its stretch only goes
    /// down; from a larger chart's layout restricted to half its faces (as a split's half
    /// starts), the half comes out flip-free, no more stretched than that start, and within
    /// 1e-3 of the half laid anew; a start that is not a layout of the chart (corners of one
    /// vertex apart, a flipped triangle, a corner missing) is refused.
    #[test]
    fn relaxing_from_a_start_never_raises_stretch_and_refuses_a_start_that_does_not_fit() {
        let m = bumpy_grid();
        let faces: Vec<usize> = (0..m.faces.len()).collect();
        let whole = parameterize(&m, &faces, ParamMethod::Best).expect("whole");
        let again = relax_from(&m, &faces, ParamMethod::Best, &whole.uv).expect("again");
        assert!(again.stretch.l2 <= whole.stretch.l2 + 1e-12);
        assert_eq!(again.stretch.flipped, 0);
        let half: Vec<usize> = (0..faces.len() / 2).collect();
        let start: Vec<Vec<DVec2>> = half.iter().map(|&f| whole.uv[f].clone()).collect();
        let from = distortion::stretch(&m, &half, &start);
        let relaxed = relax_from(&m, &half, ParamMethod::Best, &start).expect("half");
        let anew = parameterize(&m, &half, ParamMethod::Best).expect("half anew");
        assert_eq!(relaxed.stretch.flipped, 0);
        assert!(relaxed.stretch.l2 <= from.l2 + 1e-12);
        assert!(
            (relaxed.stretch.l2 - anew.stretch.l2).abs() < 1e-3,
            "{} vs {}",
            relaxed.stretch.l2,
            anew.stretch.l2
        );
        // Corners of one vertex apart.
        let mut apart = whole.uv.clone();
        apart[0][0] += DVec2::new(0.01, 0.0);
        assert!(relax_from(&m, &faces, ParamMethod::Best, &apart).is_none());
        // A flipped triangle.
        let mut mirrored = whole.uv.clone();
        for c in mirrored[5].iter_mut() {
            c.x = -c.x;
        }
        assert!(relax_from(&m, &[5], ParamMethod::Best, &mirrored[5..6]).is_none());
        // A face without its layout.
        assert!(relax_from(&m, &faces, ParamMethod::Best, &whole.uv[1..]).is_none());
    }
}
