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
