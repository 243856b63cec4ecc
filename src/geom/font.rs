//! Single-stroke vector font for piece labels and edge id numbers.
//!
//! Every glyph is a short list of open or closed polylines (pen-down sequences) and nothing
//! is ever filled, so a pen plotter can draw the text and a drag knife can score it without
//! any outline-to-centreline conversion. The idea follows the Hershey fonts (A. V. Hershey,
//! 1967), but the glyphs here are designed from scratch, not copied, on a small integer grid:
//!
//! * cap height 6 units: baseline at y = 0, top of capitals and digits at y = 6;
//! * glyph bodies are about 4 units wide (x = 0..=4) and the usual advance is 5 units, which
//!   leaves one unit of spacing; `.`, `,`, `:`, `'`, `°` and `(`, `)` are narrower, space is 4;
//! * curves are approximated by straight segments with one-unit chamfered corners, which stay
//!   legible at 3 mm cap height with a 0.3 mm pen and are easy for a knife to follow;
//! * only `,` and `_` reach below the baseline (down to y = -1).
//!
//! Lowercase letters map to uppercase. Characters without a glyph are drawn as an open box
//! ("tofu") of the normal advance. Lookalikes are kept apart on purpose: `0` has a slash while
//! `O` is rounder, `1` has a flag and a foot while `I` has serifs, `5` has a square shoulder
//! unlike `S`, `2` has a round top unlike `Z`, and `8` is round on both sides unlike `B`.
//!
//! The text is scaled so that the cap height equals the requested height in millimetres; the
//! baseline lies on y = 0, the first glyph starts at x = 0 and y points up.

use glam::DVec2;

/// Cap height of the design grid in units.
const CAP_UNITS: f64 = 6.0;

/// One polyline on the design grid, as `(x, y)` integer points.
type Stroke = &'static [(i8, i8)];

/// A glyph: its advance in grid units and its polylines.
#[derive(Clone, Copy, Debug)]
struct Glyph {
    advance: i8,
    strokes: &'static [Stroke],
}

const fn g(advance: i8, strokes: &'static [Stroke]) -> Glyph {
    Glyph { advance, strokes }
}

/// Drawn for characters the font does not cover: an open box of the normal advance.
const TOFU: Glyph = g(5, &[&[(0, 0), (4, 0), (4, 5), (0, 5), (0, 0)]]);

/// The glyph table. `c` must already be mapped to uppercase.
#[rustfmt::skip]
fn lookup(c: char) -> Option<Glyph> {
    let glyph = match c {
        ' ' => g(4, &[]),
        // Digits.
        '0' => g(5, &[&[(0, 1), (1, 0), (3, 0), (4, 1), (4, 5), (3, 6), (1, 6), (0, 5), (0, 1), (4, 5)]]),
        '1' => g(5, &[&[(1, 5), (2, 6), (2, 0)], &[(1, 0), (3, 0)]]),
        '2' => g(5, &[&[(0, 5), (1, 6), (3, 6), (4, 5), (4, 4), (0, 0), (4, 0)]]),
        '3' => g(5, &[&[(0, 5), (1, 6), (3, 6), (4, 5), (4, 4), (3, 3), (4, 2), (4, 1), (3, 0), (1, 0), (0, 1)],
                      &[(1, 3), (3, 3)]]),
        '4' => g(5, &[&[(3, 0), (3, 6), (0, 2), (4, 2)]]),
        '5' => g(5, &[&[(4, 6), (0, 6), (0, 3), (3, 3), (4, 2), (4, 1), (3, 0), (1, 0), (0, 1)]]),
        '6' => g(5, &[&[(4, 5), (3, 6), (1, 6), (0, 5), (0, 1), (1, 0), (3, 0), (4, 1), (4, 2), (3, 3), (1, 3), (0, 2)]]),
        '7' => g(5, &[&[(0, 6), (4, 6), (1, 0)]]),
        '8' => g(5, &[&[(3, 3), (1, 3), (0, 4), (0, 5), (1, 6), (3, 6), (4, 5), (4, 4), (3, 3),
                        (4, 2), (4, 1), (3, 0), (1, 0), (0, 1), (0, 2), (1, 3)]]),
        '9' => g(5, &[&[(0, 1), (1, 0), (3, 0), (4, 1), (4, 5), (3, 6), (1, 6), (0, 5), (0, 4), (1, 3), (3, 3), (4, 4)]]),
        // Letters.
        'A' => g(5, &[&[(0, 0), (2, 6), (4, 0)], &[(1, 3), (3, 3)]]),
        'B' => g(5, &[&[(0, 3), (3, 3), (4, 4), (4, 5), (3, 6), (0, 6), (0, 0), (3, 0), (4, 1), (4, 2), (3, 3)]]),
        'C' => g(5, &[&[(4, 5), (3, 6), (1, 6), (0, 5), (0, 1), (1, 0), (3, 0), (4, 1)]]),
        'D' => g(5, &[&[(0, 0), (0, 6), (2, 6), (4, 4), (4, 2), (2, 0), (0, 0)]]),
        'E' => g(5, &[&[(4, 6), (0, 6), (0, 0), (4, 0)], &[(0, 3), (3, 3)]]),
        'F' => g(5, &[&[(4, 6), (0, 6), (0, 0)], &[(0, 3), (3, 3)]]),
        'G' => g(5, &[&[(4, 5), (3, 6), (1, 6), (0, 5), (0, 1), (1, 0), (3, 0), (4, 1), (4, 3), (2, 3)]]),
        'H' => g(5, &[&[(0, 6), (0, 0)], &[(0, 3), (4, 3)], &[(4, 6), (4, 0)]]),
        'I' => g(5, &[&[(1, 6), (3, 6)], &[(2, 6), (2, 0)], &[(1, 0), (3, 0)]]),
        'J' => g(5, &[&[(2, 6), (4, 6), (4, 1), (3, 0), (1, 0), (0, 1), (0, 2)]]),
        'K' => g(5, &[&[(0, 6), (0, 0)], &[(4, 6), (0, 2)], &[(1, 3), (4, 0)]]),
        'L' => g(5, &[&[(0, 6), (0, 0), (4, 0)]]),
        'M' => g(5, &[&[(0, 0), (0, 6), (2, 3), (4, 6), (4, 0)]]),
        'N' => g(5, &[&[(0, 0), (0, 6), (4, 0), (4, 6)]]),
        'O' => g(5, &[&[(1, 0), (3, 0), (4, 2), (4, 4), (3, 6), (1, 6), (0, 4), (0, 2), (1, 0)]]),
        'P' => g(5, &[&[(0, 0), (0, 6), (3, 6), (4, 5), (4, 4), (3, 3), (0, 3)]]),
        'Q' => g(5, &[&[(1, 0), (3, 0), (4, 2), (4, 4), (3, 6), (1, 6), (0, 4), (0, 2), (1, 0)], &[(2, 2), (4, 0)]]),
        'R' => g(5, &[&[(0, 0), (0, 6), (3, 6), (4, 5), (4, 4), (3, 3), (0, 3)], &[(2, 3), (4, 0)]]),
        'S' => g(5, &[&[(4, 5), (3, 6), (1, 6), (0, 5), (0, 4), (1, 3), (3, 3), (4, 2), (4, 1), (3, 0), (1, 0), (0, 1)]]),
        'T' => g(5, &[&[(0, 6), (4, 6)], &[(2, 6), (2, 0)]]),
        'U' => g(5, &[&[(0, 6), (0, 1), (1, 0), (3, 0), (4, 1), (4, 6)]]),
        'V' => g(5, &[&[(0, 6), (2, 0), (4, 6)]]),
        'W' => g(5, &[&[(0, 6), (1, 0), (2, 4), (3, 0), (4, 6)]]),
        'X' => g(5, &[&[(0, 6), (4, 0)], &[(0, 0), (4, 6)]]),
        'Y' => g(5, &[&[(0, 6), (2, 3), (4, 6)], &[(2, 3), (2, 0)]]),
        'Z' => g(5, &[&[(0, 6), (4, 6), (0, 0), (4, 0)]]),
        // Punctuation.
        '-' => g(4, &[&[(0, 3), (3, 3)]]),
        '.' => g(2, &[&[(0, 0), (1, 0), (1, 1), (0, 1), (0, 0)]]),
        ',' => g(2, &[&[(0, 0), (0, 1), (1, 1), (1, 0), (0, -1)]]),
        ':' => g(2, &[&[(0, 1), (1, 1), (1, 2), (0, 2), (0, 1)], &[(0, 4), (1, 4), (1, 5), (0, 5), (0, 4)]]),
        '/' => g(5, &[&[(0, 0), (4, 6)]]),
        '#' => g(5, &[&[(1, 1), (1, 5)], &[(3, 1), (3, 5)], &[(0, 2), (4, 2)], &[(0, 4), (4, 4)]]),
        '+' => g(5, &[&[(0, 3), (4, 3)], &[(2, 1), (2, 5)]]),
        '(' => g(3, &[&[(2, 6), (0, 4), (0, 2), (2, 0)]]),
        ')' => g(3, &[&[(0, 6), (2, 4), (2, 2), (0, 0)]]),
        '_' => g(5, &[&[(0, -1), (4, -1)]]),
        '\'' => g(2, &[&[(1, 6), (0, 4)]]),
        '=' => g(5, &[&[(0, 2), (4, 2)], &[(0, 4), (4, 4)]]),
        '°' => g(3, &[&[(0, 5), (1, 6), (2, 5), (1, 4), (0, 5)]]),
        _ => return None,
    };
    Some(glyph)
}

/// The glyph drawn for `c`: its own after uppercase mapping, else the tofu box.
fn glyph_for(c: char) -> Glyph {
    lookup(c.to_ascii_uppercase()).unwrap_or(TOFU)
}

/// Millimetres per grid unit, or `None` for a height that cannot be drawn.
fn scale_for(height: f64) -> Option<f64> {
    let scale = height / CAP_UNITS;
    (height.is_finite() && height > 0.0 && scale > 0.0).then_some(scale)
}

/// Total advance of `text` in grid units.
fn advance_units(text: &str) -> i64 {
    text.chars().map(|c| i64::from(glyph_for(c).advance)).sum()
}

/// Polylines of `text` set at cap height `height` mm, baseline at y = 0, starting at x = 0, y up.
/// Returns the polylines (each at least 2 points) and the total advance width in mm.
pub fn text_strokes(text: &str, height: f64) -> (Vec<Vec<DVec2>>, f64) {
    let Some(scale) = scale_for(height) else {
        return (Vec::new(), 0.0);
    };
    let count: usize = text.chars().map(|c| glyph_for(c).strokes.len()).sum();
    let mut strokes = Vec::with_capacity(count);
    let mut pen: i64 = 0;
    for c in text.chars() {
        let glyph = glyph_for(c);
        for stroke in glyph.strokes {
            strokes.push(
                stroke
                    .iter()
                    .map(|&(x, y)| {
                        DVec2::new((pen + i64::from(x)) as f64 * scale, f64::from(y) * scale)
                    })
                    .collect(),
            );
        }
        pen += i64::from(glyph.advance);
    }
    (strokes, pen as f64 * scale)
}

/// Advance width of `text` at cap height `height` without building strokes.
pub fn text_width(text: &str, height: f64) -> f64 {
    match scale_for(height) {
        Some(scale) => advance_units(text) as f64 * scale,
        None => 0.0,
    }
}

/// Whether the font has a glyph for `c` (after uppercase mapping).
pub fn has_glyph(c: char) -> bool {
    lookup(c.to_ascii_uppercase()).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    const SUPPORTED: &str = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ -.,:/#+()_'=";
    const EPS: f64 = 1e-9;

    type Shape = BTreeSet<((i8, i8), (i8, i8))>;

    /// Undirected segments of a glyph in grid units, sorted: a drawing-order independent shape.
    fn segments(glyph: Glyph) -> Shape {
        glyph
            .strokes
            .iter()
            .flat_map(|s| s.windows(2))
            .map(|w| (w[0].min(w[1]), w[0].max(w[1])))
            .collect()
    }

    #[test]
    fn every_supported_char_has_a_glyph() {
        for c in SUPPORTED.chars() {
            assert!(has_glyph(c), "missing glyph for {c:?}");
            assert!(lookup(c).is_some(), "missing table entry for {c:?}");
        }
        for c in 'a'..='z' {
            assert!(has_glyph(c), "lowercase {c:?} should map to uppercase");
        }
    }

    #[test]
    fn lowercase_draws_like_uppercase() {
        assert_eq!(text_strokes("abc-xyz", 4.0), text_strokes("ABC-XYZ", 4.0));
    }

    #[test]
    fn points_lie_within_advance_and_vertical_band() {
        let height = 3.0;
        let unit = height / CAP_UNITS;
        for c in SUPPORTED.chars().chain(std::iter::once('\u{2603}')) {
            let s = c.to_string();
            let (strokes, width) = text_strokes(&s, height);
            let advance = f64::from(glyph_for(c).advance) * unit;
            assert!((width - advance).abs() < EPS, "{c:?}");
            for p in strokes.iter().flatten() {
                assert!(
                    p.x >= -EPS && p.x <= advance + EPS,
                    "{c:?}: x {} out of range",
                    p.x
                );
                assert!(
                    p.y >= -1.5 * unit - EPS && p.y <= height + EPS,
                    "{c:?}: y {} out of range",
                    p.y
                );
                if p.y < -EPS {
                    assert!(",_".contains(c), "{c:?} has an unexpected descender");
                }
            }
        }
    }

    #[test]
    fn polylines_have_two_points_and_no_zero_length_segments() {
        for c in SUPPORTED.chars() {
            let glyph = glyph_for(c);
            for stroke in glyph.strokes {
                assert!(stroke.len() >= 2, "{c:?}: short polyline");
                for w in stroke.windows(2) {
                    assert_ne!(w[0], w[1], "{c:?}: zero-length segment");
                }
            }
        }
        let (strokes, _) = text_strokes(SUPPORTED, 3.0);
        for stroke in &strokes {
            assert!(stroke.len() >= 2);
            for w in stroke.windows(2) {
                assert!(w[0].distance(w[1]) > EPS);
            }
        }
    }

    #[test]
    fn no_segment_is_drawn_twice_within_a_glyph() {
        for c in SUPPORTED.chars() {
            let glyph = glyph_for(c);
            let total: usize = glyph.strokes.iter().map(|s| s.len() - 1).sum();
            assert_eq!(segments(glyph).len(), total, "{c:?} retraces a segment");
        }
    }

    #[test]
    fn distinct_chars_have_distinct_shapes() {
        let mut shapes: Vec<(char, Shape)> = SUPPORTED
            .chars()
            .map(|c| (c, segments(glyph_for(c))))
            .collect();
        shapes.push(('\u{fffd}', segments(TOFU)));
        for (i, (a, sa)) in shapes.iter().enumerate() {
            for (b, sb) in &shapes[i + 1..] {
                assert_ne!(sa, sb, "{a:?} and {b:?} look the same");
            }
        }
    }

    #[test]
    fn lookalikes_differ() {
        for (a, b) in [('0', 'O'), ('1', 'I'), ('5', 'S'), ('2', 'Z'), ('8', 'B')] {
            assert_ne!(segments(glyph_for(a)), segments(glyph_for(b)), "{a} vs {b}");
        }
    }

    #[test]
    fn text_width_matches_text_strokes() {
        for text in [
            "",
            " ",
            "A",
            "P12-E7",
            "hello, world: #3 (x+y)=z_'",
            "é€\n",
            "0O1I5S2Z8B",
        ] {
            for height in [0.5, 3.0, 4.2, 10.0, 123.456] {
                let (_, width) = text_strokes(text, height);
                assert_eq!(text_width(text, height), width, "{text:?} at {height}");
            }
        }
    }

    #[test]
    fn width_is_linear_in_height() {
        let text = "PIECE 12: EDGE #7";
        let w1 = text_width(text, 1.0);
        assert!(w1 > 0.0);
        for height in [0.25, 2.0, 3.0, 7.5, 100.0] {
            let w = text_width(text, height);
            assert!((w - w1 * height).abs() < 1e-9 * height.max(1.0), "{height}");
        }
        // Known values: at 6 mm cap height one grid unit is 1 mm; letters advance 5, space 4, '.' 2.
        assert_eq!(text_width("AB", 6.0), 10.0);
        assert_eq!(text_width("A B", 6.0), 14.0);
        assert_eq!(text_width("1.2", 6.0), 12.0);
    }

    #[test]
    fn glyphs_are_placed_at_their_advance() {
        let (single, _) = text_strokes("T", 6.0);
        let (pair, width) = text_strokes("AT", 6.0);
        assert_eq!(width, 10.0);
        let shifted: Vec<Vec<DVec2>> = single
            .iter()
            .map(|s| s.iter().map(|p| *p + DVec2::new(5.0, 0.0)).collect())
            .collect();
        assert_eq!(&pair[2..], &shifted[..]);
    }

    #[test]
    fn unsupported_char_gives_tofu() {
        let (tofu, tofu_width) = text_strokes("\u{fffd}", 6.0);
        assert_eq!(tofu.len(), 1);
        assert_eq!(tofu_width, 5.0);
        assert_eq!(tofu[0].first(), tofu[0].last(), "tofu box is closed");
        for c in ['é', '€', '\n', '\t', '?', '!', '\u{1F600}', 'ß'] {
            assert!(!has_glyph(c), "{c:?}");
            assert_eq!(
                text_strokes(&c.to_string(), 6.0),
                (tofu.clone(), tofu_width)
            );
        }
        let (strokes, width) = text_strokes("A?B", 6.0);
        assert_eq!(width, 15.0);
        assert_eq!(strokes.len(), 2 + 1 + 1);
    }

    #[test]
    fn invalid_height_gives_nothing() {
        for height in [0.0, -1.0, -0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(text_strokes("ABC", height), (Vec::new(), 0.0), "{height}");
            assert_eq!(text_width("ABC", height), 0.0, "{height}");
        }
    }

    #[test]
    fn empty_and_blank_text() {
        assert_eq!(text_strokes("", 3.0), (Vec::new(), 0.0));
        let (strokes, width) = text_strokes("  ", 3.0);
        assert!(strokes.is_empty());
        assert_eq!(width, 4.0);
    }
}
