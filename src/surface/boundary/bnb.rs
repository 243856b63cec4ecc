//! §5 branch-and-bound on one simple loop (local vertex indices 0..m, in loop order), Fig. 9.
//!
//! A priority queue of covers ordered by potential (§5.1.2:
//! fewer charts first, then the larger largest chart), seeded with the empty cover; pop,
//! discard when the best triangulation is at least as good as the cover's bound, subtract,
//! take the best smooth choice of envelopes when every subloop has them, extend the cover by
//! every valid chart of every subloop hull (refusing charts whose angle with the cover is
//! over the threshold), and queue it unless a queued subset is at least as good (a better
//! superset replaces the subset). Charts must be smooth inside, smooth against the
//! neighbouring interior hull triangles, and at least `min_chart_area` of their hull's area.
//! Stop when the best is good enough (`good_interior`, `good_fairness`), the queue is empty,
//! or after `max_iterations` (the paper: "less than a thousand for all the models").
//! A hull without any valid chart makes each of its triangles a chart (the pathological case).
//!
//! [`Search::dive`] completes a cover depth first when the iterations run out.
//!
//! Memory: at most `QUEUE_MAX` covers wait in the queue; past that the one with the worst
//! potential is dropped (the paper's iteration bound alone leaves the queue unbounded, since
//! one iteration may queue a cover per chart of every subloop).

use super::darts::sites_valid;
use super::figures::{angle, unit_normal};
use super::{Chart, Sub};
use super::{Options, Quality};
use glam::DVec3;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::rc::Rc;

/// Covers queued at most (see the module doc).
const QUEUE_MAX: usize = 1 << 16;

pub(super) struct Run {
    pub(super) best: Option<(Vec<[usize; 3]>, Quality)>,
    pub(super) found: Vec<(Vec<[usize; 3]>, Quality)>,
    pub(super) iterations: usize,
}

#[derive(Clone, Copy, PartialEq)]
pub(super) struct Key {
    pub(super) charts: usize,
    pub(super) area: f64,
    pub(super) seq: u64,
}
impl Eq for Key {}
impl PartialOrd for Key {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Key {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.charts
            .cmp(&o.charts)
            .then(o.area.total_cmp(&self.area))
            .then(self.seq.cmp(&o.seq))
    }
}

pub(super) struct Search<'a> {
    pub(super) p: &'a [DVec3],
    pub(super) h: Vec<DVec3>,
    pub(super) orig: &'a [bool],
    /// Which points coincide (dart sides, join ends), and whether any do.
    pub(super) site: &'a [usize],
    pub(super) copies: bool,
    pub(super) m: usize,
    pub(super) thr: f64,
    pub(super) min_area: f64,
    /// The hull points before the radial offset (tried for flat subloops).
    pub(super) base: Vec<DVec3>,
    pub(super) charts: Vec<Chart>,
    pub(super) chart_ids: HashMap<Vec<[usize; 3]>, usize>,
    pub(super) subs: HashMap<Vec<usize>, Rc<Sub>>,
}

/// Edge → triangles; ordered, so that sums of angles come out the same on every run.
pub(super) type EdgeMap = BTreeMap<(usize, usize), Vec<usize>>;

impl<'a> Search<'a> {
    pub(super) fn new(
        p: &'a [DVec3],
        h: Vec<DVec3>,
        orig: &'a [bool],
        (site, copies): (&'a [usize], bool),
        thr: f64,
        min_area: f64,
    ) -> Self {
        Search {
            p,
            h,
            orig,
            site,
            copies,
            m: p.len(),
            thr,
            min_area,
            base: Vec::new(),
            charts: Vec::new(),
            chart_ids: HashMap::new(),
            subs: HashMap::new(),
        }
    }

    /// Triangles that can be part of a boundary triangulation once coinciding points are
    /// taken into account (always true without copies).
    pub(super) fn valid(&self, tris: &[[usize; 3]]) -> bool {
        !self.copies || sites_valid(self.p, self.site, tris)
    }

    pub(super) fn normal(&self, t: [usize; 3]) -> DVec3 {
        unit_normal(self.p, t)
    }

    pub(super) fn dihedral(&self, a: [usize; 3], b: [usize; 3]) -> f64 {
        angle(self.normal(a), self.normal(b))
    }

    /// Depth first, no bounds: while some subloop has no envelopes, add its largest chart;
    /// then take the best envelopes. Ends: each step removes at least one triangle's worth.
    pub(super) fn dive(&mut self) -> Option<Vec<[usize; 3]>> {
        let mut cover: Vec<usize> = Vec::new();
        for _ in 0..self.m {
            let (tris, _) = self.cover_tris(&cover);
            let subs = self.subtract(&tris);
            let infos: Vec<Rc<Sub>> = subs.iter().map(|s| self.analyse(s)).collect();
            if let Some(k) = infos.iter().position(|i| i.envelopes.is_empty()) {
                let ch = infos[k]
                    .charts
                    .iter()
                    .copied()
                    .max_by(|a, b| self.charts[*a].area.total_cmp(&self.charts[*b].area))?;
                cover.push(ch);
                cover.sort_unstable();
                continue;
            }
            let em = Self::edge_map(&tris);
            let mut all = tris.clone();
            for info in &infos {
                let pick = info
                    .envelopes
                    .iter()
                    .filter_map(|env| self.added(&em, &tris, env).map(|q| (env, q)))
                    .reduce(|a, b| if b.1.better(&a.1) { b } else { a })
                    .map_or(&info.envelopes[0], |(env, _)| env);
                all.extend_from_slice(pick);
            }
            all.sort_unstable();
            return (all.len() == self.m - 2 && self.valid(&all)).then_some(all);
        }
        None
    }

    pub(super) fn run(&mut self, opts: &Options) -> Run {
        let mut run = Run {
            best: None,
            found: Vec::new(),
            iterations: 0,
        };
        let mut seen_tri: HashSet<Vec<[usize; 3]>> = HashSet::new();
        let mut queue: BTreeMap<Key, (Vec<usize>, Quality)> = BTreeMap::new();
        let mut seen_cover: HashSet<Vec<usize>> = HashSet::new();
        let mut seq = 0u64;
        queue.insert(
            Key {
                charts: 0,
                area: 0.0,
                seq,
            },
            (Vec::new(), Quality::default()),
        );
        seen_cover.insert(Vec::new());
        let good =
            |q: &Quality| q.interior <= opts.good_interior && q.fairness <= opts.good_fairness;
        while let Some((_, (cover, _))) = queue.pop_first() {
            if run.best.as_ref().is_some_and(|b| good(&b.1))
                || run.iterations >= opts.max_iterations
            {
                break;
            }
            run.iterations += 1;
            let (tris, owner) = self.cover_tris(&cover);
            let subs = self.subtract(&tris);
            let bound = self.bound(&tris, &owner, &subs);
            if run.best.as_ref().is_some_and(|b| !bound.better(&b.1)) {
                continue;
            }
            let infos: Vec<Rc<Sub>> = subs.iter().map(|s| self.analyse(s)).collect();
            let em = Self::edge_map(&tris);
            // Stage 2: envelopes.
            if infos.iter().all(|i| !i.envelopes.is_empty()) {
                let own = self.added(&BTreeMap::new(), &[], &tris);
                let mut total = own;
                let mut all = tris.clone();
                for info in &infos {
                    let mut pick: Option<(usize, Quality)> = None;
                    for (k, env) in info.envelopes.iter().enumerate() {
                        if let Some(q) = self.added(&em, &tris, env) {
                            if pick.is_none_or(|(_, b)| q.better(&b)) {
                                pick = Some((k, q));
                            }
                        }
                    }
                    match (pick, total.as_mut()) {
                        (Some((k, q)), Some(t)) => {
                            t.interior += q.interior;
                            t.fairness += q.fairness;
                            all.extend_from_slice(&info.envelopes[k]);
                        }
                        _ => total = None,
                    }
                }
                if let Some(q) = total {
                    if all.len() == self.m - 2 && self.valid(&all) {
                        all.sort_unstable();
                        if seen_tri.insert(all.clone()) {
                            run.found.push((all.clone(), q));
                        }
                        if run.best.as_ref().is_none_or(|b| q.better(&b.1)) {
                            run.best = Some((all, q));
                        }
                    }
                }
            }
            // Stages 3–4: new covers.
            for info in &infos {
                for &ch in &info.charts {
                    let ctris = self.charts[ch].tris.clone();
                    // Smooth against the cover.
                    let mut ok = true;
                    for t in &ctris {
                        for k in 0..3 {
                            let (a, b) = (t[k], t[(k + 1) % 3]);
                            if let Some(fs) = em.get(&(a.min(b), a.max(b))) {
                                if fs.iter().any(|&f| self.dihedral(*t, tris[f]) >= self.thr) {
                                    ok = false;
                                }
                            }
                        }
                    }
                    if !ok {
                        continue;
                    }
                    let mut n = cover.clone();
                    n.push(ch);
                    n.sort_unstable();
                    if !seen_cover.insert(n.clone()) {
                        continue;
                    }
                    let (nt, no) = self.cover_tris(&n);
                    if !self.valid(&nt) {
                        continue;
                    }
                    let nq = self.bound(&nt, &no, &self.subtract(&nt));
                    if run.best.as_ref().is_some_and(|b| !nq.better(&b.1)) {
                        continue;
                    }
                    let subsets: Vec<Key> = queue
                        .iter()
                        .filter(|(_, (r, _))| r.iter().all(|x| n.binary_search(x).is_ok()))
                        .map(|(k, _)| *k)
                        .collect();
                    if !subsets.is_empty() {
                        if subsets.iter().all(|k| nq.better(&queue[k].1)) {
                            for k in &subsets {
                                queue.remove(k);
                            }
                        } else {
                            continue;
                        }
                    }
                    seq += 1;
                    let area = n.iter().map(|&c| self.charts[c].area).fold(0.0, f64::max);
                    queue.insert(
                        Key {
                            charts: n.len(),
                            area,
                            seq,
                        },
                        (n, nq),
                    );
                    if queue.len() > QUEUE_MAX {
                        queue.pop_last();
                    }
                }
            }
        }
        run
    }
}
