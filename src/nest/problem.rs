//! The nesting problem as data, independent of flatcut's pieces and of the ESICUP files: items
//! (polygons with holes and their allowed orientations), a container (a strip of fixed height
//! and free length, or bins of fixed size), the spacing; the search settings ([`Config`]) and
//! what a search returns ([`Solution`], or the item that fits in no orientation, `Unfit`).
//! The solver is `nest::solve`.
//!
//! An [`Item`] also keeps what every search reads and never changes: its area, its poles and
//! the shapes of the orientations the construction tries (computed once, when the item is
//! made).

use super::collision::{poles, Shape};
use glam::DVec2;
use std::sync::Arc;

pub use super::collision::Orient;

/// Strip problems (a roll) with at most this many items try, for each freely turning item,
/// the turns that make it shortest ([`Item::add_shortest_shapes`]) besides the four of its
/// smallest enclosing rectangle (`nest::nest`).
pub const FEW_ITEMS: usize = 8;
/// How many shortest turns such an item gets.
pub const SHORTEST_TURNS: usize = 2;

/// Allowed orientations of an item.
#[derive(Debug, Clone, PartialEq)]
pub enum Orients {
    /// A finite set.
    Set(Vec<Orient>),
    /// Any rotation, mirrored too when `mirror`.
    Free { mirror: bool },
}

/// An item to place. (The separator's moves of an item, `random_shape` and `nearby_shape`, are
/// in `solve/improve.rs`.)
#[derive(Debug, Clone)]
pub struct Item {
    /// Outer ring (counter-clockwise) then holes (clockwise), no repeated point.
    pub rings: Vec<Vec<DVec2>>,
    pub area: f64,
    pub(crate) poles: Vec<(DVec2, f64)>,
    pub orients: Orients,
    /// Shapes tried by the construction (for a set: all of them, in order).
    pub(crate) shapes: Vec<Arc<Shape>>,
}

impl Item {
    /// Normalises ring orientation, finds the poles and turns the construction shapes.
    pub(crate) fn new(mut rings: Vec<Vec<DVec2>>, orients: Orients) -> Item {
        use crate::geom::polygon::signed_area;
        for (k, r) in rings.iter_mut().enumerate() {
            let a = signed_area(r);
            if (k == 0) != (a > 0.0) {
                r.reverse();
            }
        }
        let area = signed_area(&rings[0]) + rings[1..].iter().map(|r| signed_area(r)).sum::<f64>();
        let poles = poles(&rings);
        let cons: Vec<Orient> = match &orients {
            Orients::Set(v) => v.clone(),
            Orients::Free { mirror } => {
                let a = crate::geom::polygon::min_area_rect_angle(&rings[0]).to_degrees();
                let mut v = Vec::new();
                for m in [false, true] {
                    if m && !mirror {
                        continue;
                    }
                    for q in 0..4 {
                        v.push(Orient {
                            angle_deg: (a + 90.0 * q as f64).rem_euclid(360.0),
                            mirror: m,
                        });
                    }
                }
                v
            }
        };
        let shapes = cons
            .iter()
            .map(|o| Arc::new(Shape::new(&rings, &poles, *o)))
            .collect();
        Item {
            rings,
            area,
            poles,
            orients,
            shapes,
        }
    }

    /// Few items (see [`FEW_ITEMS`]): add to a freely turning item's construction shapes the
    /// [`SHORTEST_TURNS`] turns that make it shortest along the container's length (x) while it
    /// fits the `height`, among the turns that lay an edge of its convex hull along x or y
    /// (rotating calipers: the narrowest width is reached with a hull edge flush), so that a
    /// lone piece on a roll takes the least roll. Items with a set of orientations and mirrored
    /// turns are left as they are.
    pub(crate) fn add_shortest_shapes(&mut self, height: f64) {
        if !matches!(self.orients, Orients::Free { .. }) {
            return;
        }
        let hull = crate::geom::polygon::convex_hull(&self.rings[0]);
        let n = hull.len();
        if n < 3 {
            return;
        }
        let mut cands: Vec<(f64, f64)> = Vec::new();
        for i in 0..n {
            let e = hull[(i + 1) % n] - hull[i];
            if e.length_squared() <= 0.0 {
                continue;
            }
            let theta = e.y.atan2(e.x).to_degrees();
            for base in [0.0, 90.0, 180.0, 270.0] {
                let deg = (base - theta).rem_euclid(360.0);
                let r = DVec2::from_angle(deg.to_radians());
                let (lo, hi) = crate::geom::polygon::bounds(hull.iter().map(|p| r.rotate(*p)))
                    .unwrap_or_default();
                let size = hi - lo;
                if size.y <= height - 1e-6 {
                    cands.push((size.x, deg));
                }
            }
        }
        cands.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        let mut added = 0;
        for (_, deg) in cands {
            if added == SHORTEST_TURNS {
                break;
            }
            let same = |o: &Orient| {
                let d = (o.angle_deg - deg).rem_euclid(360.0);
                !o.mirror && d.min(360.0 - d) < 1e-6
            };
            if self.shapes.iter().any(|s| same(&s.orient)) {
                continue;
            }
            let o = Orient {
                angle_deg: deg,
                mirror: false,
            };
            self.shapes
                .push(Arc::new(Shape::new(&self.rings, &self.poles, o)));
            added += 1;
        }
    }

    /// A freely turning item that fits `length` × `height` (a sheet) in none of its
    /// construction turns may still fit turned between them: a long thin piece across the
    /// sheet's diagonal. Add the whole degree that leaves it the most room (the larger of
    /// the two least slacks; ties: the smaller angle), and its half turn, as [`check_fit`]
    /// looks for a fit among whole degrees.
    pub(crate) fn add_fitting_shapes(&mut self, length: f64, height: f64) {
        if !matches!(self.orients, Orients::Free { .. }) || self.fits(length, height) {
            return;
        }
        let hull = crate::geom::polygon::convex_hull(&self.rings[0]);
        let best = (0..360u32)
            .filter_map(|d| {
                let o = Orient {
                    angle_deg: f64::from(d),
                    mirror: false,
                };
                let (lo, hi) = crate::geom::polygon::bounds(hull.iter().map(|p| o.apply(*p)))?;
                let slack = (length - (hi.x - lo.x)).min(height - (hi.y - lo.y));
                (slack >= -1e-9).then_some((slack, d))
            })
            .max_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)));
        if let Some((_, d)) = best {
            for deg in [d, (d + 180) % 360] {
                let o = Orient {
                    angle_deg: f64::from(deg),
                    mirror: false,
                };
                self.shapes
                    .push(Arc::new(Shape::new(&self.rings, &self.poles, o)));
            }
        }
    }

    /// Whether one of the construction shapes fits in `length` × `height`.
    pub(crate) fn fits(&self, length: f64, height: f64) -> bool {
        self.shapes
            .iter()
            .any(|s| s.size.x <= length + 1e-9 && s.size.y <= height + 1e-9)
    }

    /// Smallest length (x extent) over the construction shapes that fit the height.
    pub(crate) fn min_length(&self, height: f64) -> Option<f64> {
        self.shapes
            .iter()
            .filter(|s| s.size.y <= height + 1e-9)
            .map(|s| s.size.x)
            .min_by(f64::total_cmp)
    }
}

/// What the items go into.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Container {
    /// Height fixed, length (x) to minimise.
    Strip { height: f64 },
    /// Bins of this size: fewest bins, then the last one as short (in x) as possible.
    Bins { length: f64, height: f64 },
}

impl Container {
    pub fn height(&self) -> f64 {
        match self {
            Container::Strip { height } | Container::Bins { height, .. } => *height,
        }
    }
}

/// A whole problem.
#[derive(Debug, Clone)]
pub struct Problem {
    pub items: Vec<Item>,
    pub container: Container,
    /// Smallest distance between the material of two items.
    pub spacing: f64,
}

/// Search settings.
#[derive(Debug, Clone, Copy)]
pub struct Config {
    pub seconds: f64,
    pub seed: u64,
    pub threads: usize,
}

/// Where an item went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ItemPlacement {
    /// Bin (0 for a strip).
    pub bin: usize,
    pub orient: Orient,
    /// `container point = orient(item point) + translation`.
    pub translation: DVec2,
}

/// A feasible layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// One per item, same order as [`Problem::items`].
    pub placements: Vec<ItemPlacement>,
    /// Bins used (1 for a strip).
    pub bins: usize,
    /// Strip length used, or the length (x) used on the last bin.
    pub length: f64,
    /// Work spent by the search that found it.
    pub work: u64,
}

/// An item that fits the container in no allowed orientation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Unfit {
    pub item: usize,
    pub size: DVec2,
}

/// Check that every item fits the container in some orientation.
pub(crate) fn check_fit(prob: &Problem) -> Result<(), Unfit> {
    let h = prob.container.height();
    let max_len = match prob.container {
        Container::Strip { .. } => f64::INFINITY,
        Container::Bins { length, .. } => length,
    };
    for (i, it) in prob.items.iter().enumerate() {
        let fits = |s: &Shape| s.size.y <= h + 1e-9 && s.size.x <= max_len + 1e-9;
        let ok = match &it.orients {
            Orients::Set(_) => it.shapes.iter().any(|s| fits(s)),
            Orients::Free { mirror } => {
                it.shapes.iter().any(|s| fits(s))
                    || (0..360).any(|d| {
                        let o = Orient {
                            angle_deg: d as f64,
                            mirror: *mirror,
                        };
                        fits(&Shape::new(&it.rings, &[], o))
                    })
            }
        };
        if !ok {
            let size = it.shapes.first().map(|s| s.size).unwrap_or_default();
            return Err(Unfit { item: i, size });
        }
    }
    Ok(())
}
