//! Issue 21, items 4 and 5: pieces too large for the sheet are split along their own lines so
//! that every part fits, new seams are seams like any other (an id on both sides, equal
//! lengths, tabs), sheet-metal blanks come in segments joined along rulings, `--split none`
//! keeps the refusal, and jobs that fit are left as they were.

use crate::common::*;
use flatcut::pattern::split::Split;
use flatcut::pattern::Piece;
use flatcut::spec::{SheetSpec, Spec};
use std::path::Path;

const CUBE_OBJ: &str = "# 100 mm cube, six quads
v 0 0 0
v 100 0 0
v 100 100 0
v 0 100 0
v 0 0 100
v 100 0 100
v 100 100 100
v 0 100 100
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
";

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// `flatcut cut OBJ --dry-run -o OUT`, the defaults otherwise (A4).
fn dry_cut(obj: &Path, out: &Path) -> std::process::Output {
    flatcut(&[
        "cut",
        obj.to_str().unwrap(),
        "--dry-run",
        "-o",
        out.to_str().unwrap(),
    ])
}

fn report(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap()
}

/// A report piece's `bbox_mm` (x0, y0, x1, y1).
fn bbox(piece: &serde_json::Value) -> Vec<f64> {
    piece["bbox_mm"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

/// Whether a box lies on A4 inside the default 5 mm margins.
fn inside_a4(b: &[f64]) -> bool {
    b[0] >= 5.0 - 1e-6 && b[1] >= 5.0 - 1e-6 && b[2] <= 205.0 + 1e-6 && b[3] <= 292.0 + 1e-6
}

/// Length (mm) drawn with each pen in an HP-GL program (40 units per mm).
fn pen_lengths(plt: &str) -> [f64; 4] {
    let mut len = [0.0; 4];
    for s in flatcut::output::hpgl::parse(plt).expect("valid HPGL") {
        let l: f64 = s
            .points
            .windows(2)
            .map(|w| {
                let (dx, dy) = ((w[1].0 - w[0].0) as f64, (w[1].1 - w[0].1) as f64);
                (dx * dx + dy * dy).sqrt() / 40.0
            })
            .sum();
        len[s.pen as usize] += l;
    }
    len
}

/// Every seam made by the split: two sides on two pieces, equal lengths, the id written on
/// both. Returns how many there are.
fn check_split_seams(pieces: &[Piece]) -> usize {
    let sides: Vec<(&Piece, &flatcut::pattern::SeamSide)> = pieces
        .iter()
        .flat_map(|p| p.seams.iter().map(move |s| (p, s)))
        .filter(|(_, s)| s.split)
        .collect();
    let mut n = 0;
    for &(pa, a) in sides.iter().filter(|(_, s)| s.is_a) {
        let b: Vec<_> = sides
            .iter()
            .filter(|(_, s)| s.id == a.id && !s.is_a)
            .collect();
        assert_eq!(b.len(), 1, "seam {} has {} B sides", a.id, b.len());
        let (pb, b) = *b[0];
        assert!(
            (a.length - b.length).abs() <= 1e-9 * a.length.max(1.0),
            "seam {}: {} vs {}",
            a.id,
            a.length,
            b.length
        );
        for p in [pa, pb] {
            assert!(
                p.marks.iter().any(|m| m.id == a.id && !m.text.is_empty()),
                "seam {}: no id on piece {}",
                a.id,
                p.name
            );
        }
        n += 1;
    }
    n
}

/// Every piece's outline lies inside its sheet's margins.
fn inside_margins(layout: &flatcut::nest::Layout) {
    let m = layout.margin;
    for (p, at) in layout.pieces.iter().zip(&layout.placements) {
        let s = &layout.sheets[at.sheet];
        for q in p.outline.iter().flatten().map(|q| at.apply(*q)) {
            assert!(
                q.x >= m - 1e-6
                    && q.y >= m - 1e-6
                    && q.x <= s.width - m + 1e-6
                    && q.y <= s.height - m + 1e-6,
                "piece {} at {q} outside {} × {} with margin {m}",
                p.name,
                s.width,
                s.height
            );
        }
    }
}

#[test]
fn cube_obj_on_a4_is_split_into_parts_that_fit() {
    let dir = scratch("split-cube");
    let obj = write(&dir, "cube.obj", CUBE_OBJ);
    let out = dir.join("out");
    let o = flatcut(&[
        "cut",
        obj.to_str().unwrap(),
        "--device",
        "hpgl-pens",
        "--dry-run",
        "--tabs",
        "none",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rep = report(&out);
    let sheets = rep["sheets"].as_array().unwrap();
    let pieces = rep["pieces"].as_array().unwrap();
    assert!(pieces.len() >= 3, "{} pieces", pieces.len());
    let faces: u64 = pieces.iter().map(|p| p["faces"].as_u64().unwrap()).sum();
    assert_eq!(faces, 6);
    for p in pieces {
        let b = bbox(p);
        assert!(inside_a4(&b), "piece {} at {b:?}", p["name"]);
    }
    for s in sheets {
        assert_eq!(
            (s["width_mm"].as_f64(), s["height_mm"].as_f64()),
            (Some(210.0), Some(297.0))
        );
    }
    // Each of the 12 edges is cut twice (a seam, old or new) or folded once.
    let (mut cut, mut fold) = (0.0, 0.0);
    for k in 1..=sheets.len() {
        let name = if sheets.len() == 1 {
            "cube.plt".to_string()
        } else {
            format!("cube-{k}.plt")
        };
        let [_, c, f, _] = pen_lengths(&std::fs::read_to_string(out.join(name)).unwrap());
        cut += c;
        fold += f;
    }
    assert!(
        (cut + 2.0 * fold - 2400.0).abs() < 0.05 * sheets.len() as f64,
        "cut {cut} fold {fold}"
    );
    // The new seams in report.json: both lengths, equal, 100 mm a mesh edge.
    let split: Vec<_> = rep["seams"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| s["split"] == true)
        .collect();
    assert!(!split.is_empty());
    for s in &split {
        let (a, b) = (
            s["length_a_mm"].as_f64().unwrap(),
            s["length_b_mm"].as_f64().unwrap(),
        );
        assert!((a - b).abs() < 1e-6 && (a - 100.0 * s["edges"].as_f64().unwrap()).abs() < 1e-6);
        assert_ne!(s["piece_a"], s["piece_b"]);
    }

    // Through the library, with the paper defaults (glue tabs): every new seam has its id on
    // both sides, equal lengths and a tab on one side; every piece is on an A4 sheet.
    let spec = Spec::from_mesh(&obj);
    let profile = flatcut::pipeline::device("hpgl-pens", None, None).unwrap();
    let (_, layout, _) = flatcut::pipeline::plan_job(&spec, &profile, true).unwrap();
    inside_margins(&layout);
    assert!(check_split_seams(&layout.pieces) >= 2);
    for p in &layout.pieces {
        for s in p.seams.iter().filter(|s| s.split && s.is_a) {
            let other = layout
                .pieces
                .iter()
                .flat_map(|q| &q.seams)
                .find(|t| t.id == s.id && !t.is_a)
                .unwrap();
            assert!(
                s.tab != other.tab,
                "seam {}: one tab, got {} {}",
                s.id,
                s.tab,
                other.tab
            );
        }
    }
}

#[test]
fn lamp_collar_on_a4_keeps_its_area() {
    let dir = scratch("split-collar");
    let text = std::fs::read_to_string(manifest("patterns/lamp-collar.toml"))
        .unwrap()
        .replace(
            "lamp-collar-lower.csv",
            manifest("patterns/lamp-collar-lower.csv").to_str().unwrap(),
        )
        .replace(
            "lamp-collar-upper.csv",
            manifest("patterns/lamp-collar-upper.csv").to_str().unwrap(),
        );
    let sheet = text.find("[sheet]").unwrap();
    let text = format!("{}[sheet]\nwidth = 210\nheight = 297\n", &text[..sheet]);
    let path = write(&dir, "collar-a4.toml", &text);
    let mut spec = flatcut::spec::load(&path).unwrap();
    assert_eq!(spec.sheet.height, Some(297.0));
    spec.pattern.split = Some(Split::None);
    let (_, whole) = flatcut::pipeline::pieces(&spec, true).unwrap();
    assert_eq!(whole.len(), 1);
    assert!(!flatcut::pattern::split::fits(
        &whole[0],
        &flatcut::pattern::split::Room::inside(210.0, Some(297.0), spec.sheet.margin)
    ));
    spec.pattern.split = None;
    let profile = flatcut::pipeline::device("sim", None, None).unwrap();
    let (_, layout, _) = flatcut::pipeline::plan_job(&spec, &profile, true).unwrap();
    assert!(layout.pieces.len() >= 2);
    assert!(layout
        .sheets
        .iter()
        .all(|s| s.width == 210.0 && s.height == 297.0));
    inside_margins(&layout);
    let area: f64 = layout.pieces.iter().map(|p| p.area).sum();
    assert!(
        (area - whole[0].area).abs() <= 1e-3 * whole[0].area,
        "{area} vs {}",
        whole[0].area
    );
    assert!(check_split_seams(&layout.pieces) >= 1);
}

#[test]
fn large_cone_on_a_roll_comes_in_segments_joined_along_rulings() {
    use clap::Parser;
    let cli = flatcut::cli::Cli::try_parse_from([
        "flatcut",
        "fitting",
        "cone",
        "--bottom-diameter",
        "1200",
        "--top-diameter",
        "600",
        "--height",
        "500",
    ])
    .unwrap();
    let flatcut::cli::Command::Fitting(args) = cli.command else {
        panic!("not a fitting");
    };
    let mut spec = flatcut::cli::fitting::spec(&args).unwrap();
    spec.sheet = SheetSpec {
        width: 610.0,
        height: None,
        margin: 10.0,
        spacing: 5.0,
    };
    let profile = flatcut::pipeline::device("sim", None, None).unwrap();
    let (_, layout, _) = flatcut::pipeline::plan_job(&spec, &profile, true).unwrap();
    assert!(layout.roll);
    assert!(layout.pieces.len() >= 2, "{} segments", layout.pieces.len());
    inside_margins(&layout);
    // Lateral area of the frustum: π (R + r) · slant.
    let slant = (500f64 * 500.0 + 300.0 * 300.0).sqrt();
    let exact = std::f64::consts::PI * (600.0 + 300.0) * slant;
    let area: f64 = layout.pieces.iter().map(|p| p.area).sum();
    assert!((area - exact).abs() <= 3e-3 * exact, "{area} vs {exact}");
    // Segments of about equal size, each with its own bend lines.
    let (lo, hi) = layout
        .pieces
        .iter()
        .map(|p| p.area)
        .fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
    assert!(hi <= 1.1 * lo, "segments {lo} .. {hi} mm²");
    for p in &layout.pieces {
        assert!(
            p.folds.iter().any(|f| !f.tab),
            "segment {} has no bend line",
            p.name
        );
    }
    // Each new seam is one ruling (a bridge of the strip from rim to rim, the slant's length
    // within what sampling the rims leaves), the same length on both sides.
    assert_eq!(check_split_seams(&layout.pieces), layout.pieces.len() - 1);
    for s in layout
        .pieces
        .iter()
        .flat_map(|p| &p.seams)
        .filter(|s| s.split)
    {
        assert_eq!(s.count, 1, "seam {} is {} edges", s.id, s.count);
        assert!(
            (s.length - slant).abs() < 5e-4 * slant,
            "seam {}: {} vs {slant}",
            s.id,
            s.length
        );
        let chord = s.points[0].distance(s.points[1]);
        assert!((chord - s.length).abs() < 1e-6 * slant);
    }
}

#[test]
fn split_none_keeps_the_refusal_and_a_face_too_large_is_an_error() {
    let dir = scratch("split-none");
    let obj = write(&dir, "cube.obj", CUBE_OBJ);
    let out = dir.join("out");
    let o = flatcut(&[
        "cut",
        obj.to_str().unwrap(),
        "--dry-run",
        "--split",
        "none",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("piece 1 (") && err.contains("does not fit on the sheet"),
        "{err}"
    );
    let o = flatcut(&["flatten", obj.to_str().unwrap(), "--split", "sideways"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("--split"), "{}", stderr(&o));

    // One 300 × 250 mm face (two quads, folded): the big face cannot be split to fit A4.
    let panel = write(
        &dir,
        "panel.obj",
        "v 0 0 0\nv 300 0 0\nv 300 250 0\nv 0 250 0\nv 0 250 50\nv 300 250 50\nf 1 2 3 4\nf 4 3 6 5\n",
    );
    let o = dry_cut(&panel, &out);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("face 1 alone is 300.0 × 250.0 mm") && err.contains("200.0 × 287.0 mm"),
        "{err}"
    );
}

/// A 300 × 20 mm strip of one face on A4 (200 × 287 mm inside the 5 mm margins) fits no
/// quarter turn of its least rectangle, but fits across the sheet (whose diagonal inside the
/// margins is 350 mm): it is cut whole, turned between quarter turns, inside the margins. At
/// 400 mm, longer than that diagonal, the face is too large.
#[test]
fn a_long_thin_face_is_cut_across_the_sheet() {
    let dir = scratch("split-across");
    let strip = |len: f64| format!("v 0 0 0\nv {len} 0 0\nv {len} 20 0\nv 0 20 0\nf 1 2 3 4\n");
    let obj = write(&dir, "strip.obj", &strip(300.0));
    let out = dir.join("out");
    let o = dry_cut(&obj, &out);
    assert!(o.status.success(), "{}", stderr(&o));
    let rep = report(&out);
    let pieces = rep["pieces"].as_array().unwrap();
    assert_eq!(pieces.len(), 1);
    let turn = pieces[0]["rotation_deg"].as_f64().unwrap();
    let off_quarter = (turn.rem_euclid(90.0)).min(90.0 - turn.rem_euclid(90.0));
    assert!(off_quarter > 20.0, "turned {turn}°");
    let b = bbox(&pieces[0]);
    assert!(inside_a4(&b), "box {b:?}");
    let long = write(&dir, "long.obj", &strip(400.0));
    let o = dry_cut(&long, &out);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("face 1 alone is 400.0 × 20.0 mm"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn jobs_that_fit_are_not_split() {
    let mut names: Vec<_> = std::fs::read_dir(manifest("patterns"))
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    names.sort();
    for path in names {
        let mut spec = flatcut::spec::load(&path).unwrap();
        let (_, auto) = flatcut::pipeline::pieces(&spec, true).unwrap();
        spec.pattern.split = Some(Split::None);
        let (_, none) = flatcut::pipeline::pieces(&spec, true).unwrap();
        assert_eq!(auto, none, "{}", path.display());
        assert!(auto.iter().all(|p| p.seams.iter().all(|s| !s.split)));
    }
}
