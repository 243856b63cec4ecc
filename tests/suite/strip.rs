//! Issue 4 acceptance: Wang–Tang strips and the sheet-metal fittings built on them, end to end.
//! Blank figures are read from what the user gets (the HPGL of a dry run, the DXF read back
//! with the `dxf` crate), bad input gets exit 1 naming the flag or key.

use crate::common::*;
use flatcut::output::hpgl;
use flatcut::surface::strip::{Method, Strip};
use glam::DVec3;
use std::f64::consts::PI;

/// Area (mm²) and perimeter (mm) of the pen-1 (cut) contour of an HP-GL program at 40 units/mm.
fn cut_contour(plt: &str) -> (f64, f64) {
    let cut = hpgl_cut_contours(plt);
    assert_eq!(cut.len(), 1, "one cut contour");
    assert_eq!(cut[0].first(), cut[0].last(), "closed");
    area_and_length(&cut[0])
}

#[test]
fn strip_cone_blank_area_and_perimeter_from_hpgl() {
    let out = scratch("strip-cone");
    let o = flatcut(&[
        "fitting",
        "cone",
        "--bottom-diameter",
        "300",
        "--top-diameter",
        "160",
        "--height",
        "200",
        "--thickness",
        "0",
        "--device",
        "hpgl-pens",
        "--dry-run",
        "--bend-lines",
        "none",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let plt = std::fs::read_to_string(out.join("cone.plt")).unwrap();
    let (area, per) = cut_contour(&plt);
    let s = (70.0f64.powi(2) + 200.0f64.powi(2)).sqrt();
    let want_area = PI * (150.0 + 80.0) * s;
    let want_per = PI * (300.0 + 160.0) + 2.0 * s;
    let (ea, ep) = (
        (area - want_area).abs() / want_area,
        (per - want_per).abs() / want_per,
    );
    eprintln!(
        "cone blank: area {area:.1} mm² (exact {want_area:.1}, error {:.4} %), perimeter {per:.2} mm (exact {want_per:.2}, error {:.4} %)",
        100.0 * ea,
        100.0 * ep
    );
    assert!(ea < 0.003 && ep < 0.003);
    // --bend-lines none: nothing scored.
    assert!(hpgl::parse(&plt).unwrap().iter().all(|s| s.pen != 2));
    // report.json has the strip's figures: every ruling of a cone is locally convex.
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let figs = &report["surfaces"][0]["figures"];
    let interior = figs["interior_bridges"].as_f64().expect("interior_bridges");
    assert!(interior > 100.0, "{figs}");
    assert_eq!(
        figs["locally_convex_bridges"].as_f64(),
        Some(interior),
        "{figs}"
    );
    assert_eq!(
        interior,
        figs["points_p"].as_f64().unwrap() + figs["points_q"].as_f64().unwrap() - 3.0
    );
}

#[test]
fn strip_square_to_round_area_matches_classical_construction() {
    let spec = fitting_spec(&[
        "square-to-round",
        "--width",
        "400",
        "--depth",
        "300",
        "--diameter",
        "250",
        "--height",
        "300",
    ]);
    let (flats, pieces) = flatcut::pipeline::pieces(&spec, true).unwrap();
    assert_eq!(pieces.len(), 1);
    let blank = pieces[0].area;
    // Four flat triangles: each side with the circle's tangent point above its middle.
    let (w, d, r, h) = (400.0, 300.0, 125.0, 300.0);
    let tri = |side: f64, gap: f64| 0.5 * side * (h * h + gap * gap).sqrt();
    let mut classical = 2.0 * tri(w, 0.5 * d - r) + 2.0 * tri(d, 0.5 * w - r);
    // Four corner cones: apex at a corner, base a quarter of the circle.
    let apex = DVec3::new(0.5 * w, 0.5 * d, 0.0);
    let k = 200_000;
    let mut cone = 0.0;
    for i in 0..k {
        let phi = 0.5 * PI * (i as f64 + 0.5) / k as f64;
        let c = DVec3::new(r * phi.cos(), r * phi.sin(), h);
        let dc = DVec3::new(-r * phi.sin(), r * phi.cos(), 0.0);
        cone += 0.5 * (c - apex).cross(dc).length() * (0.5 * PI / k as f64);
    }
    classical += 4.0 * cone;
    let err = (blank - classical).abs() / classical;
    eprintln!(
        "square-to-round blank {blank:.0} mm², classical {classical:.0} mm², error {:.4} %",
        100.0 * err
    );
    assert!(err < 0.005);
    // The unfolding is exact: every 2D edge has its 3D length.
    check_isometric(&flats[0]);
}

fn check_isometric(flat: &flatcut::flatten::Flat) {
    let mesh = &flat.surface.mesh;
    for (f, face) in mesh.faces.iter().enumerate() {
        let n = face.verts.len();
        for i in 0..n {
            let l3 = mesh.vertices[face.verts[i]].distance(mesh.vertices[face.verts[(i + 1) % n]]);
            let l2 = flat.face_2d[f][i].distance(flat.face_2d[f][(i + 1) % n]);
            assert!(
                (l3 - l2).abs() <= 1e-9 * l3,
                "face {f} edge {i}: 3D {l3} 2D {l2}"
            );
        }
    }
}

#[test]
fn strip_fittings_flatten_isometrically_into_one_piece() {
    for args in [
        &[
            "cone",
            "--bottom-diameter",
            "300",
            "--top-diameter",
            "160",
            "--height",
            "200",
            "--offset",
            "60",
            "--thickness",
            "2",
        ][..],
        &[
            "rect-to-rect",
            "--width",
            "400",
            "--depth",
            "300",
            "--top-width",
            "200",
            "--top-depth",
            "100",
            "--height",
            "250",
            "--offset-x",
            "50",
        ],
        &[
            "pipe-miter",
            "--diameter",
            "150",
            "--length",
            "200",
            "--angle",
            "45",
        ],
        &[
            "lampshade",
            "--bottom-diameter",
            "300",
            "--bottom-depth",
            "200",
            "--top-diameter",
            "160",
            "--height",
            "180",
            "--material",
            "paper",
        ],
    ] {
        let spec = fitting_spec(args);
        let (flats, pieces) = flatcut::pipeline::pieces(&spec, true).unwrap();
        assert_eq!(pieces.len(), 1, "{}", args[0]);
        let m = &flats[0].surface.mesh;
        let bridges = m.faces.len() + 1;
        assert_eq!(m.vertices.len(), bridges + 1, "m + n − 2 triangles");
        check_isometric(&flats[0]);
        assert!(!pieces[0].folds.is_empty(), "{}: bend lines", args[0]);
        // Exact areas where the surface is known: four planar trapezoids; a cylinder cut by a
        // plane through its centre line at 200 mm has the area of a 200 mm cylinder.
        let exact = match args[0] {
            "rect-to-rect" => {
                let h = |dx: f64| (dx * dx + 250.0f64 * 250.0).sqrt();
                Some((
                    2.0 * 300.0 * h(100.0) + 200.0 * h(50.0) + 200.0 * h(150.0),
                    1e-9,
                ))
            }
            "pipe-miter" => Some((PI * 150.0 * 200.0, 1e-3)),
            _ => None,
        };
        if let Some((want, tol)) = exact {
            let got = pieces[0].area;
            assert!(
                (got - want).abs() / want < tol,
                "{}: area {got} want {want}",
                args[0]
            );
        }
    }
}

#[test]
fn strip_random_strips_flatten_to_1e_9() {
    let mut seed = 12345u64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..5 {
        let mk = |k: usize, y: f64, rnd: &mut dyn FnMut() -> f64| -> Vec<DVec3> {
            let mut x = 0.0;
            (0..k)
                .map(|_| {
                    x += 2.0 + 3.0 * rnd();
                    DVec3::new(x, y + 2.0 * rnd(), 5.0 * rnd())
                })
                .collect()
        };
        let p = mk(40, 0.0, &mut rnd);
        let q = mk(55, 30.0, &mut rnd);
        let s = Strip::raw(p, q);
        for method in [Method::GodtGmbt, Method::Gmat, Method::Local] {
            let steps = s.triangulate(method);
            let surface = flatcut::surface::Surface {
                name: "r".into(),
                source: "r".into(),
                mesh: s.mesh(&steps),
                warnings: vec![],
                bends: Some(s.bends(&steps, Default::default())),
                charts: None,
                ..Default::default()
            };
            assert_eq!(surface.mesh.faces.len(), 40 + 55 - 2);
            let flat =
                flatcut::flatten::unfold(surface, &flatcut::flatten::UnfoldOptions::default())
                    .unwrap();
            check_isometric(&flat);
        }
    }
}

/// A strip like the paper's Example II (a lace on a dress): two wavy 3D curves along half a
/// hem, 113 points each, so 225 bridges.
fn lace() -> Strip {
    let m = 113;
    let curve = |r0: f64, z0: f64, a: f64, f: f64, ph: f64, za: f64| -> Vec<DVec3> {
        (0..m)
            .map(|k| {
                let u = PI * k as f64 / (m - 1) as f64;
                let r = r0 + a * (f * u + ph).sin();
                DVec3::new(r * u.cos(), r * u.sin(), z0 + za * (1.3 * f * u).sin())
            })
            .collect()
    };
    Strip::raw(
        curve(150.0, 0.0, 6.0, 9.0, 0.0, 4.0),
        curve(170.0, 30.0, 8.0, 7.0, 1.0, 6.0),
    )
}

#[test]
fn strip_example_ii_lace_global_vs_local() {
    let s = lace();
    let g = s.metrics(&s.triangulate(Method::GodtGmbt));
    let l = s.metrics(&s.triangulate(Method::Local));
    let gm = s.metrics(&s.triangulate(Method::Gmbt));
    let total = s.m() + s.n() - 1;
    eprintln!(
        "Example II-like lace: {total} bridges; GODT+GMBT {} valid, LODT+LMBT {} valid (paper: 149 vs 113 of 225); energy GODT+GMBT {:.4}, LODT+LMBT {:.4}, GMBT {:.4}",
        g.convex, l.convex, g.energy, l.energy, gm.energy
    );
    assert_eq!(total, 225);
    assert!(g.convex >= l.convex);
    assert!(gm.energy <= l.energy);
}

#[test]
fn strip_dxf_reads_back_with_outline_on_cut_and_bends_on_bend_layers() {
    let out = scratch("strip-dxf");
    let o = flatcut(&[
        "fitting",
        "cone",
        "--bottom-diameter",
        "300",
        "--top-diameter",
        "160",
        "--height",
        "200",
        "--thickness",
        "1.5",
        "--bend-lines",
        "30",
        "--dry-run",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(out.join("cone.dxf")).unwrap();
    assert!(text.contains("AC1015"));
    let drawing = dxf::Drawing::load_file(out.join("cone.dxf")).expect("dxf crate reads it");
    let (mut cut, mut down, mut up, mut texts) = (Vec::new(), 0, 0, 0);
    let (mut lines, mut at) = (Vec::new(), Vec::new());
    for e in drawing.entities() {
        match (&e.specific, e.common.layer.as_str()) {
            (dxf::entities::EntityType::LwPolyline(p), "CUT") => cut.push(p.clone()),
            (dxf::entities::EntityType::Line(l), "BEND_DOWN") => {
                down += 1;
                lines.push((
                    glam::DVec2::new(l.p1.x, l.p1.y),
                    glam::DVec2::new(l.p2.x, l.p2.y),
                ));
            }
            (dxf::entities::EntityType::Line(_), "BEND_UP") => up += 1,
            (dxf::entities::EntityType::Text(t), "TEXT") => {
                texts += 1;
                at.push(glam::DVec2::new(t.location.x, t.location.y));
            }
            _ => {}
        }
    }
    // Each angle text starts beside its bend line, where the note is, not on it.
    for q in &at {
        let d = lines
            .iter()
            .map(|(a, b)| flatcut::geom::polygon::segment_distance(*q, *a, *b))
            .fold(f64::INFINITY, f64::min);
        assert!(d > 0.5, "angle text at {q}, {d:.3} mm from a bend line");
    }
    assert_eq!(cut.len(), 1);
    assert!(cut[0].is_closed());
    let v = &cut[0].vertices;
    let mut area = 0.0;
    for i in 0..v.len() {
        let (a, b) = (&v[i], &v[(i + 1) % v.len()]);
        area += a.x * b.y - b.x * a.y;
    }
    // Neutral surface: radii 0.9·slant/height mm smaller than the outside.
    let s = (70.0f64.powi(2) + 200.0f64.powi(2)).sqrt();
    let shift = 0.9 * s / 200.0;
    let want = PI * (150.0 - shift + 80.0 - shift) * s;
    assert!(
        (0.5 * area.abs() - want).abs() / want < 0.003,
        "{} {want}",
        0.5 * area.abs()
    );
    // A convex cone seen from its printed outside: every bend goes down; ~725 mm / 30 mm.
    assert_eq!(up, 0);
    assert!((20..=26).contains(&down), "{down} bend lines");
    assert_eq!(texts, down, "one angle text per bend");
}

fn assert_fails_naming(args: &[&str], what: &str) {
    let o = flatcut(args);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains(what), "{args:?}: {e}");
    assert_eq!(e.trim().lines().count(), 1, "one line: {e}");
}

#[test]
fn strip_bad_input_exits_1_naming_the_flag_or_key() {
    let out = scratch("strip-bad");
    let out = out.to_str().unwrap();
    let run = |bottom: &str, top: &str, t: &str, what: &str| {
        assert_fails_naming(
            &[
                "fitting",
                "cone",
                "--bottom-diameter",
                bottom,
                "--top-diameter",
                top,
                "--height",
                "200",
                "--thickness",
                t,
                "--dry-run",
                "-o",
                out,
            ],
            what,
        );
    };
    run("0", "160", "0", "--bottom-diameter");
    run("300", "-5", "0", "--top-diameter");
    run("300", "160", "90", "--thickness");
    assert_fails_naming(
        &[
            "fitting",
            "square-to-round",
            "--width",
            "400",
            "--depth",
            "300",
            "--height",
            "300",
        ],
        "--diameter",
    );

    let dir = scratch("strip-bad-spec");
    let write = |name: &str, body: &str| {
        let p = dir.join(name);
        std::fs::write(&p, body).unwrap();
        p.to_string_lossy().into_owned()
    };
    let one_point = write(
        "one.toml",
        "[[surface]]\nkind = \"strip\"\np = [[0, 0, 0]]\nq = [[0, 50, 0], [100, 50, 0]]\n",
    );
    assert_fails_naming(
        &["cut", &one_point, "--dry-run"],
        "one.toml:3: `surface[1].p`",
    );
    let same = write(
        "same.toml",
        "[[surface]]\nkind = \"strip\"\np = { kind = \"circle\", radius = 50 }\nq = { kind = \"circle\", radius = 50 }\n",
    );
    assert_fails_naming(&["cut", &same, "--dry-run"], "same.toml:4: `surface[1].q`");
    let zero = write(
        "zero.toml",
        "[[surface]]\nkind = \"strip\"\np = { kind = \"circle\", diameter = 0 }\nq = { kind = \"circle\", radius = 50, center = [0, 0, 10] }\n",
    );
    assert_fails_naming(&["cut", &zero, "--dry-run"], "`surface[1].p.radius`");
}

#[test]
fn strip_spec_curves_of_every_kind_build_and_flatten() {
    let dir = scratch("strip-spec-kinds");
    std::fs::write(
        dir.join("edge.csv"),
        "x,y,z\n0,0,0\n100,0,10\n200,0,0\n300,0,-10\n",
    )
    .unwrap();
    let spec_text = r#"
name = "kinds"

[[surface]]
kind = "strip"
name = "wave"
p = { kind = "csv", path = "edge.csv" }
q = { kind = "bezier", control = [[0, 60, 0], [150, 80, 40], [300, 60, 0]] }
method = "godt"
tolerance = 0.1

[[surface]]
kind = "strip"
name = "spline"
p = [[0, 0, 0], [100, 0, 0], [200, 20, 0]]
q = { kind = "bspline", control = [[0, 50, 10], [100, 60, 30], [200, 80, 10], [250, 90, 0]] }
bend_lines = "none"

[[surface]]
kind = "strip"
name = "oval"
p = { kind = "ellipse", center = [0, 0, 0], rx = 120, ry = 80 }
q = { kind = "rect", center = [0, 0, 100], width = 120, height = 80, corner_radius = 20 }
method = "gmat"

[sheet]
width = 1000
height = 1000
"#;
    let path = dir.join("kinds.toml");
    std::fs::write(&path, spec_text).unwrap();
    let spec = flatcut::spec::load(&path).unwrap();
    assert_eq!(spec.surfaces.len(), 3);
    let (flats, pieces) = flatcut::pipeline::pieces(&spec, true).unwrap();
    assert!(pieces.len() >= 3);
    for f in &flats {
        check_isometric(f);
    }
    // "none": no folds on the second surface's pieces.
    assert!(pieces
        .iter()
        .filter(|p| p.surface == "spline")
        .all(|p| p.folds.is_empty()));
    // The same spec twice gives the same meshes (determinism).
    let (again, _) = flatcut::pipeline::pieces(&spec, true).unwrap();
    for (a, b) in flats.iter().zip(&again) {
        assert_eq!(a.surface.mesh, b.surface.mesh);
    }
}

#[test]
fn strip_spec_metal_cone_is_developed_on_the_neutral_surface_of_its_side() {
    let dir = scratch("strip-spec-metal");
    // A frustum Ø300 → Ø160, 200 high, 2 mm metal, K = 0.4 unless the spec says otherwise.
    let spec = |material: &str, extra: &str| {
        format!(
            r#"
name = "metal-cone"

[[surface]]
kind = "strip"
p = {{ kind = "circle", center = [0, 0, 0], diameter = 300 }}
q = {{ kind = "circle", center = [0, 0, 200], diameter = 160 }}
bend_lines = "none"
{extra}

[material]
kind = "{material}"
thickness = 2

[sheet]
width = 1500
height = 1000
"#
        )
    };
    let area = |name: &str, text: &str| -> f64 {
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        let out = dir.join(name);
        let o = flatcut(&[
            "cut",
            path.to_str().unwrap(),
            "--device",
            "hpgl-pens",
            "--dry-run",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let plt = std::fs::read_to_string(out.join("metal-cone.plt")).unwrap();
        cut_contour(&plt).0
    };
    let s = (70.0f64.powi(2) + 200.0f64.powi(2)).sqrt();
    // The neutral surface lies δ along the normal from the given one; the end circles stay in
    // their planes, so both radii change by δ·s/h and the slant height stays s.
    let exact = |delta: f64| {
        let dr = delta * s / 200.0;
        PI * (150.0 - dr + 80.0 - dr) * s
    };
    for (name, material, extra, delta) in [
        ("outside", "metal", "", 0.6 * 2.0),
        ("inside", "metal", "side = \"inside\"", -0.4 * 2.0),
        (
            "k-half",
            "metal",
            "side = \"outside\"\nk_factor = 0.5",
            0.5 * 2.0,
        ),
        ("neutral", "metal", "side = \"neutral\"", 0.0),
        ("paper", "paper", "side = \"outside\"", 0.0),
    ] {
        let got = area(name, &spec(material, extra));
        let want = exact(delta);
        let err = (got - want).abs() / want;
        eprintln!(
            "{name}: blank {got:.1} mm², neutral surface {want:.1} mm² ({:.4} %)",
            100.0 * err
        );
        assert!(err < 0.002, "{name}: {got} vs {want}");
    }
    // The outside and inside blanks differ by far more than the tolerance: the shift is real.
    assert!(exact(1.2) < exact(0.0) * 0.99);
    // A K factor outside 0..1 is refused naming the key.
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, spec("metal", "k_factor = 1.5")).unwrap();
    let o = flatcut(&["cut", bad.to_str().unwrap(), "--dry-run"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("surface[1].k_factor"), "{}", stderr(&o));
}
