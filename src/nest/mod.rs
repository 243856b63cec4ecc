//! Nest stage: places pieces on sheets (bin packing) or along a roll (strip packing) without
//! overlap, inside the margins and with the requested spacing between pieces, as a
//! [`Layout`] — densely, in the manner of the current state of the art for irregular nesting.
//!
//! The files (details and sources in each):
//! - [`problem`]: the problem as data — items with their allowed orientations, the container
//!   (a strip or bins), the spacing, the search settings and the solution.
//! - `solve`: the solver — independent searches on several threads (the best kept),
//!   each a constructive start (bottom-left fill) and then the improvement: guided local
//!   search on weighted overlaps (the "separator" of sparrow, Gardeyn, Vanden Berghe, Wauters
//!   2025), strip exploration and compression for rolls; for sheets, emptying the last sheet
//!   into the others, then compressing the last sheet toward its left edge so that its remnant
//!   is one rectangle ([`Layout::remnant`]); the deterministic work budget.
//! - `collision`: exact `f64` collision detection between polygons with holes, with spacing,
//!   and the pole-based overlap proxy of sparrow — our own instead of jagua-rs (f32, no holes);
//!   see its docs for why.
//! - [`esicup`]: the ESICUP benchmark instances (JSON as used by jagua-rs and sparrow), their
//!   solutions and pictures, for `flatcut nest`.
//! - [`bench`](mod@bench): the few solver steps the benchmarks in `benches/nest.rs` time.
//!
//! flatcut's pieces: the polygon nested is the cut outline (`outline[0]`, with the holes
//! `outline[1..]` open to small pieces); every other stroke of a piece lies inside it (up to
//! [`Piece::OVERHANG_MM`]).
//! Orientations per piece come from [`NestOptions::rotations`] (a set, a step or free; per-piece
//! overrides in [`NestOptions::piece_rotations`]), doubled by mirror images when
//! [`NestOptions::mirror`]; a piece with a grain line may only turn so that the grain runs along
//! the sheet's y axis (the roll's length), either way, whatever the rotation setting. On a roll,
//! a few freely turning pieces ([`problem::FEW_ITEMS`]) also try the turns that make them
//! shortest along it ([`problem::Item::add_shortest_shapes`]), so that a lone piece takes the
//! least roll; on sheets, a piece that none of its usual turns fits tries them too, and one
//! that none of those fits either the whole degree that fits it best
//! (`Item::add_fitting_shapes`: a long thin piece across the sheet).
//!
//! Frames: on sheets the optimiser's container is the sheet inside the margins; on a roll the
//! optimiser's strip (length along its x) is the roll turned by 90°, so the length used runs
//! along the sheet's y axis as before.
//!
//! Units: [`Placement::rotation`] is in radians; the rotations a user allows ([`Rotations`])
//! and the search's orientations ([`problem::Orient`], whose type doc says why) are in degrees.
//!
//! Same inputs, seed and thread count give the same layout: the searches count work instead
//! of reading the clock (see `solve/state.rs`).

pub mod bench;
pub(crate) mod collision;
pub mod esicup;
pub mod problem;
pub(crate) mod solve;

use crate::geom::polygon;
use crate::pattern::Piece;
use glam::DVec2;
use problem::{Container, Item, Orient, Orients, Problem};

/// Allowed rotations of a piece, in degrees counter-clockwise.
#[derive(Debug, Clone, PartialEq)]
pub enum Rotations {
    /// Exactly these.
    Set(Vec<f64>),
    /// 0, step, 2 step, … below 360.
    Step(f64),
    /// Any.
    Free,
}

impl Rotations {
    fn degrees(&self) -> Option<Vec<f64>> {
        match self {
            Rotations::Set(v) if !v.is_empty() => Some(v.clone()),
            Rotations::Set(_) => Some(vec![0.0]),
            Rotations::Step(d) if *d > 0.0 && d.is_finite() => {
                let n = (360.0 / d).ceil() as usize;
                Some(
                    (0..n.min(3600))
                        .map(|k| k as f64 * d)
                        .filter(|a| *a < 360.0 - 1e-9)
                        .collect(),
                )
            }
            Rotations::Step(_) => Some(vec![0.0]),
            Rotations::Free => None,
        }
    }
}

/// Sheet or roll, the distances to keep, and the search.
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
    /// Allowed rotations of every piece (default: free).
    pub rotations: Rotations,
    /// Per-piece overrides, by [`Piece::id`].
    pub piece_rotations: Vec<(usize, Rotations)>,
    /// Pieces may also be placed mirrored (default: no; a printed side cannot be mirrored).
    pub mirror: bool,
    /// Search time (s), converted to a deterministic work budget.
    pub seconds: f64,
    pub seed: u64,
    /// Independent searches run in parallel (the best is kept).
    pub threads: usize,
}

impl Default for NestOptions {
    /// A4 portrait, 5 mm margin, 3 mm spacing, free rotation, 1 s on 2 threads, seed 1.
    fn default() -> Self {
        NestOptions {
            width: 210.0,
            height: Some(297.0),
            margin: 5.0,
            spacing: 3.0,
            rotations: Rotations::Free,
            piece_rotations: Vec::new(),
            mirror: false,
            seconds: 1.0,
            seed: 1,
            threads: 2,
        }
    }
}

/// Where a piece goes: `sheet point = rotate(mirror(piece point), rotation) + offset`, where
/// `mirror` flips x when [`Placement::mirror`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    pub sheet: usize,
    /// Radians, counter-clockwise.
    pub rotation: f64,
    /// Mirrored (x → −x) before the rotation.
    pub mirror: bool,
    pub offset: DVec2,
}

impl Placement {
    pub fn apply(&self, p: DVec2) -> DVec2 {
        let p = if self.mirror {
            DVec2::new(-p.x, p.y)
        } else {
            p
        };
        // Exact for quarter turns, so that rectangles stay edge to edge.
        let q = self.rotation / std::f64::consts::FRAC_PI_2;
        let r = if (q - q.round()).abs() < 1e-12 {
            collision::rotor(90.0 * q.round())
        } else {
            DVec2::from_angle(self.rotation)
        };
        r.rotate(p) + self.offset
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
    /// On sheets: the free rectangle (min, max corners, sheet mm) left on the last sheet, inside
    /// the margins; `None` on a roll.
    pub remnant: Option<(DVec2, DVec2)>,
}

impl Layout {
    /// Fraction of a sheet's area covered by pieces.
    pub fn utilisation(&self, sheet: usize) -> f64 {
        let s = &self.sheets[sheet];
        let used: f64 = s.pieces.iter().map(|&p| self.pieces[p].area).sum();
        used / (s.width * s.height)
    }
    /// Length of roll used (mm, with the margins), `None` on sheets.
    pub fn roll_length(&self) -> Option<f64> {
        if self.roll {
            self.sheets.first().map(|s| s.height)
        } else {
            None
        }
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
    #[error("piece {piece} has no usable outline (fewer than 3 points or no area)")]
    BadOutline { piece: String },
    /// The final check found a layout the search thought feasible infeasible (a bug).
    #[error("nesting produced an invalid layout (flatcut bug): {0}")]
    Infeasible(String),
}

/// Orientations of one piece in the sheet frame (degrees), see the module docs.
fn piece_orients(piece: &Piece, opts: &NestOptions) -> Orients {
    let mirrors: &[bool] = if opts.mirror {
        &[false, true]
    } else {
        &[false]
    };
    if let Some(g) = piece.grain {
        let mut v = Vec::new();
        for &m in mirrors {
            let g = if m {
                180.0 - g.to_degrees()
            } else {
                g.to_degrees()
            };
            for base in [90.0, 270.0] {
                v.push(Orient {
                    angle_deg: (base - g).rem_euclid(360.0),
                    mirror: m,
                });
            }
        }
        return Orients::Set(v);
    }
    let rot = opts
        .piece_rotations
        .iter()
        .find(|(id, _)| *id == piece.id)
        .map_or(&opts.rotations, |(_, r)| r);
    match rot.degrees() {
        None => Orients::Free {
            mirror: opts.mirror,
        },
        Some(d) => Orients::Set(
            mirrors
                .iter()
                .flat_map(|&m| {
                    d.iter().map(move |&deg| Orient {
                        angle_deg: deg.rem_euclid(360.0),
                        mirror: m,
                    })
                })
                .collect(),
        ),
    }
}

/// A few pieces on a roll, and a piece that fits a sheet in none of its usual turns, also try
/// the turns that make them shortest ([`Item::add_shortest_shapes`]); a piece that fits a
/// sheet in none of those either, the whole degree that fits it best
/// ([`Item::add_fitting_shapes`]). `uw` × `uh` is the room inside the margins.
fn add_shortest_turns(items: &mut [Item], roll: bool, uw: f64, uh: f64) {
    let few = items.len() <= problem::FEW_ITEMS;
    for it in items.iter_mut() {
        if (roll && few) || (!roll && !it.fits(uw, uh)) {
            it.add_shortest_shapes(if roll { uw } else { uh });
        }
        if !roll {
            it.add_fitting_shapes(uw, uh);
        }
    }
}

/// Place every piece.
pub fn nest(pieces: Vec<Piece>, opts: &NestOptions) -> Result<Layout, NestError> {
    let m = opts.margin;
    let uw = opts.width - 2.0 * m;
    let uh = opts.height.map_or(f64::INFINITY, |h| h - 2.0 * m);
    let fmt_h = |h: Option<f64>| h.map_or("∞".to_string(), |h| format!("{h}"));
    if !(uw > 0.0 && uh > 0.0) {
        return Err(NestError::NoRoom {
            width: opts.width,
            height: fmt_h(opts.height),
            margin: opts.margin,
        });
    }
    let roll = opts.height.is_none();
    // The optimiser's frame: on a roll, sheet = R90(internal) + (m + uw, m).
    let to_internal = |deg: f64| if roll { deg - 90.0 } else { deg };
    let mut items = Vec::with_capacity(pieces.len());
    for piece in &pieces {
        let rings: Vec<Vec<DVec2>> = piece
            .outline
            .iter()
            .filter(|r| r.len() >= 3)
            .cloned()
            .collect();
        if piece.outline.first().is_none_or(|r| r.len() < 3)
            || polygon::signed_area(&rings[0]).abs() <= 0.0
            || rings.iter().flatten().any(|p| !p.is_finite())
        {
            return Err(NestError::BadOutline {
                piece: piece.name.clone(),
            });
        }
        let orients = match piece_orients(piece, opts) {
            Orients::Set(v) => Orients::Set(
                v.into_iter()
                    .map(|o| Orient {
                        angle_deg: to_internal(o.angle_deg).rem_euclid(360.0),
                        mirror: o.mirror,
                    })
                    .collect(),
            ),
            f => f,
        };
        items.push(Item::new(rings, orients));
    }
    add_shortest_turns(&mut items, roll, uw, uh);
    let container = if roll {
        Container::Strip { height: uw }
    } else {
        Container::Bins {
            length: uw,
            height: uh,
        }
    };
    let prob = Problem {
        items,
        container,
        // Kept a hair apart even at spacing 0: pieces that touch along a straight edge (the
        // parts of a split piece) came out overlapping by rounding, which the exact check
        // below refuses. 1e-9 mm is far below any device's step.
        spacing: opts.spacing.max(MIN_GAP_MM),
    };
    let cfg = problem::Config {
        seconds: opts.seconds,
        seed: opts.seed,
        threads: opts.threads,
    };
    let sol = solve::solve(&prob, &cfg).map_err(|u| {
        let piece = &pieces[u.item.min(pieces.len().saturating_sub(1))];
        let pts: Vec<DVec2> = piece.points().collect();
        let r = DVec2::from_angle(polygon::min_area_rect_angle(&pts));
        let (lo, hi) = polygon::bounds(pts.iter().map(|p| r.rotate(*p))).unwrap_or_default();
        let size = hi - lo;
        NestError::TooLarge {
            piece: piece.name.clone(),
            w: size.x.max(size.y),
            h: size.x.min(size.y),
            what: if roll { "roll" } else { "sheet" },
            uw,
            uh: if uh.is_finite() {
                format!("{uh:.1}")
            } else {
                "∞".into()
            },
        }
    })?;
    let placements: Vec<Placement> = sol
        .placements
        .iter()
        .map(|p| {
            if roll {
                let t = p.translation;
                Placement {
                    sheet: 0,
                    rotation: (p.orient.angle_deg + 90.0).rem_euclid(360.0).to_radians(),
                    mirror: p.orient.mirror,
                    offset: DVec2::new(-t.y, t.x) + DVec2::new(m + uw, m),
                }
            } else {
                Placement {
                    sheet: p.bin,
                    rotation: p.orient.angle_deg.to_radians(),
                    mirror: p.orient.mirror,
                    offset: p.translation + DVec2::splat(m),
                }
            }
        })
        .collect();
    let sheets: Vec<Sheet> = (0..sol.bins)
        .map(|i| Sheet {
            width: opts.width,
            height: opts.height.unwrap_or(sol.length + 2.0 * m),
            pieces: (0..pieces.len())
                .filter(|&k| placements[k].sheet == i)
                .collect(),
        })
        .collect();
    let remnant = match opts.height {
        Some(h) if sol.bins > 0 => {
            let last = sol.bins - 1;
            let top = (0..pieces.len())
                .filter(|&k| placements[k].sheet == last)
                .flat_map(|k| pieces[k].outline[0].iter().map(move |p| (k, *p)))
                .map(|(k, p)| placements[k].apply(p).y)
                .fold(m, f64::max);
            let right = (m + sol.length, m, opts.width - m, h - m);
            let above = (m, top, opts.width - m, h - m);
            let area = |r: (f64, f64, f64, f64)| (r.2 - r.0).max(0.0) * (r.3 - r.1).max(0.0);
            let r = if area(above) > area(right) {
                above
            } else {
                right
            };
            Some((DVec2::new(r.0, r.1), DVec2::new(r.2, r.3)))
        }
        _ => None,
    };
    let layout = Layout {
        pieces,
        placements,
        sheets,
        roll,
        margin: opts.margin,
        spacing: opts.spacing,
        remnant,
    };
    // Never trust the search alone: every point inside, every pair apart, checked again.
    verify(&layout).map_err(NestError::Infeasible)?;
    Ok(layout)
}

/// The least gap the search keeps between pieces, whatever the spacing (mm).
pub const MIN_GAP_MM: f64 = 1e-9;

/// Exact check of a layout: every piece's points inside its sheet's margins, and the outlines
/// of two pieces on one sheet never closer than the spacing (a piece in another's hole is
/// fine). Returns the first problem found, naming the pieces.
pub fn verify(layout: &Layout) -> Result<(), String> {
    let m = layout.margin;
    let placed: Vec<Vec<Vec<DVec2>>> = layout
        .pieces
        .iter()
        .zip(&layout.placements)
        .map(|(p, at)| {
            p.outline
                .iter()
                .map(|r| {
                    let mut r: Vec<DVec2> = r.iter().map(|q| at.apply(*q)).collect();
                    if at.mirror {
                        r.reverse();
                    }
                    r
                })
                .collect()
        })
        .collect();
    for (k, (p, at)) in layout.pieces.iter().zip(&layout.placements).enumerate() {
        let s = &layout.sheets[at.sheet];
        for q in p.points().map(|q| at.apply(q)) {
            // Marks on the border may lie a little outside the cut outline.
            let tol = Piece::OVERHANG_MM;
            if q.x < m - tol || q.y < m - tol || q.x > s.width - m + tol || q.y > s.height - m + tol
            {
                return Err(format!(
                    "piece {} leaves the sheet at {q}",
                    layout.pieces[k].name
                ));
            }
        }
    }
    let mut work = 0;
    let shapes: Vec<collision::Shape> = placed
        .iter()
        .map(|rings| {
            let poles = collision::poles(rings);
            collision::Shape::new(
                rings,
                &poles,
                Orient {
                    angle_deg: 0.0,
                    mirror: false,
                },
            )
        })
        .collect();
    for i in 0..shapes.len() {
        for j in i + 1..shapes.len() {
            if layout.placements[i].sheet != layout.placements[j].sheet {
                continue;
            }
            let (a, b) = (&shapes[i], &shapes[j]);
            // Shapes are shifted to start at 0: undo it.
            let near = collision::collide(
                a,
                -a.shift,
                b,
                -b.shift,
                (layout.spacing - 1e-6).max(0.0),
                &mut work,
            );
            if near {
                return Err(format!(
                    "pieces {} and {} overlap or are closer than {} mm",
                    layout.pieces[i].name, layout.pieces[j].name, layout.spacing
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect_piece(id: usize, w: f64, h: f64) -> Piece {
        Piece::from_outline(
            id,
            format!("{id}"),
            vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(w, 0.0),
                DVec2::new(w, h),
                DVec2::new(0.0, h),
            ],
        )
    }

    fn quick() -> NestOptions {
        NestOptions {
            seconds: 0.05,
            ..Default::default()
        }
    }

    #[test]
    fn nest_squares_stay_inside_and_apart() {
        let pieces = (1..=12)
            .map(|i| rect_piece(i, 80.0 - i as f64 * 0.1, 80.0 - i as f64 * 0.1))
            .collect();
        let l = nest(pieces, &quick()).unwrap();
        assert_eq!(l.sheets.len(), 2);
        verify(&l).unwrap();
    }

    #[test]
    fn nest_too_large_names_both_sizes() {
        let e = nest(vec![rect_piece(1, 250.0, 250.0)], &quick()).unwrap_err();
        let s = e.to_string();
        assert!(
            s.contains("250.0 × 250.0") && s.contains("200.0 × 287.0"),
            "{s}"
        );
    }

    #[test]
    fn nest_roll_length_runs_along_y() {
        let opts = NestOptions {
            width: 100.0,
            height: None,
            rotations: Rotations::Step(90.0),
            ..quick()
        };
        let l = nest((1..=5).map(|i| rect_piece(i, 80.0, 80.0)).collect(), &opts).unwrap();
        assert_eq!(l.sheets.len(), 1);
        verify(&l).unwrap();
        // One square across the roll: five squares, four gaps and two margins long.
        assert!((l.sheets[0].height - (5.0 * 80.0 + 4.0 * 3.0 + 10.0)).abs() < 1e-6);
        assert_eq!(l.roll_length(), Some(l.sheets[0].height));
    }

    #[test]
    fn nest_grain_keeps_pieces_along_y() {
        // A long strip with its grain along its length, on a roll: it must run along y.
        let mut p = rect_piece(1, 150.0, 20.0);
        p.grain = Some(0.0);
        let opts = NestOptions {
            width: 200.0,
            height: None,
            ..quick()
        };
        let l = nest(vec![p.clone(), p], &opts).unwrap();
        for at in &l.placements {
            let g = at.apply(DVec2::X) - at.apply(DVec2::ZERO);
            assert!(g.x.abs() < 1e-9 && (g.y.abs() - 1.0).abs() < 1e-9, "{g}");
        }
        verify(&l).unwrap();
    }

    #[test]
    fn nest_small_piece_goes_into_the_hole_of_a_frame() {
        // A 100 mm frame with an 80 mm hole fills a 104 mm sheet; a 50 mm square only fits in
        // the hole, so one sheet is enough.
        let mut frame = rect_piece(1, 100.0, 100.0);
        frame.outline.push(vec![
            DVec2::new(10.0, 10.0),
            DVec2::new(10.0, 90.0),
            DVec2::new(90.0, 90.0),
            DVec2::new(90.0, 10.0),
        ]);
        frame.area = 100.0 * 100.0 - 80.0 * 80.0;
        let opts = NestOptions {
            width: 104.0,
            height: Some(104.0),
            margin: 2.0,
            spacing: 2.0,
            seconds: 0.5,
            ..Default::default()
        };
        let l = nest(vec![frame, rect_piece(2, 50.0, 50.0)], &opts).unwrap();
        verify(&l).unwrap();
        assert_eq!(l.sheets.len(), 1);
    }

    #[test]
    fn nest_mirrored_pairs_stay_apart() {
        // Right triangles, mirror allowed: whatever the search picks is feasible, and the
        // mirror image keeps the outline's area.
        let tri = |id| {
            let mut p = rect_piece(id, 60.0, 30.0);
            p.outline = vec![vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(60.0, 0.0),
                DVec2::new(0.0, 30.0),
            ]];
            p.area = 900.0;
            p
        };
        let opts = NestOptions {
            width: 100.0,
            height: None,
            mirror: true,
            seconds: 0.3,
            ..Default::default()
        };
        let l = nest((1..=6).map(tri).collect(), &opts).unwrap();
        verify(&l).unwrap();
        for (p, at) in l.pieces.iter().zip(&l.placements) {
            let pts: Vec<DVec2> = p.outline[0].iter().map(|q| at.apply(*q)).collect();
            assert!((polygon::signed_area(&pts).abs() - 900.0).abs() < 1e-6);
        }
    }

    #[test]
    fn nest_forty_rectangles_take_four_sheets_and_leave_one_rectangle() {
        // Ten to a sheet at spacing 0, with the search's hair of a gap (MIN_GAP_MM) between them.
        let pieces = (1..=40).map(|i| rect_piece(i, 89.999, 59.999)).collect();
        let opts = NestOptions {
            width: 300.0,
            height: Some(200.0),
            margin: 0.0,
            spacing: 0.0,
            rotations: Rotations::Set(vec![0.0, 90.0]),
            seconds: 0.2,
            ..Default::default()
        };
        let l = nest(pieces, &opts).unwrap();
        verify(&l).unwrap();
        assert_eq!(l.sheets.len(), 4);
        let (lo, hi) = l.remnant.unwrap();
        // The remnant is free of pieces and is the whole sheet minus the pieces' bounding box.
        let last = l.sheets.len() - 1;
        let (mut blo, mut bhi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &k in &l.sheets[last].pieces {
            for q in &l.pieces[k].outline[0] {
                let q = l.placements[k].apply(*q);
                blo = blo.min(q);
                bhi = bhi.max(q);
                assert!(
                    !(q.x > lo.x + 1e-9
                        && q.x < hi.x - 1e-9
                        && q.y > lo.y + 1e-9
                        && q.y < hi.y - 1e-9),
                    "piece {k} in the remnant"
                );
            }
        }
        let used = (bhi - blo).x * (bhi - blo).y;
        let rem = (hi - lo).x * (hi - lo).y;
        // Within the 1 µm the rectangles are short of a tenth of the sheet each way.
        assert!((used + rem - 300.0 * 200.0).abs() < 2.0, "{used} + {rem}");
    }
}
