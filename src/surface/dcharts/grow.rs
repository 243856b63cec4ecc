//! Chart growing (Julius 2006, thesis §5.2.1, eq. 5.1–5.3): the modified Lloyd iterations
//! that grow every chart around its DCS proxy and seed face.
//!
//! - **Cost** (eq. 5.1–5.3): `Cost = F^α · C^β · P^γ` with the fitting error `F` (eq. 4.1), the
//!   compactness `C = π D(S, t)² / A_C` and the straightness `P = l_outer / l_inner`. `D` is
//!   the length of the path through face centroids inside the chart from the seed,
//!   accumulated as the chart grows.
//! - **Seeds**: farthest-point seeds on the face graph (distances between centroids), the
//!   initial proxy per seed the best of its vertex fans.
//! - **Growth**: one priority queue per chart. The queues hold `Cost · A_C^β`, which does not
//!   change as the chart grows; the charts are compared at their heads with their current
//!   area. A face joins only while `F < F_max`.
//! - **Refit and reseed**: proxies are refitted (eq. 5.4, closed form, [`crate::geom::proxy`])
//!   and each seed moves to the face nearest the chart's centroid among the `k` best-fitting
//!   ones; the loop stops when fewer than [`DChartsOptions::stop_fraction`] of the faces
//!   changed chart.
//!
//! Choices where the thesis is silent: `F` is taken as `F + 10⁻⁶` in the cost so that on an
//! exactly developable region (F = 0 everywhere) compactness and straightness still order the
//! growth; a face with no inner edge to the chart counts `P = 10⁶`; ties break on face index.
//! Farthest-point seeding reaches unreached components first, so each connected component
//! gets its own charts.

use super::{DChartsOptions, NONE};
use crate::geom::cut::Graph;
use crate::geom::heap::Lowest;
use crate::geom::mesh::Mesh;
use crate::geom::proxy::{self, Moments, Proxy};
use glam::DVec3;
use std::collections::BinaryHeap;

/// Added to the fitting error in the cost (see the module doc).
const F_EPS: f64 = 1e-6;

/// The charts as they grow.
pub(super) struct State {
    /// Chart of each face (`NONE` when not yet reached).
    pub(super) assign: Vec<usize>,
    /// Path length `D` from the chart's seed, per face.
    pub(super) dist: Vec<f64>,
    /// Proxy of each chart.
    pub(super) proxies: Vec<Proxy>,
    /// Seed face of each chart.
    pub(super) seeds: Vec<usize>,
    /// Area of each chart.
    pub(super) area: Vec<f64>,
}

/// The face graph and the settings, for growing charts.
pub(super) struct Segmenter<'a> {
    pub(super) g: &'a Graph,
    pub(super) o: &'a DChartsOptions,
}

impl Segmenter<'_> {
    /// Cost of face `u` joining chart `c` at path length `d`, without the `A_C^-β` factor.
    fn key(&self, st: &State, c: usize, u: usize, d: f64) -> f64 {
        let f = st.proxies[c].error(self.g.normal[u]) + F_EPS;
        let inner: f64 = self.g.adj[u]
            .iter()
            .filter(|(v, _)| st.assign[*v] == c)
            .map(|(_, l)| l)
            .sum();
        let outer = (self.g.perimeter[u] - inner).max(0.0);
        let p = if inner > 0.0 { outer / inner } else { 1e6 };
        let compact = std::f64::consts::PI * d * d;
        f.powf(self.o.alpha) * compact.powf(self.o.beta) * p.powf(self.o.gamma)
    }

    /// Grow `charts` over unassigned faces where `allowed` holds, bounded by `bound` on F.
    pub(super) fn grow(
        &self,
        st: &mut State,
        charts: &[usize],
        allowed: &dyn Fn(usize) -> bool,
        bound: Option<f64>,
    ) {
        let nc = st.proxies.len();
        let mut slot = vec![NONE; nc];
        for (k, &c) in charts.iter().enumerate() {
            slot[c] = k;
        }
        let mut heaps: Vec<BinaryHeap<Lowest<f64>>> = vec![BinaryHeap::new(); charts.len()];
        let push = |st: &State, heaps: &mut Vec<BinaryHeap<Lowest<f64>>>, c: usize, t: usize| {
            for &(u, _) in &self.g.adj[t] {
                if st.assign[u] != NONE || !allowed(u) {
                    continue;
                }
                if let Some(b) = bound {
                    if st.proxies[c].error(self.g.normal[u]) >= b {
                        continue;
                    }
                }
                let d = st.dist[t] + self.g.centroid[t].distance(self.g.centroid[u]);
                let key = self.key(st, c, u, d);
                heaps[slot[c]].push(Lowest {
                    key,
                    id: u,
                    data: d,
                });
            }
        };
        for t in 0..st.assign.len() {
            let c = st.assign[t];
            if c != NONE && slot[c] != NONE {
                push(st, &mut heaps, c, t);
            }
        }
        // Each chart's area to the power β, kept while its area stays the same.
        let scale = |c: usize, st: &State| st.area[c].max(1e-300).powf(self.o.beta);
        let mut scaled: Vec<f64> = charts.iter().map(|&c| scale(c, st)).collect();
        loop {
            let mut best: Option<(f64, usize)> = None;
            for k in 0..charts.len() {
                while heaps[k].peek().is_some_and(|e| st.assign[e.id] != NONE) {
                    heaps[k].pop();
                }
                if let Some(e) = heaps[k].peek() {
                    let eff = e.key / scaled[k];
                    if best.is_none_or(|(b, _)| eff < b) {
                        best = Some((eff, k));
                    }
                }
            }
            let Some((_, k)) = best else { break };
            let Some(e) = heaps[k].pop() else { break };
            let c = charts[k];
            st.assign[e.id] = c;
            st.dist[e.id] = e.data;
            st.area[c] += self.g.area[e.id];
            scaled[k] = scale(c, st);
            push(st, &mut heaps, c, e.id);
        }
    }

    /// Proxy of each chart refitted to its faces (kept when a chart has no weight).
    fn refit(&self, st: &mut State) {
        let mut mo = vec![Moments::default(); st.proxies.len()];
        for (f, &c) in st.assign.iter().enumerate() {
            if c != NONE {
                mo[c].add(self.g.normal[f], self.g.area[f]);
            }
        }
        for (c, m) in mo.iter().enumerate() {
            if let Some(p) = proxy::fit(m) {
                st.proxies[c] = p;
            }
        }
    }

    /// New seed per chart: among its `k` best-fitting faces, the nearest to its centroid.
    fn reseed(&self, st: &mut State) {
        let nc = st.proxies.len();
        let mut faces: Vec<Vec<usize>> = vec![Vec::new(); nc];
        for (f, &c) in st.assign.iter().enumerate() {
            if c != NONE {
                faces[c].push(f);
            }
        }
        for (c, fs) in faces.iter().enumerate() {
            if let Some(s) = self.best_seed(&st.proxies[c], fs) {
                st.seeds[c] = s;
            }
        }
    }

    pub(super) fn best_seed(&self, p: &Proxy, faces: &[usize]) -> Option<usize> {
        if faces.is_empty() {
            return None;
        }
        let a: f64 = faces.iter().map(|&f| self.g.area[f]).sum();
        let centre = if a > 0.0 {
            faces
                .iter()
                .map(|&f| self.g.centroid[f] * self.g.area[f])
                .sum::<DVec3>()
                / a
        } else {
            faces.iter().map(|&f| self.g.centroid[f]).sum::<DVec3>() / faces.len() as f64
        };
        let mut by_fit: Vec<(f64, usize)> = faces
            .iter()
            .map(|&f| (p.error(self.g.normal[f]), f))
            .collect();
        by_fit.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        by_fit
            .iter()
            .take(self.o.seed_candidates.max(1))
            .map(|&(_, f)| (self.g.centroid[f].distance_squared(centre), f))
            .min_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)))
            .map(|(_, f)| f)
    }

    /// Initial proxy for a seed: the best of the fans around its vertices.
    fn initial_proxy(&self, mesh: &Mesh, vf: &[Vec<usize>], s: usize) -> Proxy {
        let n = self.g.normal[s];
        let fallback = Proxy {
            axis: n.try_normalize().unwrap_or(DVec3::Z),
            cos: 1.0,
        };
        mesh.faces[s]
            .verts
            .iter()
            .filter_map(|&v| proxy::fit(&self.g.moments(vf[v].iter().copied())))
            .map(|p| (p.error(n), p))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(fallback, |(_, p)| p)
    }
}

/// Farthest-point seeds on the face graph: the first is the face farthest from face 0, each
/// next the face farthest from all chosen (unreached components come first).
fn farthest_seeds(g: &Graph, k: usize) -> Vec<usize> {
    let nf = g.area.len();
    let all = |_: usize| true;
    let d0 = g.distances(&[0], &all);
    let pick = |d: &[f64]| -> usize {
        let mut best = 0;
        for f in 0..nf {
            if d[f] > d[best] || (d[f].is_infinite() && !d[best].is_infinite()) {
                best = f;
            }
        }
        best
    };
    let mut seeds = vec![pick(&d0)];
    let mut d = g.distances(&seeds, &all);
    while seeds.len() < k.min(nf) {
        let s = pick(&d);
        if d[s] <= 0.0 {
            break;
        }
        seeds.push(s);
        let ds = g.distances(&[s], &all);
        for f in 0..nf {
            d[f] = d[f].min(ds[f]);
        }
    }
    seeds
}

/// The modified Lloyd iterations (at most [`DChartsOptions::max_iterations`]): the charts as
/// grown by the last round (faces no chart reached are `NONE`), and the rounds run.
pub(super) fn lloyd(mesh: &Mesh, g: &Graph, o: &DChartsOptions) -> (State, usize) {
    let nf = mesh.faces.len();
    let sg = Segmenter { g, o };
    let mut vf: Vec<Vec<usize>> = vec![Vec::new(); mesh.vertices.len()];
    for (f, face) in mesh.faces.iter().enumerate() {
        for &v in &face.verts {
            vf[v].push(f);
        }
    }
    let seeds = farthest_seeds(g, o.charts);
    let proxies: Vec<Proxy> = seeds
        .iter()
        .map(|&s| sg.initial_proxy(mesh, &vf, s))
        .collect();
    let mut st = State {
        assign: vec![NONE; nf],
        dist: vec![0.0; nf],
        area: vec![0.0; seeds.len()],
        proxies,
        seeds,
    };
    let all = |_: usize| true;
    let mut prev: Option<Vec<usize>> = None;
    let mut iterations = 0;
    for _ in 0..o.max_iterations.max(1) {
        iterations += 1;
        st.assign.iter_mut().for_each(|a| *a = NONE);
        st.area.iter_mut().for_each(|a| *a = 0.0);
        for (c, &s) in st.seeds.iter().enumerate() {
            st.assign[s] = c;
            st.dist[s] = 0.0;
            st.area[c] = g.area[s];
        }
        let charts: Vec<usize> = (0..st.proxies.len()).collect();
        sg.grow(&mut st, &charts, &all, Some(o.f_max));
        sg.refit(&mut st);
        let changed = prev.as_ref().map_or(nf, |p| {
            p.iter().zip(&st.assign).filter(|(a, b)| a != b).count()
        });
        let done = (changed as f64) < o.stop_fraction * nf as f64;
        prev = Some(st.assign.clone());
        if done {
            break;
        }
        sg.reseed(&mut st);
    }
    (st, iterations)
}
