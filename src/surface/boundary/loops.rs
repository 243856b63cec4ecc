//! §6 several loops and §6.1 rulings: from the checked loops with their darts to the regions
//! the search triangulates one by one.
//!
//! The first loop is the outer one, the others holes (reversed if their
//! Newell normal agrees with the outer's, so that the surface lies left of every loop).
//! First, charts that connect loops: on the hull of all the loops' points (radial offset
//! applied) charts are found as in §3 — triangles with an input edge, all wound like the
//! loops, joined across edges that are not loop edges — and a chart is *connecting* when it
//! touches two loops or more. The validity conditions are those of single charts (smooth
//! inside and against the neighbouring interior hull triangles, at least `min_chart_area`
//! of the hull), plus, adapted to several loops: its subtraction must leave simple loops
//! with each touched loop entered once (so they merge into one loop, or vanish when the
//! chart covers the band between them, as on a lamp collar), and keep every ruling
//! possible. The largest valid one is taken (the paper does not say which: the largest is
//! the §5.1.2 potential's choice), subtracted, and the search for connecting charts is
//! repeated on the loops left; its triangles are part of the result. Then the user's
//! rulings between loops join them, then the *shortest tree* of connecting edges: Kruskal
//! over all vertex pairs of different loops by length, skipping an edge that comes within
//! 1e-9 × the size of a loop edge, a chart edge, a ruling or an earlier tree edge (in
//! space; this is exact for planar panels), or that shares an end with another joining
//! edge or a ruling. A joining edge `a b` is walked both ways (… a, b, around the hole, b,
//! a, …): the search sees `a` and `b` twice, as two copies nudged apart for the hulls only
//! (1 % of the shorter of the joining edge and their loop edge, along the loop edge), and
//! the same validity test refuses triangles that would use the edge or a vertex twice. In
//! the result both copies are one vertex, so the joining edge is an ordinary interior edge
//! with a triangle on each side: the mesh is a disk with holes (Euler characteristic
//! 1 − holes), its boundary exactly the input loops. Joining edges and chart rims are
//! treated as interior edges for chart extraction (§6.1). The dihedral angles across a
//! connecting chart's rim are measured in the figures but not bounded by the search of the
//! region next to it.
//!
//! Rulings (§6.1) name points of any loop. Between two loops a ruling is a joining edge
//! (taken before the shortest tree); within the joined loop it is a constraint edge that
//! splits it into regions searched separately.

use super::checks::{check_crossings, check_loops, segment_distance, size};
use super::darts::{insert_darts, sites_valid, Darted};
use super::figures::{angle, unit_normal};
use super::{BoundaryError, Dart, Input, Options};
use crate::geom::hull;
use crate::geom::mesh::newell;
use glam::DVec3;
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};

/// The boundary ready to search.
pub(super) struct Prepared {
    /// All vertices (dart copies coincide unless opened).
    pub(super) verts: Vec<DVec3>,
    /// The vertices for hulls (dart copies opened into a V).
    pub(super) hverts: Vec<DVec3>,
    /// Site of each vertex: the vertex it coincides with (a dart's left copy), else itself.
    pub(super) site: Vec<usize>,
    /// The loops as vertex ids, holes reversed when needed.
    pub(super) loop_ids: Vec<Vec<usize>>,
    /// The input's directed edges.
    pub(super) input_edges: HashSet<(usize, usize)>,
    /// Triangles of the charts that connect loops, wound like the loops.
    pub(super) fixed: Vec<[usize; 3]>,
    /// Loops joining edges (user rulings between loops and the shortest tree), undirected.
    pub(super) joins: HashSet<(usize, usize)>,
    /// The simple-or-seamed loops left to search (a join's ends appear twice).
    pub(super) regions: Vec<Vec<usize>>,
    pub(super) connecting_charts: usize,
}

pub(super) fn prepare(
    input: &Input,
    opts: &Options,
    open: bool,
) -> Result<Prepared, BoundaryError> {
    let darted = dart_loops(input, open)?;
    let v = vertices(&darted);
    let rulings = ruling_ends(input, &v.starts, &darted)?;
    let (mut cycles, fixed, pending, connecting_charts) = connect_by_charts(&v, rulings, opts);
    let (mut joins, mut used, chords) = join_by_rulings(&mut cycles, &pending)?;
    if cycles.len() > 1 {
        join_by_tree(
            &mut cycles,
            &v.verts,
            &fixed,
            &chords,
            &mut joins,
            &mut used,
        )?;
    }
    let regions = split_by_rulings(cycles, chords)?;
    Ok(Prepared {
        verts: v.verts,
        hverts: v.hverts,
        site: v.site,
        loop_ids: v.loop_ids,
        input_edges: v.input_edges,
        fixed,
        joins,
        regions,
        connecting_charts,
    })
}

/// Each loop checked and its darts inserted; the loops (darts opened for the hulls) must not
/// cross.
fn dart_loops(input: &Input, open: bool) -> Result<Vec<Darted>, BoundaryError> {
    check_loops(&input.loops)?;
    let nl = input.loops.len();
    for (k, d) in input.darts.iter().enumerate() {
        if d.looop >= nl {
            return Err(BoundaryError::Dart {
                index: k,
                message: format!("is on loop {} but there are {nl} loops", d.looop + 1),
            });
        }
    }
    let mut darted = Vec::new();
    for (l, p) in input.loops.iter().enumerate() {
        let mine: Vec<(usize, &Dart)> = input
            .darts
            .iter()
            .enumerate()
            .filter(|(_, d)| d.looop == l)
            .collect();
        darted.push(insert_darts(p, l, &mine, open)?);
    }
    let hull_loops: Vec<Vec<DVec3>> = darted.iter().map(|d| d.hull.clone()).collect();
    let labels: Vec<Vec<(usize, usize)>> = darted.iter().map(|d| d.labels.clone()).collect();
    check_crossings(&hull_loops, &labels)?;
    Ok(darted)
}

/// All loops' vertices in one list, and the loops and input edges over them.
struct Vertices {
    verts: Vec<DVec3>,
    hverts: Vec<DVec3>,
    site: Vec<usize>,
    /// First vertex of each loop.
    starts: Vec<usize>,
    loop_ids: Vec<Vec<usize>>,
    input_edges: HashSet<(usize, usize)>,
}

/// Global vertices and the input's directed edges; holes reversed when their Newell normal
/// agrees with the outer loop's.
fn vertices(darted: &[Darted]) -> Vertices {
    let mut verts: Vec<DVec3> = Vec::new();
    let mut hverts: Vec<DVec3> = Vec::new();
    let mut site: Vec<usize> = Vec::new();
    let mut starts = Vec::new();
    for d in darted {
        let s = verts.len();
        starts.push(s);
        verts.extend_from_slice(&d.pts);
        hverts.extend_from_slice(&d.hull);
        site.extend(d.twin.iter().map(|t| s + t));
    }
    let outer_normal = newell(&darted[0].hull);
    let mut loop_ids: Vec<Vec<usize>> = Vec::new();
    for (l, d) in darted.iter().enumerate() {
        let mut ids: Vec<usize> = (starts[l]..starts[l] + d.pts.len()).collect();
        if l > 0 && newell(&d.hull).dot(outer_normal) > 0.0 {
            ids.reverse();
        }
        loop_ids.push(ids);
    }
    let mut input_edges: HashSet<(usize, usize)> = HashSet::new();
    for ids in &loop_ids {
        for k in 0..ids.len() {
            input_edges.insert((ids[k], ids[(k + 1) % ids.len()]));
        }
    }
    Vertices {
        verts,
        hverts,
        site,
        starts,
        loop_ids,
        input_edges,
    }
}

/// The user's rulings as global vertex pairs, with their index.
fn ruling_ends(
    input: &Input,
    starts: &[usize],
    darted: &[Darted],
) -> Result<Vec<(usize, [usize; 2])>, BoundaryError> {
    let nl = input.loops.len();
    let mut rulings: Vec<(usize, [usize; 2])> = Vec::new();
    for (r, ru) in input.rulings.iter().enumerate() {
        let err = |message: String| BoundaryError::Ruling { index: r, message };
        let mut ends = [0; 2];
        for (e, &(l, i)) in ru.iter().enumerate() {
            if l >= nl {
                return Err(err(format!(
                    "names loop {} but there are {nl} loops",
                    l + 1
                )));
            }
            let n = input.loops[l].len();
            if i >= n {
                return Err(err(format!(
                    "point {} of loop {}: the loop has {n} points",
                    i + 1,
                    l + 1
                )));
            }
            ends[e] = starts[l] + darted[l].map[i];
        }
        if ends[0] == ends[1] {
            return Err(err("joins a point to itself".into()));
        }
        rulings.push((r, ends));
    }
    Ok(rulings)
}

/// §6: charts connecting loops first, as long as there are several loops and a valid chart:
/// the loops left, the charts' triangles, the rulings still to place and how many charts.
#[allow(clippy::type_complexity)]
fn connect_by_charts(
    v: &Vertices,
    rulings: Vec<(usize, [usize; 2])>,
    opts: &Options,
) -> (
    Vec<Vec<usize>>,
    Vec<[usize; 3]>,
    Vec<(usize, [usize; 2])>,
    usize,
) {
    let Vertices {
        verts,
        hverts,
        site,
        loop_ids,
        input_edges,
        ..
    } = v;
    let mut cycles = loop_ids.to_vec();
    let mut fixed: Vec<[usize; 3]> = Vec::new();
    let mut pending = rulings;
    let mut connecting_charts = 0;
    while cycles.len() > 1 {
        let Some((tris, next)) =
            connecting_chart(verts, hverts, site, &cycles, input_edges, &pending, opts)
        else {
            break;
        };
        pending.retain(|(_, [a, b])| !tris.iter().any(|t| t.contains(a) && t.contains(b)));
        fixed.extend(tris);
        cycles = next;
        connecting_charts += 1;
    }
    (cycles, fixed, pending, connecting_charts)
}

/// The cycle (loop) holding vertex `v`.
fn cycle_of(cycles: &[Vec<usize>], v: usize) -> Option<usize> {
    cycles.iter().position(|c| c.contains(&v))
}

/// Then the user's rulings between loops join them: the joining edges, their ends, and the
/// rulings within a loop (chords) left for [`split_by_rulings`].
#[allow(clippy::type_complexity)]
fn join_by_rulings(
    cycles: &mut Vec<Vec<usize>>,
    pending: &[(usize, [usize; 2])],
) -> Result<
    (
        HashSet<(usize, usize)>,
        HashSet<usize>,
        Vec<(usize, [usize; 2])>,
    ),
    BoundaryError,
> {
    let mut joins: HashSet<(usize, usize)> = HashSet::new();
    let mut used: HashSet<usize> = HashSet::new();
    let mut chords: Vec<(usize, [usize; 2])> = Vec::new();
    for &(r, [a, b]) in pending {
        let err = |message: String| BoundaryError::Ruling { index: r, message };
        match (cycle_of(cycles, a), cycle_of(cycles, b)) {
            (Some(x), Some(y)) if x != y => {
                if used.contains(&a) || used.contains(&b) {
                    return Err(err(
                        "an end already joins two loops (rulings between loops must not share points)".into(),
                    ));
                }
                join(cycles, x, a, y, b);
                used.extend([a, b]);
                joins.insert((a.min(b), a.max(b)));
            }
            (Some(_), Some(_)) => chords.push((r, [a, b])),
            _ => {
                return Err(err(
                    "an end lies inside a chart that connects the loops; choose other points"
                        .into(),
                ))
            }
        }
    }
    Ok((joins, used, chords))
}

/// Then the shortest tree of connecting edges (see the module doc).
fn join_by_tree(
    cycles: &mut Vec<Vec<usize>>,
    verts: &[DVec3],
    fixed: &[[usize; 3]],
    chords: &[(usize, [usize; 2])],
    joins: &mut HashSet<(usize, usize)>,
    used: &mut HashSet<usize>,
) -> Result<(), BoundaryError> {
    let avoid: HashSet<usize> = chords.iter().flat_map(|(_, e)| *e).collect();
    let mut cand: Vec<(f64, usize, usize)> = Vec::new();
    for (i, ci) in cycles.iter().enumerate() {
        for cj in &cycles[i + 1..] {
            for &a in ci {
                for &b in cj {
                    if !used.contains(&a)
                        && !used.contains(&b)
                        && !avoid.contains(&a)
                        && !avoid.contains(&b)
                    {
                        cand.push((verts[a].distance(verts[b]), a.min(b), a.max(b)));
                    }
                }
            }
        }
    }
    cand.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    let tol = 1e-9 * size(verts);
    for (_, a, b) in cand {
        if cycles.len() == 1 {
            break;
        }
        let (Some(x), Some(y)) = (cycle_of(cycles, a), cycle_of(cycles, b)) else {
            continue;
        };
        if x == y || used.contains(&a) || used.contains(&b) {
            continue;
        }
        // No crossing with the loops, the charts, the rulings or the tree so far.
        let mut segs: Vec<(usize, usize)> = Vec::new();
        for c in cycles.iter() {
            segs.extend((0..c.len()).map(|k| (c[k], c[(k + 1) % c.len()])));
        }
        for t in fixed {
            segs.extend((0..3).map(|k| (t[k], t[(k + 1) % 3])));
        }
        segs.extend(chords.iter().map(|(_, e)| (e[0], e[1])));
        segs.extend(joins.iter().copied());
        let crosses = segs.iter().any(|&(p, q)| {
            if p == a || p == b || q == a || q == b {
                return false;
            }
            segment_distance(verts[a], verts[b], verts[p], verts[q]).0 <= tol
        });
        if crosses {
            continue;
        }
        join(cycles, x, a, y, b);
        used.extend([a, b]);
        joins.insert((a, b));
    }
    if cycles.len() > 1 {
        return Err(BoundaryError::Loops(
            "the loops cannot be joined by edges that cross neither the loops nor each other"
                .into(),
        ));
    }
    Ok(())
}

/// Rulings within a loop split the region.
fn split_by_rulings(
    cycles: Vec<Vec<usize>>,
    chords: Vec<(usize, [usize; 2])>,
) -> Result<Vec<Vec<usize>>, BoundaryError> {
    let mut regions: Vec<Vec<usize>> = cycles;
    for (r, [a, b]) in chords {
        let err = |message: String| BoundaryError::Ruling { index: r, message };
        let found = regions.iter().position(|g| {
            let pa = g.iter().position(|&v| v == a);
            let pb = g.iter().position(|&v| v == b);
            match (pa, pb) {
                (Some(x), Some(y)) => {
                    let d = (x + g.len() - y) % g.len();
                    d != 0 && d != 1 && d != g.len() - 1
                }
                _ => false,
            }
        });
        let Some(gi) = found else {
            return Err(err(
                "its points are neighbours, or on different sides of another ruling (rulings must not cross)".into(),
            ));
        };
        if regions[gi].iter().filter(|&&v| v == a || v == b).count() > 2 {
            return Err(err(
                "an end is also the end of a ruling between loops; choose other points".into(),
            ));
        }
        let g = regions.swap_remove(gi);
        let (x, y) = split_at(&g, a, b);
        regions.push(x);
        regions.push(y);
    }
    Ok(regions)
}

/// Join cycle `y` into cycle `x` by the edge `a b` (`a` on `x`, `b` on `y`), walked both
/// ways: … a, b, (y around), b, a, … .
pub(super) fn join(cycles: &mut Vec<Vec<usize>>, x: usize, a: usize, y: usize, b: usize) {
    let cx = &cycles[x];
    let cy = &cycles[y];
    let i = cx.iter().position(|&v| v == a).unwrap_or(0);
    let j = cy.iter().position(|&v| v == b).unwrap_or(0);
    let mut merged: Vec<usize> = cx[..=i].to_vec();
    merged.extend_from_slice(&cy[j..]);
    merged.extend_from_slice(&cy[..=j]);
    merged.extend_from_slice(&cx[i..]);
    cycles[x] = merged;
    cycles.remove(y);
}

/// §6 "charts which connect separate loops": on the hull of all the loops' points (the §7
/// radial offset applied), charts as in §3 — hull triangles joined across edges that are not
/// loop edges, each with an input edge, all wound like the loops — that touch two loops or
/// more, smooth inside and against the neighbouring interior hull triangles, at least
/// `min_chart_area` of the hull, whose subtraction leaves simple loops (each touched loop
/// entered once, so they merge into one, or none when the chart covers them) and keeps every
/// pending ruling possible. The largest such chart, wound like the loops, and the loops left.
#[allow(clippy::type_complexity)]
pub(super) fn connecting_chart(
    verts: &[DVec3],
    hverts: &[DVec3],
    site: &[usize],
    cycles: &[Vec<usize>],
    input_edges: &HashSet<(usize, usize)>,
    pending: &[(usize, [usize; 2])],
    opts: &Options,
) -> Option<(Vec<[usize; 3]>, Vec<Vec<usize>>)> {
    let ids: Vec<usize> = cycles.iter().flatten().copied().collect();
    let m = ids.len();
    let c = ids.iter().map(|&v| hverts[v]).sum::<DVec3>() / m as f64;
    let mean = ids.iter().map(|&v| hverts[v].distance(c)).sum::<f64>() / m as f64;
    let hp: Vec<DVec3> = ids
        .iter()
        .map(|&v| hverts[v] + (hverts[v] - c).normalize_or_zero() * opts.offset * mean)
        .collect();
    let hull = hull::hull(&hp)?;
    if hull.planar.is_some() {
        return None;
    }
    let mut edge_cycle: HashMap<(usize, usize), usize> = HashMap::new();
    for (ci, cy) in cycles.iter().enumerate() {
        for k in 0..cy.len() {
            edge_cycle.insert((cy[k], cy[(k + 1) % cy.len()]), ci);
        }
    }
    let nf = hull.faces.len();
    let face = |f: usize| hull.faces[f].map(|x| ids[x]);
    let on_loop =
        |a: usize, b: usize| edge_cycle.contains_key(&(a, b)) || edge_cycle.contains_key(&(b, a));
    let global: Vec<[usize; 3]> = (0..nf).map(face).collect();
    let (sense, has_edge) = senses(&global, &edge_cycle, input_edges, verts, site);
    let thr = opts.max_dihedral_deg.to_radians();
    let hull_area = hull.area(&hp);
    let mut comp = vec![usize::MAX; nf];
    let mut best: Option<(f64, Vec<[usize; 3]>, Vec<Vec<usize>>)> = None;
    for f0 in 0..nf {
        let Some(s0) = sense[f0] else { continue };
        if comp[f0] != usize::MAX {
            continue;
        }
        comp[f0] = f0;
        let mut part = vec![f0];
        let mut k = 0;
        while k < part.len() {
            let f = part[k];
            k += 1;
            let t = face(f);
            for e in 0..3 {
                let g = hull.neighbours[f][e];
                if g == usize::MAX
                    || comp[g] != usize::MAX
                    || sense[g] != Some(s0)
                    || on_loop(t[e], t[(e + 1) % 3])
                {
                    continue;
                }
                comp[g] = f0;
                part.push(g);
            }
        }
        let tris: Vec<[usize; 3]> = part
            .iter()
            .map(|&f| {
                let t = face(f);
                if s0 {
                    t
                } else {
                    [t[0], t[2], t[1]]
                }
            })
            .collect();
        let mut touched: BTreeSet<usize> = BTreeSet::new();
        for t in &tris {
            for k in 0..3 {
                if let Some(&ci) = edge_cycle.get(&(t[k], t[(k + 1) % 3])) {
                    touched.insert(ci);
                }
            }
        }
        if touched.len() < 2 {
            continue;
        }
        let area: f64 = part
            .iter()
            .map(|&f| {
                let t = hull.faces[f];
                0.5 * (hp[t[1]] - hp[t[0]]).cross(hp[t[2]] - hp[t[0]]).length()
            })
            .sum();
        if area < opts.min_chart_area * hull_area || best.as_ref().is_some_and(|b| b.0 >= area) {
            continue;
        }
        let smooth = part.iter().all(|&f| {
            (0..3).all(|e| {
                let g = hull.neighbours[f][e];
                g == usize::MAX
                    || (comp[g] != f0 && has_edge[g])
                    || angle(unit_normal(verts, face(f)), unit_normal(verts, face(g))) < thr
            })
        });
        if !smooth || !sites_valid(verts, site, &tris) {
            continue;
        }
        let Some(left) = loops_left(&edge_cycle, &tris) else {
            continue;
        };
        let merged = cycles.len() + 1 - touched.len();
        if !(left.len() == merged || left.len() + 1 == merged) {
            continue;
        }
        let feasible = pending.iter().all(|(_, [a, b])| {
            tris.iter().any(|t| t.contains(a) && t.contains(b))
                || (left.iter().any(|c| c.contains(a)) && left.iter().any(|c| c.contains(b)))
        });
        if feasible {
            best = Some((area, tris, left));
        }
    }
    best.map(|(_, t, l)| (t, l))
}

/// Which way each hull face runs against the loops (`Some(true)`: as the loops, `Some(false)`:
/// reversed, `None`: mixed, no input edge, or invalid with the sites), and whether it has a
/// loop edge.
fn senses(
    faces: &[[usize; 3]],
    edge_cycle: &HashMap<(usize, usize), usize>,
    input_edges: &HashSet<(usize, usize)>,
    verts: &[DVec3],
    site: &[usize],
) -> (Vec<Option<bool>>, Vec<bool>) {
    let nf = faces.len();
    let mut sense: Vec<Option<bool>> = vec![None; nf];
    let mut has_edge = vec![false; nf];
    for f in 0..nf {
        let t = faces[f];
        let mut vote: Option<bool> = None;
        let mut mixed = false;
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let v = if edge_cycle.contains_key(&(a, b)) {
                has_edge[f] = true;
                input_edges.contains(&(a, b)).then_some(true)
            } else if edge_cycle.contains_key(&(b, a)) {
                has_edge[f] = true;
                input_edges.contains(&(b, a)).then_some(false)
            } else {
                None
            };
            if let Some(v) = v {
                mixed |= vote.is_some_and(|w| w != v);
                vote = Some(v);
            }
        }
        let wound = if vote == Some(false) {
            [t[0], t[2], t[1]]
        } else {
            t
        };
        if !mixed && sites_valid(verts, site, &[wound]) {
            sense[f] = vote;
        }
    }
    (sense, has_edge)
}

/// §6 subtraction of a connecting chart: the loops' edges, less the chart's, plus the chart's
/// rim reversed, walked into loops; `None` unless they are simple loops of 3 points or more.
fn loops_left(
    edge_cycle: &HashMap<(usize, usize), usize>,
    tris: &[[usize; 3]],
) -> Option<Vec<Vec<usize>>> {
    let mut rem: BTreeSet<(usize, usize)> = edge_cycle.keys().copied().collect();
    let mut ok = true;
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if !rem.remove(&(a, b)) {
                ok &= rem.insert((b, a));
            }
        }
    }
    let mut next: BTreeMap<usize, usize> = BTreeMap::new();
    let mut into: HashSet<usize> = HashSet::new();
    for &(a, b) in &rem {
        ok &= next.insert(a, b).is_none() && into.insert(b);
    }
    if !ok {
        return None;
    }
    let mut left: Vec<Vec<usize>> = Vec::new();
    let mut seen: HashSet<usize> = HashSet::new();
    for &start in next.keys() {
        if seen.contains(&start) {
            continue;
        }
        let mut cy = vec![start];
        seen.insert(start);
        let mut v = next[&start];
        while v != start && ok {
            ok = seen.insert(v);
            cy.push(v);
            v = next.get(&v).copied().unwrap_or(start);
        }
        ok &= cy.len() >= 3;
        left.push(cy);
    }
    ok.then_some(left)
}

/// Split loop `g` along the chord `a b`: (a … b) and (b … a).
pub(super) fn split_at(g: &[usize], a: usize, b: usize) -> (Vec<usize>, Vec<usize>) {
    let pa = g.iter().position(|&v| v == a).unwrap_or(0);
    let pb = g.iter().position(|&v| v == b).unwrap_or(0);
    let walk = |from: usize, to: usize| {
        let mut out = vec![g[from]];
        let mut i = from;
        while i != to {
            i = (i + 1) % g.len();
            out.push(g[i]);
        }
        out
    };
    (walk(pa, pb), walk(pb, pa))
}
