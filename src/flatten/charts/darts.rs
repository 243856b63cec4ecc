//! Darts and gussets (Julius 2006, thesis §5.2.3 "partial cuts from the boundaries toward the
//! regions with high fitting error", last paragraph, and §5.3 "shortening darts", "fixing
//! gussets and overlaps"; McCartney et al.): a chart laid flat over the material's tolerance is
//! relieved by slits from its boundary. Where the surface has positive angle defect a slit
//! opens (a dart, [`darts`]), shortened afterwards to the fewest edges that keep the chart
//! within the tolerance; where it has negative defect (a saddle) the slit's sides overlap, and
//! the overlapping region is cut off as a gusset sewn into the gap ([`gussets`]).
//!
//! Choices where the thesis is silent: the "error" a dart relieves is the angle defect
//! (discrete Gaussian curvature), smoothed over the chart's vertex graph; the tip keeps away
//! from earlier darts by their length; the path is the shortest from the chart's boundary,
//! bent edges counting shorter (as the seams of [`crate::geom::cut::disk_cuts`]).

use super::overlap::{cut_off, overlaps, self_overlap, OVERLAP_PAIRS};
use super::{Charts, FlattenOptions, Laid, Layout, Whole};
use crate::flatten::distortion::{self, Stretch};
use crate::flatten::FlattenError;
use crate::geom::cut::{self, open};
use crate::geom::mesh::Topology;
use glam::DVec2;

/// Charts with fewer faces get no darts (they are split or reported as they are).
pub(super) const DART_MIN_FACES: usize = 24;

/// A chart that can still be halved gets gussets only when its L2 excess (L2 − 1) is at most
/// this many times the tolerance's ([`gussets`]).
pub(super) const GUSSET_REACH: f64 = 1.5;

/// Darts (thesis §5.2.3, "partial cuts ... from the boundaries toward the regions with high
/// fitting error"; McCartney et al.): while the chart's L2 stretch is over the tolerance, at
/// most [`FlattenOptions::darts`] times, a cut is made from the chart's boundary to the tip
/// where the surface is most curved, and kept when the chart lays flat with a lower L2, no
/// flip and no overlap (a cut that would overlap is a gusset: [`gussets`]). Then (§5.3,
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
/// shorter (as the seams of [`crate::geom::cut::disk_cuts`]).
///
/// A trial starts from the chart as it lies, the dart still closed, and the stretch minimiser
/// opens it: one relaxation, where laying the chart anew costs the conformal map and the
/// whole minimisation. A trial within the tolerance has its seams matched and the chart over
/// it has not; matching costs stretch that grows with the boundary, so such a trial that is
/// not lower is compared again with both laid without matching. Shortening lays each trial
/// anew: a shorter dart joins corners that lie apart.
pub(super) fn darts(
    ctx: &Charts,
    laid: &mut Laid,
    opts: &FlattenOptions,
    eps: f64,
) -> Result<(), FlattenError> {
    let mesh = ctx.mesh;
    let topo = ctx.topo;
    let try_lay = |cuts: &[usize], from: Option<&Whole>| -> Option<(Vec<Vec<DVec2>>, Stretch)> {
        match ctx.lay_from(&laid.faces, cuts, from) {
            Ok(Layout::Laid(uv, s)) if s.flipped == 0 && self_overlap(&uv, eps).is_none() => {
                Some((uv, s))
            }
            _ => None,
        }
    };
    // Whether the chart opened along `cuts` lies with less stretch than along `was`, both
    // laid from `from` without their seams matched.
    let free = Charts {
        match_below: 0.0,
        ..*ctx
    };
    let relieves = |was: &[usize], cuts: &[usize], from: &Whole| {
        let l2 = |c: &[usize]| match free.lay_from(&laid.faces, c, Some(from)) {
            Ok(Layout::Laid(_, s)) if s.flipped == 0 => Some(s.l2),
            _ => None,
        };
        matches!((l2(cuts), l2(was)), (Some(a), Some(b)) if a < b)
    };
    let mut made: Vec<Vec<usize>> = Vec::new(); // each dart's edges, tip first
    let mut tips: Vec<(usize, f64)> = Vec::new();
    for _ in 0..opts.darts {
        if laid.stretch.l2 <= opts.tolerance {
            break;
        }
        let Some((tip, path)) = dart_path(ctx, &laid.faces, &laid.cuts, &tips, 1.0) else {
            break;
        };
        let mut cuts = laid.cuts.clone();
        cuts.extend(&path);
        cuts.sort_unstable();
        cuts.dedup();
        // From the chart as it lies, the dart closed: the minimiser opens it.
        let from = Whole::new(&laid.faces, &laid.uv);
        let trial = try_lay(&cuts, Some(&from));
        let len: f64 = path
            .iter()
            .map(|&e| {
                let [a, b] = topo.edges[e].verts;
                mesh.vertices[a].distance(mesh.vertices[b])
            })
            .sum();
        let Some((uv, s)) = trial else { break };
        if s.l2 >= laid.stretch.l2 && !relieves(&laid.cuts, &cuts, &from) {
            break;
        }
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
            match try_lay(&with_last(mid), None) {
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

/// Where the next dart goes: its tip and its edges, tip first (see [`darts`]). `sign` 1 looks
/// for positive angle defect (a dart, which opens), −1 for negative (a gusset, whose slit
/// overlaps).
fn dart_path(
    ctx: &Charts,
    faces: &[usize],
    cuts: &[usize],
    tips: &[(usize, f64)],
    sign: f64,
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
                (sign * (2.0 * std::f64::consts::PI - defect[v])).max(0.0)
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
    let w = |e: usize| cut::cut_weight(mesh, topo, ctx.graph, e);
    let path = cut::path_to(&adj, &w, &sources, tip, topo)?;
    (!path.is_empty()).then_some((tip, path))
}

/// Length of a path of mesh edges.
fn path_length(ctx: &Charts, path: &[usize]) -> f64 {
    path.iter()
        .map(|&e| {
            let [a, b] = ctx.topo.edges[e].verts;
            ctx.mesh.vertices[a].distance(ctx.mesh.vertices[b])
        })
        .sum()
}

/// Gussets (thesis §5.2.3 last paragraph, §5.3 "fixing gussets and overlaps"): where the
/// surface has negative angle defect (a saddle: more material around a point than a flat
/// disk holds), a slit from the chart's boundary to the most negative point ([`dart_path`]
/// with the sign turned) does not open like a dart: its two sides overlap in 2D. The
/// overlapping region is then cut off ([`cut_off`]), and the rest of the chart lays flat with
/// a wedge-shaped gap that the cut-off part, laid flat on its own, fills: the gusset, a small
/// separate piece whose edges are seams with the chart (the slit on one side, the edge it was
/// cut along on the other), so the pattern stage draws it with notches like any piece. At
/// most [`FlattenOptions::gussets`] times while the chart is over the tolerance; a gusset is
/// kept only when the chart and its gussets together have a lower L2 than the chart had, no
/// flip, no overlap, and every gusset is within the tolerance. A slit that opens after all
/// (no overlap) is kept as a dart when it lowers L2. Returns the gussets (laid, marked for
/// [`super::reattach`]).
///
/// Where the thesis is silent: a chart that can still be halved is given gussets only when
/// its L2 excess is at most [`GUSSET_REACH`] times the tolerance's (the caller decides). A
/// chart further over is nearly always halved all the same, and the trials on it cost a
/// layout of the whole chart each and leave gussets of a few faces for the merges to join
/// back; a chart that cannot be halved any more tries them whatever its stretch.
pub(super) fn gussets(ctx: &Charts, laid: &mut Laid, opts: &FlattenOptions, eps: f64) -> Vec<Laid> {
    let mut out: Vec<Laid> = Vec::new();
    let mut tips: Vec<(usize, f64)> = Vec::new();
    for _ in 0..opts.gussets {
        if laid.stretch.l2 <= opts.tolerance {
            break;
        }
        let Some((tip, path)) = dart_path(ctx, &laid.faces, &laid.cuts, &tips, -1.0) else {
            break;
        };
        let mut cuts = laid.cuts.clone();
        cuts.extend(&path);
        cuts.sort_unstable();
        cuts.dedup();
        let Ok(Layout::Laid(uv, s)) = ctx.lay(&laid.faces, &cuts) else {
            break;
        };
        let pairs = overlaps(&uv, eps, OVERLAP_PAIRS);
        let len = path_length(ctx, &path);
        if pairs.is_empty() {
            // It opened: a dart after all.
            if s.flipped > 0 || s.l2 >= laid.stretch.l2 {
                break;
            }
            tips.push((tip, len));
            laid.cuts = cuts;
            laid.uv = uv;
            laid.stretch = s;
            continue;
        }
        // The slit's two sides: walking the path from the tip, the face that runs along each
        // edge in the walking direction is on the left.
        let mut left = Vec::new();
        let mut right = Vec::new();
        let mut inside = vec![false; ctx.mesh.faces.len()];
        for &f in &laid.faces {
            inside[f] = true;
        }
        let mut v = tip;
        for &e in &path {
            let [a, b] = ctx.topo.edges[e].verts;
            let u = if a == v { b } else { a };
            for &(f, i) in &ctx.topo.edges[e].uses {
                if !inside[f] {
                    continue;
                }
                let (p, q) = Topology::corner_verts(ctx.mesh, f, i);
                if p == v && q == u {
                    left.push(f);
                } else {
                    right.push(f);
                }
            }
            v = u;
        }
        let Some((rest, pieces)) = cut_off(
            ctx,
            &laid.faces,
            &cuts,
            &left,
            &right,
            &pairs,
            &uv,
            eps,
            false,
        ) else {
            break;
        };
        let mut all: Vec<Stretch> = pieces.iter().map(|p| p.stretch).collect();
        all.push(rest.stretch);
        let together = distortion::combine(&all);
        if together.l2 >= laid.stretch.l2 || pieces.iter().any(|p| p.stretch.l2 > opts.tolerance) {
            break;
        }
        tips.push((tip, len));
        *laid = rest;
        out.extend(pieces);
    }
    out
}
