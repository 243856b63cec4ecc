//! Features a device cannot make, found before anything is cut (issue 21): a piece smaller
//! than the blade can turn in, seam ids or a label smaller than 2 mm, texts the pattern stage
//! left out for want of a clear place (issue 20, `pattern::legible`), and slits (narrow gaps of
//! a piece's border) narrower than the kerf. Each is a [`Warning`] naming the piece, printed
//! and listed in `report.json`; nothing is refused (a model of implausible size as a whole is
//! refused earlier, by `surface::size`).
//!
//! Choices where the issue is silent:
//! - A drag knife trails its tip by the offset and swivels round it at corners; below about
//!   four offsets across (a piece's smaller side, measured on its smallest enclosing
//!   rectangle) the swivels of opposite corners meet and the piece is torn rather than cut.
//!   Without a knife offset a piece under 1 mm across is still too small to handle or weed.
//! - Text height is the height of its tallest single stroke across its reading direction (a
//!   digit `1`, a letter's stem): the cap height the font was set at, whatever the text says.
//! - A slit is where two parts of a border ring that are not neighbours along it (more than
//!   twice the kerf apart along the ring) come closer than the kerf: the cut removes the
//!   material between them. Rings of more than [`MAX_SLIT_SEGMENTS`] segments are not searched
//!   (a quadratic search; such rings come from dense meshes with no slits of their own).

use crate::geom::polygon;
use crate::pattern::{Piece, Text};
use glam::DVec2;

/// Smallest height of text (mm) a knife scores or a pen draws legibly: the pattern stage's
/// floor, below which it shrinks no text to make room.
pub use crate::pattern::legible::MIN_TEXT_MM;
/// Different texts a `text-left-out` warning lists at most; the rest are counted (what they
/// say is in report.json: a bend line's angle, a seam's id).
const LEFT_OUT_LISTED: usize = 8;
/// Border rings with more segments than this are not searched for slits.
pub const MAX_SLIT_SEGMENTS: usize = 4000;

/// What the device can make.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CuttableOptions {
    /// Smallest piece (mm, its smaller side).
    pub min_piece: f64,
    /// Smallest text (mm).
    pub min_text: f64,
    /// Width of the cut (mm); 0: no slit check.
    pub kerf: f64,
}

impl CuttableOptions {
    /// For a device whose drag knife trails by `knife_offset` mm (0: none) cutting `kerf` wide.
    pub fn for_device(knife_offset: f64, kerf: f64) -> Self {
        CuttableOptions {
            min_piece: (4.0 * knife_offset).max(1.0),
            min_text: MIN_TEXT_MM,
            kerf,
        }
    }
}

/// One feature the device cannot make.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Warning {
    /// The piece's name, as written on it.
    pub piece: String,
    /// `piece-too-small`, `text-too-small` or `slit-narrower-than-kerf`; the pipeline adds
    /// `seam-mismatch` ([`crate::pattern::marks::seam_mismatches`]).
    pub kind: &'static str,
    /// One line for the user.
    pub message: String,
}

/// The features of `pieces` the device cannot make, piece by piece.
pub fn check(pieces: &[Piece], o: &CuttableOptions) -> Vec<Warning> {
    let mut out = Vec::new();
    for p in pieces {
        let warn = |kind, message| Warning {
            piece: p.name.clone(),
            kind,
            message,
        };
        let small = smaller_side(p);
        if small < o.min_piece {
            out.push(warn(
                "piece-too-small",
                format!(
                    "piece {}: {small:.2} mm across, less than the {:.2} mm the blade can turn in; make the model larger (--size)",
                    p.name, o.min_piece
                ),
            ));
        }
        let texts = p
            .marks
            .iter()
            .map(|m| (&m.text, "seam id"))
            .chain(std::iter::once((&p.label, "label")));
        let smallest = texts
            .filter_map(|(t, what)| text_height(t).map(|h| (h, what)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((h, what)) = smallest.filter(|(h, _)| *h < o.min_text) {
            out.push(warn(
                "text-too-small",
                format!(
                    "piece {}: its {what} is {h:.2} mm high, under {} mm: too small to cut or draw legibly; make the model larger (--size)",
                    p.name, o.min_text
                ),
            ));
        }
        out.extend(left_out(p).into_iter().map(|m| warn("text-left-out", m)));
        if o.kerf > 0.0 {
            if let Some((gap, at)) = narrowest_slit(p, o.kerf) {
                out.push(warn(
                    "slit-narrower-than-kerf",
                    format!(
                        "piece {}: a slit {gap:.3} mm wide at ({:.1}, {:.1}) is narrower than the {} mm kerf: the cut removes it",
                        p.name, at.x, at.y, o.kerf
                    ),
                ));
            }
        }
    }
    out
}

/// One message per kind of text the pattern stage left off a piece (`pattern::legible`):
/// the one text it says, or how many and which (at most [`LEFT_OUT_LISTED`] different ones,
/// the rest counted), the same text on several lines (a bend note) once with its count:
/// warnings of kind `text-left-out`. A piece of a curved metal model can lose dozens of bend
/// notes; one line per piece keeps the other warnings in view.
fn left_out(p: &Piece) -> Vec<String> {
    // (what, [(words, times)]) in the order first met.
    let mut kinds: Vec<(&str, Vec<(&str, usize)>)> = Vec::new();
    for l in &p.left_out {
        let i = match kinds.iter().position(|k| k.0 == l.what) {
            Some(i) => i,
            None => {
                kinds.push((l.what, Vec::new()));
                kinds.len() - 1
            }
        };
        match kinds[i].1.iter_mut().find(|w| w.0 == l.words) {
            Some(w) => w.1 += 1,
            None => kinds[i].1.push((&l.words, 1)),
        }
    }
    kinds
        .into_iter()
        .map(|(what, words)| {
            let (hint, record) = match what {
                "bend note" => (
                    "make the model larger (--size); for strips, bent sheets and spline surfaces, mark fewer bend lines (--bend-lines shop or a spacing in mm)",
                    "every bend line's angle is in report.json (pieces[].fold_lines)",
                ),
                "seam id" => (
                    "make the model larger (--size)",
                    "every seam is in report.json (seams)",
                ),
                _ => ("make the model larger (--size)", ""),
            };
            let times = |n: usize| if n > 1 { format!(" ({n} times)") } else { String::new() };
            let said = match words[..] {
                [(w, 1)] => format!("{what} \"{w}\" left out"),
                [(w, n)] => format!("{n} {what}s left out: \"{w}\"{}", times(n)),
                _ => {
                    let total: usize = words.iter().map(|w| w.1).sum();
                    let mut list: Vec<String> = words
                        .iter()
                        .take(LEFT_OUT_LISTED)
                        .map(|&(w, n)| format!("\"{w}\"{}", times(n)))
                        .collect();
                    if words.len() > LEFT_OUT_LISTED {
                        let more: usize = words[LEFT_OUT_LISTED..].iter().map(|w| w.1).sum();
                        list.push(match record {
                            "" => format!("and {more} more"),
                            r => format!("and {more} more ({r})"),
                        });
                    }
                    format!("{total} {what}s left out: {}", list.join(", "))
                }
            };
            format!(
                "piece {}: {said}; no place clear of the other text and the lines at {MIN_TEXT_MM} mm or more; {hint}",
                p.name
            )
        })
        .collect()
}

/// The smaller side of the smallest enclosing rectangle of a piece's outer outline.
fn smaller_side(p: &Piece) -> f64 {
    let Some(ring) = p.outline.first().filter(|r| r.len() >= 3) else {
        return 0.0;
    };
    let r = DVec2::from_angle(polygon::min_area_rect_angle(ring));
    polygon::bounds(ring.iter().map(|q| r.rotate(*q)))
        .map_or(0.0, |(lo, hi)| (hi - lo).min_element())
}

/// Height of a text: its tallest stroke across the reading direction; `None` for no text.
fn text_height(t: &Text) -> Option<f64> {
    if t.is_empty() {
        return None;
    }
    let dir = t.dir.unwrap_or(DVec2::X);
    let n = dir.perp();
    t.strokes
        .iter()
        .filter(|s| !s.is_empty())
        .map(|s| {
            let (lo, hi) = s
                .iter()
                .map(|q| q.dot(n))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(v), b.max(v))
                });
            hi - lo
        })
        .max_by(f64::total_cmp)
}

/// The narrowest gap under `kerf` between parts of a border ring that are not neighbours
/// along it, and where it is.
fn narrowest_slit(p: &Piece, kerf: f64) -> Option<(f64, DVec2)> {
    let mut best: Option<(f64, DVec2)> = None;
    for ring in &p.border {
        let n = ring.len();
        if !(3..=MAX_SLIT_SEGMENTS).contains(&n) {
            continue;
        }
        // Arc length at each vertex, to tell neighbours along the ring.
        let mut arc = vec![0.0; n + 1];
        for i in 0..n {
            arc[i + 1] = arc[i] + ring[i].distance(ring[(i + 1) % n]);
        }
        let total = arc[n];
        for i in 0..n {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            for j in i + 2..n {
                if i == 0 && j == n - 1 {
                    continue;
                }
                let (c, d) = (ring[j], ring[(j + 1) % n]);
                let d2 = polygon::segment_segment_distance(a, b, c, d);
                if d2 >= kerf {
                    continue;
                }
                // Along the ring, the two segments' nearest ends are this far apart.
                let along = (arc[j] - arc[i + 1]).min(total - arc[j + 1] + arc[i]);
                if along <= 2.0 * kerf {
                    continue;
                }
                if best.is_none_or(|(g, _)| d2 < g) {
                    best = Some((d2, 0.5 * (a + c)));
                }
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(id: usize, s: f64) -> Piece {
        Piece::from_outline(
            id,
            format!("{id}"),
            vec![
                DVec2::ZERO,
                DVec2::new(s, 0.0),
                DVec2::new(s, s),
                DVec2::new(0.0, s),
            ],
        )
    }

    #[test]
    fn small_pieces_small_text_and_slits_are_named() {
        let o = CuttableOptions::for_device(0.25, 0.3);
        assert!(check(&[square(1, 50.0)], &o).is_empty());
        let w = check(&[square(2, 0.8)], &o);
        assert_eq!(w.len(), 1);
        assert_eq!((w[0].piece.as_str(), w[0].kind), ("2", "piece-too-small"));
        let mut p = square(3, 50.0);
        p.label = Text {
            strokes: vec![vec![DVec2::new(10.0, 10.0), DVec2::new(10.0, 11.5)]],
            dir: None,
        };
        p.left_out.push(crate::pattern::legible::LeftOut {
            what: "bend note",
            words: "2° DOWN".into(),
        });
        p.left_out.push(crate::pattern::legible::LeftOut {
            what: "bend note",
            words: "2° DOWN".into(),
        });
        let one = check(std::slice::from_ref(&p), &o);
        assert_eq!(one.len(), 2, "{one:?}");
        assert_eq!(one[1].kind, "text-left-out");
        assert!(
            one[1]
                .message
                .starts_with("piece 3: 2 bend notes left out: \"2° DOWN\" (2 times); no place"),
            "{}",
            one[1].message
        );
        // One line per kind of text, each text said once with its count.
        for (what, words) in [("seam id", "7"), ("bend note", "5° UP")] {
            p.left_out.push(crate::pattern::legible::LeftOut {
                what,
                words: words.into(),
            });
        }
        let w = check(std::slice::from_ref(&p), &o);
        assert_eq!(w.len(), 3, "{w:?}");
        assert_eq!(w[1].kind, "text-left-out");
        assert!(
            w[1].message.starts_with(
                "piece 3: 3 bend notes left out: \"2° DOWN\" (2 times), \"5° UP\"; no place"
            ),
            "{}",
            w[1].message
        );
        assert!(
            w[2].message
                .starts_with("piece 3: seam id \"7\" left out; no place"),
            "{}",
            w[2].message
        );
        assert_eq!(w[0].kind, "text-too-small");
        assert!(w[0].message.contains("1.50 mm high"), "{}", w[0].message);
        // A U with a 0.2 mm slot between its arms, 20 mm deep.
        let u = vec![
            DVec2::ZERO,
            DVec2::new(20.2, 0.0),
            DVec2::new(20.2, 30.0),
            DVec2::new(10.2, 30.0),
            DVec2::new(10.2, 10.0),
            DVec2::new(10.0, 10.0),
            DVec2::new(10.0, 30.0),
            DVec2::new(0.0, 30.0),
        ];
        let w = check(&[Piece::from_outline(4, "4".into(), u)], &o);
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!(w[0].kind, "slit-narrower-than-kerf");
        assert!(w[0].message.contains("0.200 mm"), "{}", w[0].message);
    }
}
