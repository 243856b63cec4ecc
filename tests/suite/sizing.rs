//! Issue 21: any model, any sheet. The size of the model (`--size`, `--scale`, `--units`), the
//! refusal of implausible sizes, the sheet flags and a roll-fed device's roll, the mesh formats
//! besides OBJ (STL, PLY, OFF), `check`'s size, and the least roll for a lone piece.

use crate::common::{flatcut, manifest, scratch, shared_data, stderr};
use serde_json::Value;
use std::path::Path;

/// `cut ARGS --dry-run -q -o DIR`; the report, or a panic with stderr.
fn cut_report(args: &[&str], dir: &Path) -> Value {
    let d = dir.to_string_lossy().into_owned();
    let mut all = vec!["cut"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--dry-run", "-q", "-o", &d]);
    let o = flatcut(&all);
    assert!(o.status.success(), "{all:?}: {}", stderr(&o));
    serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap()
}

/// Exit 1 with one line on stderr that contains every needle.
fn refused(args: &[&str], needles: &[&str]) -> String {
    let o = flatcut(args);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {e}");
    for n in needles {
        assert!(e.contains(n), "{args:?}: {n:?} not in {e}");
    }
    e
}

/// The largest side of the bounding box of an OBJ file's vertices.
fn obj_extent(path: &Path) -> f64 {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for l in text.lines().filter(|l| l.starts_with("v ")) {
        for (i, w) in l.split_whitespace().skip(1).take(3).enumerate() {
            let x: f64 = w.parse().unwrap();
            lo[i] = lo[i].min(x);
            hi[i] = hi[i].max(x);
        }
    }
    (0..3).map(|i| hi[i] - lo[i]).fold(0.0, f64::max)
}

#[test]
fn sizing_fandisk_is_refused_with_a_one_line_hint_and_cuts_at_size_200() {
    require_shared!();
    let dir = scratch("sizing-fandisk");
    let mesh = shared_data("meshes/fandisk.obj");
    let mesh = mesh.to_string_lossy();
    let out = dir.join("out").to_string_lossy().into_owned();
    let e = refused(
        &["cut", &mesh, "--dry-run", "-o", &out],
        &[
            "fandisk.obj",
            "1 mm across as read",
            "millimetres",
            "--size 200",
            "--units m",
        ],
    );
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    // The same for flatten.
    refused(&["flatten", &mesh, "-o", &out], &["--size 200"]);
    // At --size 200 it cuts, and the assembled model is 200 mm across.
    let obj = dir.join("surface.obj");
    let obj_s = obj.to_string_lossy().into_owned();
    let r = cut_report(
        &[
            &mesh,
            "--size",
            "200",
            "--sheet",
            "a2",
            "--surface-obj",
            &obj_s,
        ],
        &dir.join("cut"),
    );
    assert!(r["totals"]["pieces"].as_u64().unwrap() > 1);
    let across = obj_extent(&obj);
    assert!((across - 200.0).abs() <= 0.2, "{across} mm across");
    // --units m makes it about 1 m across.
    let r = cut_report(&[&mesh, "--units", "m", "--roll", "3000"], &dir.join("m"));
    assert!(r["totals"]["area_mm2"].as_f64().unwrap() > 1e5);
}

#[test]
fn sizing_same_job_at_three_sizes_has_the_same_pieces_scaled() {
    let dir = scratch("sizing-scaled");
    let mut runs = Vec::new();
    for size in [50.0f64, 150.0, 400.0] {
        let s = size.to_string();
        let r = cut_report(
            &["patterns/house.obj", "--size", &s, "--roll", "3000"],
            &dir.join(&s),
        );
        runs.push((size, r));
    }
    let faces = |r: &Value| -> Vec<(u64, u64)> {
        r["pieces"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| (p["id"].as_u64().unwrap(), p["faces"].as_u64().unwrap()))
            .collect()
    };
    let (s0, r0) = &runs[0];
    for (s, r) in &runs[1..] {
        assert_eq!(faces(r), faces(r0), "--size {s} vs {s0}");
        let k = s / s0;
        for (a, b) in r["pieces"]
            .as_array()
            .unwrap()
            .iter()
            .zip(r0["pieces"].as_array().unwrap())
        {
            let (fa, fb) = (
                a["area_mm2"].as_f64().unwrap(),
                b["area_mm2"].as_f64().unwrap(),
            );
            assert!(
                (fa - k * k * fb).abs() <= 1e-6 * fa,
                "area {fa} vs {fb} × {k}²"
            );
            let (la, lb) = (
                a["fold_length_mm"].as_f64().unwrap(),
                b["fold_length_mm"].as_f64().unwrap(),
            );
            assert!(
                (la - k * lb).abs() <= 1e-6 * la.max(1.0),
                "folds {la} vs {lb} × {k}"
            );
        }
    }
}

#[test]
fn sizing_scale_and_units_scale_the_model() {
    let dir = scratch("sizing-units");
    let area = |r: &Value| r["totals"]["area_mm2"].as_f64().unwrap();
    // The 100 mm cube: 6 × 100² mm².
    let mm = cut_report(&["patterns/cube.obj", "--roll", "610"], &dir.join("mm"));
    assert!((area(&mm) - 60_000.0).abs() < 1e-6);
    let half = cut_report(&["patterns/cube.obj", "--scale", "0.5"], &dir.join("half"));
    assert!((area(&half) - 15_000.0).abs() < 1e-6);
    // 100 units in cm would be a metre: given in cm and scaled down 10 times, 100 mm again.
    let cm = cut_report(
        &[
            "patterns/cube.obj",
            "--units",
            "cm",
            "--scale",
            "0.1",
            "--roll",
            "610",
        ],
        &dir.join("cm"),
    );
    assert!((area(&cm) - 60_000.0).abs() < 1e-6);
    // A spec's top-level `size` sizes the job; --size wins over it.
    let spec = dir.join("cube.toml");
    std::fs::write(
        &spec,
        format!(
            "size = 50\n[[surface]]\nkind = \"mesh\"\npath = \"{}\"\n",
            manifest("patterns/cube.obj").display()
        ),
    )
    .unwrap();
    let spec = spec.to_string_lossy().into_owned();
    let s50 = cut_report(&[&spec], &dir.join("s50"));
    assert!((area(&s50) - 15_000.0).abs() < 1e-6);
    let s60 = cut_report(&[&spec, "--size", "60"], &dir.join("s60"));
    assert!((area(&s60) - 6.0 * 3600.0).abs() < 1e-6);
}

#[test]
fn sizing_sheet_flags_change_the_sheets() {
    let dir = scratch("sizing-sheets");
    let cube = ["patterns/cube.obj", "--size", "50"];
    let sheet = |extra: &[&str], name: &str| {
        let mut a = cube.to_vec();
        a.extend_from_slice(extra);
        cut_report(&a, &dir.join(name))
    };
    let wh = |r: &Value| {
        let s = &r["sheets"][0];
        (
            s["width_mm"].as_f64().unwrap(),
            s["height_mm"].as_f64().unwrap(),
        )
    };
    let a4 = sheet(&[], "a4");
    assert_eq!(
        (wh(&a4), a4["roll"].as_bool()),
        ((210.0, 297.0), Some(false))
    );
    assert_eq!(wh(&sheet(&["--sheet", "letter"], "letter")), (215.9, 279.4));
    assert_eq!(
        wh(&sheet(&["--sheet", "300x200"], "300x200")),
        (300.0, 200.0)
    );
    let inch = wh(&sheet(&["--sheet", "12x12in"], "inch"));
    assert!((inch.0 - 304.8).abs() < 1e-9 && (inch.1 - 304.8).abs() < 1e-9);
    assert_eq!(
        wh(&sheet(&["--sheet", "a4", "--landscape"], "land")),
        (297.0, 210.0)
    );
    let roll = sheet(&["--roll", "610"], "roll");
    assert_eq!(roll["roll"].as_bool(), Some(true));
    assert_eq!(wh(&roll).0, 610.0);
    assert!(roll["roll_length_mm"].as_f64().unwrap() < 297.0);
    // Margin and spacing: recorded, and every piece keeps the margin.
    let m = sheet(&["--margin", "20", "--spacing", "7"], "margin");
    assert_eq!(m["margin_mm"].as_f64(), Some(20.0));
    assert_eq!(m["spacing_mm"].as_f64(), Some(7.0));
    for p in m["pieces"].as_array().unwrap() {
        let b: Vec<f64> = p["bbox_mm"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert!(b[0] >= 20.0 - 1e-6 && b[1] >= 20.0 - 1e-6, "{b:?}");
        assert!(
            b[2] <= 210.0 - 20.0 + 1e-6 && b[3] <= 297.0 - 20.0 + 1e-6,
            "{b:?}"
        );
    }
    // Two pieces 7 mm apart at least: the gap between their boxes on a roll.
    let two = dir.join("two.toml");
    let cube_obj = manifest("patterns/cube.obj");
    std::fs::write(
        &two,
        format!(
            "[[surface]]\nkind = \"mesh\"\npath = \"{0}\"\nname = \"a\"\nscale = 0.3\n\
             [[surface]]\nkind = \"mesh\"\npath = \"{0}\"\nname = \"b\"\nscale = 0.3\n",
            cube_obj.display()
        ),
    )
    .unwrap();
    let two = two.to_string_lossy().into_owned();
    let r = cut_report(
        &[&two, "--spacing", "25", "--roll", "400"],
        &dir.join("two"),
    );
    assert_eq!(r["spacing_mm"].as_f64(), Some(25.0));
    // A roll-fed device's roll is the default sheet of a spec without [sheet].
    let r = cut_report(
        &["patterns/cube.obj", "--device", "roland-gx24"],
        &dir.join("gx24"),
    );
    assert_eq!((r["roll"].as_bool(), wh(&r).0), (Some(true), 584.0));
    // ... and the flags still win over it.
    let r = cut_report(
        &[
            "patterns/cube.obj",
            "--device",
            "roland-gx24",
            "--size",
            "50",
            "--sheet",
            "a4",
        ],
        &dir.join("gx24-a4"),
    );
    assert_eq!((r["roll"].as_bool(), wh(&r)), (Some(false), (210.0, 297.0)));
}

#[test]
fn sizing_bad_values_name_the_flag() {
    let out = scratch("sizing-bad").to_string_lossy().into_owned();
    let run = |extra: &[&str], flag: &str| {
        let mut a = vec!["cut", "patterns/cube.obj", "--dry-run", "-o", &out];
        a.extend_from_slice(extra);
        refused(&a, &[flag]);
    };
    run(&["--sheet", "b7x"], "--sheet");
    run(&["--sheet", "0x200"], "--sheet");
    run(&["--size", "-1"], "--size");
    run(&["--size", "nan"], "--size");
    run(&["--scale", "0"], "--scale");
    run(&["--units", "furlong"], "--units");
    run(&["--roll", "-610"], "--roll");
    run(&["--margin", "-2"], "--margin");
    run(&["--margin", "150"], "--margin");
    run(&["--spacing", "x"], "--spacing");
    run(&["--roll", "610", "--landscape"], "--landscape");
    refused(
        &[
            "fitting",
            "cone",
            "--bottom-diameter",
            "12",
            "--top-diameter",
            "6",
            "--height",
            "5",
            "--units",
            "ft",
        ],
        &["--units"],
    );
}

/// The 100 mm cube of `patterns/cube.obj` as (vertices, quads).
fn cube() -> (Vec<[f32; 3]>, Vec<Vec<usize>>) {
    let text = std::fs::read_to_string(manifest("patterns/cube.obj")).unwrap();
    let mut v = Vec::new();
    let mut f = Vec::new();
    for l in text.lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        match w.first() {
            Some(&"v") => v.push([w[1], w[2], w[3]].map(|x| x.parse().unwrap())),
            Some(&"f") => f.push(
                w[1..]
                    .iter()
                    .map(|x| x.parse::<usize>().unwrap() - 1)
                    .collect(),
            ),
            _ => {}
        }
    }
    (v, f)
}

fn cube_files(dir: &Path) -> Vec<std::path::PathBuf> {
    let (v, f) = cube();
    let tris: Vec<[usize; 3]> = f
        .iter()
        .flat_map(|q| (1..q.len() - 1).map(move |k| [q[0], q[k], q[k + 1]]))
        .collect();
    let mut bin = vec![0u8; 80];
    bin.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    let mut ascii = String::from("solid cube\n");
    for t in &tris {
        bin.extend_from_slice(&[0u8; 12]);
        ascii += " facet normal 0 0 0\n  outer loop\n";
        for &i in t {
            for x in v[i] {
                bin.extend_from_slice(&x.to_le_bytes());
            }
            ascii += &format!("   vertex {} {} {}\n", v[i][0], v[i][1], v[i][2]);
        }
        bin.extend_from_slice(&[0, 0]);
        ascii += "  endloop\n endfacet\n";
    }
    ascii += "endsolid cube\n";
    let mut off = format!("OFF\n# the cube\n{} {} 0\n", v.len(), f.len());
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        v.len(),
        f.len()
    );
    let mut plyb = ply.replace("ascii", "binary_little_endian").into_bytes();
    for p in &v {
        off += &format!("{} {} {}\n", p[0], p[1], p[2]);
        ply += &format!("{} {} {}\n", p[0], p[1], p[2]);
        for x in p {
            plyb.extend_from_slice(&x.to_le_bytes());
        }
    }
    for q in &f {
        let idx: Vec<String> = q.iter().map(|i| i.to_string()).collect();
        off += &format!("{} {}\n", q.len(), idx.join(" "));
        ply += &format!("{} {}\n", q.len(), idx.join(" "));
        plyb.push(q.len() as u8);
        for &i in q {
            plyb.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    let files: [(&str, Vec<u8>); 5] = [
        ("cube-bin.stl", bin),
        ("cube-ascii.STL", ascii.into_bytes()),
        ("cube.off", off.into_bytes()),
        ("cube.ply", ply.into_bytes()),
        ("cube-bin.ply", plyb),
    ];
    files
        .into_iter()
        .map(|(name, bytes)| {
            let p = dir.join(name);
            std::fs::write(&p, bytes).unwrap();
            p
        })
        .collect()
}

#[test]
fn sizing_stl_ply_and_off_of_the_cube_give_the_obj_pieces() {
    let dir = scratch("sizing-formats");
    let files = cube_files(&dir);
    let key = |r: &Value| -> Vec<String> {
        r["pieces"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| {
                format!(
                    "{} {} {} {} {} {}",
                    p["area_mm2"],
                    p["cut_length_mm"],
                    p["fold_length_mm"],
                    p["folds"],
                    p["edge_ids"],
                    p["bbox_mm"]
                )
            })
            .collect()
    };
    let obj = cut_report(&["patterns/cube.obj", "--roll", "610"], &dir.join("obj"));
    for f in &files {
        let fs = f.to_string_lossy().into_owned();
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        let r = cut_report(&[&fs, "--roll", "610"], &dir.join(format!("out-{name}")));
        assert_eq!(key(&r), key(&obj), "{name}");
        assert_eq!(r["roll_length_mm"], obj["roll_length_mm"], "{name}");
        if !name.to_ascii_lowercase().ends_with(".stl") {
            // Polygon formats keep the quads: the very same panels.
            assert_eq!(r["pieces"][0]["faces"], obj["pieces"][0]["faces"], "{name}");
        }
        // check reads it too and says how large it is.
        let o = flatcut(&["check", &fs]);
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(out.contains("100 × 100 × 100 mm"), "{out}");
    }
}

#[test]
fn sizing_broken_stl_names_the_file() {
    let dir = scratch("sizing-broken");
    let files = cube_files(&dir);
    let mut bytes = std::fs::read(&files[0]).unwrap();
    bytes.truncate(bytes.len() - 20);
    let broken = dir.join("broken.stl");
    std::fs::write(&broken, &bytes).unwrap();
    let b = broken.to_string_lossy().into_owned();
    let out = dir.join("out").to_string_lossy().into_owned();
    let e = refused(
        &["cut", &b, "--dry-run", "-o", &out],
        &["broken.stl", "STL"],
    );
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    refused(&["check", &b], &["broken.stl"]);
    // An ASCII STL with a bad number names its line.
    let text =
        std::fs::read_to_string(&files[1])
            .unwrap()
            .replacen("vertex 0 0 0", "vertex 0 zero 0", 1);
    let bad = dir.join("bad.stl");
    std::fs::write(&bad, text).unwrap();
    refused(
        &["cut", &bad.to_string_lossy(), "--dry-run", "-o", &out],
        &["bad.stl:", "zero"],
    );
}

#[test]
fn sizing_cube_spec_takes_the_least_roll() {
    let dir = scratch("sizing-cube-roll");
    let r = cut_report(&["patterns/cube.toml"], &dir);
    let len = r["roll_length_mm"].as_f64().unwrap();
    assert!(len <= 331.0, "cube.toml uses {len} mm of its 610 mm roll");
}
