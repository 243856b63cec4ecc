//! Spline developables with exact answers (issue 24's acceptance shapes, at the library level).

use super::*;

fn spec(curves: Vec<Vec<DVec3>>, apex: Option<DVec3>, closed: bool) -> SplineSpec {
    SplineSpec {
        curves,
        apex,
        degree: 3,
        closed,
        fixed: Vec::new(),
        creases: Vec::new(),
        folds: Vec::new(),
        target: None,
        handles: Vec::new(),
        outline: None,
        options: SolveOptions::default(),
        sheet: (crate::surface::SheetSide::Outside, 0.4),
        neutral_offset: 0.0,
        tolerance: 0.05,
        bend_lines: BendLines::All,
    }
}

fn wave() -> Vec<DVec3> {
    (0..8)
        .map(|i| DVec3::new(i as f64 * 30.0, 40.0 * (i as f64).sin(), 0.0))
        .collect()
}

fn circle(r: f64, z: f64, phase: f64) -> Vec<DVec3> {
    (0..8)
        .map(|i| {
            let t = phase + i as f64 * std::f64::consts::TAU / 8.0;
            DVec3::new(r * t.cos(), r * t.sin(), z)
        })
        .collect()
}

fn mesh_area(m: &Mesh) -> f64 {
    (0..m.faces.len()).map(|f| m.face_area(f)).sum()
}

/// Area of the ruled surface by the midpoint rule (exact in v for the shapes used here).
fn quadrature_area(m: &Model) -> f64 {
    let per = 2000;
    let mut area = 0.0;
    for k in 0..m.basis.spans() * per {
        let u = (k as f64 + 0.5) / per as f64;
        let (pa, ta) = at(m, Some(0), u);
        let (pb, tb) = if m.apex.is_some() {
            at(m, None, u)
        } else {
            at(m, Some(1), u)
        };
        let (ta, tb) = (ta.unwrap_or_default(), tb.unwrap_or_default());
        for j in 0..20 {
            let v = (j as f64 + 0.5) / 20.0;
            let su = ta * (1.0 - v) + tb * v;
            area += su.cross(pb - pa).length() / (per as f64 * 20.0);
        }
    }
    area
}

fn curve_length(m: &Model, c: usize) -> f64 {
    let per = 4000;
    (0..m.basis.spans() * per)
        .map(|k| {
            let u = (k as f64 + 0.5) / per as f64;
            m.basis.deriv(&m.curves[c], u).length() / per as f64
        })
        .sum()
}

#[test]
fn cylinder_is_a_fixed_point() {
    let a = wave();
    let b: Vec<DVec3> = a.iter().map(|p| *p + DVec3::Z * 150.0).collect();
    let s = spec(vec![a.clone(), b.clone()], None, false);
    let out = build(&s).unwrap();
    for (p, q) in out.model.curves[0].iter().zip(&a) {
        assert!(p.distance(*q) <= 1e-9);
    }
    for (p, q) in out.model.curves[1].iter().zip(&b) {
        assert!(p.distance(*q) <= 1e-9);
    }
    assert!(dense_sine(&out.model, 200) <= 1e-12);
    let l = curve_length(&out.model, 0);
    let area = mesh_area(&out.mesh);
    assert!(
        (area - l * 150.0).abs() / (l * 150.0) < 1e-3,
        "{area} vs {}",
        l * 150.0
    );
    // Quads of a cylinder are planar: δ and the isometry error vanish.
    let fig = |k: &str| out.figures.iter().find(|f| f.0 == k).unwrap().1;
    assert!(fig("flatness_delta") < 1e-9);
    assert!(fig("isometry_error") < 1e-9);
    assert!(!out.bends.is_empty());
}

#[test]
fn cone_both_forms_are_fixed_points_with_their_area() {
    let a = circle(100.0, 0.0, 0.1);
    let p = DVec3::new(10.0, -5.0, 200.0);
    let b: Vec<DVec3> = a.iter().map(|x| p + 0.4 * (*x - p)).collect();
    for s in [
        spec(vec![a.clone(), b], None, true),
        spec(vec![a.clone()], Some(p), true),
    ] {
        let out = build(&s).unwrap();
        assert!(out.report.moved <= 1e-9, "moved {}", out.report.moved);
        assert!(dense_sine(&out.model, 200) <= 1e-10);
        let q = quadrature_area(&out.model);
        let area = mesh_area(&out.mesh);
        assert!((area - q).abs() / q < 1e-3, "{area} vs {q}");
    }
}

#[test]
fn loft_between_twisted_rims_becomes_developable() {
    let a = circle(100.0, 0.0, 0.0);
    let b = circle(60.0, 120.0, 0.45);
    let s = spec(vec![a, b], None, true);
    let m0 = model(&s).unwrap();
    let sine0 = dense_sine(&m0, 64);
    assert!(
        sine0 > 1e-2,
        "the rims must not be developable as given ({sine0})"
    );
    let area0 = quadrature_area(&m0);
    let out = build(&s).unwrap();
    let sine = dense_sine(&out.model, 200);
    assert!(
        sine <= 1e-6,
        "sine {sine} after {} iterations",
        out.report.iterations
    );
    assert!(quadrature_area(&out.model) >= 0.5 * area0);
    assert!(out.report.moved > 0.1);
    assert!(out.warnings.is_empty());
}

#[test]
fn loft_with_one_rim_fixed_keeps_it() {
    let a = circle(100.0, 0.0, 0.0);
    let b = circle(60.0, 120.0, 0.3);
    let mut s = spec(vec![a.clone(), b], None, true);
    s.fixed = (0..8).map(|j| (0, j)).collect();
    let out = build(&s).unwrap();
    assert_eq!(out.model.curves[0], a);
    assert!(dense_sine(&out.model, 200) <= 1e-6);
}

#[test]
fn crossing_rulings_are_refused_with_u_and_v() {
    // A flat strip whose rulings all cross its middle: developable, but it folds over itself.
    let a: Vec<DVec3> = (0..5)
        .map(|i| DVec3::new(i as f64 * 25.0, 0.0, 0.0))
        .collect();
    let b: Vec<DVec3> = (0..5)
        .map(|i| DVec3::new(100.0 - i as f64 * 25.0, 50.0, 0.0))
        .collect();
    let err = build(&spec(vec![a, b], None, false)).unwrap_err();
    match err {
        SplineError::Striction { v, .. } => assert!((v - 0.5).abs() < 1e-6),
        other => panic!("{other}"),
    }
    assert!(err_text().contains("u = "));
}

fn err_text() -> String {
    SplineError::Striction {
        u: 1.0,
        v: 0.5,
        strip: 1,
    }
    .to_string()
}

#[test]
fn unequal_curves_and_a_cone_with_two_curves_are_refused() {
    let mut s = spec(vec![wave(), wave()[..7].to_vec()], None, false);
    assert!(matches!(model(&s), Err(SplineError::Shape { .. })));
    s.curves = vec![wave(), wave()];
    s.apex = Some(DVec3::Z);
    assert!(matches!(model(&s), Err(SplineError::Shape { .. })));
    s.curves = vec![wave()];
    s.apex = None;
    assert!(matches!(model(&s), Err(SplineError::Shape { .. })));
}

/// Issue 24's fold by reflection: a cylinder over a half-circle cubic (r = 100) cut by the
/// plane z = 100 + 2 y, its part above the plane mirrored in it. Curves: the bottom rim, the
/// crease (on the plane) and the mirrored top rim.
fn reflected_fold() -> Vec<Vec<DVec3>> {
    let c0: Vec<DVec3> = (0..8)
        .map(|i| {
            let t = std::f64::consts::PI * i as f64 / 7.0;
            DVec3::new(100.0 * t.cos(), 100.0 * t.sin(), 0.0)
        })
        .collect();
    let m = DVec3::new(0.0, -2.0, 1.0).normalize();
    let o = DVec3::new(0.0, 0.0, 100.0);
    let mirror = |p: DVec3| p - 2.0 * (p - o).dot(m) * m;
    let c1 = c0
        .iter()
        .map(|p| DVec3::new(p.x, p.y, 100.0 + 2.0 * p.y))
        .collect();
    let c2 = c0.iter().map(|p| mirror(*p + DVec3::Z * 400.0)).collect();
    vec![c0, c1, c2]
}

fn figure(out: &Solved, k: &str) -> f64 {
    out.figures.iter().find(|f| f.0 == k).unwrap().1
}

#[test]
fn a_fold_by_reflection_is_a_fixed_point_and_fails_with_one_side_flipped() {
    let curves = reflected_fold();
    let mut s = spec(curves.clone(), None, false);
    s.creases = vec![Crease::Fold];
    let out = build(&s).unwrap();
    assert!(out.report.moved <= 1e-9, "moved {}", out.report.moved);
    assert!(dense_sine(&out.model, 200) <= 1e-10);
    assert!(figure(&out, "crease_sine") <= 1e-9, "{:?}", out.figures);
    assert!(
        figure(&out, "crease_angle_defect") <= 1e-9,
        "{:?}",
        out.figures
    );
    // The sign test: with the right side's normals turned over, eq. 7 reads as eq. 8.
    let flipped = dense_crease_sine(&out.model, 64, true);
    assert!(flipped > 0.1, "flipped {flipped}");
    // As a geodesic crease the same shape is far from a solution.
    let mut g = s.clone();
    g.creases = vec![Crease::Geodesic];
    assert!(dense_crease_sine(&model(&g).unwrap(), 64, false) > 0.1);
    // The crease edges are fold lines, all of one sense.
    let k = out.mesh.vertices.len();
    let folds: Vec<&Bend> = out
        .bends
        .iter()
        .filter(|b| {
            let on = |v: usize| {
                let p = out.mesh.vertices[v];
                (p.z - 100.0 - 2.0 * p.y).abs() < 1e-6
            };
            on(b.verts[0]) && on(b.verts[1])
        })
        .collect();
    assert!(folds.len() > 10, "{} folds of {k} vertices", folds.len());
    let sense = folds[0].angle_deg.signum();
    assert!(folds
        .iter()
        .all(|b| b.angle_deg.signum() == sense && b.angle_deg.abs() > 10.0));
}

#[test]
fn a_perturbed_fold_is_restored_in_ten_iterations() {
    let mut curves = reflected_fold();
    let mut rng = crate::geom::rng::Rng::new(24);
    for p in &mut curves[1] {
        *p += DVec3::new(
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
        );
    }
    let mut s = spec(curves, None, false);
    s.creases = vec![Crease::Fold];
    let m0 = model(&s).unwrap();
    assert!(dense_sine(&m0, 64).max(dense_crease_sine(&m0, 64, false)) > 1e-3);
    s.options.max_iterations = 10;
    let out = build(&s).unwrap();
    let sine = dense_sine(&out.model, 200);
    let crease = dense_crease_sine(&out.model, 200, false);
    assert!(sine <= 1e-6, "sine {sine}");
    assert!(crease <= 1e-6, "crease sine {crease}");
    // Fig. 17, row 13: δ max 4.4e-4, |K| max 6.4e-4.
    assert!(figure(&out, "flatness_delta") <= 4.4e-4);
    assert!(figure(&out, "crease_angle_defect") <= 6.4e-4);
}

#[test]
fn crease_counts_and_straight_creases_are_refused() {
    let mut s = spec(reflected_fold(), None, false);
    s.creases = vec![Crease::Fold, Crease::Fold];
    let e = model(&s).unwrap_err().to_string();
    assert!(e.contains("`creases`: has 2 entries"), "{e}");
    // Three parallel straight lines: a fold condition on the middle one is refused.
    let line = |y: f64| -> Vec<DVec3> {
        (0..6)
            .map(|i| DVec3::new(i as f64 * 20.0, y, 0.0))
            .collect()
    };
    let mut s = spec(vec![line(0.0), line(50.0), line(100.0)], None, false);
    s.creases = vec![Crease::Fold];
    let e = model(&s).unwrap_err().to_string();
    assert!(e.contains("`creases[1]`: curve 2 is straight"), "{e}");
    s.creases = vec![Crease::Smooth];
    assert!(model(&s).is_ok());
}

/// A flat sheet of three curves, the middle one bowed: a crease that starts unfolded.
fn flat_sheet() -> Vec<Vec<DVec3>> {
    (0..3)
        .map(|k| {
            (0..8)
                .map(|j| {
                    let x = j as f64 * 30.0;
                    let bow = if k == 1 {
                        25.0 * (x / 210.0 * std::f64::consts::PI).sin()
                    } else {
                        0.0
                    };
                    DVec3::new(x, k as f64 * 100.0 + bow, 0.0)
                })
                .collect()
        })
        .collect()
}

#[test]
fn a_stated_direction_folds_a_flat_start_that_way_by_at_least_one_degree() {
    for (valley, sense) in [(true, -1.0), (false, 1.0)] {
        let mut s = spec(flat_sheet(), None, false);
        s.creases = vec![Crease::Fold];
        // Unfolded, the flat start is already a solution: nothing moves.
        let out = build(&s).unwrap();
        assert!(out.report.moved <= 1e-12, "{}", out.report.moved);
        assert_eq!(figure(&out, "fold_angle_max_deg"), 0.0);
        s.folds = vec![Some(FoldGoal {
            valley,
            angle: None,
        })];
        let out = build(&s).unwrap();
        let mean = figure(&out, "fold_angle_mean_deg");
        assert!((1.0 - 1e-6..1.1).contains(&mean), "mean {mean}");
        assert!(figure(&out, "crease_sine") <= 1e-9, "{:?}", out.figures);
        assert!(figure(&out, "largest_sine") <= 1e-9, "{:?}", out.figures);
        // Seen from the printed side (the mesh's faces), a valley folds towards it: the
        // pattern calls a negative dihedral a valley.
        let on = |v: usize| out.curve_verts[1].contains(&v);
        let creases: Vec<&Bend> = out
            .bends
            .iter()
            .filter(|b| on(b.verts[0]) && on(b.verts[1]))
            .collect();
        assert!(creases.len() > 10);
        assert!(creases.iter().all(|b| b.angle_deg.signum() == sense));
    }
}

#[test]
fn a_stated_angle_is_the_mean_fold_along_the_crease() {
    let mut s = spec(flat_sheet(), None, false);
    s.creases = vec![Crease::Fold];
    s.options.max_iterations = 100;
    s.folds = vec![Some(FoldGoal {
        valley: false,
        angle: Some(30f64.to_radians()),
    })];
    let out = build(&s).unwrap();
    let mean = figure(&out, "fold_angle_mean_deg");
    assert!((mean - 30.0).abs() < 0.05, "mean {mean} {:?}", out.figures);
    assert!(figure(&out, "crease_sine") <= 1e-9, "{:?}", out.figures);
    assert!(figure(&out, "largest_sine") <= 1e-9, "{:?}", out.figures);
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
}

#[test]
fn a_curve_that_stands_still_is_a_cone_apex_with_one_vertex() {
    // The first curve is one point for its first half (a cone over the bow), then moves.
    let mut curves = flat_sheet();
    for p in curves[0].iter_mut().take(4) {
        *p = DVec3::ZERO;
    }
    let mut s = spec(curves, None, false);
    s.fixed = vec![(0, 0), (0, 1), (0, 2), (0, 3)];
    s.creases = vec![Crease::Fold];
    // The far corner lifted: the cone bends about its apex.
    s.handles = vec![(curves_end(&s), DVec3::new(f64::NAN, f64::NAN, 40.0))];
    s.options.max_iterations = 100;
    let out = build(&s).unwrap();
    let at_apex = out
        .mesh
        .vertices
        .iter()
        .filter(|v| v.length() < 1e-9)
        .count();
    assert_eq!(at_apex, 1);
    for f in &out.mesh.faces {
        let p: Vec<DVec3> = f.verts.iter().map(|&v| out.mesh.vertices[v]).collect();
        assert!((p[1] - p[0]).cross(p[2] - p[0]).length() > 1e-9);
    }
    assert!(figure(&out, "largest_sine") <= 1e-9, "{:?}", out.figures);
    assert!(
        figure(&out, "handle_distance_mm") <= 1e-6,
        "{:?}",
        out.figures
    );
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
}

/// The last control point of the last curve.
fn curves_end(s: &SplineSpec) -> DVec3 {
    *s.curves.last().and_then(|c| c.last()).unwrap()
}
