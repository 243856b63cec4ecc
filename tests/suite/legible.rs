//! Issue 20, item 10 "Legible finishing": in every bundled pattern no text's box (piece label,
//! seam id, bend note) overlaps another text's box or a stroke of another kind (cut outline,
//! fold line, tab fold, notch, sewing line, grain arrow); `fitting cone` marks its bend lines
//! at a shop's spacing with notes that keep apart.
//!
//! The check here is written independently of the pattern stage's own placement
//! (`flatcut::pattern::legible`), from the definitions alone:
//! - a text set along an edge or a bend line (`dir` given) keeps its orientation relative to
//!   the piece on the sheet (it is at most turned half a turn about its centre), so its box is
//!   the smallest rectangle round its strokes along `dir` and across it;
//! - a free label (`dir` none) is turned on the sheet about the centre of its bounding box to
//!   read along the sheet's x axis, whatever rotation the nest gave the piece, so what it can
//!   cover is the disc round that centre through its farthest stroke point.
//!
//! Boxes are shrunk by 1 µm before testing, so that text touching a line is not counted.

use crate::common::*;
use flatcut::pattern::{Piece, Text};
use glam::DVec2;

const EPS: f64 = 1e-3;

/// What a text can cover on the sheet.
#[derive(Debug, Clone, Copy)]
enum Shape {
    /// Centre, unit axis `u` (reading direction), half extents along `u` and across it.
    Box {
        c: DVec2,
        u: DVec2,
        hu: f64,
        hv: f64,
    },
    Disc {
        c: DVec2,
        r: f64,
    },
}

fn shape(t: &Text) -> Option<Shape> {
    let pts: Vec<DVec2> = t.points().collect();
    if pts.is_empty() {
        return None;
    }
    Some(match t.dir {
        Some(u) => {
            let v = u.perp();
            let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
            for q in &pts {
                let l = DVec2::new(q.dot(u), q.dot(v));
                lo = lo.min(l);
                hi = hi.max(l);
            }
            let m = 0.5 * (lo + hi);
            Shape::Box {
                c: u * m.x + v * m.y,
                u,
                hu: (0.5 * (hi.x - lo.x) - EPS).max(0.0),
                hv: (0.5 * (hi.y - lo.y) - EPS).max(0.0),
            }
        }
        None => {
            let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
            for q in &pts {
                lo = lo.min(*q);
                hi = hi.max(*q);
            }
            let c = 0.5 * (lo + hi);
            let r = pts.iter().map(|q| q.distance(c)).fold(0.0, f64::max);
            Shape::Disc {
                c,
                r: (r - EPS).max(0.0),
            }
        }
    })
}

/// Distance from `q` to the segment `a`–`b`.
fn seg_dist(q: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let l2 = d.length_squared();
    let t = if l2 > 0.0 {
        ((q - a).dot(d) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    q.distance(a + d * t)
}

/// Whether the segment crosses or touches the closed box [-hu, hu] × [-hv, hv] (local frame).
fn seg_in_box(a: DVec2, b: DVec2, hu: f64, hv: f64) -> bool {
    // Liang–Barsky clipping.
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    let d = b - a;
    for (p, q) in [
        (-d.x, a.x + hu),
        (d.x, hu - a.x),
        (-d.y, a.y + hv),
        (d.y, hv - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return false;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    t0 <= t1
}

fn local(c: DVec2, u: DVec2, q: DVec2) -> DVec2 {
    let d = q - c;
    DVec2::new(d.dot(u), d.dot(u.perp()))
}

/// Distance from `q` (local frame) to the box [-hu, hu] × [-hv, hv].
fn box_dist(q: DVec2, hu: f64, hv: f64) -> f64 {
    let d = DVec2::new((q.x.abs() - hu).max(0.0), (q.y.abs() - hv).max(0.0));
    d.length()
}

fn hits_segment(s: &Shape, a: DVec2, b: DVec2) -> bool {
    match *s {
        Shape::Disc { c, r } => seg_dist(c, a, b) < r,
        Shape::Box { c, u, hu, hv } => seg_in_box(local(c, u, a), local(c, u, b), hu, hv),
    }
}

fn corners(c: DVec2, u: DVec2, hu: f64, hv: f64) -> [DVec2; 4] {
    let v = u.perp();
    [
        c - u * hu - v * hv,
        c + u * hu - v * hv,
        c + u * hu + v * hv,
        c - u * hu + v * hv,
    ]
}

fn shapes_overlap(x: &Shape, y: &Shape) -> bool {
    match (*x, *y) {
        (Shape::Disc { c: c1, r: r1 }, Shape::Disc { c: c2, r: r2 }) => c1.distance(c2) < r1 + r2,
        (Shape::Disc { c: cd, r }, Shape::Box { c, u, hu, hv })
        | (Shape::Box { c, u, hu, hv }, Shape::Disc { c: cd, r }) => {
            box_dist(local(c, u, cd), hu, hv) < r
        }
        (
            Shape::Box {
                c: c1,
                u: u1,
                hu: a1,
                hv: b1,
            },
            Shape::Box {
                c: c2,
                u: u2,
                hu: a2,
                hv: b2,
            },
        ) => {
            // Separating axis test on the four axes.
            let k1 = corners(c1, u1, a1, b1);
            let k2 = corners(c2, u2, a2, b2);
            for axis in [u1, u1.perp(), u2, u2.perp()] {
                let proj = |k: &[DVec2; 4]| {
                    k.iter()
                        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
                            (lo.min(q.dot(axis)), hi.max(q.dot(axis)))
                        })
                };
                let (l1, h1) = proj(&k1);
                let (l2, h2) = proj(&k2);
                if h1 < l2 || h2 < l1 {
                    return false;
                }
            }
            true
        }
    }
}

/// Every text of a piece with what it is.
fn texts(p: &Piece) -> Vec<(String, Shape)> {
    let mut out = Vec::new();
    for m in &p.marks {
        if let Some(s) = shape(&m.text) {
            out.push((format!("seam id {}", m.id), s));
        }
    }
    for (i, t) in p.notes.iter().enumerate() {
        if let Some(s) = shape(t) {
            out.push((format!("bend note {}", i + 1), s));
        }
    }
    if let Some(s) = shape(&p.label) {
        out.push(("label".to_string(), s));
    }
    out
}

/// Every stroke of a piece that is not text, named, as segments: each contour of the outline
/// and of the sewing line, each fold and tab fold, each notch, the grain arrow.
fn strokes(p: &Piece) -> Vec<(String, Vec<(DVec2, DVec2)>)> {
    let mut out = Vec::new();
    let ring = |r: &[DVec2]| {
        (0..r.len())
            .map(|k| (r[k], r[(k + 1) % r.len()]))
            .collect::<Vec<_>>()
    };
    let open = |s: &[DVec2]| s.windows(2).map(|w| (w[0], w[1])).collect::<Vec<_>>();
    for (i, r) in p.outline.iter().enumerate() {
        out.push((format!("cut contour {}", i + 1), ring(r)));
    }
    for (i, r) in p.seam_line.iter().enumerate() {
        out.push((format!("sewing line {}", i + 1), ring(r)));
    }
    for (i, f) in p.folds.iter().enumerate() {
        let kind = if f.tab { "tab fold" } else { "fold" };
        out.push((format!("{kind} {}", i + 1), vec![(f.a, f.b)]));
    }
    for (i, n) in p.notches.iter().enumerate() {
        out.push((format!("notch {}", i + 1), open(&n.stroke)));
    }
    let grain: Vec<_> = p.grain_line.iter().flat_map(|s| open(s)).collect();
    if !grain.is_empty() {
        out.push(("grain arrow".to_string(), grain));
    }
    out
}

/// The collisions of one piece: (text, what it overlaps), one per pair of a text and another
/// text or a stroke.
pub(crate) fn collisions(p: &Piece) -> Vec<(String, String)> {
    let texts = texts(p);
    let strokes = strokes(p);
    let mut out = Vec::new();
    for (i, (name, s)) in texts.iter().enumerate() {
        for (other, o) in &texts[i + 1..] {
            if shapes_overlap(s, o) {
                out.push((name.clone(), other.clone()));
            }
        }
        for (other, segs) in &strokes {
            if segs.iter().any(|(a, b)| hits_segment(s, *a, *b)) {
                out.push((name.clone(), other.clone()));
            }
        }
    }
    out
}

fn bundled() -> Vec<std::path::PathBuf> {
    let mut names: Vec<_> = std::fs::read_dir(manifest("patterns"))
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    names.sort();
    names
}

#[test]
fn no_text_overlaps_another_text_or_a_line_in_any_bundled_pattern() {
    let names = bundled();
    assert!(names.len() >= 20, "{names:?}");
    let mut total = 0;
    let mut report = Vec::new();
    let mut texts_seen = 0;
    for path in names {
        let spec = flatcut::spec::load(&path).unwrap();
        let (_, pieces) = flatcut::pipeline::pieces(&spec, true).unwrap();
        let mut n = 0;
        let mut first = Vec::new();
        for p in &pieces {
            texts_seen += texts(p).len();
            for (a, b) in collisions(p) {
                n += 1;
                if first.len() < 4 {
                    first.push(format!("piece {}: {a} on {b}", p.name));
                }
            }
        }
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        eprintln!("{name}: {n} collisions");
        if n > 0 {
            report.push(format!("{name}: {n} ({})", first.join("; ")));
        }
        total += n;
    }
    assert!(texts_seen > 100, "{texts_seen} texts");
    assert_eq!(total, 0, "{total} collisions:\n{}", report.join("\n"));
}

const CONE: [&str; 7] = [
    "cone",
    "--bottom-diameter",
    "300",
    "--top-diameter",
    "160",
    "--height",
    "200",
];

#[test]
fn fitting_cone_marks_a_shops_bend_lines_by_default() {
    let (_, pieces) = flatcut::pipeline::pieces(&fitting_spec(&CONE), true).unwrap();
    assert_eq!(pieces.len(), 1);
    let p = &pieces[0];
    let bends: Vec<_> = p.folds.iter().filter(|f| !f.tab).collect();
    let n = bends.len();
    eprintln!("fitting cone, default: {n} bend lines");
    // The mid-height circumference π·230 ≈ 722 mm in lines at least 20 mm apart.
    assert!((25..=36).contains(&n), "{n} bend lines");
    // Equal bends, adding up to the cone's whole turn (every ruling of `all`).
    let (_, every) = flatcut::pipeline::pieces(
        &fitting_spec(&[&CONE[..], &["--bend-lines", "all"]].concat()),
        true,
    )
    .unwrap();
    let all: Vec<_> = every[0].folds.iter().filter(|f| !f.tab).collect();
    assert!(all.len() > 200, "{} rulings", all.len());
    let total: f64 = all.iter().map(|f| f.angle).sum();
    let sum: f64 = bends.iter().map(|f| f.angle).sum();
    assert!((sum - total).abs() < 1e-9 * total, "{sum} {total}");
    for f in &bends {
        assert!((f.angle - total / n as f64).abs() < 1e-9, "{}", f.angle);
    }
    // Lines a brake operator can bump: neighbours at least 20 mm apart at their middles (where
    // the notes are) and 15 mm at the blank's short edge.
    let mids: Vec<DVec2> = bends.iter().map(|f| 0.5 * (f.a + f.b)).collect();
    let mut gaps = Vec::new();
    for (i, f) in bends.iter().enumerate() {
        let nearest_mid = mids
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, m)| m.distance(mids[i]))
            .fold(f64::INFINITY, f64::min);
        assert!(nearest_mid >= 20.0, "bend {}: {nearest_mid:.1} mm", i + 1);
        gaps.push(nearest_mid);
        let nearest = bends
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, g)| flatcut::geom::polygon::segment_segment_distance(f.a, f.b, g.a, g.b))
            .fold(f64::INFINITY, f64::min);
        assert!(nearest >= 15.0, "bend {}: {nearest:.1} mm", i + 1);
    }
    // Evenly spread, as far as the strip's bridges allow (the curves' points are 7.6 and
    // 5.5 mm apart).
    let (lo, hi) = gaps
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), g| (l.min(*g), h.max(*g)));
    eprintln!("gaps between bend lines' middles: {lo:.1} to {hi:.1} mm");
    assert!(hi <= 1.25 * lo, "{lo:.1} to {hi:.1} mm");
    // Each line has its note, the same for all, and nothing overlaps.
    assert_eq!(p.notes.len(), n);
    assert!(p.left_out.is_empty(), "{:?}", p.left_out);
    let c = collisions(p);
    assert!(c.is_empty(), "{} collisions: {c:?}", c.len());
    // `all` on the same cone: every ruling, but its notes still never overlap; those with no
    // room are left out and said so.
    let c = collisions(&every[0]);
    assert!(c.is_empty(), "{} collisions with all", c.len());
    eprintln!(
        "fitting cone --bend-lines all: {} bend lines, {} notes, {} left out",
        all.len(),
        every[0].notes.len(),
        every[0].left_out.len()
    );
    assert_eq!(every[0].notes.len() + every[0].left_out.len(), all.len());
}

#[test]
fn fitting_cone_with_every_ruling_warns_of_the_notes_left_out() {
    // A small cone (Ø60 to Ø30, 30 mm high) with all its 87 rulings: 36 mm long lines 2 mm
    // apart cannot all carry a 2 mm note.
    let out = scratch("legible-cone-all");
    // A Ø60 cone with every ruling a bend line.
    let cone = [
        "cone",
        "--bottom-diameter",
        "60",
        "--top-diameter",
        "30",
        "--height",
        "30",
        "--bend-lines",
        "all",
    ];
    let o = flatcut(
        &[
            &["fitting"],
            &cone[..],
            &["--dry-run", "-o", out.to_str().unwrap()],
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let bends = report["pieces"][0]["fold_lines"].as_array().unwrap().len();
    let left: Vec<&serde_json::Value> = report["warnings"]
        .as_array()
        .map(|w| w.iter().filter(|w| w["kind"] == "text-left-out").collect())
        .unwrap_or_default();
    // One line for the piece's bend notes, however many are left out.
    assert_eq!(left.len(), 1, "{}", report["warnings"]);
    let mut times = 0;
    for w in &left {
        let m = w["message"].as_str().unwrap();
        assert_eq!(w["piece"], "1");
        // One line for the piece's bend notes: "N bend notes left out: ..." or the one.
        let count = m
            .strip_prefix("piece 1: ")
            .and_then(|t| t.split(" bend notes left out: ").next())
            .and_then(|n| n.parse::<usize>().ok());
        assert!(
            count.is_some() || m.starts_with("piece 1: bend note \""),
            "{m}"
        );
        assert!(m.contains("° DOWN\""), "{m}");
        times += count.unwrap_or(1);
    }
    // Every line's note is drawn or said to be left out.
    let drawn = {
        let spec = fitting_spec(&cone);
        let (_, pieces) = flatcut::pipeline::pieces(&spec, true).unwrap();
        assert!(collisions(&pieces[0]).is_empty());
        pieces[0].notes.len()
    };
    eprintln!("Ø60 cone, all rulings: {bends} bend lines, {drawn} notes drawn, {times} left out");
    assert_eq!(drawn + times, bends);
    assert!(times > 0 && drawn > 0);
    assert!(stderr(&o).contains("left out"), "{}", stderr(&o));
}

/// Signed sum (degrees) of a piece's bend lines (mountains positive) and their middles.
fn bend_sum(pieces: &[Piece]) -> (f64, Vec<DVec2>) {
    let mut sum = 0.0;
    let mut mids = Vec::new();
    for p in pieces {
        for f in p.folds.iter().filter(|f| !f.tab) {
            let s = match f.kind {
                flatcut::pattern::FoldKind::Mountain => 1.0,
                flatcut::pattern::FoldKind::Valley => -1.0,
            };
            sum += s * f.angle.to_degrees();
            mids.push(0.5 * (f.a + f.b));
        }
    }
    (sum, mids)
}

#[test]
fn shop_bend_lines_of_strips_bent_sheets_and_splines_share_the_whole_bend() {
    use flatcut::surface::strip::BendLines;
    for name in ["lampshade-strip", "bent-a4", "spline-loft"] {
        let base = flatcut::spec::load(&manifest(&format!("patterns/{name}.toml"))).unwrap();
        let with = |lines: BendLines| {
            let mut spec = base.clone();
            spec.set_bend_lines(lines);
            flatcut::pipeline::pieces(&spec, true).unwrap().1
        };
        let (all, shop) = (with(BendLines::All), with(BendLines::Shop));
        let ((sum_all, mids_all), (sum_shop, mids)) = (bend_sum(&all), bend_sum(&shop));
        eprintln!(
            "{name}: all {} lines, {sum_all:.2}°; shop {} lines, {sum_shop:.2}°",
            mids_all.len(),
            mids.len()
        );
        assert!(!mids.is_empty() && mids.len() < mids_all.len(), "{name}");
        // Rulings under 0.01° carry no line of their own in `all`: the sums differ by at most
        // those.
        assert!(
            (sum_all - sum_shop).abs() <= 0.01 * mids_all.len() as f64 + 1e-6,
            "{name}: {sum_all} vs {sum_shop}"
        );
        for (i, m) in mids.iter().enumerate() {
            let nearest = mids
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, q)| q.distance(*m))
                .fold(f64::INFINITY, f64::min);
            assert!(
                nearest >= 15.0,
                "{name}: line {} {nearest:.1} mm from the next",
                i + 1
            );
        }
        assert!(shop.iter().all(|p| collisions(p).is_empty()), "{name}");
    }
}
