//! Overlap inside one chart's layout, and what is done about it (Julius 2006, thesis §5.3
//! "fixing gussets and overlaps", after Lévy et al. 2002): the overlapping face pairs found by
//! a sweep over the triangles' boxes ([`overlaps`]), the overlapping region cut off so that
//! every part lays flat without overlap ([`cut_off`]), and the parts cut off re-attached at
//! the end to a neighbour where the merge criterion holds ([`reattach`]).
//!
//! Choices where the thesis is silent: at most [`OVERLAP_PAIRS`] pairs are looked at; the
//! faces go to the side of the pair they are nearer to through the opened chart (ties to the
//! first); at most 8 rounds of cutting off.

use super::{Charts, FlattenOptions, Laid, Layout, Whole};
use crate::geom::polygon;
use crate::geom::proxy;
use glam::DVec2;
use std::sync::Arc;

/// Two faces (indices into `uv`) of one chart's layout that overlap deeper than `eps`, if
/// any.
pub(super) fn self_overlap(uv: &[Vec<DVec2>], eps: f64) -> Option<(usize, usize)> {
    overlaps(uv, eps, 1).first().copied()
}

/// Pairs of faces (indices into `uv`) of one chart's layout that overlap deeper than `eps`,
/// at most `limit` of them, in sweep order: a sweep over x of the triangles' boxes.
pub(super) fn overlaps(uv: &[Vec<DVec2>], eps: f64, limit: usize) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut tris: Vec<([DVec2; 3], usize)> = Vec::new();
    for (k, c) in uv.iter().enumerate() {
        for t in polygon::triangulate(c).iter() {
            tris.push(([c[t[0]], c[t[1]], c[t[2]]], k));
        }
    }
    // Each triangle's box: x from, x to, y from, y to.
    let mut boxes: Vec<([f64; 4], usize)> = tris
        .iter()
        .enumerate()
        .filter_map(|(i, (t, _))| {
            polygon::bounds(t.iter().copied()).map(|(lo, hi)| ([lo.x, hi.x, lo.y, hi.y], i))
        })
        .collect();
    boxes.sort_by(|a, b| a.0[0].total_cmp(&b.0[0]).then(a.1.cmp(&b.1)));
    for (k, &([_, hx, ly, hy], i)) in boxes.iter().enumerate() {
        for &([lx, _, ly2, hy2], j) in &boxes[k + 1..] {
            if lx >= hx - eps {
                break;
            }
            // Boxes apart in y (or within `eps`): no edge of either triangle finds them
            // overlapping deeper than that either.
            if ly2 >= hy - eps || ly >= hy2 - eps {
                continue;
            }
            if tris[i].1 == tris[j].1 {
                continue;
            }
            if polygon::triangles_overlap(&tris[i].0, &tris[j].0, eps) {
                out.push((tris[i].1, tris[j].1));
                if out.len() >= limit {
                    return out;
                }
            }
        }
    }
    out
}

/// Most overlapping face pairs looked at when cutting an overlap off.
pub(super) const OVERLAP_PAIRS: usize = 10_000;

/// Cut the overlapping region off a chart laid out as `uv` (faces `faces`, opened along
/// `cuts`), after Lévy et al. 2002 (the thesis' [22]): the chart is split so that each part is
/// overlap-free. The faces of the overlapping pairs are sorted to the side of `a` or `b`
/// (nearer through the opened chart, in face steps; ties to `a`): for a gusset the two sides
/// of its slit, for a global overlap the two faces found overlapping. The side with less
/// overlapping area is cut off; the rest is its largest connected part (by area; the others
/// go with the part cut off), laid flat again, and while it still overlaps its overlapping
/// faces on that side are cut off too (at most 8 rounds). Returns the rest and the cut-off
/// part's connected pieces, each laid flat (cut into a disk where needed), or `None` when
/// some part cannot be laid flat without a flip or an overlap.
#[allow(clippy::too_many_arguments)]
pub(super) fn cut_off(
    ctx: &Charts,
    faces: &[usize],
    cuts: &[usize],
    a: &[usize],
    b: &[usize],
    pairs: &[(usize, usize)],
    uv: &[Vec<DVec2>],
    eps: f64,
    warm: bool,
) -> Option<(Laid, Vec<Laid>)> {
    let within = Within::new(ctx, faces, cuts);
    let mut sides = Sides::new(&within, a, b);
    let mut off = sides.first_cut(faces, pairs, uv, ctx.mesh.faces.len());
    let whole = warm.then(|| Whole::new(faces, uv));
    let rest = within.rest(&sides, &mut off, whole.clone(), eps)?;
    let pieces = within.pieces(&off, whole.as_deref(), eps)?;
    Some((rest, pieces))
}

/// A chart's faces joined through its uncut edges.
struct Within<'a> {
    ctx: &'a Charts<'a>,
    faces: &'a [usize],
    cuts: &'a [usize],
    /// Per mesh face: in the chart.
    inside: Vec<bool>,
}

impl<'a> Within<'a> {
    fn new(ctx: &'a Charts<'a>, faces: &'a [usize], cuts: &'a [usize]) -> Self {
        let mut inside = vec![false; ctx.mesh.faces.len()];
        for &f in faces {
            inside[f] = true;
        }
        Within {
            ctx,
            faces,
            cuts,
            inside,
        }
    }

    /// Faces joined to `f` through uncut chart edges, where `within` holds.
    fn neighbours(&self, f: usize, within: &[bool]) -> Vec<usize> {
        let is_cut = |e: usize| self.cuts.binary_search(&e).is_ok();
        self.ctx.topo.face_edges[f]
            .iter()
            .filter(|&&e| !is_cut(e))
            .filter_map(|&e| match self.ctx.topo.edges[e].uses[..] {
                [(x, _), (y, _)] if x != y => Some(if x == f { y } else { x }),
                _ => None,
            })
            .filter(|&h| within[h])
            .collect()
    }

    /// Face steps from `seeds` through the chart (`usize::MAX` where not reached).
    fn steps(&self, seeds: &[usize]) -> Vec<usize> {
        let inside = &self.inside;
        let mut d = vec![usize::MAX; inside.len()];
        let mut queue = std::collections::VecDeque::new();
        for &s in seeds {
            if inside[s] && d[s] == usize::MAX {
                d[s] = 0;
                queue.push_back(s);
            }
        }
        while let Some(f) = queue.pop_front() {
            for h in self.neighbours(f, inside) {
                if d[h] == usize::MAX {
                    d[h] = d[f] + 1;
                    queue.push_back(h);
                }
            }
        }
        d
    }

    /// The connected part of the faces where `within` holds that `f0` is in (breadth first,
    /// marking `seen`).
    fn flood(&self, f0: usize, within: &[bool], seen: &mut [bool]) -> Vec<usize> {
        let mut comp = vec![f0];
        seen[f0] = true;
        let mut k = 0;
        while k < comp.len() {
            for h in self.neighbours(comp[k], within) {
                if !seen[h] {
                    seen[h] = true;
                    comp.push(h);
                }
            }
            k += 1;
        }
        comp
    }

    /// The rest of the chart once the faces `off` are cut off: its largest connected part,
    /// laid flat; while it still overlaps, its overlapping faces on the side cut off go too
    /// (at most 8 rounds). `None` when it cannot be laid flat without a flip or an overlap.
    fn rest(
        &self,
        sides: &Sides,
        off: &mut [bool],
        mut whole: Option<Arc<Whole>>,
        eps: f64,
    ) -> Option<Laid> {
        let (ctx, faces, cuts) = (self.ctx, self.faces, self.cuts);
        let nf = off.len();
        for _ in 0..8 {
            // The rest is the largest connected part left (by area, ties: smallest face); the
            // other parts go with the cut-off faces.
            let mut keep = vec![false; nf];
            let mut best: Option<(f64, Vec<usize>)> = None;
            let mut seen = vec![false; nf];
            let free: Vec<bool> = (0..nf).map(|f| self.inside[f] && !off[f]).collect();
            for &f0 in faces {
                if off[f0] || seen[f0] {
                    continue;
                }
                let comp = self.flood(f0, &free, &mut seen);
                let area = ctx.area(&comp);
                if best.as_ref().is_none_or(|(a, _)| area > *a) {
                    best = Some((area, comp));
                }
            }
            let (_, main) = best?;
            for &f in &main {
                keep[f] = true;
            }
            for &f in faces {
                if !keep[f] {
                    off[f] = true;
                }
            }
            let rest: Vec<usize> = faces.iter().copied().filter(|&f| !off[f]).collect();
            if rest.is_empty() {
                return None;
            }
            let rc = ctx.disk(&rest, &ctx.cuts_within(&rest, cuts))?;
            let Ok(Layout::Laid(ruv, rs)) = ctx.lay_from(&rest, &rc, whole.as_deref()) else {
                return None;
            };
            if rs.flipped > 0 {
                return None;
            }
            let more = overlaps(&ruv, eps, OVERLAP_PAIRS);
            if more.is_empty() {
                return Some(Laid {
                    faces: rest,
                    cuts: rc,
                    uv: ruv,
                    stretch: rs,
                    gusset: false,
                });
            }
            // The next round starts from this one's layout.
            if whole.is_some() {
                whole = Some(Whole::new(&rest, &ruv));
            }
            let mut grew = false;
            for (x, y) in more {
                for k in [x, y] {
                    let f = rest[k];
                    if sides.side(f) && !off[f] {
                        off[f] = true;
                        grew = true;
                    }
                }
            }
            if !grew {
                return None;
            }
        }
        None
    }

    /// The faces cut off, by connected piece (face order: ascending), each laid flat (cut
    /// into a disk where needed); `None` when one flips or overlaps itself.
    fn pieces(&self, off: &[bool], whole: Option<&Whole>, eps: f64) -> Option<Vec<Laid>> {
        let (ctx, cuts) = (self.ctx, self.cuts);
        let mut seen = vec![false; off.len()];
        let mut pieces = Vec::new();
        for &f0 in self.faces {
            if !off[f0] || seen[f0] {
                continue;
            }
            let mut comp = self.flood(f0, off, &mut seen);
            comp.sort_unstable();
            let pc = ctx.disk(&comp, &ctx.cuts_within(&comp, cuts))?;
            let Ok(Layout::Laid(puv, ps)) = ctx.lay_from(&comp, &pc, whole) else {
                return None;
            };
            if ps.flipped > 0 || (comp.len() > 1 && self_overlap(&puv, eps).is_some()) {
                return None;
            }
            pieces.push(Laid {
                faces: comp,
                cuts: pc,
                uv: puv,
                stretch: ps,
                gusset: true,
            });
        }
        Some(pieces)
    }
}

/// The two sides of an overlap: each face of the chart goes with the nearer of `a` and `b`
/// (in face steps through the opened chart; ties to `a`).
struct Sides {
    da: Vec<usize>,
    db: Vec<usize>,
    /// The side cut off is `a`'s.
    take_a: bool,
}

impl Sides {
    fn new(within: &Within, a: &[usize], b: &[usize]) -> Self {
        let (da, db) = (within.steps(a), within.steps(b));
        Sides {
            da,
            db,
            take_a: false,
        }
    }

    fn on_a(&self, f: usize) -> bool {
        self.da[f] <= self.db[f]
    }

    /// Whether face `f` is on the side cut off.
    fn side(&self, f: usize) -> bool {
        self.on_a(f) == self.take_a
    }

    /// The faces of the overlapping `pairs` (indices into `faces` and `uv`) on the side with
    /// less overlapping area: that side is cut off (chosen here); per mesh face, cut off.
    fn first_cut(
        &mut self,
        faces: &[usize],
        pairs: &[(usize, usize)],
        uv: &[Vec<DVec2>],
        nf: usize,
    ) -> Vec<bool> {
        let area2 = |k: usize| polygon::signed_area(&uv[k]).abs();
        let (mut sa, mut sb) = (0.0, 0.0);
        let mut fa: Vec<usize> = Vec::new();
        let mut fb: Vec<usize> = Vec::new();
        for &(x, y) in pairs {
            for k in [x, y] {
                let f = faces[k];
                if self.on_a(f) {
                    sa += area2(k);
                    fa.push(f);
                } else {
                    sb += area2(k);
                    fb.push(f);
                }
            }
        }
        self.take_a = !fa.is_empty() && (fb.is_empty() || sa <= sb);
        let mut off = vec![false; nf];
        for f in if self.take_a { fa } else { fb } {
            off[f] = true;
        }
        off
    }
}

/// Lay `done[k]` and `done[part]` out as one chart (the cuts of both, more where the union is
/// not a disk); when that is flip-free, within the tolerance, without overlap and with its
/// seams matched (`seam_error` within [`FlattenOptions::seam_tolerance`]: a union whose
/// border cannot have its 3D lengths would only be halved again once all charts are laid), it
/// becomes `done[k]` and true is returned (`done[part]` is left for the caller to drop).
pub(super) fn merge_into(
    ctx: &Charts,
    done: &mut [Laid],
    k: usize,
    part: usize,
    opts: &FlattenOptions,
    eps: f64,
) -> bool {
    match merged(ctx, done, k, part, opts, eps) {
        Some(l) => {
            done[k] = l;
            true
        }
        None => false,
    }
}

/// `done[k]` and `done[part]` laid out as one ([`laid_as_one`]), when the union is kept by the
/// checks of [`merge_into`].
fn merged(
    ctx: &Charts,
    done: &[Laid],
    k: usize,
    part: usize,
    opts: &FlattenOptions,
    eps: f64,
) -> Option<Laid> {
    laid_as_one(ctx, done, k, part).filter(|l| keeps(ctx, l, opts, eps))
}

/// Whether a layout made by merging pieces is kept: flip-free, within the tolerance, its seams
/// matched and without overlap (deeper than `eps`).
pub(super) fn keeps(ctx: &Charts, l: &Laid, opts: &FlattenOptions, eps: f64) -> bool {
    l.stretch.flipped == 0
        && l.stretch.l2 <= opts.tolerance
        && ctx.seam_error(l) <= opts.seam_tolerance
        && self_overlap(&l.uv, eps).is_none()
}

/// The first of the neighbours `near` that `done[part]` merges into ([`merge_into`]) and
/// the union, as trying them in order finds it ([`Failed::first`]). A pair `failed` already
/// is skipped; one that fails now is noted there, and so is a union over the tolerance
/// ([`Trial::Stretched`]).
pub(super) fn first_merge(
    ctx: &Charts,
    done: &[Laid],
    near: &[usize],
    part: usize,
    opts: &FlattenOptions,
    eps: f64,
    failed: &Failed,
) -> Option<(usize, Laid)> {
    failed.first(Trial::Merge, done, near, part, |k| {
        let l = laid_as_one(ctx, done, k, part)?;
        if l.stretch.l2 > opts.tolerance {
            failed.note(Trial::Stretched, &done[k], &done[part]);
        }
        Some(l).filter(|l| keeps(ctx, l, opts, eps))
    })
}

/// The trials on a pair of pieces that [`Failed`] remembers.
#[derive(Debug, Clone, Copy, Hash)]
pub(super) enum Trial {
    /// Laid out as one ([`first_merge`]).
    Merge,
    /// Shared out ([`super::merge`]'s `rebalance`).
    Share,
    /// Hinged ([`super::hinge`]).
    Hinge,
    /// Laid out as one with a slit ([`super::slit`]).
    Slit,
    /// Shared out where the two overlap ([`super::merge::share_apart`]).
    Apart,
    /// Shared out across a piece too long for the sheet ([`super::merge::share_across`]).
    Across,
    /// Laid out as one with darts ([`super::slit::dart_merge`]).
    Dart,
    /// Shared out where the two overlap, the smaller part hinged onto a piece next to it
    /// ([`super::hinge`]'s `pass_on`).
    Pass,
    /// Laid out as one without the cuts of either ([`super::slit::uncut_merge`]).
    Uncut,
    /// Laid out as one with the cuts of both ([`first_merge`]), over the tolerance: with fewer
    /// cuts the layout has less room, not more, so [`Trial::Uncut`] is not tried.
    Stretched,
}

/// Pairs of pieces, as they are laid (faces, cuts, layout), that a [`Trial`] failed on. A
/// trial is a function of the two pieces alone (and of options that stay the same while the
/// pieces are merged), so it fails again while neither has changed: the rounds of merging
/// and hinging skip it. A pair is known by a 128-bit digest of both pieces. A pass
/// ([`Trial::Pass`]) also depends on the pieces round the two; it is not tried again while
/// the two are the same all the same (a bound on the work, the result still a function of
/// the input).
#[derive(Default)]
pub(super) struct Failed(std::sync::Mutex<std::collections::HashSet<u128>>);

impl Failed {
    fn key(trial: Trial, a: &Laid, b: &Laid) -> u128 {
        use std::hash::{Hash, Hasher};
        let half = |salt: u8| {
            let mut h = std::collections::hash_map::DefaultHasher::new();
            (salt, trial).hash(&mut h);
            for l in [a, b] {
                (&l.faces, &l.cuts, l.gusset).hash(&mut h);
                for q in l.uv.iter().flatten() {
                    (q.x.to_bits(), q.y.to_bits()).hash(&mut h);
                }
            }
            h.finish() as u128
        };
        half(0) << 64 | half(1)
    }

    /// Note that `trial` failed on `a` and `b` as they are.
    pub(super) fn note(&self, trial: Trial, a: &Laid, b: &Laid) {
        let key = Self::key(trial, a, b);
        if let Ok(mut s) = self.0.lock() {
            s.insert(key);
        }
    }

    /// Whether `trial` failed on `a` and `b` as they are.
    pub(super) fn known(&self, trial: Trial, a: &Laid, b: &Laid) -> bool {
        let key = Self::key(trial, a, b);
        self.0.lock().is_ok_and(|s| s.contains(&key))
    }

    /// `run` (`trial` on `a` and `b`), unless it failed on them as they are already; a
    /// failure (`None`) is noted.
    pub(super) fn attempt<T>(
        &self,
        trial: Trial,
        a: &Laid,
        b: &Laid,
        run: impl FnOnce() -> Option<T>,
    ) -> Option<T> {
        let key = Self::key(trial, a, b);
        if self.0.lock().is_ok_and(|s| s.contains(&key)) {
            return None;
        }
        let out = run();
        if out.is_none() {
            if let Ok(mut s) = self.0.lock() {
                s.insert(key);
            }
        }
        out
    }

    /// The first of the neighbours `near`, in order, on which `trial` with `done[part]` gives
    /// something (`run` of the neighbour, through [`Failed::attempt`]), and what it gave. Two
    /// are tried at a time where a thread is idle ([`crate::geom::par::first`]): a trial is a
    /// function of the two pieces alone, so the answer is the one trying them in turn finds.
    pub(super) fn first<T: Send>(
        &self,
        trial: Trial,
        done: &[Laid],
        near: &[usize],
        part: usize,
        run: impl Fn(usize) -> Option<T> + Sync,
    ) -> Option<(usize, T)> {
        crate::geom::par::first(near, |&k| {
            self.attempt(trial, &done[k], &done[part], || run(k))
        })
        .map(|(i, r)| (near[i], r))
    }
}

/// `done[k]` and `done[part]` laid out as one chart (the cuts of both, more where the union
/// is not a disk), started from the two layouts as they lie, one moved onto the other
/// ([`super::join::moved_onto`]); `None` when it cannot be laid out. Not checked.
pub(super) fn laid_as_one(ctx: &Charts, done: &[Laid], k: usize, part: usize) -> Option<Laid> {
    let (faces, cuts) = as_one(ctx, &done[k], &done[part])?;
    let joined = super::join::moved_onto(ctx, done, k, part).map(|j| Whole::new(&j.faces, &j.uv));
    let Ok(Layout::Laid(uv, stretch)) = ctx.lay_from(&faces, &cuts, joined.as_deref()) else {
        return None;
    };
    Some(Laid {
        faces,
        cuts,
        uv,
        stretch,
        gusset: false,
    })
}

/// The faces of `a` and `b` as one chart (those of `a` first) and its cuts: those of both, more
/// where the two as one are not a disk; `None` when they cannot be cut into one.
pub(super) fn as_one(ctx: &Charts, a: &Laid, b: &Laid) -> Option<(Vec<usize>, Vec<usize>)> {
    let mut faces = a.faces.clone();
    faces.extend(&b.faces);
    let cuts = ctx.disk(&faces, &both_cuts(a, b))?;
    Some((faces, cuts))
}

/// The cuts of two charts merged into one (sorted).
pub(super) fn both_cuts(a: &Laid, b: &Laid) -> Vec<usize> {
    let mut cuts = a.cuts.clone();
    cuts.extend(&b.cuts);
    cuts.sort_unstable();
    cuts.dedup();
    cuts
}

/// Re-attach each gusset (and each part cut off for overlapping) to an adjacent piece when
/// the merging criterion of §5.2.3 holds and the merge creates no new overlap (§5.3): the
/// neighbours are tried by the length of the common boundary, longest first (ties: lower
/// piece); the criterion is the mean cylinder fitting error of the gusset's faces and two
/// rings of the neighbour's faces around their common boundary below
/// [`FlattenOptions::reattach_eta`]; the merged chart (cut into a disk where needed) must lay
/// flat with no flip, no overlap, an L2 stretch within the tolerance and its seams matched
/// ([`merge_into`]). The piece a gusset was cut from fails the overlap test by construction
/// (that is why it was cut off), unless its layout has changed since.
pub(super) fn reattach(ctx: &Charts, done: &mut Vec<Laid>, opts: &FlattenOptions, eps: f64) {
    if !done.iter().any(|l| l.gusset) {
        return;
    }
    let nf = ctx.mesh.faces.len();
    let mut owners = Owners::new(nf, done);
    let mut order: Vec<usize> = (0..done.len()).filter(|&k| done[k].gusset).collect();
    order.sort_by_key(|&k| done[k].faces.iter().copied().min().unwrap_or(0));
    for gi in order {
        for k in owners.neighbours(ctx, done, gi) {
            // Two rings of the neighbour around the common boundary, and the gusset.
            let mut region: Vec<usize> = done[gi].faces.clone();
            let mut mark = vec![false; nf];
            for &f in &region {
                mark[f] = true;
            }
            let mut front: Vec<usize> = region.clone();
            for _ in 0..2 {
                let mut next = Vec::new();
                for &f in &front {
                    for &(h, _) in &ctx.graph.adj[f] {
                        if owners.owner[h] == k && !mark[h] {
                            mark[h] = true;
                            next.push(h);
                        }
                    }
                }
                region.extend(&next);
                front = next;
            }
            match proxy::cylinder_error(&ctx.graph.moments(region.iter().copied())) {
                Some(err) if err < opts.reattach_eta => {}
                _ => continue,
            }
            if merge_into(ctx, done, k, gi, opts, eps) {
                owners.absorb(done, k, gi);
                break;
            }
        }
    }
    owners.drop_gone(done);
}

/// Which laid chart owns each face while charts are merged ([`reattach`], `merge`), and
/// which charts a merge has emptied.
pub(super) struct Owners {
    pub(super) owner: Vec<usize>,
    pub(super) gone: Vec<bool>,
}

impl Owners {
    pub(super) fn new(nf: usize, done: &[Laid]) -> Owners {
        let mut owner = vec![usize::MAX; nf];
        for (k, l) in done.iter().enumerate() {
            for &f in &l.faces {
                owner[f] = k;
            }
        }
        Owners {
            owner,
            gone: vec![false; done.len()],
        }
    }

    /// The charts next to `done[part]`, by the length of boundary they share with it
    /// (longest first, ties: lower chart).
    pub(super) fn neighbours(&self, ctx: &Charts, done: &[Laid], part: usize) -> Vec<usize> {
        let mut shared: std::collections::BTreeMap<usize, f64> = Default::default();
        for &f in &done[part].faces {
            for &(h, len) in &ctx.graph.adj[f] {
                let k = self.owner[h];
                if k != part && k != usize::MAX && !self.gone[k] {
                    *shared.entry(k).or_default() += len;
                }
            }
        }
        let mut cands: Vec<(f64, usize)> = shared.into_iter().map(|(k, l)| (l, k)).collect();
        cands.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
        cands.into_iter().map(|(_, k)| k).collect()
    }

    /// The first `n` of [`Owners::neighbours`].
    pub(super) fn nearest(&self, ctx: &Charts, done: &[Laid], part: usize, n: usize) -> Vec<usize> {
        let mut near = self.neighbours(ctx, done, part);
        near.truncate(n);
        near
    }

    /// `done[part]` was merged into `done[k]`.
    pub(super) fn absorb(&mut self, done: &[Laid], k: usize, part: usize) {
        for &f in &done[part].faces {
            self.owner[f] = k;
        }
        self.gone[part] = true;
    }

    /// The two parts of a share-out in place of the two pieces: `done[k]` becomes `ha`,
    /// `done[si]` becomes `hb`, each owning its faces.
    pub(super) fn shared(
        &mut self,
        done: &mut [Laid],
        (k, si): (usize, usize),
        (ha, hb): (Laid, Laid),
    ) {
        done[k] = ha;
        done[si] = hb;
        for p in [k, si] {
            for &f in &done[p].faces {
                self.owner[f] = p;
            }
        }
    }

    /// Drop the charts merged into others.
    pub(super) fn drop_gone(&self, done: &mut Vec<Laid>) {
        let mut k = 0;
        done.retain(|_| {
            k += 1;
            !self.gone[k - 1]
        });
    }
}
