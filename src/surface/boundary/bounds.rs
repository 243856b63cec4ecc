//! §5.1.1 cover quality: a lower bound for every triangulation that contains a cover.
//!
//! Smoothness (largest dihedral angle below `max_dihedral`), predictability
//! (interior triangles: no edge on the input polyline), fairness (sum of squared dihedral
//! angles over interior edges). Triangulations and covers compare predictability first, then
//! fairness. A cover's quality is a lower bound: its own interior triangles plus one per
//! subloop touching more than two of its charts; its own squared angles plus, per subloop
//! touching two or more charts, `(α₁ + α₂)² / (n − 1)` with αᵢ the angle between the
//! subloop's plane and the nearest triangle of the first two charts (by id: the paper's
//! "random pair", made deterministic).
//!
//! Subloop plane for the fairness bound: Newell's normal through the centroid.

use super::bnb::{EdgeMap, Search};
use super::Quality;
use crate::geom::mesh::newell;
use glam::DVec3;
use std::collections::BTreeMap;

impl Search<'_> {
    pub(super) fn edge_map(tris: &[[usize; 3]]) -> EdgeMap {
        let mut e: EdgeMap = BTreeMap::new();
        for (i, t) in tris.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                e.entry((a.min(b), a.max(b))).or_default().push(i);
            }
        }
        e
    }

    pub(super) fn cover_tris(&self, cover: &[usize]) -> (Vec<[usize; 3]>, Vec<usize>) {
        let mut tris = Vec::new();
        let mut owner = Vec::new();
        for &c in cover {
            for t in &self.charts[c].tris {
                tris.push(*t);
                owner.push(c);
            }
        }
        (tris, owner)
    }

    /// §5.1.1 cover quality: a lower bound for every triangulation containing the cover.
    pub(super) fn bound(
        &self,
        tris: &[[usize; 3]],
        owner: &[usize],
        subs: &[Vec<usize>],
    ) -> Quality {
        let em = Self::edge_map(tris);
        let mut q = Quality {
            interior: tris.iter().filter(|t| self.interior(**t)).count(),
            fairness: 0.0,
        };
        for fs in em.values() {
            if fs.len() == 2 {
                let a = self.dihedral(tris[fs[0]], tris[fs[1]]);
                q.fairness += a * a;
            }
        }
        for s in subs {
            let n = s.len();
            // Charts touching the subloop, each with its triangles on it.
            let mut touching: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
            for k in 0..n {
                let (a, b) = (s[k], s[(k + 1) % n]);
                if let Some(fs) = em.get(&(a.min(b), a.max(b))) {
                    for &f in fs {
                        touching.entry(owner[f]).or_default().push(f);
                    }
                }
            }
            if touching.len() > 2 {
                q.interior += 1;
            }
            if touching.len() >= 2 {
                let pts: Vec<DVec3> = s.iter().map(|&v| self.p[v]).collect();
                let pn = newell(&pts).normalize_or_zero();
                let alpha: Vec<f64> = touching
                    .values()
                    .take(2)
                    .map(|fs| {
                        fs.iter()
                            .map(|&f| {
                                let c = pn.dot(self.normal(tris[f])).abs().min(1.0);
                                c.acos()
                            })
                            .fold(f64::INFINITY, f64::min)
                    })
                    .collect();
                let sum = alpha.iter().sum::<f64>();
                q.fairness += sum * sum / (n as f64 - 1.0);
            }
        }
        q
    }

    /// Quality of `add` next to `base` (edges inside `add` and between the two), or `None`
    /// when some of those edges bend more than the threshold.
    pub(super) fn added(
        &self,
        base_em: &EdgeMap,
        base: &[[usize; 3]],
        add: &[[usize; 3]],
    ) -> Option<Quality> {
        let em = Self::edge_map(add);
        let mut q = Quality {
            interior: add.iter().filter(|t| self.interior(**t)).count(),
            fairness: 0.0,
        };
        for (e, fs) in &em {
            let mut pair = fs.iter().map(|&f| add[f]).collect::<Vec<_>>();
            if let Some(bs) = base_em.get(e) {
                pair.extend(bs.iter().map(|&f| base[f]));
            }
            if pair.len() == 2 {
                let a = self.dihedral(pair[0], pair[1]);
                if a >= self.thr {
                    return None;
                }
                q.fairness += a * a;
            }
        }
        Some(q)
    }
}
