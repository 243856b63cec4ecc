//! Bend lines as a sheet-metal shop marks them (`bend_lines = "shop"`, the default of
//! `flatcut fitting`): a few rulings, each bent by the same share of the whole bend, far enough
//! apart that a brake operator can bump them one by one and read the note beside each.
//!
//! A finely sampled strip has a ruling every few millimetres, each bending by a degree or two
//! (a Ø300 cone at the default tolerance: 211 rulings of 0–3°); nobody marks those. A shop
//! divides the development into equal bends instead: N lines, each standing for 1/N of the
//! total turn, placed where that share of the bending is centred.
//!
//! Choices where nothing else decides:
//! - The bending is shared out by cumulative angle: ruling `k` carries the interval
//!   `[C(k−1), C(k)]` of the cumulative absolute angle `C`, the total `T` is cut into N equal
//!   shares, and a ruling whose interval straddles two shares gives each its part, so on a cone
//!   every line carries T/N exactly instead of the jitter of whole rulings (12°, 14°, 12°, …).
//!   Its sign (mountain or valley) is the ruling's own, so the angles always add up to the
//!   strip's. Only rulings that bend themselves (more than 0.01°) are picked: no line falls
//!   inside a flat triangle. Shares whose lines fall on the same ruling (a sharp crease that
//!   carries more than one share) make one line with their sum.
//! - Which ruling of a share: a strip's bridges come in fans (several bridges from one point of
//!   a curve), each skewed by up to half a segment of the other curve from the surface's true
//!   ruling there. The line is the bridge at the share's middle, or one in the middle half of
//!   the share (by cumulative angle) whose ends lie closer to the true ruling through it (a
//!   straight line fitted to the bridges' end positions, [`ideal`]) by more than half its
//!   distance from the middle one. On a Ø300 cone the lines then cut the two edges of the
//!   blank at even steps, as a shop lays them out, instead of 11 to 16 mm apart along the
//!   short one.
//! - N is the largest number of lines that keeps every two neighbours at least
//!   [`SHOP_MIN_MM`] apart, measured as the `along` positions the caller gives (the distance
//!   between the bridges' midpoints along the strip: where the notes are written). 20 mm: a
//!   brake's narrow die and a 3 mm note both fit between two lines, and a Ø300 cone gets
//!   about 30 bends of 11–12°, a common bump schedule.

/// Least distance (mm) between two neighbouring shop bend lines, along the strip's middle.
pub const SHOP_MIN_MM: f64 = 20.0;

/// Rulings that bend less than this (degrees) are never picked.
const EPS_DEG: f64 = 0.01;

/// One ruling of a strip, in order along it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ruling {
    /// mm from the strip's start along its middle (between bridge midpoints).
    pub along: f64,
    /// mm from the start along each of the two boundaries to the ruling's ends (both `along`
    /// where only the middle is known).
    pub ends: [f64; 2],
    /// Signed bend angle, degrees.
    pub deg: f64,
}

impl Ruling {
    /// A ruling known by its middle only.
    pub fn at(along: f64, deg: f64) -> Ruling {
        Ruling {
            along,
            ends: [along, along],
            deg,
        }
    }

    fn mass(&self) -> f64 {
        if self.deg.is_finite() {
            self.deg.abs()
        } else {
            0.0
        }
    }
}

/// The rulings a shop marks: the picked indices in order and the angle each line stands for
/// (degrees, signed).
pub fn picks(rulings: &[Ruling]) -> Vec<(usize, f64)> {
    let total: f64 = rulings.iter().map(Ruling::mass).sum();
    let eligible: Vec<usize> = (0..rulings.len())
        .filter(|&k| rulings[k].mass() > EPS_DEG)
        .collect();
    let (Some(&first), Some(&last)) = (eligible.first(), eligible.last()) else {
        return Vec::new();
    };
    if total.is_nan() || total <= EPS_DEG {
        return Vec::new();
    }
    let length = (rulings[last].along - rulings[first].along).abs();
    let most = ((length / SHOP_MIN_MM).floor() as usize + 1).min(eligible.len());
    for n in (1..=most).rev() {
        let lines = share(rulings, &eligible, total, n);
        let apart = lines
            .windows(2)
            .all(|w| (rulings[w[1].0].along - rulings[w[0].0].along).abs() >= SHOP_MIN_MM);
        if apart || n == 1 {
            return lines;
        }
    }
    Vec::new()
}

/// `n` equal shares of the total bend `total` (degrees): (ruling index, signed angle), in
/// order, shares on one ruling merged. Each share's line is the eligible ruling in the middle
/// half of the share (by cumulative angle) that lies closest, at both ends, to the surface's
/// true ruling through it (see [`ideal`]): of a fan of bridges from one point, the one along
/// the surface, not one skewed by half a segment of the curves.
fn share(rulings: &[Ruling], eligible: &[usize], total: f64, n: usize) -> Vec<(usize, f64)> {
    let cell = total / n as f64;
    // Cumulative absolute angle at the start of each ruling's interval.
    let mut start = Vec::with_capacity(rulings.len());
    let mut c = 0.0;
    for r in rulings {
        start.push(c);
        c += r.mass();
    }
    // The signed angle of each cell: every ruling's part of it.
    let mut angles = vec![0.0; n];
    for (j, r) in rulings.iter().enumerate() {
        if r.mass() == 0.0 {
            continue;
        }
        let (a, b) = (start[j], start[j] + r.mass());
        let first = ((a / cell).floor() as usize).min(n - 1);
        let last = ((b / cell).floor() as usize).min(n - 1);
        for (i, angle) in angles.iter_mut().enumerate().take(last + 1).skip(first) {
            let (lo, hi) = (i as f64 * cell, (i + 1) as f64 * cell);
            let part = (b.min(hi) - a.max(lo)).max(0.0);
            *angle += part * r.deg.signum();
        }
    }
    let mid_of = |k: usize| start[k] + 0.5 * rulings[k].mass();
    let mut out: Vec<(usize, f64)> = Vec::new();
    let mut k = 0;
    for (i, angle) in angles.into_iter().enumerate() {
        let (lo, hi) = (i as f64 * cell, (i + 1) as f64 * cell);
        let mid = 0.5 * (lo + hi);
        // The eligible ruling holding the middle (else the next one).
        while k + 1 < eligible.len() && start[eligible[k]] + rulings[eligible[k]].mass() < mid {
            k += 1;
        }
        // How far a ruling's ends are from the surface's true ruling through its middle.
        let skew = |j: usize| {
            let (e, want) = (
                rulings[j].ends,
                ideal(rulings, eligible, &mid_of, mid_of(j), cell),
            );
            (e[0] - want[0]).abs() + (e[1] - want[1]).abs()
        };
        // Candidates: the rulings in the middle half of the share.
        let (qlo, qhi) = (lo + 0.25 * cell, hi - 0.25 * cell);
        let from = eligible.partition_point(|&j| start[j] + rulings[j].mass() <= qlo);
        // A straighter ruling wins over the one at the middle if it is straighter by more
        // than half of how far from it it lies (so a uniform strip keeps its lines evenly
        // spaced).
        let score =
            |j: usize| skew(j) + 0.5 * (rulings[j].along - rulings[eligible[k]].along).abs();
        let mut pick = (eligible[k], score(eligible[k]));
        for &j in eligible[from..].iter().take_while(|&&j| start[j] < qhi) {
            let s = score(j);
            if s < pick.1 {
                pick = (j, s);
            }
        }
        let pick = pick.0;
        match out.last_mut() {
            Some(last) if last.0 == pick => last.1 += angle,
            _ => out.push((pick, angle)),
        }
    }
    out
}

/// Where the ends of the surface's true ruling at cumulative angle `m` lie: a straight line
/// fitted (least squares) to the ends of the eligible rulings within a share `cell` either
/// side, against their interval middles; it runs through a staircase of fans, not along it.
fn ideal(
    rulings: &[Ruling],
    eligible: &[usize],
    mid_of: &dyn Fn(usize) -> f64,
    m: f64,
    cell: f64,
) -> [f64; 2] {
    let from = eligible.partition_point(|&j| mid_of(j) < m - cell);
    let near: Vec<usize> = eligible[from..]
        .iter()
        .copied()
        .take_while(|&j| mid_of(j) <= m + cell)
        .collect();
    let Some(&first) = near.first() else {
        let j = eligible[from.min(eligible.len() - 1)];
        return rulings[j].ends;
    };
    let n = near.len() as f64;
    let xm = near.iter().map(|&j| mid_of(j)).sum::<f64>() / n;
    let sxx: f64 = near.iter().map(|&j| (mid_of(j) - xm).powi(2)).sum();
    let mut out = rulings[first].ends;
    for (e, o) in out.iter_mut().enumerate() {
        let ym = near.iter().map(|&j| rulings[j].ends[e]).sum::<f64>() / n;
        let sxy: f64 = near
            .iter()
            .map(|&j| (mid_of(j) - xm) * (rulings[j].ends[e] - ym))
            .sum();
        let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
        *o = ym + slope * (m - xm);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cone_gets_equal_bends_at_least_the_spacing_apart() {
        // 211 rulings 3.4 mm apart, each 1.6°: 717 mm and 337.6° in all.
        let r: Vec<Ruling> = (0..211).map(|k| Ruling::at(3.4 * k as f64, 1.6)).collect();
        let p = picks(&r);
        let n = p.len();
        assert!((30..=36).contains(&n), "{n} lines");
        for (_, a) in &p {
            assert!((a - 337.6 / n as f64).abs() < 1e-9, "{a}");
        }
        for w in p.windows(2) {
            assert!(r[w[1].0].along - r[w[0].0].along >= SHOP_MIN_MM);
        }
        let sum: f64 = p.iter().map(|x| x.1).sum();
        assert!((sum - 337.6).abs() < 1e-9);
    }

    #[test]
    fn creases_take_whole_shares_and_flat_rulings_none() {
        // Four 90° creases 100 mm apart with flat rulings between: four lines of 90°.
        let mut r = Vec::new();
        for k in 0..400 {
            let deg = if k % 100 == 50 { 90.0 } else { 0.0 };
            r.push(Ruling::at(k as f64, deg));
        }
        let p = picks(&r);
        assert_eq!(
            p,
            vec![(50, 90.0), (150, 90.0), (250, 90.0), (350, 90.0)],
            "{p:?}"
        );
        assert!(picks(&[Ruling::at(0.0, 0.0), Ruling::at(5.0, 0.001)]).is_empty());
        assert!(picks(&[]).is_empty());
    }

    #[test]
    fn of_a_fan_the_bridge_along_the_true_ruling_is_picked() {
        // Rulings 1 mm apart at one end; at the other, fans: four bridges share each point
        // (0, 4, 8, …, each the nearest to its bridges). The surface's rulings run straight
        // across, so each pick is the bridge of its fan whose ends are equally far along.
        let r: Vec<Ruling> = (0..400)
            .map(|k| Ruling {
                along: k as f64,
                ends: [k as f64, 4.0 * (k as f64 / 4.0).round()],
                deg: 1.0,
            })
            .collect();
        let p = picks(&r);
        assert!(p.len() >= 15, "{}", p.len());
        for (k, _) in &p {
            let e = r[*k].ends;
            assert!((e[0] - e[1]).abs() < 0.5, "{e:?}");
        }
    }
}
