//! Splitting pieces that do not fit the sheet (issue 21, items 4 and 5): a piece larger than
//! the sheet inside its margins (or wider than the roll) at every orientation the nest tries is
//! cut into parts along its own interior edges — the fold lines and flat interior edges of an
//! unfolded mesh or chart, the rulings of a strip, a fitting or a bent sheet — so that every
//! part fits; a part too large only because it is one face is an error naming both sizes.
//!
//! **Where.** The split changes the flat, not the pieces: the faces of the island stay where
//! the flatten stage laid them (the unfolding is isometric, so a part of it is the unfolding of
//! that part), the edges between two parts stop being joined (`Flat::joined`), and the parts
//! become islands of their own. The pieces are then built again by [`super::build`], so a new
//! seam is a seam like any other: found on both borders by [`super::marks`], with its id on
//! both sides, notches, glue tabs or seam allowance by [`super::allowance`], its two sides
//! measured on their own faces (equal lengths) and listed in report.json (with `"split":
//! true`). Splitting the face set along mesh edges of the whole mesh and unfolding the parts
//! again could join faces the unfolding had cut apart, but would redo the flatten stage's
//! work and lose the chart layouts; parts of the existing layout keep them.
//!
//! **What fits.** The nest's construction places a piece turned so that its cut outline's
//! minimum-area rectangle is axis-aligned, at one of four quarter turns (a piece with a grain
//! line: grain along the sheet's y axis, either way); a piece fits when one of those boxes
//! lies within the room. The same test is applied to the built pieces, so that a piece that
//! fits today is never split and the bundled patterns' outputs do not change. A freely
//! turning piece that fits a sheet at none of those turns also fits when it does at a whole
//! degree between them (a long thin piece across the sheet's diagonal), which the nest then
//! tries; a part of several faces does not count so (parts at quarter turns pack better), a
//! single face does: it cannot be split further, and the pattern would otherwise be refused.
//! Before a part is built, its size is estimated from its faces' corners grown on every side
//! by what the material adds (tab height or seam allowance, half the kerf); a part that then
//! does not fit once built has its island split again with the estimate grown by the
//! overflow.
//!
//! **How** the faces of an island are partitioned into parts that fit: `partition::partition`.

use super::{PatternError, PatternOptions, Piece, Tabs};
use crate::flatten::Flat;
use crate::geom::polygon;
use glam::DVec2;
use std::collections::{HashMap, HashSet};

mod partition;

use partition::{partition, Sizes};

/// Parts of an island: faces each.
type Parts = Vec<Vec<usize>>;

/// A part of a split piece under this share of the whole surface's area is small (issue 20:
/// no piece under 1 % of the area) and is grown from its neighbours where it can
/// (`grow_small`).
const SMALL_PART: f64 = 0.01;

/// Whether pieces too large for the sheet are split (`--split`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Split {
    /// Split them along their own lines so that every part fits.
    #[default]
    Auto,
    /// Never: a piece that does not fit is refused by the nest.
    None,
}

/// The room a piece must fit in (mm): the sheet inside its margins, or the roll's width
/// inside its margins (`height: None`, unlimited length).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Room {
    pub width: f64,
    pub height: Option<f64>,
}

impl Room {
    /// The room of a sheet (`height: None` for a roll) with `margin` kept on every side.
    pub fn inside(width: f64, height: Option<f64>, margin: f64) -> Room {
        Room {
            width: width - 2.0 * margin,
            height: height.map(|h| h - 2.0 * margin),
        }
    }

    /// The room a piece's faces may take before it is split: this room less, on every side,
    /// what the material adds around them (tab height or seam allowance, half the kerf), as
    /// [`build_to_fit`] estimates it; `[width, height]`, the height infinite on a roll. The
    /// flatten stage merges no two pieces into one larger than that
    /// ([`crate::flatten::charts::FlattenOptions::room`]).
    pub fn for_faces(&self, opts: &PatternOptions) -> [f64; 2] {
        let grow = 2.0 * grow_estimate(opts);
        [
            self.width - grow,
            self.height.map_or(f64::INFINITY, |h| h - grow),
        ]
    }

    /// Positive and finite (a roll's length aside): something can be placed at all.
    fn usable(&self) -> bool {
        self.width.is_finite()
            && self.width > 0.0
            && self.height.is_none_or(|h| h.is_finite() && h > 0.0)
    }

    /// How far (mm) a box of this size sticks out of the room; ≤ 0 when it fits (within the
    /// nest's 1e-9 mm).
    fn overflow(&self, size: DVec2) -> f64 {
        let over_y = self.height.map_or(f64::NEG_INFINITY, |h| size.y - h);
        (size.x - self.width).max(over_y) - 1e-9
    }

    fn what(&self) -> &'static str {
        if self.height.is_some() {
            "sheet"
        } else {
            "roll"
        }
    }

    fn height_text(&self) -> String {
        self.height.map_or("∞".into(), |h| format!("{h:.1}"))
    }
}

/// The least overflow (mm) of a point set over the orientations the nest tries (see
/// [`overflow`]): `angles_deg`, and where it fits a sheet at none of them and may turn freely
/// (`free`: no grain line), every whole degree, as the nest then does (it adds the whole
/// degree that leaves the most room to the turns it tries): a long thin piece may fit across
/// the sheet's diagonal. ≤ 0 fits.
fn turned_overflow(points: &[DVec2], angles_deg: &[f64], room: &Room, free: bool) -> f64 {
    let least = overflow(points, angles_deg, room);
    let Some(height) = room.height else {
        return least;
    };
    if least <= 0.0 || !free {
        return least;
    }
    // Nothing longer than the sheet's diagonal fits it at any turn.
    let hull = polygon::convex_hull(points);
    let diameter2 = hull
        .iter()
        .flat_map(|p| hull.iter().map(move |q| p.distance_squared(*q)))
        .fold(0.0, f64::max);
    if diameter2 > room.width * room.width + height * height {
        return least;
    }
    let whole: Vec<f64> = (0..360).map(f64::from).collect();
    least.min(overflow(&hull, &whole, room))
}

/// The least overflow (mm) of a point set over the orientations given (degrees): ≤ 0 fits.
fn overflow(points: &[DVec2], angles_deg: &[f64], room: &Room) -> f64 {
    angles_deg
        .iter()
        .map(|&deg| {
            let r = turn(deg);
            let (lo, hi) = polygon::bounds(points.iter().map(|p| r.rotate(*p))).unwrap_or_default();
            room.overflow(hi - lo)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Rotation by `deg` degrees, exact for quarter turns (as the nest turns pieces).
fn turn(deg: f64) -> DVec2 {
    let q = deg.rem_euclid(360.0);
    match q {
        0.0 => DVec2::X,
        90.0 => DVec2::Y,
        180.0 => DVec2::NEG_X,
        270.0 => DVec2::NEG_Y,
        _ => DVec2::from_angle(q.to_radians()),
    }
}

/// The orientations (degrees) the nest's construction tries for points whose minimum-area
/// rectangle is at `angle` (radians): its four quarter turns, or with a grain the two that
/// put the long side along y.
fn rect_angles(angle: f64, grain: bool) -> Vec<f64> {
    let quarters: &[f64] = if grain {
        &[1.0, 3.0]
    } else {
        &[0.0, 1.0, 2.0, 3.0]
    };
    let a = angle.to_degrees();
    quarters
        .iter()
        .map(|q| (a + 90.0 * q).rem_euclid(360.0))
        .collect()
}

/// How far (mm) a built piece overflows the room at the nest's orientations: ≤ 0 fits.
pub fn piece_overflow(piece: &Piece, room: &Room) -> f64 {
    let Some(outer) = piece.outline.first() else {
        return 0.0;
    };
    let angles = match piece.grain {
        Some(g) => [90.0, 270.0]
            .iter()
            .map(|b| (b - g.to_degrees()).rem_euclid(360.0))
            .collect(),
        None => rect_angles(polygon::min_area_rect_angle(outer), false),
    };
    let pts: Vec<DVec2> = piece
        .outline
        .iter()
        .filter(|r| r.len() >= 3)
        .flatten()
        .copied()
        .collect();
    turned_overflow(&pts, &angles, room, piece.grain.is_none())
}

/// Whether a built piece fits the room in an orientation the nest tries.
pub fn fits(piece: &Piece, room: &Room) -> bool {
    piece_overflow(piece, room) <= 0.0
}

/// Build the pieces of every flat ([`super::build`]) so that each fits `room`: pieces that do
/// not are split (see the module docs), changing their flat's islands and joined edges. When
/// every piece fits as it is, the pieces are exactly [`super::build`]'s and the flats are
/// untouched. A part that is a single face too large for the room is
/// [`PatternError::TooLarge`].
pub fn build_to_fit(
    flats: &mut [Flat],
    opts: &PatternOptions,
    room: &Room,
) -> Result<Vec<Piece>, PatternError> {
    let pieces = super::build(flats, opts)?;
    if !room.usable() || pieces.iter().all(|p| fits(p, room)) {
        return Ok(pieces);
    }
    let originals: Vec<(Vec<Vec<usize>>, Vec<bool>)> = flats
        .iter()
        .map(|f| (f.islands.clone(), f.joined.clone()))
        .collect();
    // The growth estimate of every island that must be split (None: it fits as it is).
    let base = grow_estimate(opts);
    let mut grow: Vec<Vec<Option<f64>>> = Vec::new();
    let mut k = 0;
    for f in flats.iter() {
        grow.push(
            (0..f.islands.len())
                .map(|_| {
                    k += 1;
                    (!fits(&pieces[k - 1], room)).then_some(base)
                })
                .collect(),
        );
    }
    // Parts under this share of the whole surface are grown where they can (`grow_small`).
    let total: f64 = flats.iter().map(|f| f.surface.mesh.area()).sum();
    let small = SMALL_PART * total;
    let mut last = pieces;
    let mut cache: HashMap<(usize, usize), (f64, Parts)> = HashMap::new();
    let mut stuck: HashMap<(usize, usize), u32> = HashMap::new();
    for _round in 0..8 {
        let mut tags = Vec::new();
        let mut origin: Vec<(usize, usize, bool)> = Vec::new(); // (flat, island, one face)
        let mut split_edges: Vec<HashSet<usize>> = Vec::new();
        for (fi, flat) in flats.iter_mut().enumerate() {
            let (islands, joined) = &originals[fi];
            flat.islands = islands.clone();
            flat.joined = joined.clone();
            let mut plans = Vec::new();
            for (ii, faces) in islands.iter().enumerate() {
                let Some(g) = grow[fi][ii] else {
                    plans.push(None);
                    continue;
                };
                // The same growth gives the same partition: made once.
                let parts = match cache.get(&(fi, ii)) {
                    Some((cg, parts)) if *cg == g => parts.clone(),
                    _ => {
                        // Small parts are grown only while the island's parts have not come
                        // out too large: grown ones are the likelier to.
                        let sizes = Sizes {
                            grow: g,
                            small,
                            grow_small: !stuck.contains_key(&(fi, ii)),
                        };
                        partition(flat, faces, opts, room, ii, sizes)?
                    }
                };
                cache.insert((fi, ii), (g, parts.clone()));
                plans.push(Some(parts));
            }
            let (t, o, cut) = apply(flat, &plans);
            tags.push(t);
            origin.extend(o.into_iter().map(|(ii, one)| (fi, ii, one)));
            split_edges.push(cut);
        }
        let mut pieces = super::build_tagged(flats, &tags, opts)?;
        // Each island's largest overflow this round (its parts come out over together).
        let mut worst: Vec<((usize, usize), f64)> = Vec::new();
        for (p, &(fi, ii, one)) in pieces.iter().zip(&origin) {
            let over = piece_overflow(p, room);
            if over <= 0.0 {
                continue;
            }
            if one {
                return Err(too_large(p, room));
            }
            match worst.iter_mut().find(|w| w.0 == (fi, ii)) {
                Some(w) => w.1 = w.1.max(over),
                None => worst.push(((fi, ii), over)),
            }
        }
        let again = !worst.is_empty();
        for ((fi, ii), over) in worst {
            // Grown by the overflow (an island that fit as a whole now needs splitting too:
            // possible only when the piece changed, which the same faces cannot), doubled
            // each round the island still came out whole: the estimate can be short by much
            // more than the overflow (a seam allowance mitred at a sharp corner reaches far
            // past its width), while a part of a split island is only a little too large,
            // unless it still is after two rounds (a new partition can land its parts just
            // as far over: couplingdown in fabric, part 3a 0.12 mm over after 8 rounds).
            // Once per island and round, by its worst part: its parts share one estimate.
            let whole = cache
                .get(&(fi, ii))
                .is_none_or(|(_, parts)| parts.len() <= 1);
            let k = stuck.entry((fi, ii)).or_insert(0u32);
            let factor = if whole {
                f64::from(1u32 << *k)
            } else {
                f64::from(1u32 << k.saturating_sub(2))
            };
            *k = (*k + 1).min(16);
            let g = grow[fi][ii].get_or_insert(base);
            *g += (0.5 * over + 0.5) * factor;
        }
        let offset: Vec<usize> = flats
            .iter()
            .scan(0, |n, f| {
                let at = *n;
                *n += f.islands.len();
                Some(at)
            })
            .collect();
        for (fi, cut) in split_edges.iter().enumerate() {
            let n = flats[fi].islands.len();
            for p in &mut pieces[offset[fi]..offset[fi] + n] {
                mark_split_seams(p, cut);
            }
        }
        last = pieces;
        if !again {
            break;
        }
    }
    explain_stretch(flats, &last, opts);
    Ok(last)
}

/// A part of a split piece laid out from charts that stretches more than the material's
/// tolerance (its layout is the piece's, within it as a whole) gets a warning on its surface
/// saying so, which report.json lists.
fn explain_stretch(flats: &mut [Flat], pieces: &[Piece], opts: &PatternOptions) {
    let Some(limit) = opts.stretch_limit else {
        return;
    };
    for p in pieces.iter().filter(|p| p.seams.iter().any(|s| s.split)) {
        let Some(flat) = flats
            .iter_mut()
            .find(|f| f.surface.name == p.surface && f.surface.charts.is_some())
        else {
            continue;
        };
        let l2 = crate::flatten::charts::stretch_of(flat, &p.faces).l2;
        if l2 > limit {
            flat.surface.warnings.push(format!(
                "surface `{}`: part {} stretches by L2 {l2:.5}, over the material's {limit:.4}: it is cut from a piece split to fit the sheet, laid out as that piece (within the tolerance as a whole), where the stretch gathers; a larger sheet keeps the piece whole",
                p.surface, p.name
            ));
        }
    }
}

/// What the material adds around a part at most (mm): tabs or seam allowance, half the kerf.
fn grow_estimate(opts: &PatternOptions) -> f64 {
    let tabs = if opts.tabs == Tabs::None {
        0.0
    } else {
        opts.tab_height
    };
    tabs.max(opts.allowance).max(0.0) + 0.5 * opts.kerf.max(0.0)
}

/// Seam sides running along an edge the split cut are marked `split`.
fn mark_split_seams(p: &mut Piece, cut: &HashSet<usize>) {
    for s in &mut p.seams {
        let Some(ring) = p.border_edges.get(s.ring).filter(|r| !r.is_empty()) else {
            continue;
        };
        let n = ring.len();
        s.split = (0..s.count).any(|i| cut.contains(&ring[(s.first + i) % n]));
    }
}

/// The size of a point set's minimum-area rectangle (along its sides).
fn rect_size(pts: &[DVec2]) -> DVec2 {
    let r = turn(polygon::min_area_rect_angle(pts).to_degrees());
    let (lo, hi) = polygon::bounds(pts.iter().map(|q| r.rotate(*q))).unwrap_or_default();
    hi - lo
}

/// The error for a single face that cannot fit, with its size and the room's.
fn too_large(p: &Piece, room: &Room) -> PatternError {
    let pts: Vec<DVec2> = p.outline.iter().flatten().copied().collect();
    let size = rect_size(&pts);
    PatternError::TooLarge {
        surface: p.surface.clone(),
        piece: p.name.clone(),
        face: p.faces.first().map_or(0, |f| f + 1),
        w: size.x.max(size.y),
        h: size.x.min(size.y),
        what: room.what(),
        uw: room.width,
        uh: room.height_text(),
    }
}

/// Puts the parts of the split islands into the flat: edges between two parts are no longer
/// joined, each part is an island (after the parts of the islands before it). Returns the
/// islands' name tags (`3`, or `3a`, `3b`, … for the parts of island 3), each island's
/// original island and whether it is a single face of a split island, and the edges cut.
#[allow(clippy::type_complexity)]
fn apply(
    flat: &mut Flat,
    plans: &[Option<Vec<Vec<usize>>>],
) -> (Vec<String>, Vec<(usize, bool)>, HashSet<usize>) {
    let mut islands = Vec::new();
    let mut tags = Vec::new();
    let mut origin = Vec::new();
    for (ii, faces) in flat.islands.iter().enumerate() {
        match &plans[ii] {
            Some(parts) if parts.len() > 1 => {
                for (j, part) in parts.iter().enumerate() {
                    islands.push(part.clone());
                    tags.push(format!("{}{}", ii + 1, letters(j)));
                    origin.push((ii, part.len() == 1));
                }
            }
            _ => {
                islands.push(faces.clone());
                tags.push(format!("{}", ii + 1));
                origin.push((ii, faces.len() == 1));
            }
        }
    }
    for (k, faces) in islands.iter().enumerate() {
        for &f in faces {
            flat.face_island[f] = k;
        }
    }
    let mut cut = HashSet::new();
    for (e, edge) in flat.topology.edges.iter().enumerate() {
        if flat.joined[e] && edge.uses.len() == 2 {
            let (a, b) = (edge.uses[0].0, edge.uses[1].0);
            if flat.face_island[a] != flat.face_island[b] {
                flat.joined[e] = false;
                cut.insert(e);
            }
        }
    }
    if let Some(charts) = flat.surface.charts.as_mut() {
        charts.clone_from(&flat.face_island);
    }
    flat.islands = islands;
    (tags, origin, cut)
}

/// `a`, `b`, … `z`, `aa`, `ab`, …
fn letters(mut j: usize) -> String {
    let mut s = Vec::new();
    loop {
        s.push(b'a' + (j % 26) as u8);
        if j < 26 {
            break;
        }
        j = j / 26 - 1;
    }
    s.reverse();
    String::from_utf8(s).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flatten::{unfold, UnfoldOptions};

    #[test]
    fn part_letters_run_on_past_z() {
        let names: Vec<String> = [0, 1, 25, 26, 27, 701, 702].map(letters).into();
        assert_eq!(names, ["a", "b", "z", "aa", "ab", "zz", "aaa"]);
    }

    /// A surface of the faces `faces` over `verts`, for tests.
    fn surface<F: AsRef<[usize]>>(
        name: &str,
        verts: Vec<glam::DVec3>,
        faces: &[F],
    ) -> crate::surface::Surface {
        crate::surface::Surface {
            name: name.into(),
            source: "t.obj".into(),
            mesh: crate::geom::mesh::Mesh::from_polygons(verts, faces),
            ..Default::default()
        }
    }

    /// A flat row of `n` squares of `side` mm along x, as one surface.
    pub(super) fn row_of_squares(n: usize, side: f64) -> crate::surface::Surface {
        let mut verts = Vec::new();
        for i in 0..=n {
            verts.push(glam::DVec3::new(side * i as f64, 0.0, 0.0));
            verts.push(glam::DVec3::new(side * i as f64, side, 0.0));
        }
        let faces: Vec<[usize; 4]> = (0..n)
            .map(|i| [2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1])
            .collect();
        surface("row", verts, &faces)
    }

    /// A 300 × 20 mm face on a 190 × 277 mm room (A4 inside 10 mm margins) fits no quarter
    /// turn of its least rectangle, but fits turned by a whole degree between them: it is
    /// kept whole. With a grain line, which fixes its turn, it does not fit; in a room whose
    /// diagonal is shorter than the face, it is too large.
    #[test]
    fn a_long_thin_face_fits_across_the_room_unless_its_grain_fixes_the_turn() {
        let corners = [(0.0, 0.0), (300.0, 0.0), (300.0, 20.0), (0.0, 20.0)];
        let verts = corners.map(|(x, y)| glam::DVec3::new(x, y, 0.0)).to_vec();
        let strip = surface("strip", verts, &[[0, 1, 2, 3]]);
        let room = Room {
            width: 190.0,
            height: Some(277.0),
        };
        let opts = PatternOptions::default();
        let mut flats = vec![unfold(strip, &UnfoldOptions::default()).unwrap()];
        let pieces = build_to_fit(&mut flats, &opts, &room).expect("fits across");
        assert_eq!(pieces.len(), 1);
        let outer = &pieces[0].outline[0];
        let quarters = rect_angles(polygon::min_area_rect_angle(outer), false);
        assert!(overflow(outer, &quarters, &room) > 10.0);
        let whole: Vec<f64> = (0..360).map(f64::from).collect();
        assert!(overflow(outer, &whole, &room) <= 0.0);
        assert!(fits(&pieces[0], &room));
        let mut grained = pieces[0].clone();
        grained.grain = Some(0.0);
        assert!(!fits(&grained, &room));
        // Less room than the strip's length across it: too large at any turn.
        let narrow = Room {
            width: 150.0,
            height: Some(250.0),
        };
        assert!(!fits(&pieces[0], &narrow));
        assert!(matches!(
            build_to_fit(&mut flats, &opts, &narrow),
            Err(PatternError::TooLarge { .. })
        ));
    }

    /// A flat row of five 100 mm squares on a 250 × 250 mm room: three parts (two squares
    /// at most each), cut along square edges, one new seam each, the faces kept.
    #[test]
    fn a_row_of_squares_is_cut_between_squares() {
        let row = row_of_squares(5, 100.0);
        let mut flats = vec![unfold(row, &UnfoldOptions::default()).unwrap()];
        let room = Room {
            width: 250.0,
            height: Some(250.0),
        };
        let opts = PatternOptions::default();
        assert!(!fits(
            &super::super::build(&flats, &opts).unwrap()[0],
            &room
        ));
        let pieces = build_to_fit(&mut flats, &opts, &room).unwrap();
        assert_eq!(pieces.len(), 3);
        assert!(pieces.iter().all(|p| fits(p, &room)));
        let mut sizes: Vec<usize> = pieces.iter().map(|p| p.faces.len()).collect();
        sizes.sort_unstable();
        assert_eq!(sizes, [1, 2, 2]);
        let names: Vec<&str> = pieces.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["1a", "1b", "1c"]);
        let split: Vec<_> = pieces
            .iter()
            .flat_map(|p| &p.seams)
            .filter(|s| s.split)
            .collect();
        assert_eq!(split.len(), 4);
        assert!(split
            .iter()
            .all(|s| s.count == 1 && (s.length - 100.0).abs() < 1e-9));
        assert_eq!(flats[0].islands.len(), 3);
    }

    /// A flat sheet of `nx` × `ny` squares of `side` mm, each cut by a diagonal, its inner
    /// corners moved by up to `jitter` mm (the same each run), as one surface.
    fn triangulated_sheet(nx: usize, ny: usize, side: f64, jitter: f64) -> crate::surface::Surface {
        let mut rng = crate::geom::rng::Rng::new(7);
        let mut verts = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                let inner = 0 < i && i < nx && 0 < j && j < ny;
                let d = if inner {
                    glam::DVec3::new(rng.f64() - 0.5, rng.f64() - 0.5, 0.0) * (2.0 * jitter)
                } else {
                    glam::DVec3::ZERO
                };
                verts.push(glam::DVec3::new(side * i as f64, side * j as f64, 0.0) + d);
            }
        }
        let at = |i: usize, j: usize| j * (nx + 1) + i;
        let mut faces: Vec<[usize; 3]> = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                faces.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                faces.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        surface("sheet", verts, &faces)
    }

    /// Regression (blade in fabric at 3,000 mm on A4 went on for over 5 minutes): when
    /// several parts of a split piece came out a little too large once their seam allowance
    /// was added, the growth estimate was raised once per part, doubling from the third on, so
    /// that it passed the sheet and every face became a part of its own (16,222 parts for the
    /// nest). It is now raised once per round by the worst part. A 600 × 400 mm sheet of
    /// uneven triangles (the allowance mitred at their sharp corners reaches past its width)
    /// with a 10 mm allowance on A4 (200 × 287 mm inside the margins): 71 parts before, 18
    /// now, each fitting the sheet.
    #[test]
    fn parts_that_come_out_too_large_grow_the_estimate_once_per_round() {
        let sheet = triangulated_sheet(30, 20, 20.0, 8.0);
        let mut flats = vec![unfold(sheet, &UnfoldOptions::default()).unwrap()];
        let room = Room::inside(210.0, Some(297.0), 5.0);
        let opts = PatternOptions {
            allowance: 10.0,
            ..Default::default()
        };
        let pieces = build_to_fit(&mut flats, &opts, &room).unwrap();
        assert!(pieces.iter().all(|p| fits(p, &room)));
        // 240,000 mm² of faces, at most 180 × 267 mm of them per part: 5 parts at the least.
        assert!(
            (5..=24).contains(&pieces.len()),
            "{} parts: {:?}",
            pieces.len(),
            pieces.iter().map(|p| p.faces.len()).collect::<Vec<_>>()
        );
        let faces: usize = pieces.iter().map(|p| p.faces.len()).sum();
        assert_eq!(faces, 1200);
    }
}
