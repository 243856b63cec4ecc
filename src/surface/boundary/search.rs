//! The search of every region (§5), with the §7 radial offset and what happens when it finds
//! nothing: one region at a time, each with its own branch-and-bound ([`super::bnb`]), the
//! results joined with the connecting charts into one mesh, and the alternatives.
//!
//! §7 radial offset: hulls and charts are computed on points moved `offset` (default 0.1) ×
//! their mean distance from the centre of mass C, radially away from C; the triangulation is
//! then built on the input points, and all angles are measured there. The boundary stays
//! exactly the input. Smoothing (`smooth = true` in the spec) resamples a closed cubic
//! B-spline through the points instead, and then the boundary is the resampled curve.
//!
//! The radial offset is skipped when it leaves fewer loop edges on the hull than the input
//! points do (a scalloped edge near the centre of mass sinks inside its hull when pushed).
//!
//! When no smooth triangulation exists within the limits, the search is run again with the
//! thresholds relaxed (180°, no area limit) and a warning says so; if even that finds
//! nothing in `max_iterations`, the cover is completed depth first (the largest chart of
//! each subloop without envelopes, at most n steps), with a warning; a fan from the first
//! vertex is the last resort (a subloop whose hull is flat but folded over itself).
//!
//! Alternatives: one region's next best with the other regions' best, region by region, until
//! `alternatives` meshes are listed.

use super::bnb::Search;
use super::darts::sites_valid;
use super::figures::{figures, to_mesh};
use super::loops::Prepared;
use super::{Options, Output, RELAXED};
use crate::geom::hull;
use glam::DVec3;
use std::collections::{HashMap, HashSet};
use std::time::Instant;

/// Search every region; `false` when a region with copies got no valid triangulation.
pub(super) fn search(prep: Prepared, opts: &Options, t0: Instant) -> (Output, bool) {
    let Prepared {
        verts,
        hverts,
        site,
        loop_ids,
        input_edges,
        fixed,
        joins,
        regions,
        connecting_charts,
    } = prep;
    let mut best: Vec<Vec<[usize; 3]>> = vec![fixed.clone()];
    let mut warnings = Vec::new();
    let mut iterations = 0;
    let mut alts: Vec<Vec<Vec<[usize; 3]>>> = vec![Vec::new()];
    let mut all_ok = true;
    for g in &regions {
        let q = g.len();
        let pts: Vec<DVec3> = g.iter().map(|&v| verts[v]).collect();
        // Hull points: a join's two copies of an end are nudged apart, each along its loop
        // edge (1 % of the shorter of that edge and the join), for the hulls only.
        let mut times: HashMap<usize, usize> = HashMap::new();
        for &v in g {
            *times.entry(v).or_default() += 1;
        }
        let hp: Vec<DVec3> = (0..q)
            .map(|k| {
                let v = g[k];
                if times[&v] < 2 {
                    return hverts[v];
                }
                let (a, b) = (g[(k + q - 1) % q], g[(k + 1) % q]);
                let (nb, partner) = if joins.contains(&(v.min(b), v.max(b))) {
                    (a, b)
                } else {
                    (b, a)
                };
                let d = verts[nb] - verts[v];
                let eps = 0.01 * d.length().min(verts[partner].distance(verts[v]));
                hverts[v] + d.normalize_or_zero() * eps
            })
            .collect();
        let lsite: Vec<usize> = g.iter().map(|&v| site[v]).collect();
        let mut sorted = lsite.clone();
        sorted.sort_unstable();
        sorted.dedup();
        let copies = sorted.len() < q;
        let orig: Vec<bool> = (0..q)
            .map(|k| input_edges.contains(&(g[k], g[(k + 1) % q])))
            .collect();
        let res = solve(&pts, &hp, &orig, &lsite, copies, opts, &mut warnings);
        all_ok &= res.valid;
        iterations += res.iterations;
        let to_global = |t: &Vec<[usize; 3]>| -> Vec<[usize; 3]> {
            t.iter().map(|f| f.map(|x| g[x])).collect()
        };
        best.push(to_global(&res.best));
        alts.push(res.alternatives.iter().map(to_global).collect());
    }
    let faces: Vec<[usize; 3]> = best.iter().flatten().copied().collect();
    all_ok &= sites_valid(&verts, &site, &faces);
    let mesh = to_mesh(&verts, &faces);
    let mut figures = figures(&verts, &faces, &input_edges, &loop_ids);
    figures.iterations = iterations;
    figures.seconds = t0.elapsed().as_secs_f64();
    figures.connecting_charts = connecting_charts;
    figures.joining_edges = joins.len();
    // Alternatives: one region's next best with the other regions' best, region by region.
    let mut alternatives = Vec::new();
    'regions: for (r, list) in alts.iter().enumerate() {
        for alt in list {
            if alternatives.len() + 1 >= opts.alternatives {
                break 'regions;
            }
            let mut all: Vec<[usize; 3]> = Vec::new();
            for (s, b) in best.iter().enumerate() {
                all.extend_from_slice(if s == r { alt } else { b });
            }
            alternatives.push(to_mesh(&verts, &all));
        }
    }
    (
        Output {
            mesh,
            figures,
            alternatives,
            warnings,
        },
        all_ok,
    )
}

pub(super) struct Solved {
    pub(super) best: Vec<[usize; 3]>,
    pub(super) alternatives: Vec<Vec<[usize; 3]>>,
    pub(super) iterations: usize,
    /// False when the loop has copies (darts, joins) and no valid triangulation was found.
    pub(super) valid: bool,
}

/// `pts` the points, `base` the points for hulls (copies moved apart), `site` which points
/// coincide, `copies` whether any do.
pub(super) fn solve(
    pts: &[DVec3],
    base: &[DVec3],
    orig: &[bool],
    site: &[usize],
    copies: bool,
    opts: &Options,
    warnings: &mut Vec<String>,
) -> Solved {
    let m = pts.len();
    if m == 3 {
        return Solved {
            best: vec![[0, 1, 2]],
            alternatives: vec![],
            iterations: 0,
            valid: !copies || sites_valid(pts, site, &[[0, 1, 2]]),
        };
    }
    // §7 radial offset for the hulls, unless it takes more loop edges off the hull than the
    // points as given (a scalloped edge near the centre of mass can sink inside).
    let c = base.iter().copied().sum::<DVec3>() / m as f64;
    let mean = base.iter().map(|p| p.distance(c)).sum::<f64>() / m as f64;
    let mut hpts: Vec<DVec3> = base
        .iter()
        .map(|p| *p + (*p - c).normalize_or_zero() * opts.offset * mean)
        .collect();
    if opts.offset != 0.0 && loop_edges_on_hull(base) > loop_edges_on_hull(&hpts) {
        hpts = base.to_vec();
    }
    let mut s = Search::new(
        pts,
        hpts,
        orig,
        (site, copies),
        opts.max_dihedral_deg.to_radians(),
        opts.min_chart_area,
    );
    s.base = base.to_vec();
    let mut r = s.run(opts);
    let mut relaxed = Search::new(
        pts,
        s.h.clone(),
        orig,
        (site, copies),
        std::f64::consts::PI,
        0.0,
    );
    relaxed.base = base.to_vec();
    if r.best.is_none() {
        let r2 = relaxed.run(opts);
        warnings.push(format!(
            "{RELAXED} {}° and charts over {} % of their hull: the limits were relaxed",
            opts.max_dihedral_deg,
            100.0 * opts.min_chart_area
        ));
        r.iterations += r2.iterations;
        r.best = r2.best;
        r.found = r2.found;
    }
    let best = match r.best {
        Some((t, _)) => t,
        None => match relaxed.dive() {
            Some(t) => {
                warnings.push(
                    "the search ran out of iterations: the triangulation was completed by taking the largest chart of each open subloop".into(),
                );
                t
            }
            None => {
                warnings.push(
                    "no boundary triangulation found: a fan from the first point is used".into(),
                );
                (1..m - 1).map(|k| [0, k, k + 1]).collect()
            }
        },
    };
    let mut found = r.found;
    found.sort_by(|a, b| {
        a.1.interior
            .cmp(&b.1.interior)
            .then(a.1.fairness.total_cmp(&b.1.fairness))
    });
    Solved {
        alternatives: found
            .into_iter()
            .map(|(t, _)| t)
            .filter(|t| *t != best)
            .collect(),
        valid: !copies || sites_valid(pts, site, &best),
        best,
        iterations: r.iterations,
    }
}

/// How many loop edges `k → k+1` are edges of the convex hull of the points (all of them when
/// the points are planar: the loop is then filled in its plane).
pub(super) fn loop_edges_on_hull(p: &[DVec3]) -> usize {
    let m = p.len();
    let Some(h) = hull::hull(p) else { return 0 };
    if h.planar.is_some() {
        return m;
    }
    let mut edges: HashSet<(usize, usize)> = HashSet::new();
    for f in &h.faces {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    (0..m)
        .filter(|&k| {
            let (a, b) = (k, (k + 1) % m);
            edges.contains(&(a.min(b), a.max(b)))
        })
        .count()
}
