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
//! fits today is never split and the bundled patterns' outputs do not change. Before a part is
//! built, its size is estimated from its faces' corners grown on every side by what the
//! material adds (tab height or seam allowance, half the kerf); a part that then does not fit
//! once built has its island split again with the estimate grown by the overflow.
//!
//! **How** (the issue asks for few parts, straight and short seams, parts of similar size;
//! the choices below are ours). The faces of the island are put in a sequence, in several
//! ways: by their centroids along each of 12 directions 15° apart and along the axes of the
//! island's minimum-area rectangle (ties broken along the perpendicular, so a sequence sweeps
//! a straight front across the piece), and by their distance through joined edges from one end
//! of the island (on a strip — a path of faces between rulings — that is the order along the
//! strip, and every cut is one ruling). A partition is a cut of the sequence into runs; the
//! parts are the runs' connected pieces. For each sequence the greedy partition (each run as
//! long as fits) gives the fewest runs K that sequence allows; the runs are then balanced to
//! equal areas (each cut moved, within a quarter of a part's area, to where its seam costs
//! least). A part under 1 % of the whole surface's area (issue 20's bound for a piece; the
//! tip of a piece a run ends on, a piece of a run cut off from the rest) then takes faces from
//! the parts beside it while it fits and they stay whole and not small; an island whose parts
//! came out too large once built is partitioned again without this, grown parts being the
//! likelier to. Of all feasible partitions the one with fewest parts wins, then the one with
//! fewest parts over the stretch limit, then with fewest small parts, then the lowest cost:
//! the seams' length over the square root of a part's area (edges where the surface does not
//! bend — the diagonal of a flat quad, of a cone's planar strip between two rulings — and that
//! are no named bend line count double, so seams run along folds and rulings), plus twice the
//! largest part's excess area over the mean. On a large cone this gives what a shop lays out:
//! equal segments joined along rulings, each with its own bend lines.

use super::{PatternError, PatternOptions, Piece, Tabs};
use crate::flatten::Flat;
use crate::geom::polygon;
use glam::DVec2;
use std::collections::{HashMap, HashSet};

/// Parts of an island: faces each.
type Parts = Vec<Vec<usize>>;

/// A part of a split piece under this share of the whole surface's area is small (issue 20:
/// no piece under 1 % of the area) and is grown from its neighbours where it can
/// (`grow_small`).
const SMALL_PART: f64 = 0.01;

/// Below this bend (0.01°, as the strips' bend lines) an interior edge is flat: a seam there
/// would cross a panel rather than follow a line of the surface.
const BENDS_RAD: f64 = 0.01 * std::f64::consts::PI / 180.0;

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
    overflow(&pts, &angles, room)
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
    let total: f64 = flats
        .iter()
        .map(|f| {
            (0..f.surface.mesh.faces.len())
                .map(|g| f.surface.mesh.face_area(g))
                .sum::<f64>()
        })
        .sum();
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
                        let grow_small = !stuck.contains_key(&(fi, ii));
                        partition(flat, faces, g, opts, room, ii, (small, grow_small))?
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
        let mut again = false;
        for (p, &(fi, ii, one)) in pieces.iter().zip(&origin) {
            let over = piece_overflow(p, room);
            if over <= 0.0 {
                continue;
            }
            if one {
                return Err(too_large(p, room));
            }
            // Grown by the overflow (an island that fit as a whole now needs splitting too:
            // possible only when the piece changed, which the same faces cannot), doubled
            // each round the island still came out whole: the estimate can be short by much
            // more than the overflow (a seam allowance mitred at a sharp corner reaches far
            // past its width), while a part of a split island is only a little too large,
            // unless it still is after two rounds (a new partition can land its parts just
            // as far over: couplingdown in fabric, part 3a 0.12 mm over after 8 rounds).
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
            again = true;
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

/// The error for a single face that cannot fit, with its size and the room's.
fn too_large(p: &Piece, room: &Room) -> PatternError {
    let pts: Vec<DVec2> = p.outline.iter().flatten().copied().collect();
    let r = turn(polygon::min_area_rect_angle(&pts).to_degrees());
    let (lo, hi) = polygon::bounds(pts.iter().map(|q| r.rotate(*q))).unwrap_or_default();
    let size = hi - lo;
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

/// One island being split: its faces (local indices), their centroids, areas and corners,
/// and the joined edges between them with their seam cost.
struct Island<'a> {
    flat: &'a Flat,
    faces: &'a [usize],
    centroid: Vec<DVec2>,
    area: Vec<f64>,
    adj: Vec<Vec<usize>>,
    /// (u, v, cost) with u < v: a joined edge, its length doubled where it is not a line of
    /// the surface (where it does not bend and is no named bend line).
    links: Vec<(usize, usize, f64)>,
    grain: bool,
    room: Room,
    grow: f64,
    /// Area (mm²) under which a part is small (`grow_small`).
    small: f64,
    /// Whether small parts are grown (`grow_small`).
    grow_small: bool,
    /// [`PatternOptions::stretch_limit`], for an island laid out from charts.
    limit: Option<f64>,
    /// Every face's corners with the face (local), sorted by x then y: the hull of a large
    /// set of faces is taken from it without sorting again.
    sorted: Vec<(DVec2, usize)>,
}

impl<'a> Island<'a> {
    fn new(flat: &'a Flat, faces: &'a [usize], opts: &PatternOptions, room: &Room) -> Self {
        let n = faces.len();
        let mut local = HashMap::new();
        for (i, &f) in faces.iter().enumerate() {
            local.insert(f, i);
        }
        // Lines of the surface: where it bends at all, or a bend line it names.
        let named = super::bends::fold_angles(flat, opts.fold_threshold_deg.to_radians());
        let mut adj = vec![Vec::new(); n];
        let mut links = Vec::new();
        for (u, &f) in faces.iter().enumerate() {
            for (i, &e) in flat.topology.face_edges[f].iter().enumerate() {
                let edge = &flat.topology.edges[e];
                if !flat.joined[e] || edge.uses.len() != 2 || edge.uses[0] != (f, i) {
                    continue;
                }
                let Some(&v) = local.get(&edge.uses[1].0) else {
                    continue;
                };
                if v == u {
                    continue;
                }
                let (a, b) = flat.corner_edge(f, i);
                let line = named[e].is_some() || flat.dihedral[e].abs() > BENDS_RAD;
                let cost = a.distance(b) * if line { 1.0 } else { 2.0 };
                adj[u].push(v);
                adj[v].push(u);
                links.push((u.min(v), u.max(v), cost));
            }
        }
        let centroid = faces
            .iter()
            .map(|&f| {
                let c = &flat.face_2d[f];
                c.iter().copied().sum::<DVec2>() / c.len().max(1) as f64
            })
            .collect();
        let area = faces
            .iter()
            .map(|&f| flat.surface.mesh.face_area(f))
            .collect();
        let mut sorted: Vec<(DVec2, usize)> = faces
            .iter()
            .enumerate()
            .flat_map(|(u, &f)| flat.face_2d[f].iter().map(move |&p| (p, u)))
            .filter(|(p, _)| p.is_finite())
            .collect();
        sorted.sort_by(|a, b| a.0.x.total_cmp(&b.0.x).then(a.0.y.total_cmp(&b.0.y)));
        Island {
            flat,
            faces,
            centroid,
            area,
            adj,
            links,
            grain: opts.grain,
            room: *room,
            grow: 0.0,
            small: 0.0,
            grow_small: false,
            limit: opts.stretch_limit.filter(|_| flat.surface.charts.is_some()),
            sorted,
        }
    }

    /// Whether a part (local faces) stretches by more than [`Island::limit`] as laid.
    fn over_limit(&self, part: &[usize]) -> bool {
        let Some(limit) = self.limit else {
            return false;
        };
        let faces: Vec<usize> = part.iter().map(|&u| self.faces[u]).collect();
        let uv: Vec<Vec<DVec2>> = faces
            .iter()
            .map(|&f| self.flat.face_2d[f].clone())
            .collect();
        crate::flatten::distortion::stretch(&self.flat.surface.mesh, &faces, &uv).l2 > limit
    }

    /// Overflow (mm) of a set of local faces, grown by `self.grow` unless it is one face.
    fn overflow(&self, set: &[usize]) -> f64 {
        // Its hull: a large set's from the corners sorted once, a small one's by sorting its
        // own. The box of the hull is the box of the set.
        let pts = if set.len() * 8 < self.faces.len() {
            let pts: Vec<DVec2> = set
                .iter()
                .flat_map(|&u| self.flat.face_2d[self.faces[u]].iter().copied())
                .collect();
            polygon::convex_hull(&pts)
        } else {
            let mut inside = vec![false; self.faces.len()];
            for &u in set {
                inside[u] = true;
            }
            let pts = self
                .sorted
                .iter()
                .filter(|(_, u)| inside[*u])
                .map(|(p, _)| *p);
            polygon::hull_of_sorted(pts.collect())
        };
        let grow = if set.len() == 1 { 0.0 } else { self.grow };
        let angles = rect_angles(polygon::hull_rect_angle(&pts), self.grain);
        let room = Room {
            width: self.room.width - 2.0 * grow,
            height: self.room.height.map(|h| h - 2.0 * grow),
        };
        overflow(&pts, &angles, &room)
    }

    /// Connected pieces (through joined edges) of a set of local faces, each in set order.
    fn components(&self, set: &[usize], stamp: &mut [usize], mark: usize) -> Vec<Vec<usize>> {
        for &u in set {
            stamp[u] = mark;
        }
        let mut out = Vec::new();
        let done = mark + 1;
        for &u0 in set {
            if stamp[u0] != mark {
                continue;
            }
            stamp[u0] = done;
            let mut comp = vec![u0];
            let mut i = 0;
            while i < comp.len() {
                let u = comp[i];
                i += 1;
                for &v in &self.adj[u] {
                    if stamp[v] == mark {
                        stamp[v] = done;
                        comp.push(v);
                    }
                }
            }
            comp.sort_unstable();
            out.push(comp);
        }
        out
    }

    /// The sequences of faces the partitions cut (see the module docs), without repeats.
    fn orders(&self) -> Vec<Vec<usize>> {
        let n = self.faces.len();
        let (lo, hi) = polygon::bounds(self.centroid.iter().copied()).unwrap_or_default();
        let quantum = 1e-6 * (hi - lo).length().max(1e-9);
        let mut dirs: Vec<DVec2> = (0..12)
            .map(|j| DVec2::from_angle(j as f64 * std::f64::consts::PI / 12.0))
            .collect();
        let a = polygon::min_area_rect_angle(&self.centroid);
        let axis = DVec2::from_angle(-a);
        dirs.push(axis);
        dirs.push(axis.perp());
        let mut out: Vec<Vec<usize>> = Vec::new();
        for d in dirs {
            let mut order: Vec<usize> = (0..n).collect();
            let key = |u: usize| {
                let c = self.centroid[u];
                ((c.dot(d) / quantum).round() as i64, c.perp_dot(d))
            };
            order.sort_by(|&u, &v| {
                let (a, b) = (key(u), key(v));
                a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)).then(u.cmp(&v))
            });
            out.push(order);
        }
        // Through joined edges from one end: the face farthest from face 0, then the order
        // of distance from it (ties along the line between the two ends).
        let far = |s: usize| -> (Vec<usize>, usize) {
            let mut dist = vec![usize::MAX; n];
            dist[s] = 0;
            let mut queue = std::collections::VecDeque::from([s]);
            let mut last = s;
            while let Some(u) = queue.pop_front() {
                last = u;
                for &v in &self.adj[u] {
                    if dist[v] == usize::MAX {
                        dist[v] = dist[u] + 1;
                        queue.push_back(v);
                    }
                }
            }
            (dist, last)
        };
        if n > 0 {
            let (_, end) = far(0);
            let (dist, other) = far(end);
            let d = (self.centroid[other] - self.centroid[end]).normalize_or_zero();
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|&u, &v| {
                dist[u]
                    .cmp(&dist[v])
                    .then(self.centroid[u].dot(d).total_cmp(&self.centroid[v].dot(d)))
                    .then(u.cmp(&v))
            });
            out.push(order);
        }
        let mut seen = HashSet::new();
        out.retain(|o| seen.insert(o.clone()));
        out
    }
}

/// Partition of one island into parts (global face ids) that each fit, estimated with
/// `grow`; a single face that does not fit on its own is [`PatternError::TooLarge`].
fn partition(
    flat: &Flat,
    faces: &[usize],
    grow: f64,
    opts: &PatternOptions,
    room: &Room,
    island: usize,
    (small, grow_parts): (f64, bool),
) -> Result<Vec<Vec<usize>>, PatternError> {
    let mut isl = Island::new(flat, faces, opts, room);
    isl.grow = grow;
    isl.small = small;
    isl.grow_small = grow_parts;
    for u in 0..faces.len() {
        if isl.overflow(&[u]) > 0.0 {
            return Err(face_too_large(&isl, u, island));
        }
    }
    let total: f64 = isl.area.iter().sum();
    let n = faces.len();
    let mut stamp = vec![0usize; n];
    let mut mark = 1;
    let mut best: Best = None;
    let orders = isl.orders();
    // Runs [cuts[i], cuts[i + 1]) of an order, as parts if each fits.
    let mut parts_of = |order: &[usize], cuts: &[usize]| -> Option<Vec<Vec<usize>>> {
        let mut parts = Vec::new();
        for w in cuts.windows(2) {
            mark += 2;
            for comp in isl.components(&order[w[0]..w[1]], &mut stamp, mark) {
                if isl.overflow(&comp) > 0.0 {
                    return None;
                }
                parts.push(comp);
            }
        }
        Some(parts)
    };
    let mut greedy_runs = Vec::new();
    for order in &orders {
        // Greedy: each run as long as fits (binary search on its end).
        let mut cuts = vec![0];
        let mut s = 0;
        while s < n {
            let mut ok = |t: usize| parts_of(order, &[s, t]).is_some();
            let t = if ok(n) {
                n
            } else {
                // ok(lo) holds (every face fits alone, checked above), ok(hi) does not.
                let (mut lo, mut hi) = (s + 1, n);
                while hi - lo > 1 {
                    let mid = (lo + hi) / 2;
                    if ok(mid) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                lo
            };
            cuts.push(t);
            s = t;
        }
        greedy_runs.push(cuts.len() - 1);
        if let Some(parts) = parts_of(order, &cuts) {
            consider(&isl, grow_small(&isl, merge(&isl, parts)), total, &mut best);
        }
    }
    let k_min = greedy_runs.iter().copied().min().unwrap_or(1);
    for (order, &k_own) in orders.iter().zip(&greedy_runs) {
        let mut ks = vec![k_min];
        if k_own != k_min {
            ks.push(k_own);
        }
        for k in ks {
            let cuts = balanced(&isl, order, k, total);
            if let Some(parts) = parts_of(order, &cuts) {
                consider(&isl, grow_small(&isl, merge(&isl, parts)), total, &mut best);
            }
        }
    }
    let parts = best
        .map(|(_, p)| p)
        .unwrap_or_else(|| vec![(0..n).collect()]);
    Ok(parts
        .into_iter()
        .map(|p| p.into_iter().map(|u| faces[u]).collect())
        .collect())
}

/// Fewer parts: the smallest part that can join a neighbour (through a joined edge) and
/// still fit does, into the neighbour it shares the longest seam with, until none can. A run
/// of a sequence can fall apart into pieces, and a small one is better joined to another.
fn merge(isl: &Island, mut parts: Vec<Vec<usize>>) -> Vec<Vec<usize>> {
    let mut part_of = vec![0; isl.faces.len()];
    loop {
        for (k, p) in parts.iter().enumerate() {
            for &u in p {
                part_of[u] = k;
            }
        }
        let area = |p: &Vec<usize>| p.iter().map(|&u| isl.area[u]).sum::<f64>();
        let mut by_size: Vec<usize> = (0..parts.len()).collect();
        by_size.sort_by(|&a, &b| area(&parts[a]).total_cmp(&area(&parts[b])).then(a.cmp(&b)));
        let mut joined = None;
        'parts: for &k in &by_size {
            // Neighbours by shared seam length, longest first.
            let mut shared: Vec<(usize, f64)> = Vec::new();
            for &(u, v, c) in &isl.links {
                let (pu, pv) = (part_of[u], part_of[v]);
                let other = if pu == k && pv != k {
                    pv
                } else if pv == k && pu != k {
                    pu
                } else {
                    continue;
                };
                match shared.iter_mut().find(|x| x.0 == other) {
                    Some(x) => x.1 += c,
                    None => shared.push((other, c)),
                }
            }
            shared.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
            for (j, _) in shared {
                let mut union = parts[k].clone();
                union.extend_from_slice(&parts[j]);
                if isl.overflow(&union) <= 0.0 {
                    joined = Some((k, j, union));
                    break 'parts;
                }
            }
        }
        let Some((k, j, mut union)) = joined else {
            return parts;
        };
        union.sort_unstable();
        let (keep, drop) = (k.min(j), k.max(j));
        parts[keep] = union;
        parts.remove(drop);
    }
}

/// Small parts grown: a part under [`Island::small`] (a run of a sequence that ends on a tip
/// of the piece, or a piece of a run cut off from the rest) takes faces from the parts next to
/// it, one at a time, until it is no longer small, as long as it still fits with the growth
/// estimate to spare (a grown part's border is ragged, and the outline built on it reaches
/// further) and the part the face leaves stays connected and not small. The face taken is the
/// one with the most edges on the small part, then the nearest its centroid, so the part grows
/// round rather than along its border; a part that can take none stays as it is.
fn grow_small(isl: &Island, mut parts: Vec<Vec<usize>>) -> Vec<Vec<usize>> {
    let n = isl.faces.len();
    let area = |p: &[usize]| p.iter().map(|&u| isl.area[u]).sum::<f64>();
    let mut small: Vec<usize> = (0..parts.len())
        .filter(|&k| area(&parts[k]) < isl.small)
        .collect();
    if small.is_empty() || parts.len() < 2 || !isl.grow_small {
        return parts;
    }
    small.sort_by(|&a, &b| area(&parts[a]).total_cmp(&area(&parts[b])).then(a.cmp(&b)));
    let mut part_of = vec![0; n];
    for (k, p) in parts.iter().enumerate() {
        for &u in p {
            part_of[u] = k;
        }
    }
    let mut stamp = vec![0usize; n];
    let mut mark = 1;
    for k in small {
        let mut have = area(&parts[k]);
        while have < isl.small {
            let centre = parts[k]
                .iter()
                .map(|&u| isl.centroid[u] * isl.area[u])
                .sum::<DVec2>()
                / have.max(1e-300);
            // Faces next to the part: (face, edges on the part, distance to its centre).
            let mut cands: Vec<(usize, usize, f64)> = Vec::new();
            for &u in &parts[k] {
                for &v in &isl.adj[u] {
                    if part_of[v] == k {
                        continue;
                    }
                    match cands.iter_mut().find(|c| c.0 == v) {
                        Some(c) => c.1 += 1,
                        None => cands.push((v, 1, isl.centroid[v].distance(centre))),
                    }
                }
            }
            cands.sort_by(|a, b| b.1.cmp(&a.1).then(a.2.total_cmp(&b.2)).then(a.0.cmp(&b.0)));
            let mut took = None;
            for &(v, _, _) in &cands {
                let j = part_of[v];
                if area(&parts[j]) - isl.area[v] < isl.small {
                    continue;
                }
                let mut grown = parts[k].clone();
                grown.push(v);
                if isl.overflow(&grown) > -isl.grow {
                    continue;
                }
                let rest: Vec<usize> = parts[j].iter().copied().filter(|&u| u != v).collect();
                mark += 2;
                if isl.components(&rest, &mut stamp, mark).len() != 1 {
                    continue;
                }
                took = Some((v, j, grown, rest));
                break;
            }
            let Some((v, j, grown, rest)) = took else {
                break;
            };
            part_of[v] = k;
            have += isl.area[v];
            parts[k] = grown;
            parts[j] = rest;
        }
        parts[k].sort_unstable();
    }
    parts
}

/// The best partition so far: (number of parts, parts over the stretch limit, small parts,
/// cost) and the parts.
type Best = Option<((usize, usize, usize, f64), Vec<Vec<usize>>)>;

/// Keep `parts` if it beats the best so far: fewer parts, then fewer parts over the stretch
/// limit (a part of a layout can stretch more than the whole), then fewer small parts (under
/// [`Island::small`]), then a lower cost (seam length over a part's typical size, twice the
/// largest part's excess area over the mean).
fn consider(isl: &Island, parts: Vec<Vec<usize>>, total: f64, best: &mut Best) {
    let mut part_of = vec![0; isl.faces.len()];
    for (k, p) in parts.iter().enumerate() {
        for &u in p {
            part_of[u] = k;
        }
    }
    let mean = total / parts.len() as f64;
    let seam: f64 = isl
        .links
        .iter()
        .filter(|(u, v, _)| part_of[*u] != part_of[*v])
        .map(|l| l.2)
        .sum();
    let largest = parts
        .iter()
        .map(|p| p.iter().map(|&u| isl.area[u]).sum::<f64>())
        .fold(0.0, f64::max);
    let cost = seam / mean.sqrt().max(1e-9) + 2.0 * (largest / mean.max(1e-300) - 1.0);
    let over = parts.iter().filter(|p| isl.over_limit(p)).count();
    let small = parts
        .iter()
        .filter(|p| p.iter().map(|&u| isl.area[u]).sum::<f64>() < isl.small)
        .count();
    let score = (parts.len(), over, small, cost);
    let better = match best {
        None => true,
        Some((s, _)) => {
            (score.0, score.1, score.2) < (s.0, s.1, s.2)
                || ((score.0, score.1, score.2) == (s.0, s.1, s.2) && score.3 < s.3 - 1e-12)
        }
    };
    if better {
        *best = Some((score, parts));
    }
}

/// Cuts of an order into `k` runs of about equal area, each cut moved within a quarter of a
/// run's area to where the edges it crosses cost least.
fn balanced(isl: &Island, order: &[usize], k: usize, total: f64) -> Vec<usize> {
    let n = order.len();
    let mut rank = vec![0; n];
    for (r, &u) in order.iter().enumerate() {
        rank[u] = r;
    }
    // Area before position q, and the cost of the edges a cut at q crosses.
    let mut before = vec![0.0; n + 1];
    for (r, &u) in order.iter().enumerate() {
        before[r + 1] = before[r] + isl.area[u];
    }
    let mut diff = vec![0.0; n + 2];
    for &(u, v, c) in &isl.links {
        let (a, b) = (rank[u].min(rank[v]), rank[u].max(rank[v]));
        diff[a + 1] += c;
        diff[b + 1] -= c;
    }
    let mut crossing = vec![0.0; n + 1];
    let mut acc = 0.0;
    for q in 0..=n {
        acc += diff[q];
        crossing[q] = acc;
    }
    let share = total / k as f64;
    let size = share.sqrt().max(1e-9);
    let mut cuts = vec![0];
    for j in 1..k {
        let target = share * j as f64;
        let prev = *cuts.last().unwrap_or(&0);
        let q = (prev + 1..n)
            .filter(|&q| (before[q] - target).abs() <= 0.25 * share)
            .min_by(|&a, &b| {
                let f = |q: usize| crossing[q] / size + 2.0 * (before[q] - target).abs() / share;
                f(a).total_cmp(&f(b)).then(a.cmp(&b))
            })
            .unwrap_or_else(|| {
                (prev + 1..n)
                    .min_by(|&a, &b| {
                        (before[a] - target)
                            .abs()
                            .total_cmp(&(before[b] - target).abs())
                    })
                    .unwrap_or(n)
            });
        if q >= n {
            break;
        }
        cuts.push(q);
    }
    cuts.push(n);
    cuts
}

/// The error for face `u` of an island, too large for the room on its own.
fn face_too_large(isl: &Island, u: usize, island: usize) -> PatternError {
    let f = isl.faces[u];
    let pts = &isl.flat.face_2d[f];
    let r = turn(polygon::min_area_rect_angle(pts).to_degrees());
    let (lo, hi) = polygon::bounds(pts.iter().map(|q| r.rotate(*q))).unwrap_or_default();
    let size = hi - lo;
    PatternError::TooLarge {
        surface: isl.flat.surface.name.clone(),
        piece: format!("{}", island + 1),
        face: f + 1,
        w: size.x.max(size.y),
        h: size.x.min(size.y),
        what: isl.room.what(),
        uw: isl.room.width,
        uh: isl.room.height_text(),
    }
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

    /// A flat row of `n` squares of `side` mm along x, as one surface.
    fn row_of_squares(n: usize, side: f64) -> crate::surface::Surface {
        let mut verts = Vec::new();
        for i in 0..=n {
            verts.push(glam::DVec3::new(side * i as f64, 0.0, 0.0));
            verts.push(glam::DVec3::new(side * i as f64, side, 0.0));
        }
        let faces: Vec<[usize; 4]> = (0..n)
            .map(|i| [2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1])
            .collect();
        crate::surface::Surface {
            name: "row".into(),
            source: "t.obj".into(),
            mesh: crate::geom::mesh::Mesh::from_polygons(verts, &faces),
            ..Default::default()
        }
    }

    /// A row of 40 squares of 10 mm, flat: a part of two squares at its end takes squares from
    /// the part beside it until it has 8 (800 mm², the "small" bound here), the other part
    /// staying one strip; not past what fits the room; and not from a part that would then be
    /// small itself.
    #[test]
    fn a_small_part_grows_from_its_neighbour_while_it_fits() {
        let flat = unfold(row_of_squares(40, 10.0), &UnfoldOptions::default()).unwrap();
        assert_eq!(flat.islands.len(), 1);
        let all = &flat.islands[0];
        // Local faces along the row, by the x of their centroid.
        let opts = PatternOptions::default();
        let grown = |room: f64, parts: Vec<Vec<usize>>| {
            let room = Room {
                width: room,
                height: Some(room),
            };
            let mut isl = Island::new(&flat, all, &opts, &room);
            isl.small = 800.0 - 1e-6;
            isl.grow_small = true;
            let mut by_x: Vec<usize> = (0..all.len()).collect();
            by_x.sort_by(|&a, &b| isl.centroid[a].x.total_cmp(&isl.centroid[b].x));
            let parts: Vec<Vec<usize>> = parts
                .into_iter()
                .map(|p| p.into_iter().map(|k| by_x[k]).collect())
                .collect();
            // Each part as (first x, last x, squares).
            grow_small(&isl, parts)
                .iter()
                .map(|p| {
                    let x = p.iter().map(|&u| isl.centroid[u].x);
                    (
                        x.clone().fold(f64::MAX, f64::min),
                        x.fold(0.0, f64::max),
                        p.len(),
                    )
                })
                .collect::<Vec<(f64, f64, usize)>>()
        };
        let two = |a: usize, b: usize| vec![(0..a).collect(), (a..b).collect::<Vec<usize>>()];
        // Grown to 8 squares, both parts still runs of the row.
        assert_eq!(
            grown(250.0, two(2, 40)),
            [(5.0, 75.0, 8), (85.0, 395.0, 32)]
        );
        // A 55 mm room holds 5 squares: it stops there, still small.
        assert_eq!(grown(55.0, two(2, 40)), [(5.0, 45.0, 5), (55.0, 395.0, 35)]);
        // The part beside it has 8 squares: taking one would make it small.
        let three = vec![(0..2).collect(), (2..10).collect(), (10..40).collect()];
        assert_eq!(
            grown(250.0, three),
            [(5.0, 15.0, 2), (25.0, 95.0, 8), (105.0, 395.0, 30)]
        );
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
}
