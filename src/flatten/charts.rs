//! Flattening of a segmented smooth surface: every chart of [`Surface::charts`] becomes one
//! island, laid flat by [`super::param::parameterize`] (LSCM / ABF++, scaled so that its 2D
//! area equals its 3D area), and [`flatten`] picks between that and the exact polyhedral
//! [`super::unfold()`] for the CLI.
//!
//! **Cuts inside a chart** ([`Surface::cuts`], thesis §5.2.3): a chart is opened along its cut
//! edges before it is parameterised: [`crate::surface::dcharts::open`] gives one vertex per
//! wedge of faces around each mesh vertex, so the vertices along a seam are split, and the
//! opened chart is laid flat as a mesh of its own. A chart that is still not a disk gets the
//! cuts of [`crate::surface::dcharts::disk_cuts`] (a tube the shortest seam between its rims);
//! cuts a split leaves useless are dropped and found again. A cut edge is never `joined`, so
//! the pattern stage draws it as a cut line with seam marks on both sides, like a seam
//! between two pieces; [`Surface::cuts`] of the result lists the cuts that stayed inside a
//! piece.
//!
//! The [`Flat`] it builds is the one the pattern stage already reads: `face_2d` per face
//! corner, counter-clockwise (a chart laid out mirrored is mirrored back); `joined` for the
//! edges inside a chart (their two copies coincide, the layout being per opened vertex);
//! `dihedral` the signed bend of every interior edge, as [`super::unfold()`] computes it.
//!
//! After the thesis' §5.3 ("overlaps cut away", "darts shortened", "a piece over the
//! material's tolerance"), a chart
//! - whose layout overlaps itself deeper than the unfolder's tolerance (a global overlap, or a
//!   gusset folding over) is split between the two overlapping faces
//!   ([`crate::surface::dcharts::split_between`]: each face goes with the nearer of the two,
//!   through the chart), so the overlapping parts end up in different pieces; a chart that
//!   needed seams to be a disk (a tube whose layout spirals over itself) is halved along
//!   the bisector instead;
//! - whose L2 stretch is over [`FlattenOptions::tolerance`] first gets darts (`darts` below: up
//!   to [`FlattenOptions::darts`] partial cuts from its boundary toward its most curved
//!   region, then shortened while it stays within the tolerance);
//!
//! and is split along the bisector of its two most distant faces
//! ([`crate::surface::dcharts::bisect`]) when
//! - it has a flipped triangle,
//! - the parameteriser refuses it (no cut makes it a disk),
//! - or its L2 stretch is still over the tolerance — at most [`FlattenOptions::max_splits`]
//!   times per chart (its darts dropped, each half gets its own); what is still over it then
//!   is reported (a warning on the surface, and the stretch of every piece in `report.json`).
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
use crate::geom::mesh::{Face, Mesh, Topology};
use crate::geom::polygon;
use crate::spec::MaterialKind;
use crate::surface::dcharts::{self, bisect, disk_cuts, open, split_between, Graph};
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
    /// Most darts cut into a chart over the tolerance before it is split (see the module doc); 0
    /// for none.
    pub darts: usize,
}

impl Default for FlattenOptions {
    fn default() -> Self {
        FlattenOptions {
            unfold: UnfoldOptions::default(),
            method: ParamMethod::default(),
            tolerance: material_tolerance(MaterialKind::Paper),
            max_splits: 3,
            darts: 4,
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
    /// Edges cut open inside the chart (topology ids, sorted).
    cuts: Vec<usize>,
    uv: Vec<Vec<DVec2>>,
    stretch: Stretch,
}

/// A chart waiting to be laid flat.
struct Todo {
    faces: Vec<usize>,
    /// Times split for stretch.
    splits: usize,
    /// Edges cut open inside it (sorted), inherited from the surface or a larger chart.
    cuts: Vec<usize>,
}

/// What [`Charts::lay`] made of a chart.
enum Layout {
    Laid(Vec<Vec<DVec2>>, Stretch),
    /// The parameteriser refused it (not a disk, solver failure) or gave non-finite points.
    Refused,
}

/// The mesh and what every chart needs.
struct Charts<'a> {
    mesh: &'a Mesh,
    topo: &'a Topology,
    graph: &'a Graph,
    method: ParamMethod,
}

impl Charts<'_> {
    /// The chart's faces opened along `cuts` and laid flat: the opened chart becomes a mesh of
    /// its own (vertices split along the cuts), parameterised, then turned counter-clockwise.
    fn lay(&self, faces: &[usize], cuts: &[usize]) -> Result<Layout, param::ParamError> {
        let op = open(self.mesh, self.topo, faces, &|e| {
            cuts.binary_search(&e).is_ok()
        });
        let local = Mesh {
            vertices: op.vertex.iter().map(|&v| self.mesh.vertices[v]).collect(),
            faces: faces
                .iter()
                .zip(op.corners)
                .map(|(&f, verts)| Face {
                    verts,
                    line: self.mesh.faces[f].line,
                })
                .collect(),
        };
        let ids: Vec<usize> = (0..faces.len()).collect();
        let p = match param::parameterize(&local, &ids, self.method) {
            Ok(p) => p,
            // A sliver triangle cannot be laid flat in any chart: say which (mesh numbering).
            Err(param::ParamError::Degenerate { face, line, angle }) => {
                return Err(param::ParamError::Degenerate {
                    face: faces.get(face).copied().unwrap_or(face),
                    line,
                    angle,
                })
            }
            Err(_) => return Ok(Layout::Refused),
        };
        let mut uv = p.uv;
        if uv.iter().any(|c| c.iter().any(|q| !q.is_finite())) {
            return Ok(Layout::Refused);
        }
        // Counter-clockwise, as the pattern stage expects.
        let total: f64 = uv.iter().map(|c| polygon::signed_area(c)).sum();
        let stretch = if total < 0.0 {
            for c in uv.iter_mut() {
                for q in c.iter_mut() {
                    q.x = -q.x;
                }
            }
            distortion::stretch(&local, &ids, &uv)
        } else {
            p.stretch
        };
        Ok(Layout::Laid(uv, stretch))
    }

    /// Cuts that make the chart a disk: `cuts` when they do, else `cuts` with more
    /// ([`disk_cuts`]), else new ones from scratch; `None` when the chart must be split.
    fn disk(&self, faces: &[usize], cuts: &[usize]) -> Option<Vec<usize>> {
        let has = |e: usize| cuts.binary_search(&e).is_ok();
        if let Some(more) = disk_cuts(self.mesh, self.topo, self.graph, faces, &has) {
            let mut all = cuts.to_vec();
            all.extend(more);
            all.sort_unstable();
            all.dedup();
            return Some(all);
        }
        if cuts.is_empty() {
            return None;
        }
        disk_cuts(self.mesh, self.topo, self.graph, faces, &|_| false)
    }

    /// The edges of `cuts` inside `faces` (both faces of the edge in it).
    fn cuts_within(&self, faces: &[usize], cuts: &[usize]) -> Vec<usize> {
        if cuts.is_empty() {
            return Vec::new();
        }
        let mut inside = vec![false; self.mesh.faces.len()];
        for &f in faces {
            inside[f] = true;
        }
        cuts.iter()
            .copied()
            .filter(|&e| self.topo.edges[e].uses.iter().all(|u| inside[u.0]))
            .collect()
    }
}

/// Lay each chart flat as one island (cutting and splitting where needed, see the module
/// doc).
pub fn charts(mut surface: Surface, opts: &FlattenOptions) -> Result<Flat, FlattenError> {
    let mesh = &surface.mesh;
    let nf = mesh.faces.len();
    let chart_of = match &surface.charts {
        Some(c) if c.len() == nf => c.clone(),
        _ => vec![0; nf],
    };
    let topology = mesh.topology();
    let graph = Graph::new(mesh, &topology);
    let ctx = Charts {
        mesh,
        topo: &topology,
        graph: &graph,
        method: opts.method,
    };
    // The surface's cuts as edge ids (pairs that are not edges of the mesh are ignored).
    let mut edge_of: std::collections::HashMap<[usize; 2], usize> = Default::default();
    for (e, edge) in topology.edges.iter().enumerate() {
        let [a, b] = edge.verts;
        edge_of.insert([a.min(b), a.max(b)], e);
    }
    let mut surface_cuts: Vec<usize> = surface
        .cuts
        .iter()
        .filter_map(|&[a, b]| edge_of.get(&[a.min(b), a.max(b)]).copied())
        .collect();
    surface_cuts.sort_unstable();
    surface_cuts.dedup();
    let count = chart_of.iter().copied().max().map_or(0, |m| m + 1);
    let mut groups: Vec<Vec<usize>> = vec![Vec::new(); count];
    for (f, &c) in chart_of.iter().enumerate() {
        groups[c].push(f);
    }
    let mut todo: Vec<Todo> = groups
        .into_iter()
        .filter(|g| !g.is_empty())
        .map(|faces| Todo {
            cuts: ctx.cuts_within(&faces, &surface_cuts),
            faces,
            splits: 0,
        })
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
    let lay = |faces: &[usize], cuts: &[usize]| -> Result<Layout, FlattenError> {
        ctx.lay(faces, cuts).map_err(|e| match e {
            param::ParamError::Degenerate { face, .. } => degenerate(face.min(nf - 1)),
            _ => degenerate(faces[0]),
        })
    };
    // Push the two halves of a chart (cuts kept where they fall inside a half).
    let push_halves = |todo: &mut Vec<Todo>, a: Vec<usize>, b: Vec<usize>, t: &Todo, splits| {
        let (ca, cb) = (ctx.cuts_within(&a, &t.cuts), ctx.cuts_within(&b, &t.cuts));
        todo.push(Todo {
            faces: b,
            splits,
            cuts: cb,
        });
        todo.push(Todo {
            faces: a,
            splits,
            cuts: ca,
        });
    };
    let split_it = |todo: &mut Vec<Todo>, t: &Todo, splits: usize| {
        let (a, b) = bisect(&graph, &t.faces);
        if a.is_empty() || b.is_empty() {
            return false;
        }
        push_halves(todo, a, b, t, splits);
        true
    };
    while let Some(mut t) = todo.pop() {
        let Some(cuts) = ctx.disk(&t.faces, &t.cuts) else {
            if t.faces.len() == 1 || !split_it(&mut todo, &t, t.splits) {
                return Err(degenerate(t.faces[0]));
            }
            continue;
        };
        t.cuts = cuts;
        let (uv, stretch) = match lay(&t.faces, &t.cuts)? {
            Layout::Laid(uv, s) => (uv, s),
            Layout::Refused => {
                if t.faces.len() == 1 || !split_it(&mut todo, &t, t.splits) {
                    return Err(degenerate(t.faces[0]));
                }
                continue;
            }
        };
        if t.faces.len() > 1 {
            // Overlapping parts go to different pieces: split between the two faces.
            if let Some((x, y)) = self_overlap(&uv, overlap_eps) {
                // A chart cut open into a disk (a tube) is halved instead, as a whole.
                if !t.cuts.is_empty() && split_it(&mut todo, &t, t.splits) {
                    continue;
                }
                let (a, b) = split_between(&graph, &t.faces, t.faces[x], t.faces[y]);
                if !a.is_empty() && !b.is_empty() {
                    push_halves(&mut todo, a, b, &t, t.splits);
                    continue;
                }
            }
            if stretch.flipped > 0 && split_it(&mut todo, &t, t.splits) {
                continue;
            }
        }
        let inherited = t.cuts.clone();
        let mut laid = Laid {
            faces: t.faces,
            cuts: t.cuts,
            uv,
            stretch,
        };
        if laid.stretch.l2 > opts.tolerance && opts.darts > 0 && laid.faces.len() >= DART_MIN_FACES
        {
            darts(&ctx, &mut laid, opts, overlap_eps)?;
        }
        if laid.stretch.l2 > opts.tolerance && t.splits < opts.max_splits && laid.faces.len() >= 8 {
            // Darts are dropped: each half gets its own.
            let t = Todo {
                faces: laid.faces,
                splits: t.splits,
                cuts: inherited,
            };
            if split_it(&mut todo, &t, t.splits + 1) {
                continue;
            }
            laid.faces = t.faces;
        }
        done.push(laid);
    }

    // Islands numbered by smallest face.
    done.sort_by_key(|l| l.faces.iter().copied().min().unwrap_or(0));
    let mut face_2d: Vec<Vec<DVec2>> = vec![Vec::new(); nf];
    let mut face_island = vec![0; nf];
    let mut islands = Vec::with_capacity(done.len());
    let ne = topology.edges.len();
    let mut is_cut = vec![false; ne];
    for (k, l) in done.iter().enumerate() {
        if l.stretch.l2 > opts.tolerance {
            over.push((k, l.stretch.l2));
        }
        for (f, c) in l.faces.iter().zip(&l.uv) {
            face_2d[*f] = c.clone();
            face_island[*f] = k;
        }
        for &e in &l.cuts {
            is_cut[e] = true;
        }
        let mut faces = l.faces.clone();
        faces.sort_unstable();
        islands.push(faces);
    }
    let mut joined = vec![false; ne];
    let mut dihedral = vec![0.0; ne];
    let mut lengths = 0.0;
    for (e, edge) in topology.edges.iter().enumerate() {
        lengths += mesh.vertices[edge.verts[0]].distance(mesh.vertices[edge.verts[1]]);
        let [(f, i), (g, j)] = edge.uses[..] else {
            continue;
        };
        dihedral[e] = bend(mesh, f, i, g);
        if face_island[f] == face_island[g] && !is_cut[e] {
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
    let mut cuts: Vec<[usize; 2]> = (0..ne)
        .filter(|&e| is_cut[e])
        .map(|e| {
            let [a, b] = topology.edges[e].verts;
            [a.min(b), a.max(b)]
        })
        .collect();
    cuts.sort_unstable();
    surface.cuts = cuts;
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

/// Charts with fewer faces get no darts (they are split or reported as they are).
pub const DART_MIN_FACES: usize = 24;

/// Darts (thesis §5.2.3, "partial cuts ... from the boundaries toward the regions with high
/// fitting error"; McCartney et al.): while the chart's L2 stretch is over the tolerance, at
/// most [`FlattenOptions::darts`] times, a cut is made from the chart's boundary to the tip
/// where the surface is most curved, and kept when the chart lays flat with a lower L2, no
/// flip and no overlap (a cut that would overlap is a gusset; none are made). Then (§5.3,
/// "shortening darts") each dart, once the chart is within the tolerance, is shortened from its
/// tip to the fewest edges that keep it there (bisection on the number of edges kept).
///
/// The tip: "error" is the angle defect (discrete Gaussian curvature), which is what a dart
/// relieves: a cut opens by the total curvature it encloses. The positive defect of every
/// vertex inside the chart is smoothed over the chart's vertex graph (10 rounds of averaging
/// with the neighbours; boundary and cut vertices count 0, so the peak keeps away from them),
/// and the tip is its largest value among inner vertices farther from every earlier dart's tip
/// than that dart is long (a seam relieves a disc of its own length around its tip). The path:
/// the shortest from the chart's boundary (cuts included) to the tip, bent edges counting
/// shorter (as the seams of [`disk_cuts`]).
fn darts(
    ctx: &Charts,
    laid: &mut Laid,
    opts: &FlattenOptions,
    eps: f64,
) -> Result<(), FlattenError> {
    let mesh = ctx.mesh;
    let topo = ctx.topo;
    let try_lay = |cuts: &[usize]| -> Option<(Vec<Vec<DVec2>>, Stretch)> {
        match ctx.lay(&laid.faces, cuts) {
            Ok(Layout::Laid(uv, s)) if s.flipped == 0 && self_overlap(&uv, eps).is_none() => {
                Some((uv, s))
            }
            _ => None,
        }
    };
    let mut made: Vec<Vec<usize>> = Vec::new(); // each dart's edges, tip first
    let mut tips: Vec<(usize, f64)> = Vec::new();
    for _ in 0..opts.darts {
        if laid.stretch.l2 <= opts.tolerance {
            break;
        }
        let Some((tip, path)) = dart_path(ctx, &laid.faces, &laid.cuts, &tips) else {
            break;
        };
        let mut cuts = laid.cuts.clone();
        cuts.extend(&path);
        cuts.sort_unstable();
        cuts.dedup();
        let Some((uv, s)) = try_lay(&cuts) else { break };
        if s.l2 >= laid.stretch.l2 {
            break;
        }
        let len: f64 = path
            .iter()
            .map(|&e| {
                let [a, b] = topo.edges[e].verts;
                mesh.vertices[a].distance(mesh.vertices[b])
            })
            .sum();
        tips.push((tip, len));
        made.push(path);
        laid.cuts = cuts;
        laid.uv = uv;
        laid.stretch = s;
    }
    if laid.stretch.l2 > opts.tolerance {
        return Ok(());
    }
    // Shorten: keep the last `k` edges of each dart (those at the boundary).
    for dart in made.iter_mut() {
        let path = dart.clone();
        let without: Vec<usize> = laid
            .cuts
            .iter()
            .copied()
            .filter(|e| !path.contains(e))
            .collect();
        let with_last = |k: usize| {
            let mut c = without.clone();
            c.extend(&path[path.len() - k..]);
            c.sort_unstable();
            c
        };
        // Smallest k in 1..len with stretch within the tolerance (len edges: known to be).
        let (mut lo, mut hi) = (1, path.len());
        let mut best: Option<(usize, Vec<Vec<DVec2>>, Stretch)> = None;
        while lo < hi {
            let mid = (lo + hi) / 2;
            match try_lay(&with_last(mid)) {
                Some((uv, s)) if s.l2 <= opts.tolerance => {
                    best = Some((mid, uv, s));
                    hi = mid;
                }
                _ => lo = mid + 1,
            }
        }
        if let Some((k, uv, s)) = best.filter(|b| b.0 == hi) {
            laid.cuts = with_last(k);
            laid.uv = uv;
            laid.stretch = s;
            *dart = path[path.len() - k..].to_vec();
        }
    }
    Ok(())
}

/// Where the next dart goes: its tip and its edges, tip first (see [`darts`]).
fn dart_path(
    ctx: &Charts,
    faces: &[usize],
    cuts: &[usize],
    tips: &[(usize, f64)],
) -> Option<(usize, Vec<usize>)> {
    let mesh = ctx.mesh;
    let topo = ctx.topo;
    let has = |e: usize| cuts.binary_search(&e).is_ok();
    let op = open(mesh, topo, faces, &has);
    let nv = mesh.vertices.len();
    // Inner vertices: one local copy and no boundary edge.
    let mut copies = vec![0u32; nv];
    for &v in &op.vertex {
        copies[v] += 1;
    }
    let mut inside = vec![false; mesh.faces.len()];
    for &f in faces {
        inside[f] = true;
    }
    let mut boundary = vec![false; nv];
    let mut defect = vec![0.0; nv];
    let mut in_chart = vec![false; nv];
    for &f in faces {
        let vs = &mesh.faces[f].verts;
        let m = vs.len();
        for (i, &e) in topo.face_edges[f].iter().enumerate() {
            let u = &topo.edges[e].uses;
            let inner = u.len() == 2 && u.iter().all(|x| inside[x.0]) && !has(e);
            if !inner {
                boundary[vs[i]] = true;
                boundary[vs[(i + 1) % m]] = true;
            }
        }
        for c in 0..m {
            let (p, a, b) = (
                mesh.vertices[vs[c]],
                mesh.vertices[vs[(c + m - 1) % m]],
                mesh.vertices[vs[(c + 1) % m]],
            );
            let ang = (a - p).angle_between(b - p);
            if ang.is_finite() {
                defect[vs[c]] += ang;
            }
            in_chart[vs[c]] = true;
        }
    }
    let inner_v = |v: usize| in_chart[v] && !boundary[v] && copies[v] == 1;
    let mut field: Vec<f64> = (0..nv)
        .map(|v| {
            if inner_v(v) {
                (2.0 * std::f64::consts::PI - defect[v]).max(0.0)
            } else {
                0.0
            }
        })
        .collect();
    let mut adj: Vec<Vec<(usize, usize)>> = vec![Vec::new(); nv];
    let mut edges: Vec<usize> = faces
        .iter()
        .flat_map(|&f| topo.face_edges[f].iter().copied())
        .filter(|&e| {
            let u = &topo.edges[e].uses;
            u.len() == 2 && u.iter().all(|x| inside[x.0]) && !has(e)
        })
        .collect();
    edges.sort_unstable();
    edges.dedup();
    for &e in &edges {
        let [a, b] = topo.edges[e].verts;
        adj[a].push((b, e));
        adj[b].push((a, e));
    }
    for _ in 0..10 {
        let next: Vec<f64> = (0..nv)
            .map(|v| {
                if !inner_v(v) {
                    return 0.0;
                }
                let s: f64 = adj[v].iter().map(|&(u, _)| field[u]).sum();
                (field[v] + s) / (1 + adj[v].len()) as f64
            })
            .collect();
        field = next;
    }
    let tip = (0..nv)
        .filter(|&v| inner_v(v) && field[v] > 0.0)
        .filter(|&v| {
            tips.iter()
                .all(|&(t, len)| mesh.vertices[v].distance(mesh.vertices[t]) > len)
        })
        .max_by(|&a, &b| field[a].total_cmp(&field[b]).then(b.cmp(&a)))?;
    // Shortest path from the boundary to the tip.
    let sources: Vec<usize> = (0..nv).filter(|&v| in_chart[v] && boundary[v]).collect();
    let w = |e: usize| dcharts::cut_weight(mesh, topo, ctx.graph, e);
    let path = dcharts::path_to(&adj, &w, &sources, tip, topo)?;
    (!path.is_empty()).then_some((tip, path))
}
