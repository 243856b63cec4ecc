//! Issue 5 acceptance: bent sheets (Bo–Wang geodesic-controlled developables). The blank is
//! read back from what the user gets (the HPGL of a dry run), the mesh is checked triangle by
//! triangle against the flat sheet, a helix must give a circular cylinder, and a sheet that
//! would hold a point of the curve of regression is refused with exit 1 and the position.

use crate::common::*;
use flatcut::geom::curve::Curve;
use flatcut::output::hpgl;
use flatcut::surface::geodesic::{
    self, ArcLength, BentSpec, Control, FlatPath, GeodesicError, LengthFit, Param, PieceSpec,
    Spline,
};
use flatcut::surface::strip::BendLines;
use glam::{DVec2, DVec3};

/// Closed pen-1 (cut) contours of an HP-GL program at 40 units/mm, in mm.
fn cut_contours(plt: &str) -> Vec<Vec<DVec2>> {
    let strokes = hpgl::parse(plt).expect("valid HPGL");
    strokes
        .iter()
        .filter(|s| s.pen == 1)
        .map(|s| {
            s.points
                .iter()
                .map(|&(x, y)| DVec2::new(x as f64 / 40.0, y as f64 / 40.0))
                .collect::<Vec<_>>()
        })
        .collect()
}

fn area_perimeter(pts: &[DVec2]) -> (f64, f64) {
    let mut area = 0.0;
    let mut per = 0.0;
    for w in pts.windows(2) {
        area += w[0].perp_dot(w[1]);
        per += w[0].distance(w[1]);
    }
    (0.5 * area.abs(), per)
}

/// The first surface of a spec file, which must be a bent sheet.
fn bent_spec(path: &std::path::Path) -> BentSpec {
    let spec = flatcut::spec::load(path).expect("spec loads");
    spec.surfaces[0].bent.clone().expect("a bent sheet")
}

/// The arc length `s = … mm` an error message gives.
fn arc_length_in(err: &str) -> f64 {
    err.split("s = ")
        .nth(1)
        .and_then(|t| t.split(" mm").next())
        .and_then(|t| t.parse().ok())
        .expect("arc length in the message")
}

fn bent_of(path: &str) -> (BentSpec, geodesic::Bent) {
    let b = bent_spec(&manifest(path));
    let bent = geodesic::bend(&b).expect("bends");
    (b, bent)
}

/// Largest relative difference between a triangle's 3D and flat edge lengths.
fn worst_edge_error(bent: &geodesic::Bent) -> f64 {
    let mut worst: f64 = 0.0;
    for f in &bent.mesh.faces {
        for i in 0..3 {
            let (a, b) = (f.verts[i], f.verts[(i + 1) % 3]);
            let l3 = bent.mesh.vertices[a].distance(bent.mesh.vertices[b]);
            let l2 = bent.flat[a].distance(bent.flat[b]);
            worst = worst.max((l3 - l2).abs() / l2);
        }
    }
    worst
}

/// The folded line in 3D: the line's start, its crossings with the rulings of `piece`, its end.
fn folded_line(spec: &BentSpec, bent: &geodesic::Bent, piece: usize) -> Option<Vec<DVec3>> {
    let FlatPath::Line([a, b]) = spec.pieces[piece].path else {
        return None;
    };
    let d = (b - a).normalize();
    let mut pts = Vec::new();
    let on_mesh = |p: DVec2| -> Option<DVec3> {
        // The point lies in some triangle: barycentric interpolation of the 3D corners.
        for f in &bent.mesh.faces {
            let v = [f.verts[0], f.verts[1], f.verts[2]];
            let (p0, p1, p2) = (bent.flat[v[0]], bent.flat[v[1]], bent.flat[v[2]]);
            let den = (p1 - p0).perp_dot(p2 - p0);
            let l1 = (p - p0).perp_dot(p2 - p0) / den;
            let l2 = (p1 - p0).perp_dot(p - p0) / den;
            let l0 = 1.0 - l1 - l2;
            if l0 >= -1e-9 && l1 >= -1e-9 && l2 >= -1e-9 {
                let m = &bent.mesh.vertices;
                return Some(m[v[0]] * l0 + m[v[1]] * l1 + m[v[2]] * l2);
            }
        }
        None
    };
    pts.push(on_mesh(a + d * 1e-9)?);
    for r in bent.rulings.iter().filter(|r| r.piece == Some(piece)) {
        pts.push(on_mesh(r.point)?);
    }
    pts.push(on_mesh(b - d * 1e-9)?);
    Some(pts)
}

fn polyline_length(p: &[DVec3]) -> f64 {
    p.windows(2).map(|w| w[0].distance(w[1])).sum()
}

#[test]
fn bent_a4_round_trip_area_and_perimeter_from_hpgl() {
    let out = scratch("bent-a4");
    let obj = out.join("a4.obj");
    let o = flatcut(&[
        "cut",
        "patterns/bent-a4.toml",
        "--device",
        "hpgl-pens",
        "--dry-run",
        "-o",
        out.to_str().unwrap(),
        "--surface-obj",
        obj.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let plt = std::fs::read_to_string(out.join("bent-a4.plt")).unwrap();
    let cuts = cut_contours(&plt);
    assert_eq!(cuts.len(), 1, "one blank, no holes");
    let (area, per) = area_perimeter(&cuts[0]);
    let (a0, p0) = (210.0 * 297.0, 2.0 * (210.0 + 297.0));
    eprintln!(
        "bent-a4 blank: area {area:.3} mm² ({:+.5} %), perimeter {per:.4} mm ({:+.5} %)",
        100.0 * (area - a0) / a0,
        100.0 * (per - p0) / p0
    );
    assert!((area - a0).abs() / a0 < 1e-3, "area {area}");
    assert!((per - p0).abs() / p0 < 1e-3, "perimeter {per}");
    // Score lines (pen 2) every 20 mm or so across the S.
    let strokes = hpgl::parse(&plt).unwrap();
    let scores = strokes.iter().filter(|s| s.pen == 2).count();
    assert!((8..=20).contains(&scores), "{scores} score lines");
    // The OBJ is the bent surface: its triangles have the blank's area.
    let text = std::fs::read_to_string(&obj).unwrap();
    let v: Vec<DVec3> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let n: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            DVec3::new(n[0], n[1], n[2])
        })
        .collect();
    let area3: f64 = text
        .lines()
        .filter_map(|l| l.strip_prefix("f "))
        .map(|l| {
            let i: Vec<usize> = l
                .split_whitespace()
                .map(|x| x.parse::<usize>().unwrap() - 1)
                .collect();
            0.5 * (v[i[1]] - v[i[0]]).cross(v[i[2]] - v[i[0]]).length()
        })
        .sum();
    assert!((area3 - a0).abs() / a0 < 1e-9, "3D area {area3}");
    // Bent for real: the S rises and falls by tens of mm.
    let (zmin, zmax) = v
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.z), b.max(p.z)));
    assert!(zmax > 20.0 && zmin < -20.0, "z from {zmin} to {zmax}");
}

#[test]
fn bent_isometry_triangles_and_control_curve_length() {
    for path in [
        "patterns/bent-a4.toml",
        "patterns/business-card.toml",
        "patterns/lamp-panel.toml",
    ] {
        let (spec, bent) = bent_of(path);
        let worst = worst_edge_error(&bent);
        eprintln!(
            "{path}: {} triangles, {} rulings, worst edge error {worst:.2e}, curve {:.9} mm for a {:.3} mm line, folded line strays {:.4} mm",
            bent.mesh.faces.len(),
            bent.rulings.len(),
            bent.lengths[0],
            spec.pieces[0].path.length(),
            bent.drifts[0]
        );
        assert!(worst < 1e-6, "{path}: {worst}");
        // The control curve after re-parameterisation is as long as the line, and so is the
        // folded line through the mesh.
        let len = spec.pieces[0].path.length();
        assert!((bent.lengths[0] - len).abs() / len < 1e-6, "{path}");
        // (Not where the line crosses a hole: the lamp panel's.)
        if let Some(line) = folded_line(&spec, &bent, 0) {
            let folded = polyline_length(&line);
            assert!((folded - len).abs() / len < 1e-6, "{path}: folded {folded}");
        } else {
            assert!(!spec.holes.is_empty(), "{path}");
        }
        assert!(bent.drifts[0] <= spec.tolerance, "{path}");
        // The flatten stage lays it out in one island with every edge at its 3D length.
        let surface = flatcut::surface::Surface {
            name: "t".into(),
            mesh: bent.mesh.clone(),
            bends: Some(bent.bends.clone()),
            ..Default::default()
        };
        let flat = flatcut::flatten::unfold(surface, &Default::default()).unwrap();
        assert_eq!(flat.islands.len(), 1, "{path}");
        for (f, pts) in flat.face_2d.iter().enumerate() {
            let v = &flat.surface.mesh.faces[f].verts;
            for i in 0..3 {
                let l3 = flat.surface.mesh.vertices[v[i]]
                    .distance(flat.surface.mesh.vertices[v[(i + 1) % 3]]);
                let l2 = pts[i].distance(pts[(i + 1) % 3]);
                assert!((l3 - l2).abs() <= 1e-9 * l3, "{path}: face {f}");
            }
        }
    }
}

#[test]
fn bent_arc_length_matches_dense_sampling() {
    // The Gauss–Legendre arc length of a Bézier and of a B-spline against a polyline sampled at
    // 1e-5 mm chordal tolerance (chord deficit far below 1e-6 relative).
    let bez = vec![
        DVec3::new(105.0, 0.0, 0.0),
        DVec3::new(105.0, 110.0, 90.0),
        DVec3::new(105.0, 190.0, -90.0),
        DVec3::new(105.0, 297.0, 0.0),
    ];
    let bs = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(30.0, 5.0, 0.0),
        DVec3::new(52.0, -4.0, 6.0),
        DVec3::new(56.0, 0.0, 26.0),
        DVec3::new(42.0, 3.0, 34.0),
        DVec3::new(32.0, 0.0, 22.0),
    ];
    let cases: Vec<(Box<dyn Param>, Curve)> = vec![
        (
            Box::new(Spline::bezier(bez.clone())),
            Curve::Bezier { control: bez },
        ),
        (
            Box::new(Spline::bspline(bs.clone(), 3)),
            Curve::BSpline {
                control: bs,
                degree: 3,
                closed: false,
            },
        ),
    ];
    for (p, c) in &cases {
        let gl = ArcLength::new(p.as_ref()).total();
        let poly = flatcut::geom::curve::length(&c.sample(1e-5).unwrap());
        assert!((gl - poly).abs() / gl < 1e-6, "{gl} vs {poly}");
        // And the evaluator agrees with geom::curve's sampling at the ends.
        let (a, b) = p.domain();
        let s = c.sample(0.1).unwrap();
        assert!(p.eval(a)[0].distance(s.points[0]) < 1e-12);
        assert!(p.eval(b)[0].distance(*s.points.last().unwrap()) < 1e-12);
    }
}

/// A circular helix of radius `r` and pitch parameter `c`: (r cos θ, r sin θ, c θ).
struct Helix {
    r: f64,
    c: f64,
    turns: f64,
}

impl Param for Helix {
    fn domain(&self) -> (f64, f64) {
        (0.0, std::f64::consts::TAU * self.turns)
    }
    fn eval(&self, u: f64) -> [DVec3; 4] {
        let (s, co) = u.sin_cos();
        let r = self.r;
        [
            DVec3::new(r * co, r * s, self.c * u),
            DVec3::new(-r * s, r * co, self.c),
            DVec3::new(-r * co, -r * s, 0.0),
            DVec3::new(r * s, -r * co, 0.0),
        ]
    }
}

fn rect(w: f64, h: f64) -> Vec<DVec2> {
    vec![
        DVec2::ZERO,
        DVec2::new(w, 0.0),
        DVec2::new(w, h),
        DVec2::new(0.0, h),
    ]
}

fn piece(line: [DVec2; 2], control: Vec<DVec3>) -> PieceSpec {
    PieceSpec {
        path: FlatPath::Line(line),
        control: Control::Curve(Curve::Bezier { control }),
        fit: LengthFit::Scale,
    }
}

#[test]
fn bent_helix_gives_the_circular_cylinder() {
    let (r, c) = (40.0, 15.0);
    let helix = Helix { r, c, turns: 0.6 };
    let len = ArcLength::new(&helix).total();
    // A strip of paper whose centre line is the helix (trimmed exactly to its length).
    let spec = BentSpec {
        outline: rect(len, 40.0),
        holes: vec![],
        pieces: vec![PieceSpec {
            path: FlatPath::Line([DVec2::new(0.0, 20.0), DVec2::new(len, 20.0)]),
            control: Control::Curve(Curve::Bezier { control: vec![] }),
            fit: LengthFit::Trim,
        }],
        tolerance: 0.02,
        bend_lines: BendLines::All,
    };
    let bent = geodesic::bend_with(&spec, &[(&helix, None)]).unwrap();
    assert!(worst_edge_error(&bent) < 1e-9);
    // Analytic: rulings along the axis; on the flat sheet at angle α from the line with
    // tan α = κ/τ = r/c.
    let alpha = (r / c).atan();
    let mut worst_r: f64 = 0.0;
    let mut n = 0;
    for ru in bent.rulings.iter().filter(|x| x.piece.is_some()) {
        n += 1;
        assert!(
            ru.dir_3d.cross(DVec3::Z).length() < 1e-9,
            "ruling {} not along the axis",
            ru.dir_3d
        );
        let flat_angle = ru.dir.angle_to(DVec2::X).abs();
        let flat_angle = flat_angle.min(std::f64::consts::PI - flat_angle);
        assert!((flat_angle - alpha).abs() < 1e-9, "{flat_angle} vs {alpha}");
        for e in &ru.edges {
            for &v in e {
                let p = bent.mesh.vertices[v];
                worst_r = worst_r.max((DVec2::new(p.x, p.y).length() - r).abs());
            }
        }
    }
    eprintln!(
        "helix r {r} c {c}: {n} rulings, all along z; ruling ends within {worst_r:.4} mm of the cylinder"
    );
    assert!(n > 10);
    assert!(worst_r < spec.tolerance, "{worst_r}");
}

fn write_spec(dir: &std::path::Path, name: &str, body: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, body).unwrap();
    p.to_string_lossy().into_owned()
}

#[test]
fn bent_curve_of_regression_in_the_sheet_exits_1_with_position() {
    let dir = scratch("bent-regression");
    // A curve whose torsion changes fast: its rulings fan and meet inside the card.
    let spec = write_spec(
        &dir,
        "twist.toml",
        r#"
[[surface]]
kind = "bent-sheet"
name = "twisted"
outline = [85, 55]
line = [[0, 27.5], [85, 27.5]]
control_points = { kind = "bspline", degree = 3, control = [[0, 27.5, 0], [20, 27.5, 0], [38, 29, 8], [36, 31, 26], [20, 32, 26], [18, 33, 12]] }
"#,
    );
    let o = flatcut(&["cut", &spec, "--dry-run", "-o", dir.to_str().unwrap()]);
    let err = stderr(&o);
    eprintln!("{err}");
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("twist.toml:6"), "{err}");
    assert!(err.contains("curve of regression"), "{err}");
    // The position: arc length along the line in mm, distance and depth in mm.
    let s = arc_length_in(&err);
    assert!(s > 0.0 && s < 85.0, "{s}");
    assert!(err.contains("inside the sheet's edge"), "{err}");
    assert!(!dir.join("twisted.plt").exists());

    // The same through the library: the error carries the figures.
    let b = bent_spec(std::path::Path::new(&spec));
    match geodesic::bend(&b) {
        Err(GeodesicError::Regression {
            s: s2, dist, depth, ..
        }) => {
            assert!((s2 - s).abs() < 0.01);
            assert!(dist > 0.0 && depth > 0.0 && dist < 55.0);
        }
        other => panic!("expected a regression error, got {other:?}"),
    }
}

#[test]
fn bent_lamp_panel_hole_is_cut() {
    let out = scratch("bent-lamp");
    let o = flatcut(&[
        "cut",
        "patterns/lamp-panel.toml",
        "--device",
        "hpgl-pens",
        "--dry-run",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let plt = std::fs::read_to_string(out.join("lamp-panel.plt")).unwrap();
    let mut cuts: Vec<(f64, f64)> = cut_contours(&plt)
        .iter()
        .map(|c| area_perimeter(c))
        .collect();
    cuts.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert_eq!(cuts.len(), 2, "outline and hole: {cuts:?}");
    // The octagon of circumradius 30: area 2√2 r², side 2 r sin(22.5°).
    let (ha, hp) = (
        2.0 * 2f64.sqrt() * 900.0,
        16.0 * 30.0 * (std::f64::consts::PI / 8.0).sin(),
    );
    eprintln!(
        "lamp panel: hole {:.2} mm² / {:.3} mm, outline {:.1} mm² / {:.2} mm",
        cuts[0].0, cuts[0].1, cuts[1].0, cuts[1].1
    );
    assert!((cuts[0].0 - ha).abs() / ha < 2e-3, "{cuts:?}");
    assert!((cuts[0].1 - hp).abs() / hp < 2e-3, "{cuts:?}");
    assert!((cuts[1].0 - 60000.0).abs() / 60000.0 < 1e-3);
    assert!((cuts[1].1 - 1000.0).abs() / 1000.0 < 1e-3);
}

#[test]
fn bent_hole_beside_the_rulings_and_two_pieces() {
    // Two curved pieces at both ends of a long sheet, planar between, with a hole in the
    // planar middle that no ruling crosses.
    let spec = BentSpec {
        outline: rect(300.0, 100.0),
        holes: vec![vec![
            DVec2::new(140.0, 40.0),
            DVec2::new(160.0, 40.0),
            DVec2::new(160.0, 60.0),
            DVec2::new(140.0, 60.0),
        ]],
        pieces: vec![
            piece(
                [DVec2::new(0.0, 50.0), DVec2::new(100.0, 50.0)],
                vec![
                    DVec3::new(0.0, 0.0, 0.0),
                    DVec3::new(40.0, 0.0, 30.0),
                    DVec3::new(90.0, 0.0, 20.0),
                ],
            ),
            piece(
                [DVec2::new(200.0, 50.0), DVec2::new(300.0, 50.0)],
                vec![
                    DVec3::new(0.0, 0.0, 0.0),
                    DVec3::new(50.0, 0.0, 0.0),
                    DVec3::new(90.0, 0.0, 30.0),
                ],
            ),
        ],
        tolerance: 0.05,
        bend_lines: BendLines::All,
    };
    let bent = geodesic::bend(&spec).unwrap();
    assert!(worst_edge_error(&bent) < 1e-9);
    assert!(
        bent.rulings.iter().any(|r| r.piece.is_none()),
        "a cut line through the hole"
    );
    let bends = bent.bends.len();
    let folds = bent.rulings.iter().filter(|r| r.piece.is_some()).count();
    assert_eq!(
        bends, folds,
        "one bend line per ruling, none for the hole's cut line"
    );
    // Each piece's folded line is as long as its line.
    for p in 0..2 {
        let l = polyline_length(&folded_line(&spec, &bent, p).unwrap());
        assert!((l - 100.0).abs() < 1e-6, "piece {p}: {l}");
    }
    // The planar middle stays planar: the hole's corners lie in one plane with the middle's.
    let surface = flatcut::surface::Surface {
        name: "two".into(),
        mesh: bent.mesh.clone(),
        ..Default::default()
    };
    let flat = flatcut::flatten::unfold(surface, &Default::default()).unwrap();
    assert_eq!(flat.islands.len(), 1);
    // Each bend line's angle (mountain positive) is the dihedral angle the flatten stage sees.
    for b in &bent.bends {
        let key = [b.verts[0].min(b.verts[1]), b.verts[0].max(b.verts[1])];
        let e = flat
            .topology
            .edges
            .iter()
            .position(|e| e.verts == key)
            .expect("bend line is a mesh edge");
        let d = flat.dihedral[e].to_degrees();
        assert!((d - b.angle_deg).abs() < 1e-6, "{d} vs {}", b.angle_deg);
    }
    assert!(bent.bends.iter().any(|b| b.angle_deg > 0.0));
    assert!(bent.bends.iter().any(|b| b.angle_deg < 0.0));
    // Area kept: 300 × 100 less the 20 × 20 hole.
    let area: f64 = (0..bent.mesh.faces.len())
        .map(|f| bent.mesh.face_area(f))
        .sum();
    assert!((area - 29600.0).abs() < 1e-6, "{area}");

    // The second piece's rulings turned so that they reach the first piece's: refused.
    let mut crossing = spec.clone();
    crossing.holes.clear();
    crossing.pieces[1].path = FlatPath::Line([DVec2::new(60.0, 0.0), DVec2::new(60.0, 100.0)]);
    match geodesic::bend(&crossing) {
        Err(GeodesicError::Crossing { a, b, .. }) => assert_eq!((a, b), (0, 1)),
        other => panic!("expected crossing rulings, got {:?}", other.map(|_| ())),
    }
}

#[test]
fn bent_handles_meet_their_normals() {
    // The sheet, 200 mm along the line, held at two points 150 mm apart, sags into a circular
    // arc: sin(x)/x = 150/200 gives the half angle x; the normals at the ends (toward the
    // centre) lean inward by x.
    let (mut lo, mut hi) = (0.1f64, 3.0f64);
    for _ in 0..60 {
        let m = 0.5 * (lo + hi);
        if m.sin() / m > 0.75 {
            lo = m;
        } else {
            hi = m;
        }
    }
    let x = lo;
    let (n0, n1) = (
        DVec3::new(x.sin(), 0.0, x.cos()),
        DVec3::new(-x.sin(), 0.0, x.cos()),
    );
    let end = DVec3::new(150.0, 0.0, 0.0);
    let (c, m0, m1) = geodesic::handles_curve(DVec3::ZERO, n0, end, n1, 200.0).unwrap();
    let len = ArcLength::new(&Spline::bezier(c.clone())).total();
    eprintln!("handles: normals missed by {m0:.3}° and {m1:.3}°, length {len:.3} mm; {c:?}");
    assert!(m0 < 1.0 && m1 < 1.0, "{m0} {m1}");
    assert!((len - 200.0).abs() < 2.0, "{len}");
    // A quartic through both handle points.
    assert_eq!(c[0], DVec3::ZERO);
    assert_eq!(c[4], end);
    let spec = BentSpec {
        outline: rect(200.0, 80.0),
        holes: vec![],
        pieces: vec![PieceSpec {
            path: FlatPath::Line([DVec2::new(0.0, 40.0), DVec2::new(200.0, 40.0)]),
            control: Control::Handles {
                start: DVec3::ZERO,
                start_normal: n0,
                end,
                end_normal: n1,
            },
            fit: LengthFit::Scale,
        }],
        tolerance: 0.05,
        bend_lines: BendLines::None,
    };
    let bent = geodesic::bend(&spec).unwrap();
    assert!(bent.bends.is_empty());
    assert!(worst_edge_error(&bent) < 1e-9);
    // The bent sheet's far edge lands near the end handle (the length fit moved it little).
    let far = folded_line(&spec, &bent, 0).unwrap();
    let tip = *far.last().unwrap();
    assert!(tip.distance(end) < 2.0, "{tip}");
    // The sheet sags below the handles, printed side up (toward the normals).
    let zmin = bent
        .mesh
        .vertices
        .iter()
        .map(|v| v.z)
        .fold(f64::MAX, f64::min);
    assert!(zmin < -40.0, "{zmin}");

    // Handles farther apart than the line is long: paper does not stretch.
    let mut far = spec.clone();
    far.pieces[0].control = Control::Handles {
        start: DVec3::ZERO,
        start_normal: DVec3::Z,
        end: DVec3::new(250.0, 0.0, 0.0),
        end_normal: DVec3::Z,
    };
    let e = geodesic::bend(&far).unwrap_err().to_string();
    assert!(e.contains("does not stretch"), "{e}");
}

fn assert_spec_fails(dir: &std::path::Path, body: &str, want: &[&str]) {
    let spec = write_spec(dir, "bad.toml", body);
    let o = flatcut(&["cut", &spec, "--dry-run", "-o", dir.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{body}\n{err}");
    for w in want {
        assert!(err.contains(w), "expected `{w}` in: {err}");
    }
    assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
}

#[test]
fn bent_bad_input_exits_1_naming_the_key() {
    let dir = scratch("bent-bad");
    let head = "[[surface]]\nkind = \"bent-sheet\"\n";
    let ok_line = "line = [[0, 50], [200, 50]]\n";
    let ok_ctrl = "control_points = [[0, 0, 0], [100, 0, 40], [200, 0, 0]]\n";
    let ok_outline = "outline = [200, 100]\n";
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_line}{ok_ctrl}"),
        &["surface[1].outline", "missing"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}{ok_ctrl}"),
        &["surface[1].line", "missing"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}{ok_line}"),
        &["exactly one of `control_points` and `handles`"],
    );
    // Curves on the sheet (§5): `arc` and `flat_curve`, exactly one of them or `line`.
    let arc = "arc = { center = [100, 0], radius = 60, start_deg = 30, end_deg = 150 }\n";
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}{ok_line}{arc}{ok_ctrl}"),
        &[
            "bad.toml:4",
            "exactly one of `line`, `arc` and `flat_curve`",
        ],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}arc = {{ center = [100, 0], radius = 60, start_deg = 30 }}\n{ok_ctrl}"),
        &["surface[1].arc.end_deg", "missing"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}arc = {{ center = [100, 0], radius = -6, start_deg = 30, end_deg = 90 }}\n{ok_ctrl}"),
        &["surface[1].arc.radius", "positive"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}arc = {{ centre = [100, 0], radius = 6, start_deg = 30, end_deg = 90 }}\n{ok_ctrl}"),
        &["surface[1].arc.centre", "unknown key"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}arc = {{ center = [100, 0], radius = 120, start_deg = 30, end_deg = 150 }}\n{ok_ctrl}"),
        &["bad.toml:4", "leaves the sheet at s = "],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}flat_curve = {{ kind = \"nurbs\", control = [[0, 50], [100, 60], [200, 50]] }}\n{ok_ctrl}"),
        &["surface[1].flat_curve.kind", "bspline"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}{arc}{ok_ctrl}"),
        &[
            "bad.toml:4",
            "bends less than the curve drawn on the sheet",
            "short by",
        ],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}outline = [200, -1]\n{ok_line}{ok_ctrl}"),
        &["bad.toml:3", "surface[1].outline", "positive"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}line = [[0, 50]]\n{ok_ctrl}"),
        &["surface[1].line", "at least 2 points"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}line = [[0, 50], [300, 50]]\n{ok_ctrl}"),
        &["bad.toml:4", "not on the sheet"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}{ok_line}control_points = [[0, 0, 0], [200, 0, 0]]\n"),
        &["at least 3"],
    );
    assert_spec_fails(
        &dir,
        &format!(
            "{head}{ok_outline}holes = [[[190, 90], [250, 90], [250, 120]]]\n{ok_line}{ok_ctrl}"
        ),
        &["hole 1", "not inside the outline"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}{ok_line}{ok_ctrl}length_fit = \"stretch\"\n"),
        &["surface[1].length_fit", "scale"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}{ok_line}control_points = [[0, 0, 0], [100, 0, 40], [200, 0, nan]]\n"),
        &["surface[1].control_points"],
    );
    assert_spec_fails(
        &dir,
        "[[surface]]\nkind = \"strip\"\np = [[0, 0, 0], [100, 0, 0]]\nq = [[0, 50, 0], [100, 50, 0]]\noutline = [10, 10]\n",
        &["surface[1].outline", "bent sheets"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}{ok_line}control_points = [[0, 0, 0], [50, 0, 20], [100, 0, 0]]\nlength_fit = \"trim\"\n"),
        &["shorter than the line"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}{ok_line}{ok_ctrl}tolerance = 0\n"),
        &["surface[1].tolerance"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}{ok_outline}{ok_line}handles = {{ start = [0, 0, 0], start_normal = [0, 0, 1], end = [300, 0, 0], end_normal = [0, 0, 1] }}\n"),
        &["does not stretch"],
    );
    assert_spec_fails(
        &dir,
        &format!("{head}outline = [[0, 0], [100, 100], [100, 0], [0, 100]]\nline = [[10, 50], [90, 50]]\n{ok_ctrl}"),
        &["crosses itself"],
    );
}

#[test]
fn bent_pieces_in_a_spec_and_flatten_writes_the_surface_obj() {
    let dir = scratch("bent-pieces");
    let spec = write_spec(
        &dir,
        "two.toml",
        r#"
name = "two"
[[surface]]
kind = "bent-sheet"
outline = [300, 100]
holes = [[[140, 40], [160, 40], [160, 60], [140, 60]]]
bend_lines = "none"
pieces = [
  { line = [[0, 50], [100, 50]], control_points = [[0, 0, 0], [40, 0, 30], [90, 0, 20]] },
  { line = [[200, 50], [300, 50]], control_points = { kind = "bspline", degree = 2, control = [[0, 0, 0], [50, 0, 0], [70, 0, -10], [90, 0, -30]] }, length_fit = "scale" },
]
[sheet]
width = 420
height = 297
"#,
    );
    let obj = dir.join("two.obj");
    let o = flatcut(&[
        "flatten",
        &spec,
        "-o",
        dir.to_str().unwrap(),
        "--surface-obj",
        obj.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&obj).unwrap();
    assert!(text.starts_with("# flatcut surface mesh (mm)"));
    assert!(text.lines().filter(|l| l.starts_with("f ")).count() > 20);
    // No score lines when bend_lines = "none".
    let out = dir.join("cut");
    let o = flatcut(&[
        "cut",
        &spec,
        "--device",
        "hpgl-pens",
        "--dry-run",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let plt = std::fs::read_to_string(out.join("two.plt")).unwrap();
    let strokes = hpgl::parse(&plt).unwrap();
    assert!(strokes.iter().all(|s| s.pen != 2));
    assert_eq!(cut_contours(&plt).len(), 2, "outline and hole");
    // A key of a piece at the top level as well is an error.
    let bad = write_spec(
        &dir,
        "bad.toml",
        "[[surface]]\nkind = \"bent-sheet\"\noutline = [300, 100]\nline = [[0, 50], [100, 50]]\npieces = [{ line = [[0, 50], [100, 50]], control_points = [[0, 0, 0], [40, 0, 30], [90, 0, 20]] }]\n",
    );
    let o = flatcut(&["cut", &bad, "--dry-run", "-o", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("goes into each entry of `pieces`"),
        "{}",
        stderr(&o)
    );
}

// ---------------------------------------------------------------------------------------------
// Non-geodesic control curves (§5): a curve on the sheet whose geodesic curvature is kept
// ---------------------------------------------------------------------------------------------

/// A circle of radius `r` about `centre` in the plane z = `z`, from angle `a0` over `sweep`
/// (radians, counter-clockwise seen from +z): exact derivatives.
struct Circle {
    centre: DVec2,
    r: f64,
    z: f64,
    a0: f64,
    sweep: f64,
}

impl Param for Circle {
    fn domain(&self) -> (f64, f64) {
        (self.a0, self.a0 + self.sweep)
    }
    fn eval(&self, u: f64) -> [DVec3; 4] {
        let (s, c) = u.sin_cos();
        let r = self.r;
        [
            DVec3::new(self.centre.x + r * c, self.centre.y + r * s, self.z),
            DVec3::new(-r * s, r * c, 0.0),
            DVec3::new(-r * c, -r * s, 0.0),
            DVec3::new(r * s, -r * c, 0.0),
        ]
    }
}

/// An annulus sector about the origin between radii `r0` and `r1`, angles `a0`..`a1` (degrees).
fn annulus_sector(r0: f64, r1: f64, a0: f64, a1: f64) -> Vec<DVec2> {
    let n = 48;
    let at = |r: f64, i: usize| {
        let a = (a0 + (a1 - a0) * i as f64 / n as f64).to_radians();
        DVec2::new(r * a.cos(), r * a.sin())
    };
    let mut out: Vec<DVec2> = (0..=n).map(|i| at(r1, i)).collect();
    out.extend((0..=n).rev().map(|i| at(r0, i)));
    out
}

fn arc_piece(radius: f64, start_deg: f64, end_deg: f64) -> PieceSpec {
    PieceSpec {
        path: FlatPath::Arc {
            center: DVec2::ZERO,
            radius,
            start_deg,
            end_deg,
        },
        control: Control::Curve(Curve::Bezier { control: vec![] }),
        fit: LengthFit::Scale,
    }
}

#[test]
fn bent_arc_on_the_same_planar_arc_stays_flat() {
    // The flat arc of radius 60 from 10° to 100°, and as control curve that very arc in space.
    let (r, a0, a1) = (60.0, 10.0, 100.0);
    let spec = BentSpec {
        outline: annulus_sector(40.0, 80.0, 0.0, 110.0),
        holes: vec![],
        pieces: vec![arc_piece(r, a0, a1)],
        tolerance: 0.05,
        bend_lines: BendLines::All,
    };
    let circle = Circle {
        centre: DVec2::ZERO,
        r,
        z: 0.0,
        a0: f64::to_radians(a0),
        sweep: f64::to_radians(a1 - a0),
    };
    let bent = geodesic::bend_with(&spec, &[(&circle, None)]).unwrap();
    let worst_fold = bent
        .rulings
        .iter()
        .map(|r| r.angle.abs())
        .fold(0.0, f64::max);
    // The sheet is where it lay: every vertex at its flat position, z = 0.
    let moved = bent
        .mesh
        .vertices
        .iter()
        .zip(&bent.flat)
        .map(|(v, f)| v.distance(DVec3::new(f.x, f.y, 0.0)))
        .fold(0.0, f64::max);
    eprintln!(
        "planar arc r {r}: {} rulings, largest fold {worst_fold:.2e} rad, vertices moved {moved:.2e} mm, drift {:.2e} mm",
        bent.rulings.len(),
        bent.drifts[0]
    );
    assert!(worst_fold <= 1e-9, "{worst_fold}");
    assert!(bent.bends.is_empty());
    assert!(moved < 1e-9, "{moved}");
    assert!(worst_edge_error(&bent) < 1e-9);
    // Turned the other way round (clockwise on the sheet, the curve from its other end) it
    // is still the same flat sheet, printed side down (the sign of g follows the flat curve).
    let cw = BentSpec {
        pieces: vec![arc_piece(r, a1, a0)],
        ..spec.clone()
    };
    let back = Circle {
        centre: DVec2::new(0.0, 0.0),
        r,
        z: 0.0,
        a0: f64::to_radians(a0),
        sweep: f64::to_radians(a1 - a0),
    };
    let bent = geodesic::bend_with(&cw, &[(&back, None)]).unwrap();
    let worst_fold = bent.rulings.iter().map(|r| r.angle).fold(0.0, f64::max);
    let flat_z = bent
        .mesh
        .vertices
        .iter()
        .map(|v| v.z.abs())
        .fold(0.0, f64::max);
    assert!(worst_fold <= 1e-9 && flat_z < 1e-9, "{worst_fold} {flat_z}");
}

/// Closest distance between the 3D line through `p` along `d` and the point `q`.
fn line_point_distance(p: DVec3, d: DVec3, q: DVec3) -> f64 {
    (q - p).cross(d.normalize()).length()
}

#[test]
fn bent_arc_on_a_parallel_circle_gives_its_cone() {
    // A cone with its apex H above the centre of a circle of radius ρ: the slant distance to the
    // circle is R = √(ρ² + H²) = 100, and the cone develops into a disc of radius R on which the
    // circle is an arc of radius R (its geodesic curvature 1/R is kept).
    let (rho, h_apex): (f64, f64) = (60.0, 80.0);
    let big_r = (rho * rho + h_apex * h_apex).sqrt();
    let sweep3 = 100.0f64; // degrees of the circle in space
    let sweep2 = sweep3 * rho / big_r; // degrees of the arc on the sheet
    let (a0, a1) = (30.0, 30.0 + sweep2);
    let tol = 0.02;
    let spec = BentSpec {
        outline: annulus_sector(70.0, 130.0, a0 - 2.0, a1 + 2.0),
        holes: vec![],
        pieces: vec![arc_piece(big_r, a0, a1)],
        tolerance: tol,
        bend_lines: BendLines::All,
    };
    let circle = Circle {
        centre: DVec2::ZERO,
        r: rho,
        z: 0.0,
        a0: 0.0,
        sweep: sweep3.to_radians(),
    };
    let bent = geodesic::bend_with(&spec, &[(&circle, None)]).unwrap();
    // (c) Isometry on every triangle, and the control curve as long as the arc on the sheet.
    let worst = worst_edge_error(&bent);
    let flat_len = spec.pieces[0].path.length();
    let len_err = (bent.lengths[0] - flat_len).abs() / flat_len;
    assert!(worst < 1e-9, "{worst}");
    assert!(len_err < 1e-6, "{} vs {flat_len}", bent.lengths[0]);
    // On the sheet the rulings are the radii of the disc: they cross the arc at right angles
    // (a parallel circle is a line of curvature: τ_g = 0).
    let folds: Vec<_> = bent.rulings.iter().filter(|r| r.piece == Some(0)).collect();
    assert!(folds.len() > 20, "{}", folds.len());
    let radial = folds
        .iter()
        .map(|r| r.dir.perp_dot(r.point.normalize()).abs())
        .fold(0.0, f64::max);
    assert!(radial < 1e-9, "flat rulings off the radius by {radial}");
    // In space every ruling runs through one point (the folded sheet is a pyramid over the
    // disc's centre), and that point is the cone's apex, on the side the normal rule picks.
    // The common point: where the last ruling comes closest to the first one.
    let (first, last) = (folds[0], folds[folds.len() - 1]);
    let (v0, v1) = (
        bent.mesh.vertices[first.edges[0][0]],
        bent.mesh.vertices[last.edges[0][0]],
    );
    let n = first.dir_3d.cross(last.dir_3d);
    let t = (v1 - v0).cross(last.dir_3d).dot(n) / n.length_squared();
    let q = v0 + first.dir_3d * t;
    let apex = DVec3::new(0.0, 0.0, h_apex * q.z.signum());
    let mut through = 0.0f64;
    let mut worst_axis = 0.0f64;
    for r in &folds {
        let p = bent.mesh.vertices[r.edges[0][0]];
        through = through.max(line_point_distance(p, r.dir_3d, q));
        worst_axis = worst_axis.max(line_point_distance(p, r.dir_3d, apex));
    }
    eprintln!(
        "cone ρ {rho} H {h_apex} (R {big_r}): {} rulings, isometry {worst:.1e}, length {len_err:.1e}, drift {:.4} mm, rulings meet within {through:.1e} mm, pass the apex {apex} within {worst_axis:.4} mm",
        folds.len(),
        bent.drifts[0]
    );
    assert!(bent.drifts[0] <= tol, "{}", bent.drifts[0]);
    // (Flat rulings radial to 1e-9 rad over R = 100 mm: 1e-7 mm, and rounding in 30 folds.)
    assert!(through < 1e-6, "{through}");
    // The polyhedral cone's apex is the disc centre carried by the folds: its position inherits
    // the folded arc's error (≤ tol) magnified by R/H along the axis (a pyramid over a polygon
    // whose corners are off the circle by δ has its apex off by δ·R/H): 2·tol·R/H.
    assert!(worst_axis < 2.0 * tol * big_r / h_apex, "{worst_axis}");
    // The ruling ends lie on the cone: at distance ρ(1 − z/H) from the axis (apex side). (Not
    // the sheet beyond the end rulings: it stays planar, §3.4.)
    let mut worst_cone = 0.0f64;
    for r in &folds {
        for &i in r.edges.iter().flatten() {
            let v = bent.mesh.vertices[i];
            let z = v.z * apex.z.signum();
            worst_cone =
                worst_cone.max((DVec2::new(v.x, v.y).length() - rho * (1.0 - z / h_apex)).abs());
        }
    }
    eprintln!("ruling ends off the cone by {worst_cone:.4} mm");
    assert!(worst_cone < 2.0 * tol * big_r / h_apex, "{worst_cone}");
}

#[test]
fn bent_arc_control_curve_too_straight_exits_1_with_position() {
    let dir = scratch("bent-arc-short");
    // An arc of radius 50 on the sheet, a control curve that is nearly straight in its middle.
    let spec = write_spec(
        &dir,
        "short.toml",
        r#"
[[surface]]
kind = "bent-sheet"
name = "band"
outline = [[-80, 0], [80, 0], [80, 70], [-80, 70]]
arc = { center = [0, 0], radius = 50, start_deg = 30, end_deg = 150 }
control_points = [[0, 0, 0], [40, 0, 40], [80, 0, 0], [120, 0, 40]]
"#,
    );
    let o = flatcut(&["cut", &spec, "--dry-run", "-o", dir.to_str().unwrap()]);
    let err = stderr(&o);
    eprintln!("{err}");
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("short.toml:6"), "{err}");
    assert!(
        err.contains("bends less than the curve drawn on the sheet"),
        "{err}"
    );
    let s = arc_length_in(&err);
    // The S-shaped control curve is straight at its inflection, half way along.
    let len = 50.0 * 120f64.to_radians();
    assert!((s - 0.5 * len).abs() < 1.0, "{s} of {len}");
    assert!(err.contains("short by"), "{err}");
    assert!(!dir.join("band.plt").exists());
    // The library's figures: the shortfall is the flat curvature minus the curve's.
    let b = bent_spec(std::path::Path::new(&spec));
    match geodesic::bend(&b) {
        Err(GeodesicError::Curvature {
            s: s2,
            kappa,
            c,
            short,
            ..
        }) => {
            assert!((s2 - s).abs() < 0.01);
            assert!((c - 0.02).abs() < 1e-12, "{c}");
            assert!(kappa < 1e-3, "{kappa}");
            assert!(short > 0.0 && (short - (c - kappa)).abs() < 1e-12);
        }
        other => panic!("expected a curvature error, got {:?}", other.map(|_| ())),
    }
}

#[test]
fn bent_arc_band_pattern_and_flat_curve_spec() {
    let out = scratch("bent-arc-band");
    let o = flatcut(&[
        "cut",
        "patterns/bent-arc-band.toml",
        "--device",
        "hpgl-pens",
        "--dry-run",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The blank is the annulus sector: area (π/6)(180² − 120²), within 0.1 %.
    let plt = std::fs::read_to_string(out.join("bent-arc-band.plt")).unwrap();
    let cuts = cut_contours(&plt);
    assert_eq!(cuts.len(), 1);
    let (area, _) = area_perimeter(&cuts[0]);
    let want = geodesic_sector_area();
    eprintln!("arc band blank {area:.2} mm² vs {want:.2} mm²");
    assert!((area - want).abs() / want < 1e-3, "{area} vs {want}");
    let (spec, bent) = bent_of("patterns/bent-arc-band.toml");
    assert!(worst_edge_error(&bent) < 1e-9);
    let len = spec.pieces[0].path.length();
    assert!((bent.lengths[0] - len).abs() / len < 1e-6);
    assert!(bent.drifts[0] <= spec.tolerance, "{}", bent.drifts[0]);
    // Its control curve is a quintic Bézier within 0.03 % of the circle of radius 100, so the
    // band is nearly the cone with its apex 111.8 mm off the circle's plane: rulings nearly
    // radial on the sheet, their ends near the cone (the tolerance, magnified by R/H as in the
    // exact cone's test, plus what the Bézier's curvature error turns the rulings by).
    let h_apex = (150.0f64 * 150.0 - 100.0 * 100.0).sqrt();
    let folds: Vec<_> = bent.rulings.iter().filter(|r| r.piece == Some(0)).collect();
    let tilt = folds
        .iter()
        .map(|r| {
            r.dir
                .perp_dot(r.point.normalize())
                .abs()
                .asin()
                .to_degrees()
        })
        .fold(0.0, f64::max);
    let z_sign = folds
        .iter()
        .flat_map(|r| r.edges.iter().flatten())
        .map(|&i| bent.mesh.vertices[i])
        .map(|v| v.z * (v.x.hypot(v.y) - 100.0))
        .sum::<f64>()
        .signum();
    let mut off_cone = 0.0f64;
    for &i in folds.iter().flat_map(|r| r.edges.iter().flatten()) {
        let v = bent.mesh.vertices[i];
        let z = -v.z * z_sign;
        off_cone = off_cone.max((v.x.hypot(v.y) - 100.0 * (1.0 - z / h_apex)).abs());
    }
    eprintln!(
        "arc band: {} rulings, at most {tilt:.3}° off the radius, ends within {off_cone:.3} mm of the cone, drift {:.4} mm",
        folds.len(),
        bent.drifts[0]
    );
    assert!(tilt < 0.5, "{tilt}");
    assert!(
        off_cone < 2.0 * spec.tolerance * 150.0 / h_apex,
        "{off_cone}"
    );

    // A Bézier drawn on the sheet (`flat_curve`), gently curved, on a curve bent much more.
    let dir = scratch("bent-flat-curve");
    let path = write_spec(
        &dir,
        "s.toml",
        r#"
[[surface]]
kind = "bent-sheet"
outline = [160, 80]
flat_curve = [[0, 40], [50, 48], [110, 32], [160, 40]]
control_points = [[0, 0, 0], [40, 0, 40], [120, 0, 40], [160, 0, 0]]
tolerance = 0.05
"#,
    );
    let b = bent_spec(std::path::Path::new(&path));
    assert!(matches!(b.pieces[0].path, FlatPath::Curve(_)));
    let bent = geodesic::bend(&b).unwrap();
    let worst = worst_edge_error(&bent);
    let len = b.pieces[0].path.length();
    eprintln!(
        "flat Bézier: {} rulings, isometry {worst:.1e}, curve {:.6} for {len:.6} mm, drift {:.4} mm",
        bent.rulings.len(),
        bent.lengths[0],
        bent.drifts[0]
    );
    assert!(worst < 1e-9);
    assert!((bent.lengths[0] - len).abs() / len < 1e-6);
    assert!(bent.drifts[0] <= 0.05);
    // The normal turns against the curve here (c and κ vary: θ' ≠ 0); a finer tolerance must
    // bring the folded curve closer (it would not with a wrong geodesic torsion).
    let mut fine = b.clone();
    fine.tolerance = 0.002;
    let bent = geodesic::bend(&fine).unwrap();
    eprintln!(
        "flat Bézier at 0.002 mm: {} rulings, drift {:.5} mm",
        bent.rulings.len(),
        bent.drifts[0]
    );
    assert!(bent.drifts[0] <= 0.002, "{}", bent.drifts[0]);
    assert!(worst_edge_error(&bent) < 1e-9);
    let o = flatcut(&["cut", &path, "--dry-run", "-o", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
}

fn geodesic_sector_area() -> f64 {
    // The pattern's outline is the sector polygon with 30 chords per arc.
    let n = 30.0;
    let a = 60f64.to_radians() / n;
    0.5 * n * a.sin() * (180.0f64.powi(2) - 120.0f64.powi(2))
}

#[test]
fn bent_arc_on_a_helix_follows_it_as_the_tolerance_shrinks() {
    // A helix (κ = 0.0219/mm, τ = 0.0082/mm) carrying a flat arc of radius 100 mm: the normal
    // turns along the curve (θ' = 0 but τ_g = τ + θ' ≠ 0 and the rulings are oblique). The
    // folded arc must follow the helix to the tolerance at every tolerance: a wrong geodesic
    // torsion would leave an error that does not shrink with the step.
    let helix = Helix {
        r: 40.0,
        c: 15.0,
        turns: 0.5,
    };
    let len = ArcLength::new(&helix).total();
    let big_r = 100.0;
    let sweep = (len / big_r).to_degrees();
    for tol in [0.1, 0.01, 0.001] {
        let spec = BentSpec {
            outline: annulus_sector(80.0, 120.0, -5.0, sweep + 5.0),
            holes: vec![],
            pieces: vec![arc_piece(big_r, 0.0, sweep)],
            tolerance: tol,
            bend_lines: BendLines::All,
        };
        let bent = geodesic::bend_with(&spec, &[(&helix, None)]).unwrap();
        let oblique = bent
            .rulings
            .iter()
            .map(|r| r.dir.perp_dot(r.point.normalize()).abs())
            .fold(f64::INFINITY, f64::min);
        eprintln!(
            "helix on an arc at {tol} mm: {} rulings, drift {:.5} mm, isometry {:.1e}, rulings at least {:.1}° off the radius",
            bent.rulings.len(),
            bent.drifts[0],
            worst_edge_error(&bent),
            oblique.asin().to_degrees()
        );
        assert!(bent.drifts[0] <= tol, "{tol}: {}", bent.drifts[0]);
        assert!(worst_edge_error(&bent) < 1e-9);
        assert!((bent.lengths[0] - len).abs() / len < 1e-6);
        assert!(oblique > 0.1, "{oblique}");
    }
}
