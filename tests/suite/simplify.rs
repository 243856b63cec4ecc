//! Simplified seams between D-Charts pieces (issue 7, thesis §5.3, `pattern::simplify`): the
//! acceptance meshes fandisk and mushroom cut with `segment = "dcharts"`, each built twice
//! (`simplify = 0` and the tolerance under test) and compared piece by piece; bad spec values;
//! the report.
//!
//! Figures are printed (`cargo test --test suite simplify:: -- --nocapture`).

use crate::common::*;
use flatcut::flatten::Flat;
use flatcut::geom::polygon;
use flatcut::pattern::{Piece, SeamSide};
use glam::DVec2;
use std::path::{Path, PathBuf};

/// A spec cutting `mesh` (shared data) with D-Charts, scaled by `scale`, with `extra` lines in
/// its surface and `[pattern]` notches every 20 mm.
fn spec(dir: &Path, file: &str, mesh: &str, scale: f64, extra: &str) -> PathBuf {
    let path = dir.join(file);
    let text = format!(
        "name = \"{file}\"\n[[surface]]\nkind = \"mesh\"\npath = \"{}\"\nscale = {scale}\nsegment = \"dcharts\"\n{extra}\n[sheet]\nwidth = 500\nheight = 700\nmargin = 5\nspacing = 3\n[pattern]\nnotches = 20\n",
        shared_data(&format!("meshes/{mesh}")).to_string_lossy()
    );
    std::fs::write(&path, text).unwrap();
    path
}

fn pieces(path: &Path) -> (Vec<Flat>, Vec<Piece>) {
    let text = std::fs::read_to_string(path).unwrap();
    let spec = flatcut::spec::parse(&text, path).unwrap();
    flatcut::pipeline::pieces(&spec, true).unwrap()
}

fn length(points: &[DVec2]) -> f64 {
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// Distance from `q` to a closed ring.
fn ring_distance(ring: &[DVec2], q: DVec2) -> f64 {
    (0..ring.len())
        .map(|i| polygon::segment_distance(q, ring[i], ring[(i + 1) % ring.len()]))
        .fold(f64::INFINITY, f64::min)
}

/// Whether `sub` is `ring` with some points left out, in order, starting anywhere.
fn is_subsequence(sub: &[DVec2], ring: &[DVec2]) -> bool {
    let n = ring.len();
    let Some(start) = ring.iter().position(|q| *q == sub[0]) else {
        return false;
    };
    let mut k = 0;
    for i in 0..n {
        if k < sub.len() && ring[(start + i) % n] == sub[k] {
            k += 1;
        }
    }
    k == sub.len()
}

/// Both sides of each seam id.
fn seam_pairs(pieces: &[Piece]) -> Vec<(&SeamSide, &SeamSide)> {
    let sides: Vec<&SeamSide> = pieces.iter().flat_map(|p| p.seams.iter()).collect();
    sides
        .iter()
        .filter(|s| s.is_a)
        .map(|a| {
            let b = sides
                .iter()
                .find(|b| b.id == a.id && !b.is_a)
                .expect("side B");
            (*a, *b)
        })
        .collect()
}

/// Everything the simplified pieces must satisfy against the unsimplified ones.
fn check(name: &str, mesh: &str, scale: f64, tol: f64) {
    let dir = scratch(&format!("simplify-{name}"));
    let (_, plain) = pieces(&spec(&dir, "plain.toml", mesh, scale, "simplify = 0"));
    let (flats, simple) = pieces(&spec(
        &dir,
        "simple.toml",
        mesh,
        scale,
        &format!("simplify = {tol}"),
    ));
    assert_eq!(plain.len(), simple.len());
    let count =
        |ps: &[Piece]| -> usize { ps.iter().flat_map(|p| &p.border).map(|r| r.len()).sum() };
    let (before, after) = (count(&plain), count(&simple));
    let mut max_dev = 0.0f64;
    let mut max_mismatch = 0.0f64;
    let mut max_mismatch_before = 0.0f64;
    let mut max_growth = 0.0f64;
    let mut min_id_mean = f64::INFINITY;
    for (p0, p1) in plain.iter().zip(&simple) {
        assert!(p0.simplified.is_none());
        let s = p1.simplified.expect("simplified");
        assert_eq!(
            s.vertices_before,
            p0.border.iter().map(|r| r.len()).sum::<usize>()
        );
        assert_eq!(
            s.vertices_after,
            p1.border.iter().map(|r| r.len()).sum::<usize>()
        );
        assert!(
            s.max_deviation <= tol + 1e-9,
            "{} {}",
            p1.name,
            s.max_deviation
        );
        assert_eq!(p0.border.len(), p1.border.len());
        for (r0, r1) in p0.border.iter().zip(&p1.border) {
            // Every vertex left is an original one, in order; every original vertex is
            // within the tolerance of the simplified ring.
            assert!(r1.len() >= 3 && r1.len() <= r0.len());
            assert!(is_subsequence(r1, r0), "{}: not a subsequence", p1.name);
            for q in r0 {
                let d = ring_distance(r1, *q);
                max_dev = max_dev.max(d);
                assert!(d <= tol + 1e-9, "{}: {q} is {d} mm off", p1.name);
            }
            // No self-intersection that was not there before.
            if polygon::is_simple_ring(r0) {
                assert!(polygon::is_simple_ring(r1), "{} crosses itself", p1.name);
            }
        }
        // No fold line crosses the simplified border (they meet only at fold ends) unless it
        // already crossed the unsimplified one.
        let crosses = |rings: &[Vec<DVec2>], f: &flatcut::pattern::Fold| {
            rings.iter().any(|r| {
                (0..r.len()).any(|i| {
                    let (a, b) = (r[i], r[(i + 1) % r.len()]);
                    let touch = [f.a, f.b]
                        .iter()
                        .any(|q| polygon::segment_distance(*q, a, b) < 1e-6);
                    !touch && polygon::segments_intersect(a, b, f.a, f.b)
                })
            })
        };
        for f in p1
            .folds
            .iter()
            .filter(|f| !f.tab && !crosses(&p0.border, f))
        {
            for r in &p1.border {
                for i in 0..r.len() {
                    let (a, b) = (r[i], r[(i + 1) % r.len()]);
                    // A fold ending on the border touches it there (its end and the border
                    // point are copies of one vertex, equal to about 1e-12).
                    let shared = [f.a, f.b]
                        .iter()
                        .any(|q| polygon::segment_distance(*q, a, b) < 1e-6);
                    assert!(
                        shared || !polygon::segments_intersect(a, b, f.a, f.b),
                        "{}: fold {} crosses the border",
                        p1.name,
                        f.edge
                    );
                }
            }
        }
        for r in &p1.outline {
            assert!(
                polygon::is_simple_ring(r),
                "{}: outline crosses itself",
                p1.name
            );
        }
        // Seam ids: inside the piece, and no smaller than on the unsimplified piece (a
        // simplified segment stands for several mesh edges; the room beside it is measured in
        // the piece, not taken from its first face).
        let id_heights = |p: &Piece| -> Vec<f64> {
            p.marks
                .iter()
                .map(|m| {
                    let up = m.text.dir.map_or(DVec2::Y, |d| d.perp());
                    let h = m.text.strokes.iter().flatten().map(|q| q.dot(up));
                    let (lo, hi) = h.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), v| {
                        (l.min(v), u.max(v))
                    });
                    (hi - lo).max(0.0)
                })
                .collect()
        };
        for m in &p1.marks {
            for q in m.text.strokes.iter().flatten() {
                assert!(
                    polygon::contains_rings(&p1.border, *q),
                    "{}: seam id {} sticks out at {q}",
                    p1.name,
                    m.id
                );
            }
        }
        let (h0, h1) = (id_heights(p0), id_heights(p1));
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        min_id_mean = min_id_mean.min(mean(&h1));
        // Legibility (`pattern::legible`) may shrink an id that would cross a line; the
        // average stays within 10 % of the unsimplified piece's.
        assert!(
            mean(&h1) >= 0.9 * mean(&h0) - 1e-9,
            "{}: seam ids {:.2} mm high on average, {:.2} before simplifying",
            p1.name,
            mean(&h1),
            mean(&h0)
        );
        // Still the same side up, holes still inside the outer ring.
        assert!(polygon::signed_area(&p1.border[0]) > 0.0);
        for h in &p1.border[1..] {
            assert!(h.iter().all(|q| polygon::contains(&p1.border[0], *q)));
        }
    }
    // Seams: both sides equally long (within the bound, or no worse than before), the same
    // number of segments, notches at equal fractions of their lengths.
    let pairs0 = seam_pairs(&plain);
    let pairs1 = seam_pairs(&simple);
    assert_eq!(pairs0.len(), pairs1.len());
    let mut notches = 0;
    for ((a0, b0), (a, b)) in pairs0.iter().zip(&pairs1) {
        assert_eq!(a0.id, a.id);
        assert_eq!(a.count, b.count);
        assert_eq!(a.points.len(), a.count + 1);
        let (la, lb) = (length(&a.points), length(&b.points));
        assert!((a.length - la).abs() < 1e-9 && (b.length - lb).abs() < 1e-9);
        let was = (length(&a0.points) - length(&b0.points)).abs();
        let mismatch = (la - lb).abs();
        max_mismatch = max_mismatch.max(mismatch);
        max_mismatch_before = max_mismatch_before.max(was);
        max_growth = max_growth.max(mismatch - was);
        assert!(
            mismatch <= flatcut::pattern::simplify::MISMATCH_MM.max(was) + 1e-9,
            "seam {}: {la} vs {lb} (was {was})",
            a.id
        );
        // Side B is side A reversed, vertex for vertex: the same 3D vertices survive. The 2D
        // copies differ, so compare which original vertex each is (its index in the chain).
        // (A chain all round a ring ends where it starts: search forward from the last match.)
        let idx = |s: &SeamSide, orig: &SeamSide| -> Vec<usize> {
            let mut from = 0;
            s.points
                .iter()
                .map(|q| {
                    let k = from
                        + orig.points[from..]
                            .iter()
                            .position(|o| o == q)
                            .expect("an original vertex, in order");
                    from = k + 1;
                    k
                })
                .collect()
        };
        let ia = idx(a, a0);
        let ib: Vec<usize> = idx(b, b0).iter().rev().map(|&i| a0.count - i).collect();
        assert_eq!(ia, ib, "seam {}", a.id);
        assert_eq!(a.notches.len(), b.notches.len());
        for (sa, sb) in a.notches.iter().zip(b.notches.iter().rev()) {
            assert!(
                (sa / la - (1.0 - sb / lb)).abs() < 1e-9,
                "seam {}: {sa}/{la} vs {sb}/{lb}",
                a.id
            );
            notches += 1;
        }
        // Side A's own notches stay where they were asked for: every 20 mm of its length.
        if la >= 25.0 {
            assert!((a.notches[0] - 20.0).abs() < 1e-9);
        }
    }
    println!(
        "{name}: {} pieces, {} seams, outline vertices {before} -> {after} ({:.0} %), max deviation {max_dev:.4} mm (tolerance {tol}), seam length mismatch max {max_mismatch:.4} mm (before {max_mismatch_before:.4}; largest growth on one seam {max_growth:.4}), {notches} notch pairs, seam ids at least {min_id_mean:.2} mm high on average per piece",
        simple.len(),
        pairs1.len(),
        100.0 * after as f64 / before as f64
    );
    assert!(after < before, "{before} -> {after}");
    assert!(flats[0].surface.charts.is_some());

    // Nested feasibly: every placed outline inside the sheet margins.
    let opts = flatcut::nest::NestOptions {
        width: 500.0,
        height: Some(700.0),
        margin: 5.0,
        spacing: 3.0,
        seconds: 0.2,
        ..Default::default()
    };
    let layout = flatcut::nest::nest(simple, &opts).expect("nest");
    for (p, at) in layout.pieces.iter().zip(&layout.placements) {
        for q in p.outline.iter().flatten() {
            let q = at.apply(*q);
            assert!(
                q.x >= 5.0 - 1e-6
                    && q.x <= 495.0 + 1e-6
                    && q.y >= 5.0 - 1e-6
                    && q.y <= 695.0 + 1e-6,
                "{}: {q}",
                p.name
            );
        }
    }
}

#[test]
fn fandisk_seams_simplified_within_half_a_millimetre() {
    require_shared!();
    check("fandisk", "fandisk.obj", 100.0, 0.5);
}

#[test]
fn mushroom_seams_simplified_within_half_a_millimetre() {
    require_shared!();
    check("mushroom", "mushroom.obj", 300.0, 0.5);
}

#[test]
fn simplify_zero_keeps_every_mesh_edge() {
    require_shared!();
    let dir = scratch("simplify-zero");
    let (flats, ps) = pieces(&spec(
        &dir,
        "zero.toml",
        "fandisk.obj",
        100.0,
        "simplify = 0",
    ));
    let flat = &flats[0];
    for p in &ps {
        assert!(p.simplified.is_none());
        // Each border segment is a whole mesh edge of its face.
        for (r, ring) in p.border.iter().enumerate() {
            for k in 0..ring.len() {
                let f = p.border_faces[r][k];
                let c = &flat.face_2d[f];
                let i = c.iter().position(|q| *q == ring[k]).expect("a face corner");
                assert_eq!(c[(i + 1) % c.len()], ring[(k + 1) % ring.len()]);
            }
        }
    }
    // The same as the bare pattern stage with simplification off.
    let opts = flatcut::pattern::PatternOptions {
        notches: Some(20.0),
        ..flatcut::pattern::PatternOptions::for_material(flatcut::spec::MaterialKind::Paper)
    };
    let off = flatcut::pattern::PatternOptions {
        simplify: 0.0,
        ..opts.clone()
    };
    assert_eq!(flatcut::pattern::build(&flats, &off).unwrap(), ps);
    // And the material's default (0.5 mm on paper) simplifies.
    assert_eq!(opts.simplify, 0.5);
    let simple = flatcut::pattern::build(&flats, &opts).unwrap();
    assert!(simple.iter().all(|p| p.simplified.is_some()));
}

#[test]
fn bad_simplify_values_are_refused_with_file_and_line() {
    require_shared!();
    let dir = scratch("simplify-bad");
    let mesh = shared_data("meshes/cylinder.obj");
    for (k, value) in ["-0.5", "nan", "inf", "\"fine\"", "true"]
        .iter()
        .enumerate()
    {
        let path = dir.join(format!("bad{k}.toml"));
        std::fs::write(
            &path,
            format!(
                "[[surface]]\nkind = \"mesh\"\npath = \"{}\"\nsegment = \"dcharts\"\nsimplify = {value}\n",
                mesh.to_string_lossy()
            ),
        )
        .unwrap();
        let o = flatcut(&[
            "flatten",
            &path.to_string_lossy(),
            "-o",
            &dir.join("out").to_string_lossy(),
        ]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{value}: {err}");
        assert!(
            err.contains(&format!("bad{k}.toml:5")) && err.contains("simplify"),
            "{value}: {err}"
        );
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
    // Not a key of strips.
    let path = dir.join("strip.toml");
    std::fs::write(
        &path,
        "[[surface]]\nkind = \"strip\"\np = [[0, 0, 0], [100, 0, 0]]\nq = [[0, 50, 10], [100, 50, 10]]\nsimplify = 0.5\n",
    )
    .unwrap();
    let o = flatcut(&[
        "flatten",
        &path.to_string_lossy(),
        "-o",
        &dir.join("o2").to_string_lossy(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("strip.toml:5"), "{}", stderr(&o));
}

#[test]
fn report_names_vertices_deviation_and_mismatch() {
    require_shared!();
    let dir = scratch("simplify-report");
    let path = spec(&dir, "fan.toml", "fandisk.obj", 100.0, "");
    let out = dir.join("out");
    let o = flatcut(&[
        "cut",
        &path.to_string_lossy(),
        "--device",
        "hpgl-pens",
        "--dry-run",
        "-q",
        "-o",
        &out.to_string_lossy(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let mut before = 0;
    let mut after = 0;
    for p in report["pieces"].as_array().unwrap() {
        let s = &p["simplify"];
        assert_eq!(s["tolerance_mm"].as_f64(), Some(0.5));
        before += s["vertices_before"].as_u64().unwrap();
        after += s["vertices_after"].as_u64().unwrap();
        assert!(s["max_deviation_mm"].as_f64().unwrap() <= 0.5);
        assert!(s["max_seam_mismatch_mm"].as_f64().unwrap() >= 0.0);
    }
    assert!(after < before, "{before} -> {after}");
    // An exact unfolding has no such key.
    let out2 = dir.join("cube");
    let o = flatcut(&[
        "cut",
        "patterns/cube.toml",
        "--device",
        "hpgl-pens",
        "--dry-run",
        "-q",
        "-o",
        &out2.to_string_lossy(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(out2.join("report.json")).unwrap();
    assert!(!text.contains("simplify"));
}
