//! LODT + LMBT (§4), kept for comparison: the greedy walk; when neither successor is valid it
//! finds the nearest valid bridge `E_{i',j'}` with i' > i and j' > j (fewest steps, then the
//! one most balanced between P and Q, then smaller i'), or the ending bridge if there is
//! none, and reaches it by LMBT.

use super::{Step, Strip};

impl Strip {
    /// LODT + LMBT (§4).
    pub(super) fn local(&self) -> Vec<Step> {
        let (m, n) = (self.m(), self.n());
        let valid = |i: usize, j: usize| self.is_end(i, j) || self.locally_convex(i, j);
        let mut steps = Vec::with_capacity(m + n - 2);
        let (mut i, mut j) = (0, 0);
        let mut prev = Step::P;
        // Steps of least energy at the current bridge, with a forced choice at the borders.
        let lmbt_step = |i: usize, j: usize, prev: Step, ti: usize, tj: usize| -> Step {
            if i == ti {
                Step::Q
            } else if j == tj {
                Step::P
            } else if self.energy(i, j, prev, Step::Q) < self.energy(i, j, prev, Step::P) {
                Step::Q
            } else {
                Step::P
            }
        };
        while i + 1 < m || j + 1 < n {
            let s = if i + 1 == m {
                Step::Q
            } else if j + 1 == n {
                Step::P
            } else {
                match (valid(i + 1, j), valid(i, j + 1)) {
                    (true, false) => Step::P,
                    (false, true) => Step::Q,
                    (true, true) => lmbt_step(i, j, prev, m, n),
                    (false, false) => {
                        // Nearest valid bridge beyond, then LMBT to it.
                        let (ti, tj) = self.nearest_valid(i, j);
                        while i < ti || j < tj {
                            let s = lmbt_step(i, j, prev, ti, tj);
                            steps.push(s);
                            match s {
                                Step::P => i += 1,
                                Step::Q => j += 1,
                            }
                            prev = s;
                        }
                        continue;
                    }
                }
            };
            steps.push(s);
            match s {
                Step::P => i += 1,
                Step::Q => j += 1,
            }
            prev = s;
        }
        steps
    }

    /// Nearest valid bridge (i', j') with i' > i and j' > j, else the ending bridge.
    fn nearest_valid(&self, i: usize, j: usize) -> (usize, usize) {
        let (m, n) = (self.m(), self.n());
        let max_d = (m - 1 - i) + (n - 1 - j);
        for d in 2..=max_d {
            // Most balanced first, then smaller i'.
            let mut cands: Vec<(usize, usize)> = (1..d)
                .map(|di| (i + di, j + d - di))
                .filter(|&(a, b)| a < m && b < n)
                .collect();
            cands.sort_by_key(|&(a, b)| ((a - i).abs_diff(b - j), a));
            for (a, b) in cands {
                if self.is_end(a, b) || self.locally_convex(a, b) {
                    return (a, b);
                }
            }
        }
        (m - 1, n - 1)
    }
}
