//! Hole filling (Julius 2006, thesis §5.2.2): the faces no chart reached within `F_max` form
//! connected holes; a hole larger than [`super::DChartsOptions::small_hole`] of the total area (or one
//! no chart touches) gets a new chart grown inside it, again and again while new holes
//! appear; the small ones are then grown into by the charts around them without the `F_max`
//! bound.
//!
//! Choice where the thesis is silent: a new chart's proxy is fitted to the whole hole, its seed
//! is the hole's best seed face as in the Lloyd iterations (the plane `z` when the hole has no
//! area).

use super::grow::{Segmenter, State};
use super::NONE;
use crate::geom::cut::Graph;
use crate::geom::proxy::{self, Proxy};
use glam::DVec3;

/// Fill the holes left by the Lloyd iterations (see the module doc), so that every face has a
/// chart; returns the number of charts added.
pub(super) fn fill(sg: &Segmenter, st: &mut State) -> usize {
    let (g, o) = (sg.g, sg.o);
    let total_area: f64 = g.area.iter().sum();
    let all = |_: usize| true;
    let mut added = 0;
    loop {
        let holes = holes(g, &st.assign);
        let mut new_charts = Vec::new();
        for h in &holes {
            let area: f64 = h.iter().map(|&f| g.area[f]).sum();
            let touched = h
                .iter()
                .any(|&f| g.adj[f].iter().any(|&(u, _)| st.assign[u] != NONE));
            if area > o.small_hole * total_area || !touched {
                let p = proxy::fit(&g.moments(h.iter().copied())).unwrap_or(Proxy {
                    axis: DVec3::Z,
                    cos: 1.0,
                });
                let s = sg.best_seed(&p, h).unwrap_or(h[0]);
                let c = st.proxies.len();
                st.proxies.push(p);
                st.seeds.push(s);
                st.area.push(g.area[s]);
                st.assign[s] = c;
                st.dist[s] = 0.0;
                new_charts.push(c);
            }
        }
        if new_charts.is_empty() {
            break;
        }
        added += new_charts.len();
        sg.grow(st, &new_charts, &all, Some(o.f_max));
    }
    let charts: Vec<usize> = (0..st.proxies.len()).collect();
    sg.grow(st, &charts, &all, None);
    // Anything still unassigned (cannot happen: every hole touches a chart) joins chart 0.
    for a in st.assign.iter_mut() {
        if *a == NONE {
            *a = 0;
        }
    }
    added
}

/// Connected components of unassigned faces.
fn holes(g: &Graph, assign: &[usize]) -> Vec<Vec<usize>> {
    let nf = assign.len();
    let mut seen = vec![false; nf];
    let mut out = Vec::new();
    for f in 0..nf {
        if assign[f] != NONE || seen[f] {
            continue;
        }
        let mut comp = vec![f];
        seen[f] = true;
        let mut k = 0;
        while k < comp.len() {
            let t = comp[k];
            k += 1;
            for &(u, _) in &g.adj[t] {
                if assign[u] == NONE && !seen[u] {
                    seen[u] = true;
                    comp.push(u);
                }
            }
        }
        out.push(comp);
    }
    out
}
