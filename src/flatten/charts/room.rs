//! Pieces split to fit the sheet (issue 20: no piece over the tolerance, none under 1 % of the
//! area): a piece that does not fit the sheet ([`FlattenOptions::sheet`]) at any quarter turn
//! of its least rectangle nor at any whole degree of turn is halved ([`Charts::split_in_two`]: along the bisector of its two
//! most distant faces, across its length) and each half laid out again from the whole's layout
//! ([`Charts::lay_from`]), its seams matched, as the halves of a chart split for stretch are;
//! the halves again, until each fits the room ([`FlattenOptions::room`]: the sheet less what
//! the material adds round a piece). The pattern stage would otherwise cut the piece as it
//! lies, and a part of a layout can stretch more than the whole (a part round the most
//! stretched region) and be a small tip; here the parts are laid out on their own, and small
//! ones go to the merges and hinges that follow.
//!
//! Choices: halving is repeated in rounds (at most [`ROOM_ROUNDS`]); a half over the tolerance
//! goes on as any chart does (darts, gussets, laid out exactly), not split for stretch again. A
//! piece that fits the sheet but not the room is left to the pattern stage, which knows what it
//! adds round it (tabs and seam allowance only along seams), and so is a piece that fits the
//! sheet turned at a whole degree only (the nest turns a whole piece so): a piece that fits as
//! built is never cut.

use super::join::fits_room;
use super::{Charts, Degenerate, FlattenOptions, Laid, Start, Todo, Whole};
use crate::flatten::FlattenError;
use crate::geom::polygon;
use glam::DVec2;

/// Rounds of halving at most (a piece 2⁸ times the room is left to the pattern stage).
const ROOM_ROUNDS: usize = 8;

/// Halve every piece of `done` that does not fit the sheet, and its parts until they fit the
/// room, in rounds (see the module doc).
pub(super) fn fit_room(
    ctx: &Charts,
    done: &mut Vec<Laid>,
    opts: &FlattenOptions,
    eps: f64,
    degenerate: &Degenerate<'_>,
) -> Result<(), FlattenError> {
    let Some(sheet) = opts.sheet else {
        return Ok(());
    };
    // Whether each piece of `done` is a part of a piece halved here.
    let mut part = vec![false; done.len()];
    for _ in 0..ROOM_ROUNDS {
        let mut todo = Vec::new();
        let mut keep = Vec::with_capacity(done.len());
        let mut kept_part = Vec::with_capacity(done.len());
        for (l, was_halved) in done.drain(..).zip(std::mem::take(&mut part)) {
            let halve = l.faces.len() > 1
                && !fits_room(opts.room, &l.uv)
                && (was_halved || !fits_turned(sheet, &l.uv));
            if halve {
                let t = Todo {
                    faces: l.faces.clone(),
                    splits: opts.max_splits,
                    cuts: l.cuts.clone(),
                    cut_off: l.gusset,
                    start: Start::Anew,
                };
                let whole = Whole::new(&l.faces, &l.uv);
                if ctx.split_in_two(&mut todo, &t, opts.max_splits, Some(whole)) {
                    continue;
                }
            }
            keep.push(l);
            kept_part.push(was_halved);
        }
        (*done, part) = (keep, kept_part);
        if todo.is_empty() {
            break;
        }
        // Popped last to first, as the halves were pushed.
        todo.reverse();
        let halves = ctx.lay_trees(opts, eps, todo, degenerate)?;
        part.extend(halves.iter().map(|_| true));
        done.extend(halves);
    }
    Ok(())
}

/// Whether the layout `uv` fits `sheet` (width, height) at a quarter turn of its least
/// rectangle or at some whole degree of turn: the nest turns a whole piece so (a long thin
/// piece across the sheet's diagonal), and the pattern stage then does not cut it.
fn fits_turned(sheet: [f64; 2], uv: &[Vec<DVec2>]) -> bool {
    if fits_room(Some(sheet), uv) {
        return true;
    }
    let pts: Vec<DVec2> = uv.iter().flatten().copied().collect();
    (0..180).any(|deg| {
        let turn = DVec2::from_angle(f64::from(deg).to_radians());
        polygon::bounds(pts.iter().map(|&p| turn.rotate(p))).is_some_and(|(lo, hi)| {
            let size = hi - lo;
            size.x <= sheet[0] && size.y <= sheet[1]
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flatten::charts::{as_they_lie, self_overlap, strip_and_squares, Fixture};

    /// A 200 × 100 mm rectangle and a 200 × 1.5 mm strip along its bottom, on the plane, the
    /// sheet 160 mm square and the room (what a piece may take before growing by its tabs)
    /// 150 mm: the rectangle does not fit the sheet, so it is halved across its length and
    /// each half fits the room, laid flat (L2 1) without overlap, every face in one piece; the
    /// strip fits the sheet turned across its diagonal and is left as it is. Without a
    /// sheet nothing changes; nor do a rectangle and strip 160 mm long, which fit the sheet
    /// but not the room (the pattern stage knows whether they fit once built).
    #[test]
    fn pieces_too_large_for_the_sheet_are_halved_until_they_fit_the_room() {
        let degenerate = |f: usize| FlattenError::Degenerate {
            surface: "test".into(),
            face: f + 1,
            line: None,
        };
        let (room, sheet) = (Some([150.0, 150.0]), Some([160.0, 160.0]));
        let fit = |blocks: &[(std::ops::Range<usize>, std::ops::Range<usize>)], sheet| {
            let (mesh, ranges) = strip_and_squares(blocks);
            let fx = Fixture::new(mesh);
            let opts = FlattenOptions {
                room,
                sheet,
                ..FlattenOptions::default()
            };
            let mut done = as_they_lie(&fx.mesh, &ranges);
            fit_room(&fx.charts(&opts), &mut done, &opts, 1e-6, &degenerate).unwrap();
            let mut faces: Vec<usize> = done.iter().flat_map(|l| l.faces.clone()).collect();
            faces.sort_unstable();
            assert_eq!(faces, (0..fx.mesh.faces.len()).collect::<Vec<_>>());
            for l in &done {
                assert!((l.stretch.l2 - 1.0).abs() < 1e-9, "{}", l.stretch.l2);
                assert_eq!(l.stretch.flipped, 0);
                assert!(self_overlap(&l.uv, 1e-6).is_none());
            }
            done
        };
        let both = [(0..20, 1..11), (0..20, 0..1)];
        let done = fit(&both, sheet);
        // The rectangle (faces 0..400) in two halves that fit the room; the strip (40 faces)
        // fits the sheet across its diagonal, so it is left as it is.
        assert_eq!(done.len(), 3);
        for l in &done {
            if l.faces[0] < 400 {
                assert!(l.faces.len() < 400 && fits_room(room, &l.uv));
            } else {
                assert_eq!(l.faces.len(), 40);
                assert!(!fits_room(sheet, &l.uv) && fits_turned(sheet.unwrap(), &l.uv));
            }
        }
        assert_eq!(fit(&both, None).len(), 2);
        // 160 mm long: within the sheet, over the room.
        let near = fit(&[(0..16, 1..11), (0..16, 0..1)], sheet);
        assert_eq!(near.len(), 2);
        assert!(!fits_room(room, &near[0].uv) && fits_room(sheet, &near[0].uv));
    }
}
