//! Issue 20, item 9: metal meshes are developed like fittings. Each fold of a metal piece
//! gets the bend allowance of its angle (K, inside radius, thickness), so the blank is the
//! flat pattern a brake folds back into the model: a 100 mm box in 2 mm steel comes out with
//! every side shorter than 100 mm by the bend deductions of its folds, bend lines on the bend
//! centre lines, and report.json lists each bend's allowance and deduction.
//!
//! The expected figures are computed here from the textbook formulas (BA = θ·(R + K·t),
//! OSSB = (R + t)·tan(θ/2), ISSB = R·tan(θ/2), BD = 2·setback − BA), not from flatcut's own.

use crate::common::*;
use flatcut::pattern::{FoldKind, Piece};
use flatcut::spec::{MaterialKind, Spec};
use glam::DVec2;
use std::f64::consts::FRAC_PI_2;
use std::path::{Path, PathBuf};

/// Bend allowance of a bend of `theta` radians.
fn ba(theta: f64, t: f64, k: f64, r: f64) -> f64 {
    theta * (r + k * t)
}

/// Bend deduction: to the outside mold line for a mountain fold, the inside one for a valley.
fn bd(theta: f64, t: f64, k: f64, r: f64, mountain: bool) -> f64 {
    let setback = if mountain { r + t } else { r } * (theta / 2.0).tan();
    2.0 * setback - ba(theta, t, k, r)
}

/// A spec cutting `mesh` from metal with the `[material]` lines `material`, on a 1 m sheet.
fn spec(dir: &Path, mesh: &Path, material: &str) -> PathBuf {
    let path = dir.join("job.toml");
    let text = format!(
        "name = \"job\"\n[[surface]]\nkind = \"mesh\"\npath = \"{}\"\nsegment = \"faces\"\n\
         [material]\nkind = \"metal\"\n{material}\n[sheet]\nwidth = 1000\nheight = 1000\n",
        mesh.display()
    );
    std::fs::write(&path, text).unwrap();
    path
}

fn pieces(path: &Path) -> Vec<Piece> {
    let spec = flatcut::spec::load(path).unwrap();
    flatcut::pipeline::pieces(&spec, true).unwrap().1
}

/// Across the bend lines (`lines`) parallel to `dir`: the distances from the blank's edge
/// (`outline`) to the first bend line, between consecutive bend lines, and from the last to
/// the other edge (mm). Each bend line is straight across, its ends within `tol` of one offset.
fn gaps(lines: &[(DVec2, DVec2)], outline: &[DVec2], dir: DVec2, tol: f64) -> Vec<f64> {
    let n = dir.perp();
    let mut at: Vec<f64> = lines
        .iter()
        .filter(|(a, b)| (*b - *a).normalize().perp_dot(dir).abs() < tol / 100.0)
        .map(|(a, b)| {
            assert!((a.dot(n) - b.dot(n)).abs() < tol, "{a} {b}");
            a.dot(n)
        })
        .collect();
    at.sort_by(f64::total_cmp);
    let across = outline.iter().map(|q| q.dot(n));
    let lo = across.clone().fold(f64::INFINITY, f64::min);
    let hi = across.fold(f64::NEG_INFINITY, f64::max);
    let mut edges = vec![lo];
    edges.extend(at);
    edges.push(hi);
    edges.windows(2).map(|w| w[1] - w[0]).collect()
}

/// [`gaps`] of a piece's bend lines and outline.
fn gaps_across(p: &Piece, dir: DVec2) -> Vec<f64> {
    let lines: Vec<_> = p
        .folds
        .iter()
        .filter(|f| !f.tab)
        .map(|f| (f.a, f.b))
        .collect();
    gaps(&lines, &p.outline[0], dir, 1e-9)
}

/// Checks the gaps across the box's bend lines both ways (three bend lines one way, two the
/// other): 100 − BD between two bend lines, 100 − BD/2 from a bend line to a free edge.
fn check_box_gaps(lines: &[(DVec2, DVec2)], outline: &[DVec2], deduction: f64, tol: f64) {
    let d0 = (lines[0].1 - lines[0].0).normalize();
    let mut counts = Vec::new();
    for dir in [d0, d0.perp()] {
        let gaps = gaps(lines, outline, dir, tol);
        counts.push(gaps.len() - 1);
        let last = gaps.len() - 1;
        for (i, g) in gaps.iter().enumerate() {
            let want = if i == 0 || i == last {
                100.0 - deduction / 2.0
            } else {
                100.0 - deduction
            };
            assert!(
                (g - want).abs() < 0.05,
                "gap {i} across {dir}: {g} for {want}"
            );
            assert!(
                (g - want).abs() < tol,
                "gap {i} across {dir}: {g} for {want}"
            );
        }
    }
    counts.sort();
    assert_eq!(counts, [2, 3]);
}

/// Extent (mm) of the blank along `dir`.
fn extent_along(p: &Piece, dir: DVec2) -> f64 {
    let along = p.outline[0].iter().map(|q| q.dot(dir));
    along.clone().fold(f64::NEG_INFINITY, f64::max) - along.fold(f64::INFINITY, f64::min)
}

#[test]
fn a_100_mm_box_in_2_mm_steel_is_shorter_by_the_bend_deductions_of_its_folds() {
    let dir = scratch("bends-box");
    // `[material]` gives only the thickness: K = 0.4 and R = t are the defaults.
    let path = spec(&dir, &manifest("patterns/cube.obj"), "thickness = 2");
    let pieces = pieces(&path);
    assert_eq!(pieces.len(), 1);
    let p = &pieces[0];
    let (t, k, r) = (2.0, 0.4, 2.0);
    let (allowance, deduction) = (ba(FRAC_PI_2, t, k, r), bd(FRAC_PI_2, t, k, r, true));
    assert!((deduction - 3.601770).abs() < 1e-6, "{deduction}");

    // Five bends of 90°, each with the allowance and deduction of the formula.
    let dev = p
        .development
        .as_ref()
        .expect("a metal mesh piece is developed");
    assert_eq!(dev.skipped, None);
    assert_eq!(p.folds.len(), 5);
    assert_eq!(dev.bends.len(), 5);
    for f in &p.folds {
        assert_eq!(f.kind, FoldKind::Mountain);
        assert!((f.angle - FRAC_PI_2).abs() < 1e-9);
        let b = dev.bend(f.edge).expect("each bend line has its figures");
        assert!((b.allowance - allowance).abs() < 1e-9, "{b:?}");
        assert!((b.deduction - deduction).abs() < 1e-9, "{b:?}");
        assert!((b.setback - (r + t)).abs() < 1e-9, "{b:?}");
    }
    // Every face: 100 − BD between two bend lines, 100 − BD/2 from a bend line to a free
    // edge, in both directions of the cross-shaped net (five folds: three one way, two the
    // other).
    let lines: Vec<_> = p.folds.iter().map(|f| (f.a, f.b)).collect();
    check_box_gaps(&lines, &p.outline[0], deduction, 1e-6);
    let d0 = (p.folds[0].b - p.folds[0].a).normalize();
    // The blank: 300 − 2 BD by 400 − 3 BD (the issue: it was 300 × 400 before).
    let mut sides = [extent_along(p, d0), extent_along(p, d0.perp())];
    sides.sort_by(f64::total_cmp);
    assert!(
        (sides[0] - (300.0 - 2.0 * deduction)).abs() < 1e-6,
        "{sides:?}"
    );
    assert!(
        (sides[1] - (400.0 - 3.0 * deduction)).abs() < 1e-6,
        "{sides:?}"
    );

    // A round relief where two bends of the base meet: it clears the square where the two
    // bend zones (BA wide about each bend line) overlap.
    assert_eq!(dev.reliefs.len(), 4);
    for &rr in &dev.reliefs {
        assert!((rr - allowance / 2.0 * 2f64.sqrt()).abs() < 1e-4, "{rr}");
    }
    // The blank is one simple outline, each bend line on it or inside.
    assert_eq!(p.outline.len(), 1);
    assert!(flatcut::geom::polygon::is_simple_ring(&p.outline[0]));
    for f in &p.folds {
        let mid = 0.5 * (f.a + f.b);
        assert!(flatcut::geom::polygon::contains(&p.outline[0], mid));
        for end in [f.a, f.b] {
            let d = flatcut::geom::polygon::rings_distance(&p.outline, end);
            assert!(d > -1e-6, "bend line end {end} is {d} mm outside the blank");
        }
    }
    // The base's four bend lines stop at the reliefs: 100 − BD − 2 r long (the relief's arc
    // is cut within 0.01 mm of its circle).
    let base: Vec<f64> = p
        .folds
        .iter()
        .map(|f| f.a.distance(f.b))
        .filter(|l| *l < 99.0)
        .collect();
    assert_eq!(base.len(), 4);
    for l in base {
        let want = 100.0 - deduction - 2.0 * dev.reliefs[0];
        assert!((l - want).abs() < 0.02, "{l} for {want}");
    }
}

#[test]
fn the_box_from_the_command_line_reports_each_bends_allowance() {
    let dir = scratch("bends-box-cli");
    let out = dir.join("out");
    let o = flatcut(&[
        "cut",
        "patterns/cube.obj",
        "--material",
        "metal",
        "--thickness",
        "2",
        "--k-factor",
        "0.4",
        "--bend-radius",
        "2",
        "--sheet",
        "600x600",
        "--dry-run",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let (allowance, deduction) = (
        ba(FRAC_PI_2, 2.0, 0.4, 2.0),
        bd(FRAC_PI_2, 2.0, 0.4, 2.0, true),
    );
    let p = &rep["pieces"][0];
    let d = &p["bend_development"];
    assert_eq!(d["thickness_mm"], 2.0);
    assert_eq!(d["k_factor"], 0.4);
    assert_eq!(d["inside_radius_mm"], 2.0);
    let bends = d["bends"].as_array().unwrap();
    assert_eq!(bends.len(), 5);
    assert_eq!(bends.len(), p["fold_lines"].as_array().unwrap().len());
    for b in bends {
        assert_eq!(b["angle_deg"], 90.0);
        assert_eq!(b["inside_radius_mm"], 2.0);
        assert_eq!(b["k_factor"], 0.4);
        assert_eq!(b["mold_line"], "outside");
        let num = |k: &str| b[k].as_f64().unwrap();
        assert!((num("allowance_mm") - allowance).abs() < 1e-6, "{b}");
        assert!((num("deduction_mm") - deduction).abs() < 1e-6, "{b}");
        assert!((num("setback_mm") - 4.0).abs() < 1e-6, "{b}");
    }
    assert_eq!(d["corner_reliefs_mm"].as_array().unwrap().len(), 4);
    // Developed seams are not seam mismatches; nothing was left undeveloped.
    assert!(rep.get("warnings").is_none(), "{}", rep["warnings"]);

    // The DXF a shop reads: the bend lines (BEND_DOWN: mountain folds) on the bend centre
    // lines of the cut blank, to its 0.1 µm precision.
    let drawing = dxf::Drawing::load_file(out.join("cube.dxf")).expect("dxf crate reads it");
    let (mut cut, mut lines) = (Vec::new(), Vec::new());
    for e in drawing.entities() {
        match (&e.specific, e.common.layer.as_str()) {
            (dxf::entities::EntityType::LwPolyline(p), "CUT") => {
                cut.extend(p.vertices.iter().map(|v| DVec2::new(v.x, v.y)))
            }
            (dxf::entities::EntityType::Line(l), "BEND_DOWN") => {
                lines.push((DVec2::new(l.p1.x, l.p1.y), DVec2::new(l.p2.x, l.p2.y)))
            }
            _ => {}
        }
    }
    assert_eq!(lines.len(), 5);
    check_box_gaps(&lines, &cut, deduction, 1e-3);
}

/// Two rectangles, `a` and `b` mm deep and 100 mm wide, joined along a 100 mm edge and bent
/// by `theta_deg` there; a mountain fold seen from the printed side when `mountain`.
fn hinge(path: &Path, theta_deg: f64, a: f64, b: f64, mountain: bool) {
    let t = theta_deg.to_radians();
    let (y, z) = (a + b * t.cos(), b * t.sin());
    let mut faces = [vec![1, 2, 3, 4], vec![4, 3, 5, 6]];
    if mountain {
        // The printed side is the one the faces turn counter-clockwise for: from below, the
        // second face bends away.
        faces.iter_mut().for_each(|f| f.reverse());
    }
    let mut text = format!(
        "v 0 0 0\nv 100 0 0\nv 100 {a} 0\nv 0 {a} 0\nv 100 {y:.17} {z:.17}\nv 0 {y:.17} {z:.17}\n"
    );
    for f in faces {
        let f: Vec<String> = f.iter().map(|i| i.to_string()).collect();
        text += &format!("f {}\n", f.join(" "));
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn folds_of_other_angles_get_the_allowance_of_their_angle() {
    let dir = scratch("bends-angles");
    // (deflection, mountain, K, R): the mesh is the outside of a mountain fold and the inside
    // of a valley fold, where the deduction is negative (the blank grows).
    let cases = [
        (45.0, false, 0.4, 2.0),
        (45.0, true, 0.4, 2.0),
        (120.0, true, 0.33, 3.0),
        (120.0, false, 0.33, 3.0),
    ];
    for (theta_deg, mountain, k, r) in cases {
        let mesh = dir.join("hinge.obj");
        hinge(&mesh, theta_deg, 60.0, 40.0, mountain);
        let path = spec(
            &dir,
            &mesh,
            &format!("thickness = 2\nk_factor = {k}\nbend_radius = {r}"),
        );
        let what = format!(
            "{theta_deg}° {}",
            if mountain { "mountain" } else { "valley" }
        );
        let pieces = pieces(&path);
        assert_eq!(pieces.len(), 1, "{what}");
        let p = &pieces[0];
        assert_eq!(p.folds.len(), 1, "{what}");
        let f = &p.folds[0];
        let theta = theta_deg.to_radians();
        assert!((f.angle - theta).abs() < 1e-9, "{what}: {}", f.angle);
        let kind = if mountain {
            FoldKind::Mountain
        } else {
            FoldKind::Valley
        };
        assert_eq!(f.kind, kind, "{what}");
        let deduction = bd(theta, 2.0, k, r, mountain);
        let b = p.development.as_ref().and_then(|d| d.bend(f.edge)).unwrap();
        assert!(
            (b.allowance - ba(theta, 2.0, k, r)).abs() < 1e-9,
            "{what}: {b:?}"
        );
        assert!((b.deduction - deduction).abs() < 1e-9, "{what}: {b:?}");
        // The bend line: 60 − BD/2 from one free edge, 40 − BD/2 from the other, across the
        // whole 100 mm width (the sides are square to it: no relief, no jog).
        let along = (f.b - f.a).normalize();
        let mut gaps = gaps_across(p, along);
        gaps.sort_by(f64::total_cmp);
        let want = [40.0 - deduction / 2.0, 60.0 - deduction / 2.0];
        for (g, w) in gaps.iter().zip(want) {
            assert!((g - w).abs() < 0.05, "{what}: {gaps:?} for {want:?}");
            assert!((g - w).abs() < 1e-6, "{what}: {gaps:?} for {want:?}");
        }
        assert!((extent_along(p, along) - 100.0).abs() < 1e-9, "{what}");
        assert!((f.a.distance(f.b) - 100.0).abs() < 1e-9, "{what}");
    }
}

#[test]
fn bad_k_factors_and_bend_radii_are_refused_naming_the_key() {
    let dir = scratch("bends-bad");
    let mesh = manifest("patterns/cube.obj");
    for (line, key) in [
        ("k_factor = 1.5", "material.k_factor"),
        ("k_factor = -0.1", "material.k_factor"),
        ("k_factor = nan", "material.k_factor"),
        ("bend_radius = -1", "material.bend_radius"),
        ("bend_radius = inf", "material.bend_radius"),
    ] {
        let path = spec(&dir, &mesh, &format!("thickness = 2\n{line}"));
        let o = flatcut(&["cut", path.to_str().unwrap(), "--dry-run", "-q"]);
        assert_eq!(o.status.code(), Some(1), "{line}: {}", stderr(&o));
        let err = stderr(&o);
        // FILE:LINE: the key (line 9 of the spec: after [material], kind and thickness).
        assert!(err.contains("job.toml:9"), "{line}: {err}");
        assert!(err.contains(key), "{line}: {err}");
    }
    for (flag, value) in [
        ("--k-factor", "2"),
        ("--k-factor", "nan"),
        ("--bend-radius", "-0.5"),
        ("--thickness", "0"),
    ] {
        let o = flatcut(&[
            "cut",
            "patterns/cube.obj",
            "--material",
            "metal",
            flag,
            value,
            "--dry-run",
            "-q",
        ]);
        assert_eq!(o.status.code(), Some(1), "{flag} {value}: {}", stderr(&o));
        assert!(stderr(&o).contains(flag), "{flag} {value}: {}", stderr(&o));
    }
}

#[test]
fn only_metal_meshes_are_developed() {
    // Paper and fabric pieces of the cube, and a metal strip (developed on its neutral
    // surface when it is made), carry no development.
    let cube = flatcut::spec::load(&manifest("patterns/cube.toml")).unwrap();
    for kind in [MaterialKind::Paper, MaterialKind::Fabric] {
        let mut s: Spec = cube.clone();
        s.material.kind = kind;
        let (_, pieces) = flatcut::pipeline::pieces(&s, true).unwrap();
        assert!(pieces.iter().all(|p| p.development.is_none()), "{kind}");
    }
    let duct = flatcut::spec::load(&manifest("patterns/duct-transition.toml")).unwrap();
    assert_eq!(duct.material.kind, MaterialKind::Metal);
    let (_, pieces) = flatcut::pipeline::pieces(&duct, true).unwrap();
    assert!(pieces.iter().all(|p| p.development.is_none()));
}

#[test]
fn a_mesh_cut_as_metal_without_a_thickness_is_1_mm_sheet_not_paper() {
    // `--material metal` on a bare OBJ (no `[material]`): the metal default, 1 mm, with R = t;
    // a thickness stated in the spec or by a flag stays whatever the kind.
    let dir = scratch("bends-metal-default");
    let run = |args: &[&str], name: &str| -> f64 {
        let out = dir.join(name);
        let mut all = vec!["cut"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["--sheet", "600x600", "--dry-run", "-q", "-o"]);
        all.push(out.to_str().unwrap());
        let o = flatcut(&all);
        assert!(o.status.success(), "{}", stderr(&o));
        let rep: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        let d = &rep["pieces"][0]["bend_development"];
        assert_eq!(d["inside_radius_mm"], d["thickness_mm"]);
        d["thickness_mm"].as_f64().unwrap()
    };
    assert_eq!(
        run(&["patterns/cube.obj", "--material", "metal"], "bare"),
        1.0
    );
    assert_eq!(
        run(
            &[
                "patterns/cube.obj",
                "--material",
                "metal",
                "--thickness",
                "1.5"
            ],
            "flag"
        ),
        1.5
    );
    let path = spec(&dir, &manifest("patterns/cube.obj"), "thickness = 0.8");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("kind = \"metal\"", "kind = \"paper\"");
    std::fs::write(&path, text).unwrap();
    assert_eq!(
        run(&[path.to_str().unwrap(), "--material", "metal"], "stated"),
        0.8
    );
}
