//! Nest stage: places pieces on sheets (or along a roll) without overlap, inside the margins
//! and with the requested spacing between pieces, as a [`Layout`].
//!
//! This first nesting is rectangle based and always correct, not dense: each piece is turned to
//! its minimum-area bounding rectangle (rotating calipers over the convex hull) with the long
//! side along x (across the roll), turned a further 90° only when that is the only way it
//! fits, and the rectangles are packed in shelves, tallest first (first-fit decreasing height),
//! opening new sheets as needed. Irregular nesting is a later stage of this module.
//!
//! A piece larger than the usable sheet is an error that gives both sizes.

use crate::geom::polygon;
use crate::pattern::Piece;
use glam::DVec2;

/// Sheet or roll and the distances to keep.
#[derive(Debug, Clone, PartialEq)]
pub struct NestOptions {
    /// Sheet width (mm), or the roll width.
    pub width: f64,
    /// Sheet height (mm); `None` for a roll of unlimited length.
    pub height: Option<f64>,
    /// Empty border kept on every side (mm).
    pub margin: f64,
    /// Gap between pieces (mm).
    pub spacing: f64,
}

impl Default for NestOptions {
    /// A4 portrait, 5 mm margin, 3 mm spacing.
    fn default() -> Self {
        NestOptions {
            width: 210.0,
            height: Some(297.0),
            margin: 5.0,
            spacing: 3.0,
        }
    }
}

/// Where a piece goes: `sheet point = rotate(piece point, rotation) + offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    pub sheet: usize,
    /// Radians, counter-clockwise.
    pub rotation: f64,
    pub offset: DVec2,
}

impl Placement {
    pub fn apply(&self, p: DVec2) -> DVec2 {
        DVec2::from_angle(self.rotation).rotate(p) + self.offset
    }
}

/// One sheet of material.
#[derive(Debug, Clone, PartialEq)]
pub struct Sheet {
    pub width: f64,
    /// For a roll: the length used, including the margin at the end.
    pub height: f64,
    /// Pieces on this sheet (indices into [`Layout::pieces`]).
    pub pieces: Vec<usize>,
}

/// Pieces and where they go.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    pub pieces: Vec<Piece>,
    /// One per piece, same order.
    pub placements: Vec<Placement>,
    pub sheets: Vec<Sheet>,
    pub roll: bool,
    pub margin: f64,
    pub spacing: f64,
}

impl Layout {
    /// Fraction of a sheet's area covered by pieces.
    pub fn utilisation(&self, sheet: usize) -> f64 {
        let s = &self.sheets[sheet];
        let used: f64 = s.pieces.iter().map(|&p| self.pieces[p].area).sum();
        used / (s.width * s.height)
    }
}

/// Errors of the nest stage.
#[derive(Debug, thiserror::Error)]
pub enum NestError {
    #[error("piece {piece} ({w:.1} × {h:.1} mm) does not fit on the {what} ({uw:.1} × {uh} mm inside the margins); use a larger sheet or roll, or scale the surface down")]
    TooLarge {
        piece: String,
        w: f64,
        h: f64,
        what: &'static str,
        uw: f64,
        uh: String,
    },
    #[error("sheet of {width} × {height} mm with a {margin} mm margin leaves no room")]
    NoRoom {
        width: f64,
        height: String,
        margin: f64,
    },
}

struct Shelf {
    sheet: usize,
    y: f64,
    h: f64,
    x: f64,
}

/// Place every piece.
pub fn nest(pieces: Vec<Piece>, opts: &NestOptions) -> Result<Layout, NestError> {
    let uw = opts.width - 2.0 * opts.margin;
    let uh = opts.height.map_or(f64::INFINITY, |h| h - 2.0 * opts.margin);
    let fmt_h = |h: Option<f64>| h.map_or("∞".to_string(), |h| format!("{h}"));
    if !(uw > 0.0 && uh > 0.0) {
        return Err(NestError::NoRoom {
            width: opts.width,
            height: fmt_h(opts.height),
            margin: opts.margin,
        });
    }
    // Orientation and size of each piece.
    let mut boxes = Vec::with_capacity(pieces.len());
    for piece in &pieces {
        let pts: Vec<DVec2> = piece.points().collect();
        let mut angle = polygon::min_area_rect_angle(&pts);
        let size_at = |a: f64| {
            let r = DVec2::from_angle(a);
            polygon::bounds(pts.iter().map(|p| r.rotate(*p)))
                .map(|(lo, hi)| (lo, hi - lo))
                .unwrap_or((DVec2::ZERO, DVec2::ZERO))
        };
        let (_, size) = size_at(angle);
        let fits = |s: DVec2| s.x <= uw + 1e-9 && s.y <= uh + 1e-9;
        if !fits(size) {
            if fits(DVec2::new(size.y, size.x)) {
                angle += std::f64::consts::FRAC_PI_2;
            } else {
                return Err(NestError::TooLarge {
                    piece: piece.name.clone(),
                    w: size.x,
                    h: size.y,
                    what: if opts.height.is_some() {
                        "sheet"
                    } else {
                        "roll"
                    },
                    uw,
                    uh: if uh.is_finite() {
                        format!("{uh:.1}")
                    } else {
                        "∞".into()
                    },
                });
            }
        }
        let (lo, size) = size_at(angle);
        boxes.push((angle, lo, size));
    }
    // Tallest first; ties by piece order.
    let mut order: Vec<usize> = (0..pieces.len()).collect();
    order.sort_by(|&a, &b| boxes[b].2.y.total_cmp(&boxes[a].2.y).then(a.cmp(&b)));

    let mut shelves: Vec<Shelf> = Vec::new();
    let mut sheet_top: Vec<f64> = Vec::new(); // next free y per sheet
    let mut placements = vec![
        Placement {
            sheet: 0,
            rotation: 0.0,
            offset: DVec2::ZERO
        };
        pieces.len()
    ];
    for k in order {
        let (angle, lo, size) = boxes[k];
        let shelf = shelves
            .iter()
            .position(|s| size.y <= s.h + 1e-9 && s.x + size.x <= uw + 1e-9);
        let s = match shelf {
            Some(s) => s,
            None => {
                let sheet = (0..sheet_top.len())
                    .find(|&i| sheet_top[i] + size.y <= uh + 1e-9)
                    .unwrap_or_else(|| {
                        sheet_top.push(0.0);
                        sheet_top.len() - 1
                    });
                shelves.push(Shelf {
                    sheet,
                    y: sheet_top[sheet],
                    h: size.y,
                    x: 0.0,
                });
                sheet_top[sheet] += size.y + opts.spacing;
                shelves.len() - 1
            }
        };
        let shelf = &mut shelves[s];
        let corner = DVec2::new(opts.margin + shelf.x, opts.margin + shelf.y);
        placements[k] = Placement {
            sheet: shelf.sheet,
            rotation: angle,
            offset: corner - lo,
        };
        shelf.x += size.x + opts.spacing;
    }
    let sheets = (0..sheet_top.len())
        .map(|i| Sheet {
            width: opts.width,
            height: opts.height.unwrap_or_else(|| {
                // Used length: the top of the highest piece plus the end margin.
                (0..pieces.len())
                    .filter(|&k| placements[k].sheet == i)
                    .map(|k| placements[k].offset.y + boxes[k].1.y + boxes[k].2.y)
                    .fold(opts.margin, f64::max)
                    + opts.margin
            }),
            pieces: (0..pieces.len())
                .filter(|&k| placements[k].sheet == i)
                .collect(),
        })
        .collect();
    Ok(Layout {
        pieces,
        placements,
        sheets,
        roll: opts.height.is_none(),
        margin: opts.margin,
        spacing: opts.spacing,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(id: usize, s: f64) -> Piece {
        Piece::from_outline(
            id,
            format!("{id}"),
            vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(s, 0.0),
                DVec2::new(s, s),
                DVec2::new(0.0, s),
            ],
        )
    }

    fn bbox(l: &Layout, k: usize) -> (DVec2, DVec2) {
        polygon::bounds(l.pieces[k].points().map(|p| l.placements[k].apply(p))).unwrap()
    }

    #[test]
    fn pieces_stay_inside_and_apart() {
        // Two 80 mm squares per row, three rows per A4 sheet: twelve squares take two sheets.
        let pieces = (1..=12).map(|i| square(i, 80.0 - i as f64 * 0.1)).collect();
        let l = nest(pieces, &NestOptions::default()).unwrap();
        assert_eq!(l.sheets.len(), 2);
        assert_eq!(l.sheets[0].pieces.len(), 6);
        for k in 0..l.pieces.len() {
            let (lo, hi) = bbox(&l, k);
            assert!(lo.x >= 5.0 - 1e-9 && lo.y >= 5.0 - 1e-9);
            assert!(hi.x <= 205.0 + 1e-9 && hi.y <= 292.0 + 1e-9);
            for j in 0..k {
                if l.placements[j].sheet != l.placements[k].sheet {
                    continue;
                }
                let (lo2, hi2) = bbox(&l, j);
                let apart = lo.x >= hi2.x + 3.0 - 1e-9
                    || lo2.x >= hi.x + 3.0 - 1e-9
                    || lo.y >= hi2.y + 3.0 - 1e-9
                    || lo2.y >= hi.y + 3.0 - 1e-9;
                assert!(apart, "pieces {j} and {k} too close");
            }
        }
    }

    #[test]
    fn too_large_names_both_sizes() {
        let e = nest(vec![square(1, 250.0)], &NestOptions::default()).unwrap_err();
        let s = e.to_string();
        assert!(
            s.contains("250.0 × 250.0") && s.contains("200.0 × 287.0"),
            "{s}"
        );
    }

    #[test]
    fn roll_grows_to_fit() {
        let opts = NestOptions {
            width: 100.0,
            height: None,
            ..Default::default()
        };
        let l = nest((1..=5).map(|i| square(i, 80.0)).collect(), &opts).unwrap();
        assert_eq!(l.sheets.len(), 1);
        assert!((l.sheets[0].height - (5.0 * 80.0 + 4.0 * 3.0 + 10.0)).abs() < 1e-9);
    }
}
