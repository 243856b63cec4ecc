//! Issue 24 acceptance through the command line: `kind = "spline"` specs with exact answers
//! (a cylinder, a cone in both forms, a fold by reflection), a loft that is not developable as
//! given, and bad input exiting 1 with `FILE:LINE` and the key. Blank figures are read from
//! what the user gets (the cut contour of the HP-GL of a dry run, report.json); the 3D figures
//! they are compared with are computed here by quadrature on the spec's own curves.

use crate::common::*;
use flatcut::geom::bspline::BSpline;
use glam::DVec3;
use std::path::{Path, PathBuf};

/// A TOML list of curves.
fn toml_curves(curves: &[Vec<DVec3>]) -> String {
    let curve = |c: &Vec<DVec3>| {
        let pts: Vec<String> = c
            .iter()
            .map(|p| format!("[{:.12}, {:.12}, {:.12}]", p.x, p.y, p.z))
            .collect();
        format!("  [{}],\n", pts.join(", "))
    };
    format!("[\n{}]", curves.iter().map(curve).collect::<String>())
}

/// A spline spec with `curves` and `extra` surface keys, on a 1200 × 1200 mm sheet.
fn spline_spec(dir: &Path, curves: &[Vec<DVec3>], extra: &str) -> PathBuf {
    let text = format!(
        "name = \"spline\"\n[[surface]]\nkind = \"spline\"\ncurves = {}\n{extra}\n[sheet]\nwidth = 1200\nheight = 1200\n",
        toml_curves(curves)
    );
    let path = dir.join("spline.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// Run a dry run on the pen plotter profile; returns the output folder's report.json.
fn cut(dir: &Path, spec: &Path, extra: &[&str]) -> serde_json::Value {
    let out = dir.join("out");
    let mut args = vec![
        "cut",
        spec.to_str().unwrap(),
        "--device",
        "hpgl-pens",
        "--dry-run",
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = flatcut(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    read_json(&out.join("report.json"))
}

/// Area (mm²) and perimeter (mm) of each pen-1 (cut) contour of the run's HP-GL (40 units/mm).
fn cut_contours(dir: &Path) -> Vec<(f64, f64)> {
    let plt = std::fs::read_to_string(dir.join("out/spline.plt")).unwrap();
    hpgl_cut_contours(&plt)
        .iter()
        .map(|c| area_and_length(c))
        .collect()
}

/// A JSON file read.
fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The control points of every curve of the first surface of a `--spline-json` document.
fn design_curves(d: &serde_json::Value) -> Vec<Vec<DVec3>> {
    let num = |v: &serde_json::Value| v.as_f64().unwrap();
    d["surfaces"][0]["curves"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            c.as_array()
                .unwrap()
                .iter()
                .map(|p| DVec3::new(num(&p[0]), num(&p[1]), num(&p[2])))
                .collect()
        })
        .collect()
}

fn figure(report: &serde_json::Value, k: &str) -> f64 {
    report["surfaces"][0]["figures"][k]
        .as_f64()
        .unwrap_or_else(|| panic!("no figure {k}: {}", report["surfaces"][0]))
}

/// Length of a curve by the midpoint rule.
fn length(basis: &BSpline, c: &[DVec3]) -> f64 {
    let per = 4000;
    (0..basis.spans() * per)
        .map(|k| basis.deriv(c, (k as f64 + 0.5) / per as f64).length() / per as f64)
        .sum()
}

/// Area of the ruled surface (1 − v) a + v b (b the apex when `apex`) by the midpoint rule.
fn ruled_area(basis: &BSpline, a: &[DVec3], b: Option<&[DVec3]>, apex: DVec3) -> f64 {
    let per = 2000;
    let mut area = 0.0;
    for k in 0..basis.spans() * per {
        let u = (k as f64 + 0.5) / per as f64;
        let (pa, ta) = (basis.eval(a, u), basis.deriv(a, u));
        let (pb, tb) = match b {
            Some(b) => (basis.eval(b, u), basis.deriv(b, u)),
            None => (apex, DVec3::ZERO),
        };
        for j in 0..20 {
            let v = (j as f64 + 0.5) / 20.0;
            area += (ta * (1.0 - v) + tb * v).cross(pb - pa).length() / (per as f64 * 20.0);
        }
    }
    area
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn spline_cylinder_blank_is_length_by_150() {
    let dir = scratch("spline-cylinder");
    let a: Vec<DVec3> = (0..8)
        .map(|i| DVec3::new(i as f64 * 60.0, 40.0 * (i as f64 * 1.3).sin(), 0.0))
        .collect();
    let b: Vec<DVec3> = a.iter().map(|p| *p + 150.0 * DVec3::Z).collect();
    let spec = spline_spec(&dir, &[a.clone(), b.clone()], "");
    let report = cut(&dir, &spec, &[]);
    assert!(figure(&report, "control_points_moved_mm") <= 1e-9);
    assert_eq!(figure(&report, "iterations"), 0.0);
    // The developability sine at 200 parameters per span, on the solved design as built.
    let s = flatcut::spec::load(&spec).unwrap();
    let surface = flatcut::surface::build(&s.surfaces[0]).unwrap();
    let model = &surface.spline.as_ref().unwrap().model;
    // The spec holds the points to 12 decimals; the solve leaves them where they are.
    for (c, given) in model.curves.iter().zip([&a, &b]) {
        for (p, q) in c.iter().zip(given) {
            assert!(p.distance(*q) <= 1e-9, "{p} moved from {q}");
        }
    }
    let sine = flatcut::surface::spline::dense_sine(model, 200);
    assert!(sine <= 1e-12, "sine {sine}");
    let l = length(&model.basis, &a);
    let contours = cut_contours(&dir);
    assert_eq!(contours.len(), 1, "one piece");
    let (area, per) = contours[0];
    eprintln!(
        "cylinder blank: {area:.1} mm² vs {:.1}, perimeter {per:.2} vs {:.2}",
        l * 150.0,
        2.0 * l + 300.0
    );
    assert!(rel(area, l * 150.0) < 1e-3);
    assert!(rel(per, 2.0 * l + 300.0) < 1e-3);
}

fn circle(r: f64, z: f64, phase: f64) -> Vec<DVec3> {
    (0..8)
        .map(|i| {
            let t = phase + i as f64 * std::f64::consts::TAU / 8.0;
            DVec3::new(r * t.cos(), r * t.sin(), z + 15.0 * (2.0 * t).sin())
        })
        .collect()
}

#[test]
fn spline_cone_blanks_have_the_area_of_the_cone() {
    let a = circle(100.0, 0.0, 0.1);
    let p = DVec3::new(10.0, -5.0, 200.0);
    let b: Vec<DVec3> = a.iter().map(|x| p + 0.4 * (*x - p)).collect();
    let basis = BSpline::new(3, 8, true).unwrap();
    let apex = format!("apex = [{}, {}, {}]\nclosed = true", p.x, p.y, p.z);
    for (name, curves, extra, want) in [
        (
            "frustum",
            vec![a.clone(), b.clone()],
            "closed = true".to_string(),
            ruled_area(&basis, &a, Some(&b), p),
        ),
        (
            "apex",
            vec![a.clone()],
            apex,
            ruled_area(&basis, &a, None, p),
        ),
    ] {
        let dir = scratch(&format!("spline-cone-{name}"));
        let spec = spline_spec(&dir, &curves, &extra);
        let report = cut(&dir, &spec, &["--bend-lines", "none", "--tabs", "none"]);
        assert!(figure(&report, "control_points_moved_mm") <= 1e-9, "{name}");
        let contours = cut_contours(&dir);
        assert_eq!(contours.len(), 1, "{name}: one piece");
        let area = contours[0].0;
        eprintln!("cone ({name}) blank: {area:.1} mm² vs {want:.1} by quadrature");
        assert!(rel(area, want) < 1e-3, "{name}: {area} vs {want}");
        // Opened at one seam ruling, which is a seam of the piece with itself and a tab.
        let seams = report["seams"].as_array().unwrap();
        assert_eq!(seams.len(), 1, "{name}: {seams:?}");
        let s = &seams[0];
        assert_eq!(
            (s["piece_a"].as_u64(), s["piece_b"].as_u64()),
            (Some(1), Some(1))
        );
        let (la, lb) = (
            s["length_a_mm"].as_f64().unwrap(),
            s["length_b_mm"].as_f64().unwrap(),
        );
        assert!((la - lb).abs() < 1e-6 && la > 100.0, "{name}: {la} vs {lb}");
    }
}

/// Issue 24's fold by reflection (see the library's tests): bottom rim, crease on the plane
/// z = 100 + 2y, mirrored top rim.
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

#[test]
fn spline_fold_by_reflection_gives_one_piece_with_the_crease_length() {
    let dir = scratch("spline-fold");
    let curves = reflected_fold();
    let spec = spline_spec(&dir, &curves, "creases = [\"fold\"]");
    let json = dir.join("design/fold.json");
    let report = cut(
        &dir,
        &spec,
        &[
            "--bend-lines",
            "none",
            "--spline-json",
            json.to_str().unwrap(),
        ],
    );
    assert!(figure(&report, "control_points_moved_mm") <= 1e-9);
    assert!(figure(&report, "crease_angle_defect") <= 1e-9);
    assert!(figure(&report, "crease_sine") <= 1e-9);
    let pieces = report["pieces"].as_array().unwrap();
    assert_eq!(pieces.len(), 1, "one piece");
    // With no ruling scored, every fold line is on the crease.
    let folds = pieces[0]["fold_lines"].as_array().unwrap();
    let flat: f64 = folds.iter().map(|f| f["length_mm"].as_f64().unwrap()).sum();
    let kinds: std::collections::BTreeSet<&str> =
        folds.iter().map(|f| f["kind"].as_str().unwrap()).collect();
    let basis = BSpline::new(3, 8, false).unwrap();
    let crease = length(&basis, &curves[1]);
    eprintln!(
        "fold: flat crease {flat:.3} mm vs 3D {crease:.3} mm in {} segments, {kinds:?}",
        folds.len()
    );
    assert!(rel(flat, crease) < 1e-3, "{flat} vs {crease}");
    assert_eq!(kinds.len(), 1, "the crease folds one way: {kinds:?}");
    assert!(folds
        .iter()
        .all(|f| f["angle_deg"].as_f64().unwrap() > 10.0));
    // The design as JSON: the curves as solved (here as given), the crease, and the crease
    // on the flat piece with its 3D length.
    let d = read_json(&json);
    let s = &d["surfaces"][0];
    assert_eq!(s["degree"], 3);
    assert_eq!(s["knots"].as_array().unwrap().len(), 8 + 3 + 1);
    assert_eq!(s["creases"][0]["condition"], "fold");
    assert_eq!(s["strips"], serde_json::json!([[1, 2], [2, 3]]));
    let solved = design_curves(&d);
    for (c, curve) in curves.iter().enumerate() {
        for (k, p) in curve.iter().enumerate() {
            let q = solved[c][k];
            assert!(
                p.distance(q) < 1e-8,
                "curve {} point {}: {q} vs {p}",
                c + 1,
                k + 1
            );
        }
    }
    let dev = s["development"]["curves"].as_array().unwrap();
    let on2: Vec<&serde_json::Value> = dev.iter().filter(|c| c["curve"] == 2).collect();
    assert_eq!(on2.len(), 1, "the crease lies on one piece");
    let pts = on2[0]["points"].as_array().unwrap();
    let flat_len: f64 = pts
        .windows(2)
        .map(|w| {
            let (a, b) = (&w[0], &w[1]);
            let dx = a[0].as_f64().unwrap() - b[0].as_f64().unwrap();
            let dy = a[1].as_f64().unwrap() - b[1].as_f64().unwrap();
            dx.hypot(dy)
        })
        .sum();
    assert!(rel(flat_len, crease) < 1e-3, "{flat_len} vs {crease}");
    // Asked of a spec without a spline surface, the flag is refused before anything is cut.
    let o = flatcut(&[
        "cut",
        "patterns/cube.toml",
        "--dry-run",
        "-o",
        dir.join("cube").to_str().unwrap(),
        "--spline-json",
        dir.join("cube.json").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--spline-json"), "{}", stderr(&o));
    assert!(!dir.join("cube/report.json").exists());
}

#[test]
fn spline_loft_between_rims_that_are_not_developable_is_solved() {
    let dir = scratch("spline-loft");
    let a: Vec<DVec3> = (0..8)
        .map(|i| {
            let t = i as f64 * std::f64::consts::TAU / 8.0;
            DVec3::new(100.0 * t.cos(), 100.0 * t.sin(), 0.0)
        })
        .collect();
    let b: Vec<DVec3> = (0..8)
        .map(|i| {
            let t = 0.45 + i as f64 * std::f64::consts::TAU / 8.0;
            DVec3::new(60.0 * t.cos(), 60.0 * t.sin(), 120.0)
        })
        .collect();
    let basis = BSpline::new(3, 8, true).unwrap();
    let area0 = ruled_area(&basis, &a, Some(&b), DVec3::ZERO);
    let spec = spline_spec(&dir, &[a, b], "closed = true");
    let report = cut(&dir, &spec, &["--bend-lines", "none"]);
    let sine = figure(&report, "largest_sine");
    let moved = figure(&report, "control_points_moved_mm");
    let area: f64 = report["pieces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["area_mm2"].as_f64().unwrap())
        .sum();
    eprintln!(
        "loft: sine {sine:.2e} after {} iterations, control points moved {moved:.2} mm, area {area:.0} of {area0:.0} mm²",
        figure(&report, "iterations")
    );
    assert!(sine <= 1e-6);
    assert!(moved > 0.1, "the rims had to move");
    assert!(area >= 0.5 * area0);
    assert!(report["surfaces"][0]["warnings"]
        .as_array()
        .unwrap()
        .is_empty());
}

/// A spec from `body` (the surface's keys after `kind`) must exit 1 naming `FILE:LINE` and
/// `key`.
fn refused(body: &str, line: usize, key: &str) {
    let dir = scratch("spline-bad");
    let path = dir.join("bad.toml");
    let text = format!("[[surface]]\nkind = \"spline\"\n{body}\n");
    std::fs::write(&path, &text).unwrap();
    let o = flatcut(&[
        "cut",
        path.to_str().unwrap(),
        "--dry-run",
        "-o",
        dir.join("out").to_str().unwrap(),
    ]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{text}\n{e}");
    let at = format!("{}:{line}", path.display());
    assert!(
        e.contains(&at) && e.contains(&format!("`{key}`")),
        "{text}\nwant {at} and `{key}`, got: {e}"
    );
    assert!(!e.contains("panicked"), "{e}");
    assert!(!dir.join("out/report.json").exists());
}

#[test]
fn spline_bad_input_exits_1_with_file_line_and_key() {
    let line4 = "[[0, 0, 0], [50, 10, 0], [100, 0, 0], [150, 10, 0]]";
    let line3 = "[[0, 0, 100], [50, 10, 100], [100, 0, 100]]";
    let up = |z: f64| format!("[[0, 0, {z}], [50, 10, {z}], [100, 0, {z}], [150, 10, {z}]]");
    let flat = |y: f64| format!("[[0, {y}, 0], [50, {y}, 0], [100, {y}, 0], [150, {y}, 0]]");
    let two = format!("curves = [\n  {line4},\n  {},\n]", up(100.0));
    let cases: Vec<(String, usize, &str)> = vec![
        ("degree = 3".into(), 1, "surface[1].curves"),
        (
            format!("curves = [\n  {line4},\n  {line3},\n]"),
            5,
            "surface[1].curves[2]",
        ),
        (format!("{two}\ndegree = 6"), 7, "surface[1].degree"),
        (format!("{two}\ndegree = 2.5"), 7, "surface[1].degree"),
        (
            format!("curves = [\n  {line4},\n  {},\n  {},\n]\ncreases = [\"fold\", \"fold\"]", up(100.0), up(200.0)),
            8,
            "surface[1].creases",
        ),
        (
            format!("curves = [\n  {},\n  {},\n  {},\n]\ncreases = [\"fold\"]", flat(0.0), flat(50.0), flat(100.0)),
            8,
            "surface[1].creases[1]",
        ),
        (
            format!("curves = [\n  {line4},\n  {},\n  {},\n]\ncreases = [\"crumple\"]", up(100.0), up(200.0)),
            8,
            "surface[1].creases[1]",
        ),
        (format!("{two}\nepsilon2 = 0"), 7, "surface[1].epsilon2"),
        (format!("{two}\nepsilon1 = -1"), 7, "surface[1].epsilon1"),
        (format!("{two}\nmax_iterations = 0"), 7, "surface[1].max_iterations"),
        (format!("{two}\ntolerance = nan"), 7, "surface[1].tolerance"),
        (format!("{two}\napex = [0, 0, 300]"), 7, "surface[1].apex"),
        (format!("{two}\nfixed = [[3, 1]]"), 7, "surface[1].fixed"),
        (format!("{two}\nfixed = [[1, 9]]"), 7, "surface[1].fixed"),
        (format!("{two}\nfixed = [\"apex\"]"), 7, "surface[1].fixed[1]"),
        (format!("{two}\npath = \"x.obj\""), 7, "surface[1].path"),
        (format!("{two}\nloop = [[0, 0], [1, 0], [0, 1]]"), 7, "surface[1].loop"),
        (
            format!("curves = [\n  [[0, 0, 0], [50, nan, 0], [100, 0, 0], [150, 10, 0]],\n  {},\n]", up(100.0)),
            4,
            "surface[1].curves[1][2]",
        ),
        ("curves = 3".into(), 3, "surface[1].curves"),
        (format!("{two}\nhandles = [{{ at = [0, 0, 0] }}]"), 7, "surface[1].handles[1].to"),
        (format!("{two}\nhandles = [{{ at = [0, 0, 0], to = [1, 2], by = 3 }}]"), 7, "surface[1].handles[1].by"),
        (format!("{two}\nhandles = 4"), 7, "surface[1].handles"),
        (format!("{two}\ntarget = \"missing.obj\""), 7, "surface[1].target"),
        (format!("{two}\ntarget = {{ path = \"x.csv\", scale = -1 }}"), 7, "surface[1].target.scale"),
        ("curves = [3, 4]".into(), 3, "surface[1].curves[1]"),
        // Stated folds: one per interior curve, on a crease that folds, a known kind and an
        // angle in (0, 180) degrees.
        (
            format!("curves = [\n  {line4},\n  {},\n  {},\n]\ncreases = [\"fold\"]\nfolds = [\"valley\", \"valley\"]", up(100.0), up(200.0)),
            9,
            "surface[1].folds",
        ),
        (
            format!("curves = [\n  {line4},\n  {},\n  {},\n]\ncreases = [\"smooth\"]\nfolds = [\"valley\"]", up(100.0), up(200.0)),
            9,
            "surface[1].folds[1]",
        ),
        (
            format!("curves = [\n  {line4},\n  {},\n  {},\n]\ncreases = [\"fold\"]\nfolds = [\"up\"]", up(100.0), up(200.0)),
            9,
            "surface[1].folds[1]",
        ),
        (
            format!("curves = [\n  {line4},\n  {},\n  {},\n]\ncreases = [\"fold\"]\nfolds = [{{ kind = \"valley\", angle_deg = 180 }}]", up(100.0), up(200.0)),
            9,
            "surface[1].folds[1]",
        ),
        (
            format!("curves = [\n  {line4},\n  {},\n  {},\n]\ncreases = [\"fold\"]\nfolds = [{{ kind = \"valley\", angle = 20 }}]", up(100.0), up(200.0)),
            9,
            "surface[1].folds[1]",
        ),
        (format!("{two}\nfolds = \"valley\""), 7, "surface[1].folds"),
        // Rulings that all cross the strip's middle: refused at the line of `curves`.
        (
            "curves = [\n  [[0, 0, 0], [25, 0, 0], [50, 0, 0], [75, 0, 0], [100, 0, 0]],\n  [[100, 50, 0], [75, 50, 0], [50, 50, 0], [25, 50, 0], [0, 50, 0]],\n]".into(),
            3,
            "curves",
        ),
    ];
    for (body, line, key) in cases {
        refused(&body, line, key);
    }
    // Spline keys on another kind are refused too.
    let dir = scratch("spline-bad-kind");
    let path = dir.join("strip.toml");
    std::fs::write(
        &path,
        "[[surface]]\nkind = \"strip\"\np = [[0, 0, 0], [100, 0, 0]]\nq = [[0, 0, 50], [100, 0, 50]]\ncreases = [\"fold\"]\n",
    )
    .unwrap();
    let o = flatcut(&["cut", path.to_str().unwrap(), "--dry-run"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains(":5: `surface[1].creases`"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn spline_lamp_pattern_is_one_sheet_folded_on_its_circle_with_a_glued_seam() {
    let dir = scratch("spline-lamp");
    let out = dir.join("out");
    let o = flatcut(&[
        "cut",
        "patterns/spline-fold-lamp.toml",
        "--dry-run",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = read_json(&out.join("report.json"));
    let pieces = report["pieces"].as_array().unwrap();
    assert_eq!(pieces.len(), 1);
    assert_eq!(pieces[0]["tabs"], 1, "a glue tab on the seam");
    assert!(figure(&report, "largest_sine") <= 1e-10);
    assert!(figure(&report, "crease_angle_defect") <= 1e-9);
    // The crease, a circle of radius 100 in 3D, is one fold of that length on the sheet.
    let folds = pieces[0]["fold_lines"].as_array().unwrap();
    let flat: f64 = folds.iter().map(|f| f["length_mm"].as_f64().unwrap()).sum();
    let s = flatcut::spec::load(&manifest("patterns/spline-fold-lamp.toml")).unwrap();
    let sp = s.surfaces[0].spline.as_ref().unwrap();
    let basis = BSpline::new(3, 8, true).unwrap();
    let crease = length(&basis, &sp.curves[1]);
    assert!(rel(flat, crease) < 1e-3, "{flat} vs {crease}");
    assert!(folds.iter().all(|f| f["kind"] == folds[0]["kind"]));
}

#[test]
fn spline_target_cylinder_is_fitted_from_its_principal_rectangle() {
    require_shared!();
    let dir = scratch("spline-target");
    let mesh = shared_data("meshes/cylinder.obj");
    let spec = dir.join("spline.toml");
    std::fs::write(
        &spec,
        format!(
            "name = \"spline\"\n[[surface]]\nkind = \"spline\"\ntarget = {{ path = {:?}, scale = 100 }}\nbend_lines = \"none\"\n[sheet]\nwidth = 1000\nheight = 1000\n",
            mesh.to_str().unwrap()
        ),
    )
    .unwrap();
    let json = dir.join("design.json");
    let report = cut(&dir, &spec, &["--spline-json", json.to_str().unwrap()]);
    let d = read_json(&json);
    let curves = design_curves(&d);
    assert_eq!(curves.len(), 2);
    let basis = BSpline::new(3, curves[0].len(), false).unwrap();
    // Rulings along the cylinder's axis (x).
    let mut worst: f64 = 0.0;
    for k in 0..=200 {
        let u = basis.spans() as f64 * k as f64 / 200.0;
        let e = basis.eval(&curves[1], u) - basis.eval(&curves[0], u);
        worst = worst.max(e.angle_between(DVec3::X * e.x.signum()).to_degrees());
    }
    // Distances of the target's vertices (mm) from the solved surface.
    let raw = flatcut::surface::import::read(&mesh).unwrap();
    let mut target_mesh = raw.mesh;
    target_mesh.vertices.iter_mut().for_each(|p| *p *= 100.0);
    let model = flatcut::surface::spline::Model {
        basis: basis.clone(),
        curves,
        apex: None,
        fixed: Vec::new(),
        creases: Vec::new(),
        folds: Vec::new(),
        target: Some(flatcut::surface::spline::target::Target::from_mesh(
            &target_mesh,
        )),
        handles: Vec::new(),
        outline: None,
    };
    let dist = flatcut::surface::spline::target_distances(&model);
    let within = dist.iter().filter(|&&x| x <= 0.3).count() as f64 / dist.len() as f64;
    let sine = flatcut::surface::spline::dense_sine(&model, 200);
    eprintln!(
        "target: rulings within {worst:.4}° of the axis, {:.1} % of {} vertices within 0.3 mm (RMS {:.3} mm, coverage {}), sine {sine:.2e} after {} iterations",
        100.0 * within,
        dist.len(),
        figure(&report, "approximation_rms_mm"),
        figure(&report, "coverage"),
        figure(&report, "iterations")
    );
    assert!(worst <= 0.5, "rulings {worst}° off the axis");
    assert!(within >= 0.9, "{within}");
    assert!(sine <= 1e-6, "{sine}");
    assert_eq!(report["pieces"].as_array().unwrap().len(), 1);
}

#[test]
fn spline_handle_drags_a_corner_and_the_fixed_edge_stays() {
    let dir = scratch("spline-handle");
    let a: Vec<DVec3> = (0..5)
        .map(|i| DVec3::new(50.0 * i as f64, 0.0, 0.0))
        .collect();
    let b: Vec<DVec3> = a.iter().map(|p| *p + 120.0 * DVec3::Y).collect();
    let spec = spline_spec(
        &dir,
        &[a.clone(), b],
        "fixed = [1]\nhandles = [{ at = [200, 120, 0], to = [190, 100, 50] }]",
    );
    let json = dir.join("design.json");
    let report = cut(&dir, &spec, &["--spline-json", json.to_str().unwrap()]);
    let d = read_json(&json);
    let curves = design_curves(&d);
    assert_eq!(curves[0], a, "the fixed edge stays");
    // The corner is the last control point of the clamped curve 2.
    let corner = *curves[1].last().unwrap();
    let goal = DVec3::new(190.0, 100.0, 50.0);
    eprintln!(
        "handle: corner at {corner} ({:.2e} mm from the goal) after {} iterations, sine {:.2e}",
        corner.distance(goal),
        figure(&report, "iterations"),
        figure(&report, "largest_sine")
    );
    assert!(corner.distance(goal) < 1e-6);
    assert!(figure(&report, "handle_distance_mm") < 1e-6);
    assert!(figure(&report, "largest_sine") <= 1e-6);
}

/// Control points (`n`, cubic, clamped) of the least-squares fit to `f(t)`, t in [0, 1] with
/// t = u / spans.
#[allow(clippy::needless_range_loop)] // rows and columns of one small matrix
fn fit_curve_n(n: usize, f: impl Fn(f64) -> DVec3) -> Vec<DVec3> {
    let basis = BSpline::new(3, n, false).unwrap();
    let mut a = vec![vec![0.0; n]; n];
    let mut b = vec![DVec3::ZERO; n];
    for k in 0..=400 {
        let t = k as f64 / 400.0;
        let r = basis.rows(t * basis.spans() as f64);
        let p = f(t);
        for &(i, wi) in &r.point {
            b[i] += p * wi;
            for &(j, wj) in &r.point {
                a[i][j] += wi * wj;
            }
        }
    }
    // Gaussian elimination (the matrix is positive definite).
    for c in 0..n {
        for r in c + 1..n {
            let f = a[r][c] / a[c][c];
            for k in c..n {
                a[r][k] -= f * a[c][k];
            }
            b[r] = b[r] - b[c] * f;
        }
    }
    let mut x = vec![DVec3::ZERO; n];
    for c in (0..n).rev() {
        let mut s = b[c];
        for k in c + 1..n {
            s -= x[k] * a[c][k];
        }
        x[c] = s / a[c][c];
    }
    x
}

/// The arc through (0, 120), (105, 150), (210, 120): centre (105, −48.75), radius 198.75.
fn a4_arc(t: f64) -> DVec3 {
    let (cy, r) = (-48.75, 198.75);
    let half = (105.0f64 / r).asin();
    let a = std::f64::consts::FRAC_PI_2 + half - 2.0 * half * t;
    DVec3::new(105.0 + r * a.cos(), cy + r * a.sin(), 0.0)
}

/// An A4 run (`curves` and `extra` keys, outline 210 × 297, a `fold` crease on curve 2 along
/// the arc) through the command line: its report, the blank's area and perimeter from the
/// cut contour, and how far the flat crease lies from the arc (mm).
fn a4_run(
    name: &str,
    curves: &[Vec<DVec3>],
    extra: &str,
) -> (serde_json::Value, serde_json::Value, f64, f64, f64) {
    let dir = scratch(name);
    let spec = spline_spec(
        &dir,
        curves,
        &format!("outline = [210, 297]\ncreases = [\"fold\"]\nbend_lines = \"none\"\n{extra}"),
    );
    let json = dir.join("design.json");
    let report = cut(
        &dir,
        &spec,
        &["--tabs", "none", "--spline-json", json.to_str().unwrap()],
    );
    let contours = cut_contours(&dir);
    assert_eq!(contours.len(), 1);
    let (area, per) = contours[0];
    // The crease on the flat piece, against the arc (distance to its circle).
    let d = read_json(&json);
    let dev = d["surfaces"][0]["development"]["curves"]
        .as_array()
        .unwrap();
    let flat: Vec<&serde_json::Value> = dev.iter().filter(|c| c["curve"] == 2).collect();
    assert_eq!(flat.len(), 1);
    let pts: Vec<(f64, f64)> = flat[0]["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect();
    // The piece lies in its own frame: place it by the crease's ends, (0, 120) and (210, 120).
    let (p0, p1) = (pts[0], pts[pts.len() - 1]);
    let (ux, uy) = ((p1.0 - p0.0) / 210.0, (p1.1 - p0.1) / 210.0);
    let off = pts
        .iter()
        .map(|&(x, y)| {
            let (dx, dy) = (x - p0.0, y - p0.1);
            let (sx, sy) = (dx * ux + dy * uy, -dx * uy + dy * ux);
            let (ax, ay) = (sx, 120.0 + sy);
            (((ax - 105.0).powi(2) + (ay + 48.75).powi(2)).sqrt() - 198.75).abs()
        })
        .fold(0.0, f64::max);
    eprintln!(
        "{name}: blank {area:.1} mm² (62370), perimeter {per:.2} mm (1014), development error {:.2e}, handles {:.2e} mm from their goal, flat crease within {off:.4} mm of the arc, sine {:.2e}, crease sine {:.2e}, fold mean {:.3}° max {:.3}°, {} iterations",
        figure(&report, "outline_isometry_error"),
        figure(&report, "handle_distance_mm"),
        figure(&report, "largest_sine"),
        figure(&report, "crease_sine"),
        figure(&report, "fold_angle_mean_deg"),
        figure(&report, "fold_angle_max_deg"),
        figure(&report, "iterations"),
    );
    assert!(rel(area, 62370.0) < 1e-3, "{area}");
    assert!(rel(per, 1014.0) < 1e-3, "{per}");
    assert!(off < 0.1, "{off}");
    assert!(figure(&report, "outline_isometry_error") < 1e-6);
    assert!(figure(&report, "handle_distance_mm") < 0.01);
    assert!(figure(&report, "largest_sine") <= 1e-6);
    assert!(figure(&report, "crease_sine") <= 1e-6);
    (report, d, area, per, off)
}

/// The crease along the arc and the lines y = 0 and y = 297, each of `n` control points.
fn a4_curves(n: usize) -> [Vec<DVec3>; 3] {
    let mut crease = fit_curve_n(n, a4_arc);
    crease[0] = DVec3::new(0.0, 120.0, 0.0);
    crease[n - 1] = DVec3::new(210.0, 120.0, 0.0);
    let line = |y: f64| fit_curve_n(n, move |t| DVec3::new(210.0 * t, y, 0.0));
    [line(0.0), crease, line(297.0)]
}

const A4_LIFT: &str =
    "handles = [{ at = [0, 297, 0], lift = 80 }, { at = [210, 297, 0], lift = 80 }";

#[test]
fn spline_a4_with_a_crease_lifted_by_handles_stays_the_a4_sheet() {
    // The bottom edge fixed as a straight line: every ruling of the lower strip ends on it,
    // so that strip stays planar, and a curved crease beside a plane cannot fold.
    a4_run(
        "spline-a4",
        &a4_curves(8),
        &format!("fixed = [1]\n{A4_LIFT}]"),
    );
}

#[test]
fn spline_a4_folds_along_its_arc_by_the_stated_angle() {
    // The bottom edge's middle pinned, the top corners lifted, the crease folded by 20° on
    // average as a valley, then as a mountain.
    for (kind, other) in [("valley", "mountain"), ("mountain", "valley")] {
        let (report, design, ..) = a4_run(
            &format!("spline-a4-{kind}"),
            &a4_curves(8),
            &format!("folds = [{{ kind = \"{kind}\", angle_deg = 20 }}]\nmax_iterations = 200\n{A4_LIFT}, {{ at = [105, 0, 0], to = [105, 0, 0] }}]"),
        );
        let mean = figure(&report, "fold_angle_mean_deg");
        assert!((mean - 20.0).abs() < 0.05, "{mean}");
        assert!(figure(&report, "fold_angle_max_deg") >= 10.0);
        let lines = report["pieces"][0]["fold_lines"].as_array().unwrap();
        assert!(lines.len() > 10, "{}", lines.len());
        assert!(lines
            .iter()
            .all(|l| l["kind"] == kind && l["kind"] != other));
        assert!(lines
            .iter()
            .all(|l| l["angle_deg"].as_f64().unwrap() >= 10.0));
        // The pin holds the point of the flat sheet it was put on: the bottom edge's point at
        // (105, 0, 0) in 3D is 105 mm along that edge on the blank.
        let basis = BSpline::new(3, 8, false).unwrap();
        let bottom = &design_curves(&design)[0];
        let pin = DVec3::new(105.0, 0.0, 0.0);
        let u0 = (0..=20_000)
            .map(|k| k as f64 * basis.spans() as f64 / 20_000.0)
            .min_by(|&a, &b| {
                let d = |u: f64| basis.eval(bottom, u).distance(pin);
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        assert!(basis.eval(bottom, u0).distance(pin) < 0.01);
        let dev = &design["surfaces"][0]["development"];
        let num = |v: &serde_json::Value| v.as_f64().unwrap();
        let params: Vec<f64> = dev["params"].as_array().unwrap().iter().map(num).collect();
        let flat: Vec<(f64, f64)> = dev["curves"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["curve"] == 1)
            .unwrap()["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| (num(&p[0]), num(&p[1])))
            .collect();
        let i = params.iter().position(|&u| u >= u0).unwrap().max(1);
        let t = (u0 - params[i - 1]) / (params[i] - params[i - 1]);
        let at = (
            flat[i - 1].0 + t * (flat[i].0 - flat[i - 1].0),
            flat[i - 1].1 + t * (flat[i].1 - flat[i - 1].1),
        );
        let along = ((at.0 - flat[0].0).powi(2) + (at.1 - flat[0].1).powi(2)).sqrt();
        eprintln!("{kind}: the pin is {along:.4} mm along the bottom edge of the blank");
        assert!((along - 105.0).abs() < 0.05, "{along}");
    }
}

#[test]
fn spline_a4_with_its_bottom_edge_fixed_fans_from_its_corners() {
    // The bottom curve stands still at each corner for half the sheet (eight equal control
    // points each): the lower strip is two cones with their apexes in the corners and a fan
    // between, so the fixed straight edge no longer holds the strip flat.
    let [_, crease, top] = a4_curves(16);
    let corner = |x: f64| vec![DVec3::new(x, 0.0, 0.0); 8];
    let bottom: Vec<DVec3> = corner(0.0).into_iter().chain(corner(210.0)).collect();
    let dir = scratch("spline-a4-fans");
    let obj = dir.join("surface.obj");
    let spec = spline_spec(
        &dir,
        &[bottom, crease, top],
        &format!("outline = [210, 297]\ncreases = [\"fold\"]\nbend_lines = \"none\"\nfixed = [1]\nmax_iterations = 200\n{A4_LIFT}]"),
    );
    let report = cut(
        &dir,
        &spec,
        &["--tabs", "none", "--surface-obj", obj.to_str().unwrap()],
    );
    let contours = cut_contours(&dir);
    assert_eq!(contours.len(), 1);
    let (area, per) = contours[0];
    eprintln!(
        "a4 fans: blank {area:.1} mm², perimeter {per:.2} mm, sine {:.2e}, handles {:.2e} mm, {} iterations",
        figure(&report, "largest_sine"),
        figure(&report, "handle_distance_mm"),
        figure(&report, "iterations")
    );
    assert!(rel(area, 62370.0) < 1e-3, "{area}");
    assert!(rel(per, 1014.0) < 1e-3, "{per}");
    assert!(figure(&report, "largest_sine") <= 1e-6);
    assert!(figure(&report, "handle_distance_mm") < 0.01);
    assert_eq!(
        report["surfaces"][0]["warnings"]
            .as_array()
            .map_or(0, Vec::len),
        0
    );
    // One vertex at each apex (read without welding anything), no triangle without area.
    let raw = flatcut::surface::obj::read(&obj).unwrap();
    assert_eq!(raw.welded, 0);
    let m = raw.mesh;
    for apex in [DVec3::ZERO, DVec3::new(210.0, 0.0, 0.0)] {
        let at = m
            .vertices
            .iter()
            .filter(|v| v.distance(apex) < 1e-6)
            .count();
        assert_eq!(at, 1, "vertices at {apex}");
    }
    for (i, f) in m.faces.iter().enumerate() {
        let p: Vec<DVec3> = f.verts.iter().map(|&v| m.vertices[v]).collect();
        assert!((p[1] - p[0]).cross(p[2] - p[0]).length() > 1e-9, "face {i}");
    }
}

#[test]
fn spline_metal_cylinder_is_developed_on_the_neutral_surface_of_its_side() {
    let a: Vec<DVec3> = (0..8)
        .map(|i| {
            let t = i as f64 * std::f64::consts::TAU / 8.0;
            DVec3::new(100.0 * t.cos(), 70.0 * t.sin(), 0.0)
        })
        .collect();
    let b: Vec<DVec3> = a.iter().map(|p| *p + 150.0 * DVec3::Z).collect();
    let basis = BSpline::new(3, 8, true).unwrap();
    let l = length(&basis, &a);
    // A closed convex curve offset by d inward is 2πd shorter; K = 0.4, t = 2 mm.
    let tau = std::f64::consts::TAU;
    let mut areas = Vec::new();
    for (side, want) in [
        ("outside", l - tau * 0.6 * 2.0),
        ("inside", l + tau * 0.4 * 2.0),
        ("neutral", l),
    ] {
        let dir = scratch(&format!("spline-metal-{side}"));
        let extra = format!(
            "closed = true\nside = \"{side}\"\n[material]\nkind = \"metal\"\nthickness = 2"
        );
        let spec = spline_spec(&dir, &[a.clone(), b.clone()], &extra);
        // `[sheet]` follows `extra` in the spec; the material table ends before it.
        cut(&dir, &spec, &["--bend-lines", "none"]);
        let contours = cut_contours(&dir);
        let area = contours.iter().map(|c| c.0).fold(0.0, f64::max);
        eprintln!("metal ({side}): blank {area:.1} mm² vs {:.1}", want * 150.0);
        assert!(
            rel(area, want * 150.0) < 1e-3,
            "{side}: {area} vs {}",
            want * 150.0
        );
        areas.push(area);
    }
    // The sampling's chord error cancels in the differences: the offsets themselves, to 1 %.
    let (outside, inside, neutral) = (areas[0], areas[1], areas[2]);
    assert!(
        rel(neutral - outside, 150.0 * tau * 1.2) < 1e-2,
        "{}",
        neutral - outside
    );
    assert!(
        rel(inside - neutral, 150.0 * tau * 0.8) < 1e-2,
        "{}",
        inside - neutral
    );
}
