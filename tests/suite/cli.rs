//! The command line end to end: every bundled pattern cuts, the cube's HPGL carries exactly its
//! edges, outputs are deterministic, and bad input gets exit code 1 with one line that names
//! the file and the cause.

use crate::common::*;
use flatcut::output::hpgl;

fn pen_lengths(plt: &str) -> [f64; 4] {
    let mut len = [0.0; 4];
    for s in hpgl::parse(plt).expect("valid HPGL") {
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

#[test]
fn every_pattern_cuts_with_hpgl_pens_dry_run() {
    let mut names: Vec<String> = std::fs::read_dir(manifest("patterns"))
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert!(names.len() >= 4, "{names:?}");
    for name in names {
        let out = scratch(&format!("pattern-{name}"));
        let o = flatcut(&[
            "cut",
            &format!("patterns/{name}.toml"),
            "--device",
            "hpgl-pens",
            "--dry-run",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        for f in [
            format!("{name}.plt"),
            format!("{name}.svg"),
            format!("{name}.pdf"),
            format!("{name}-1.png"),
            "report.json".into(),
        ] {
            assert!(out.join(&f).is_file(), "{name}: {f} missing");
        }
        let plt = std::fs::read_to_string(out.join(format!("{name}.plt"))).unwrap();
        assert!(plt.starts_with("IN;") && plt.trim_end().ends_with("PU;SP0;"));
        // No partial files left behind (the run's manifest is the one hidden file).
        let leftovers = std::fs::read_dir(&out)
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .map(|e| {
                        let n = e.file_name().to_string_lossy().into_owned();
                        n.starts_with('.') && n != flatcut::output::files::MANIFEST
                    })
                    .unwrap_or(false)
            })
            .count();
        assert_eq!(leftovers, 0);
    }
}

#[test]
fn cube_hpgl_cuts_and_folds_every_edge_once() {
    let out = scratch("cube-hpgl");
    let o = flatcut(&[
        "cut",
        "patterns/cube.toml",
        "--device",
        "hpgl-pens",
        "--dry-run",
        "--tabs",
        "none",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let plt = std::fs::read_to_string(out.join("cube.plt")).unwrap();
    let [_, cut, fold, draw] = pen_lengths(&plt);
    // Each of the 12 edges is either cut (appearing twice) or folded.
    assert!(
        (cut + 2.0 * fold - 2400.0).abs() < 0.05,
        "cut {cut} fold {fold}"
    );
    // A one-piece net: five folds.
    assert!((fold - 500.0).abs() < 0.05, "fold {fold}");
    assert!(draw > 0.0, "edge ids and label are drawn with pen 3");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["totals"]["pieces"], 1);
    assert_eq!(report["pieces"][0]["folds"]["mountain"], 5);
    // Each seam's id on both of its sides; the seams cover the 1400 mm border once per side.
    let seams = report["seams"].as_array().unwrap();
    assert_eq!(report["pieces"][0]["edge_ids"], 2 * seams.len());
    let both: f64 = seams
        .iter()
        .map(|s| s["length_a_mm"].as_f64().unwrap() + s["length_b_mm"].as_f64().unwrap())
        .sum();
    assert!((both - 1400.0).abs() < 1e-6, "{both}");
    let folds = report["pieces"][0]["fold_lines"].as_array().unwrap();
    assert_eq!(folds.len(), 5);
    for f in folds {
        assert_eq!(f["kind"], "mountain");
        assert!((f["angle_deg"].as_f64().unwrap() - 90.0).abs() < 1e-6);
        assert!((f["length_mm"].as_f64().unwrap() - 100.0).abs() < 1e-6);
    }
    assert!(report["pieces"][0]["source"]
        .as_str()
        .unwrap()
        .ends_with("cube.obj"));
    assert!((report["totals"]["cut_length_mm"].as_f64().unwrap() - 1400.0).abs() < 1e-6);
}

#[test]
fn same_input_gives_byte_identical_output() {
    let (a, b) = (scratch("det-a"), scratch("det-b"));
    for d in [&a, &b] {
        let o = flatcut(&[
            "cut",
            "patterns/house.toml",
            "--dry-run",
            "-q",
            "-o",
            d.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    for f in ["house.plt", "house.svg", "house-1.png", "report.json"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f} differs"
        );
    }
}

#[test]
fn bare_obj_uses_defaults() {
    let out = scratch("bare-obj");
    let o = flatcut(&[
        "cut",
        "patterns/tetrahedron.obj",
        "--dry-run",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["material"]["kind"], "paper");
    assert_eq!(report["sheets"][0]["width_mm"], 210.0);
    assert_eq!(report["sheets"][0]["height_mm"], 297.0);
    assert_eq!(report["margin_mm"], 5.0);
    assert_eq!(report["spacing_mm"], 3.0);
    assert_eq!(report["device"], "sim");
}

#[test]
fn flatten_and_check_subcommands() {
    let out = scratch("flatten-house");
    let o = flatcut(&[
        "flatten",
        "patterns/house.toml",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.join("house.svg").is_file() && out.join("house-1.png").is_file());
    assert!(!out.join("house.plt").exists());
    let o = flatcut(&["check", "patterns/cube.obj", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(s["faces"], 6);
    assert_eq!(s["edges"], 12);
    assert_eq!(s["boundary_loops"], 0);
    assert!((s["max_angle_defect_deg"].as_f64().unwrap() - 90.0).abs() < 1e-9);
    let o = flatcut(&["check", "patterns/lampshade.obj", "--json"]);
    let s: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(s["boundary_loops"], 2);
    assert!(s["max_angle_defect_deg"].as_f64().unwrap() < 1e-9);
}

#[test]
fn help_shows_examples() {
    let o = flatcut(&["cut", "--help"]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("Examples:") && text.contains("--dry-run"),
        "{text}"
    );
}

/// Run, expect exit 1 and a single stderr line containing every `needle`.
fn expect_user_error(args: &[&str], needles: &[&str]) {
    let o = flatcut(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "{args:?}: expected one line, got {err}");
    for n in needles {
        assert!(
            lines[0].contains(n),
            "{args:?}: `{n}` not in `{}`",
            lines[0]
        );
    }
}

#[test]
fn bad_input_is_exit_1_with_one_line() {
    let dir = scratch("bad-input");
    let p = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let out = p("out");

    // Missing file.
    expect_user_error(
        &["cut", &p("nope.obj"), "-o", &out],
        &["nope.obj", "No such file"],
    );
    expect_user_error(
        &["cut", &p("nope.toml"), "-o", &out],
        &["nope.toml", "cannot read"],
    );

    // A spec whose mesh is missing: names the spec line and the mesh.
    std::fs::write(
        dir.join("lost.toml"),
        "name = \"lost\"\n[[surface]]\nkind = \"mesh\"\npath = \"gone.obj\"\n",
    )
    .unwrap();
    expect_user_error(
        &["cut", &p("lost.toml"), "-o", &out],
        &["lost.toml:4", "gone.obj"],
    );

    // Not an OBJ.
    std::fs::write(
        dir.join("photo.obj"),
        [0x89u8, 0x50, 0x4e, 0x47, 0, 1, 2, 3, 255],
    )
    .unwrap();
    expect_user_error(
        &["cut", &p("photo.obj"), "-o", &out],
        &["photo.obj", "not an OBJ"],
    );
    std::fs::write(dir.join("notes.obj"), "dear diary\ntoday I cut paper\n").unwrap();
    expect_user_error(
        &["cut", &p("notes.obj"), "-o", &out],
        &["notes.obj", "not an OBJ"],
    );

    // NaN coordinate: names the line.
    std::fs::write(
        dir.join("nan.obj"),
        "v 0 0 0\nv 10 0 0\nv 0 NaN 0\nf 1 2 3\n",
    )
    .unwrap();
    expect_user_error(
        &["cut", &p("nan.obj"), "-o", &out],
        &["nan.obj:3", "not a finite number"],
    );

    // Unknown spec key: names file, line and key.
    std::fs::write(
        dir.join("typo.toml"),
        format!(
            "[[surface]]\nkind = \"mesh\"\npath = \"{}\"\n\n[sheet]\nwidht = 300\n",
            manifest("patterns/cube.obj").display()
        ),
    )
    .unwrap();
    expect_user_error(
        &["cut", &p("typo.toml"), "-o", &out],
        &["typo.toml:6", "widht"],
    );

    // Piece larger than the sheet, and splitting turned off: both sizes.
    std::fs::write(
        dir.join("big.toml"),
        format!(
            "[[surface]]\nkind = \"mesh\"\npath = \"{}\"\n",
            manifest("patterns/cube.obj").display()
        ),
    )
    .unwrap();
    expect_user_error(
        &[
            "cut",
            &p("big.toml"),
            "--tabs",
            "none",
            "--split",
            "none",
            "-o",
            &out,
        ],
        &["big.toml", "400.0 × 300.0 mm", "200.0 × 287.0 mm"],
    );

    // Unknown device, bad material flag.
    expect_user_error(
        &[
            "cut",
            "patterns/cube.toml",
            "--device",
            "laserjet",
            "-o",
            &out,
        ],
        &["laserjet", "hpgl-pens"],
    );
    let o = flatcut(&["cut", "patterns/cube.toml", "--material", "wood"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));

    // Nothing that looks complete was left behind by the failures.
    assert!(!dir.join("out").join("report.json").exists());
}

#[test]
fn non_manifold_and_flipped_meshes() {
    let dir = scratch("mesh-faults");
    let out = dir.join("out").to_string_lossy().into_owned();
    std::fs::write(
        dir.join("fin.obj"),
        "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 -10 0\nv 0 0 10\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
    )
    .unwrap();
    expect_user_error(
        &["cut", dir.join("fin.obj").to_str().unwrap(), "-o", &out],
        &["fin.obj:6", "shared by 3 faces"],
    );
    // One face of the cube wound the wrong way: repaired with a warning, still cuts.
    let cube = std::fs::read_to_string(manifest("patterns/cube.obj")).unwrap();
    let flipped = cube.replacen("f 5 6 7 8", "f 8 7 6 5", 1);
    assert_ne!(cube, flipped);
    std::fs::write(dir.join("flipped.obj"), flipped).unwrap();
    std::fs::write(
        dir.join("flipped.toml"),
        "[[surface]]\nkind = \"mesh\"\npath = \"flipped.obj\"\n[sheet]\nwidth = 610\nroll = true\n",
    )
    .unwrap();
    let o = flatcut(&[
        "cut",
        dir.join("flipped.toml").to_str().unwrap(),
        "--dry-run",
        "-o",
        &out,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("reversed the winding of 1 faces"),
        "{}",
        stderr(&o)
    );
}
