//! Issue 8, the pattern half: seams re-assemble in 3D, notches meet, outlines with glue tabs
//! stay simple and apart in the HP-GL, labels lie inside their pieces and read upright on the
//! sheet, fabric gets its allowance and notch slits, metal its bend notes.

use crate::common::*;
use flatcut::flatten::Flat;
use flatcut::geom::polygon;
use flatcut::pattern::{Piece, SeamSide};
use flatcut::spec::{MaterialKind, Spec};
use flatcut::toolpath::StrokeRole;
use glam::{DVec2, DVec3};

fn load(path: &std::path::Path, material: MaterialKind, notches: Option<f64>) -> Spec {
    let mut spec = flatcut::spec::load(path).unwrap();
    spec.material.kind = material;
    spec.pattern.notches = notches;
    spec
}

/// The 3D positions of the `count + 1` points of a seam side, through the faces the border
/// segments belong to.
fn chain_3d(flat: &Flat, p: &Piece, s: &SeamSide) -> Vec<DVec3> {
    let mesh = &flat.surface.mesh;
    let ring = &p.border[s.ring];
    let n = ring.len();
    let mut out = Vec::new();
    for k in 0..s.count {
        let j = (s.first + k) % n;
        let f = p.border_faces[s.ring][j];
        let corners = &flat.face_2d[f];
        let i = corners
            .iter()
            .position(|q| *q == ring[j])
            .expect("border point is a face corner");
        let verts = &mesh.faces[f].verts;
        if k == 0 {
            out.push(mesh.vertices[verts[i]]);
        }
        out.push(mesh.vertices[verts[(i + 1) % verts.len()]]);
    }
    out
}

/// The 3D point of arc length `s` along a flat chain: same edge, same fraction.
fn at_arc(flat: &[DVec2], pts: &[DVec3], s: f64) -> DVec3 {
    let (k, t) = flatcut::pattern::marks::segment_at(flat, s);
    pts[k].lerp(pts[k + 1], t)
}

/// Every seam: two sides of equal length on its two pieces, the same 3D edge chain (side B
/// runs it backwards), and notches that land on the same 3D points.
fn check_seams(flats: &[Flat], pieces: &[Piece]) -> (usize, usize) {
    let flat_of = |p: &Piece| flats.iter().find(|f| f.surface.name == p.surface).unwrap();
    let sides: Vec<(&Piece, &SeamSide)> = pieces
        .iter()
        .flat_map(|p| p.seams.iter().map(move |s| (p, s)))
        .collect();
    let (mut seams, mut notches) = (0, 0);
    for &(pa, a) in sides.iter().filter(|(_, s)| s.is_a) {
        let b_sides: Vec<_> = sides
            .iter()
            .filter(|(_, s)| s.id == a.id && !s.is_a)
            .collect();
        assert_eq!(b_sides.len(), 1, "seam {} has one side B", a.id);
        let &(pb, b) = b_sides[0];
        assert_eq!(a.partner, pb.id);
        assert_eq!(b.partner, pa.id);
        assert!(
            (a.length - b.length).abs() < 1e-9 * (1.0 + a.length),
            "seam {}",
            a.id
        );
        assert_eq!(a.count, b.count);
        let (ca, cb) = (chain_3d(flat_of(pa), pa, a), chain_3d(flat_of(pb), pb, b));
        let scale = 1.0 + a.length;
        for (qa, qb) in ca.iter().zip(cb.iter().rev()) {
            assert!(
                qa.distance(*qb) < 1e-9 * scale,
                "seam {}: {qa} vs {qb}",
                a.id
            );
        }
        // The 3D chain is as long as the flat one (isometric unfolding).
        let l3: f64 = ca.windows(2).map(|w| w[0].distance(w[1])).sum();
        assert!(
            (l3 - a.length).abs() < 1e-3,
            "seam {}: {l3} vs {}",
            a.id,
            a.length
        );
        assert_eq!(a.notches.len(), b.notches.len());
        for (sa, sb) in a.notches.iter().zip(b.notches.iter().rev()) {
            let (qa, qb) = (at_arc(&a.points, &ca, *sa), at_arc(&b.points, &cb, *sb));
            assert!(
                qa.distance(qb) < 1e-9 * scale,
                "seam {} notch: {qa} vs {qb}",
                a.id
            );
            notches += 1;
        }
        // The pair near A's start makes the notches asymmetric: turned end for end, side A's
        // notches would not land on themselves.
        let n = a.notches.len();
        if n >= 2 {
            let reversed =
                (0..n).any(|i| (a.notches[i] - (a.length - a.notches[n - 1 - i])).abs() > 0.5);
            assert!(reversed, "seam {}: notches symmetric {:?}", a.id, a.notches);
        }
        seams += 1;
    }
    (seams, notches)
}

#[test]
fn seams_reassemble_in_3d_and_notches_meet() {
    require_shared!();
    let cube = load(
        &manifest("patterns/cube.toml"),
        MaterialKind::Paper,
        Some(20.0),
    );
    let (flats, pieces) = flatcut::pipeline::pieces(&cube, true).unwrap();
    let (n, k) = check_seams(&flats, &pieces);
    assert!(n >= 1 && k > 0, "{n} seams, {k} notches");
    // Every cut edge of the cube is in exactly one seam: 7 edges, 700 mm per side.
    let a_len: f64 = pieces
        .iter()
        .flat_map(|p| &p.seams)
        .filter(|s| s.is_a)
        .map(|s| s.length)
        .sum();
    assert!((a_len - 700.0).abs() < 1e-9, "{a_len}");

    let dir = scratch("pattern-fandisk-seams");
    let fan = load(&fandisk_spec(&dir), MaterialKind::Fabric, Some(10.0));
    let (flats, pieces) = flatcut::pipeline::pieces(&fan, true).unwrap();
    let (n, k) = check_seams(&flats, &pieces);
    assert!(n > 20 && k > 50, "{n} seams, {k} notches");
}

/// Closed pen-1 strokes of an HP-GL file as rings in mm.
fn cut_rings(plt: &str) -> Vec<Vec<DVec2>> {
    flatcut::output::hpgl::parse(plt)
        .unwrap()
        .into_iter()
        .filter(|s| s.pen == 1 && s.points.len() > 3 && s.points.first() == s.points.last())
        .map(|s| {
            let mut r: Vec<DVec2> = s
                .points
                .iter()
                .map(|&(x, y)| DVec2::new(x as f64, y as f64) / 40.0)
                .collect();
            r.pop();
            r
        })
        .collect()
}

fn rings_touch(a: &[DVec2], b: &[DVec2]) -> bool {
    let (la, ha) = polygon::bounds(a.iter().copied()).unwrap();
    let (lb, hb) = polygon::bounds(b.iter().copied()).unwrap();
    if la.x > hb.x || lb.x > ha.x || la.y > hb.y || lb.y > ha.y {
        return false;
    }
    for i in 0..a.len() {
        let (p, q) = (a[i], a[(i + 1) % a.len()]);
        for j in 0..b.len() {
            if polygon::segments_intersect(p, q, b[j], b[(j + 1) % b.len()]) {
                return true;
            }
        }
    }
    false
}

#[test]
fn paper_outlines_with_tabs_are_simple_and_apart() {
    require_shared!();
    let dir = scratch("pattern-tabs");
    let fan = fandisk_spec(&dir);
    for (name, spec) in [
        ("cube", manifest("patterns/cube.toml")),
        ("fandisk", fan.clone()),
    ] {
        let out = dir.join(name);
        let o = flatcut(&[
            "cut",
            spec.to_str().unwrap(),
            "--device",
            "hpgl-pens",
            "--dry-run",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        let tabs: u64 = report["pieces"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["tabs"].as_u64().unwrap())
            .sum();
        assert!(tabs >= 3, "{name}: {tabs} tabs");
        let mut plts: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "plt"))
            .collect();
        plts.sort();
        assert!(!plts.is_empty());
        for plt in plts {
            let rings = cut_rings(&std::fs::read_to_string(&plt).unwrap());
            assert!(rings.len() >= report["pieces"].as_array().unwrap().len().min(1));
            for (i, r) in rings.iter().enumerate() {
                assert!(polygon::is_simple_ring(r), "{name}: ring {i} not simple");
                for (j, s) in rings.iter().enumerate().skip(i + 1) {
                    assert!(!rings_touch(r, s), "{name}: rings {i} and {j} touch");
                }
            }
        }
    }
}

#[test]
fn labels_are_inside_and_upright_marks_inside() {
    require_shared!();
    let dir = scratch("pattern-labels");
    let spec = load(&fandisk_spec(&dir), MaterialKind::Paper, None);
    let profile = flatcut::profile::find("hpgl-pens").unwrap();
    let (_, layout, job) = flatcut::pipeline::plan_job(&spec, &profile, true).unwrap();
    let mut labels = 0;
    for sheet in &job.sheets {
        for s in &sheet.strokes {
            let Some(k) = s.piece else { continue };
            let at = layout.placements[k];
            let piece = &layout.pieces[k];
            let outline: Vec<Vec<DVec2>> = piece
                .outline
                .iter()
                .map(|r| r.iter().map(|q| at.apply(*q)).collect())
                .collect();
            if matches!(s.role, StrokeRole::Label | StrokeRole::Mark) {
                for q in &s.points {
                    assert!(
                        polygon::contains_rings(&outline, *q),
                        "piece {}: {:?} point {q} outside",
                        piece.name,
                        s.role
                    );
                }
            }
            if s.role == StrokeRole::Label {
                labels += 1;
            }
        }
    }
    // Upright: the label's strokes on the sheet are its strokes in the piece frame, moved,
    // never turned, whatever the rotation the nest chose.
    for (k, piece) in layout.pieces.iter().enumerate() {
        let on_sheet: Vec<DVec2> = job
            .sheets
            .iter()
            .flat_map(|s| &s.strokes)
            .filter(|s| s.piece == Some(k) && s.role == StrokeRole::Label)
            .flat_map(|s| s.points.iter().copied())
            .collect();
        let own: Vec<DVec2> = piece.label.points().collect();
        assert_eq!(on_sheet.len(), own.len(), "piece {}", piece.name);
        assert!(!own.is_empty(), "piece {} has a label", piece.name);
        // Strokes may be drawn in either direction: compare as point sets.
        let mean = |v: &[DVec2]| v.iter().copied().sum::<DVec2>() / v.len() as f64;
        let shift = mean(&on_sheet) - mean(&own);
        for b in &own {
            let near = on_sheet.iter().any(|a| (*a - *b - shift).length() < 1e-6);
            assert!(near, "piece {}: label turned or distorted", piece.name);
        }
    }
    assert!(labels > 0);
}

#[test]
fn fabric_gets_allowance_and_notch_slits_metal_bend_notes() {
    let cube = load(&manifest("patterns/cube.toml"), MaterialKind::Fabric, None);
    let mut spec = cube.clone();
    spec.pattern.notches = None; // the material's default: every 50 mm
    let (_, pieces) = flatcut::pipeline::pieces(&spec, true).unwrap();
    let p = &pieces[0];
    assert_eq!(p.seam_line, p.border);
    // The cut line keeps 10 mm from the sewing line everywhere (more at mitred corners).
    let border = &p.border[0];
    for q in &p.outline[0] {
        let d = (0..border.len())
            .map(|i| polygon::segment_distance(*q, border[i], border[(i + 1) % border.len()]))
            .fold(f64::INFINITY, f64::min);
        assert!(d > 10.0 - 1e-6, "{q}: {d}");
    }
    assert!(polygon::signed_area(&p.outline[0]) > polygon::signed_area(border) + 10.0 * 1300.0);
    // Slits: 3 mm, from the cut line inward.
    assert!(!p.notches.is_empty());
    for n in &p.notches {
        assert!(n.cut);
        assert!((n.stroke[0].distance(n.stroke[1]) - 3.0).abs() < 1e-9);
        let on_outline = (0..p.outline[0].len()).any(|i| {
            let o = &p.outline[0];
            polygon::segment_distance(n.stroke[0], o[i], o[(i + 1) % o.len()]) < 1e-3
        });
        assert!(on_outline, "notch at {} starts on the cut line", n.at);
    }
    assert!(p.grain.is_some() && p.grain_line.len() == 3);

    let mut metal = cube;
    metal.material.kind = MaterialKind::Metal;
    metal.pattern.bend_notches = Some(true);
    let (_, pieces) = flatcut::pipeline::pieces(&metal, true).unwrap();
    let p = &pieces[0];
    assert_eq!(p.notes.len(), p.folds.len());
    assert!(p.seams.iter().all(|s| !s.tab));
    // Five bends, both ends on the outline: ten V notches of 2 × 1.5 mm / 2 mm² each... the
    // outline loses their area and gains their sides.
    let lost = polygon::signed_area(&p.border[0]) - polygon::signed_area(&p.outline[0]);
    assert!(lost > 5.0 && lost < 30.0, "{lost}");
    assert!(polygon::is_simple_ring(&p.outline[0]));
}

#[test]
fn metal_bend_notes_stay_on_the_blank_of_a_boundary_panel() {
    // The gazebo roof panel (a boundary developable): many bends close to the outline, some in
    // thin triangles. Each bend note lies on its piece (beside the bend on either side, smaller
    // if need be, or left out), so the layout passes the nest's own check.
    let spec = load(
        &manifest("patterns/gazebo-roof.toml"),
        MaterialKind::Metal,
        None,
    );
    let (_, pieces) = flatcut::pipeline::pieces(&spec, true).unwrap();
    let p = &pieces[0];
    assert!(p.folds.len() > 10, "{} bends", p.folds.len());
    assert!(
        p.notes.len() * 10 >= p.folds.len() * 8,
        "{} of {} bends have their note",
        p.notes.len(),
        p.folds.len()
    );
    for t in &p.notes {
        for q in t.points() {
            assert!(
                polygon::contains_rings(&p.border, q),
                "note point {q} off the blank"
            );
        }
    }
    let dir = scratch("pattern-gazebo-metal");
    let o = flatcut(&[
        "cut",
        manifest("patterns/gazebo-roof.toml").to_str().unwrap(),
        "--material",
        "metal",
        "--device",
        "hpgl-pens",
        "--dry-run",
        "-o",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Issue 20's exit 2: couplingdown at 300 mm with paper tabs stopped with "piece 13 leaves
/// the sheet" — a tab fold ended 0.31 mm outside its outline, where cleaning had trimmed an
/// acute corner, and past the margin. Folds are now cut back to the outline.
#[test]
fn couplingdown_at_300_mm_cuts_with_every_fold_inside_its_piece() {
    require_shared!();
    let out = scratch("couplingdown-300");
    let o = flatcut(&[
        "cut",
        &shared_data("meshes/couplingdown.obj").to_string_lossy(),
        "--size",
        "300",
        "--dry-run",
        "-q",
        "-o",
        &out.to_string_lossy(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert!(report["pieces"].as_array().unwrap().len() > 13);
}
