//! GP-GL (Graphtec native mode) end to end: every bundled pattern planned for the
//! `graphtec-ce6000-gpgl` profile, encoded as GP-GL, streamed through a pseudo-terminal into the
//! simulated Graphtec cutter, whose recorded tool-down paths must equal the job's within one
//! device unit (0.1 mm).
//!
//! The profile gets the pen of a tool change (`toolpath::passes::with_pen`), so that labels and
//! seam ids are in the job too. The blade offset is set to 0 for the comparison, so that the recorded path is the holder's,
//! which is the job's (with an offset the simulator records the trailing blade tip; the bundled
//! profile with its offset is checked on the house in `device.rs`). The line runs at 460800
//! baud and motion takes no time, so the 18 patterns stream in seconds.

use crate::common::*;
use flatcut::device::sim::SimConfig;
use flatcut::device::stream::{self, StreamOptions};
use flatcut::profile::{self, Profile};
use std::time::Duration;

/// The simulator's name for the tool of `kind`: the first tool of the profile with the same
/// tool number and force.
fn sim_name(p: &Profile, kind: &str) -> String {
    let t = &p.tools[kind];
    p.tools
        .iter()
        .find(|(_, u)| (u.pen, u.force) == (t.pen, t.force))
        .map(|(k, _)| k.clone())
        .unwrap()
}

#[test]
fn every_bundled_pattern_on_gpgl_equals_the_job_within_one_step() {
    // With the knife holder's pen of a tool change, so that labels and seam ids are drawn too.
    let mut p =
        flatcut::toolpath::passes::with_pen(&profile::find("graphtec-ce6000-gpgl").unwrap());
    assert_eq!(p.language, profile::Language::Gpgl);
    p.knife_offset = 0.0;
    p.serial.baud = 460_800;
    let mut patterns: Vec<_> = std::fs::read_dir(manifest("patterns"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|f| f.extension().is_some_and(|x| x == "toml"))
        .collect();
    patterns.sort();
    assert!(patterns.len() >= 18, "{patterns:?}");
    let (mut paths_checked, mut sheets_checked) = (0usize, 0usize);
    for file in &patterns {
        let name = file.file_stem().unwrap().to_string_lossy().to_string();
        let spec = flatcut::spec::load(file).unwrap();
        let (_, _, design) = flatcut::pipeline::plan_job(&spec, &p, true).unwrap();
        let job = flatcut::pipeline::machine_job(&design, &p, &spec);
        for (k, sheet) in job.sheets.iter().enumerate() {
            let program = flatcut::output::program(sheet, &p).unwrap();
            let opts = StreamOptions {
                timeout: Duration::from_secs(20),
                progress: false,
                ..StreamOptions::default()
            };
            let (sent, rep) = stream::stream_job(
                SimConfig::new(p.clone()),
                &program,
                &opts,
                Duration::from_secs(60),
            )
            .unwrap();
            let at = format!("{name} sheet {}", k + 1);
            sent.unwrap_or_else(|e| panic!("{at}: {e}"));
            assert_eq!(rep.bytes_received, program.len(), "{at}");
            assert_eq!(rep.violations(), 0, "{at}");
            assert!(rep.ignored.is_empty(), "{at}: {:?}", rep.ignored);
            assert!(rep.tool_down_at_end.is_none(), "{at}");
            // The job's strokes in GP-GL steps, per tool, with passes.
            let mut expected: Vec<(String, Vec<[f64; 2]>)> = Vec::new();
            for s in &sheet.strokes {
                let Some(kind) = flatcut::toolpath::tool_kind(s.role, |q| p.has(q)) else {
                    continue;
                };
                let mut pts: Vec<[f64; 2]> = s
                    .points
                    .iter()
                    .map(|q| {
                        let d = flatcut::output::to_device(&p, sheet.width, sheet.height, *q);
                        [d.x, d.y]
                    })
                    .collect();
                pts.dedup_by(|a, b| a[0].round() == b[0].round() && a[1].round() == b[1].round());
                let passes = p.tool(kind).unwrap().passes() as usize;
                // The pen shares the knife's holder and sends no force: the simulator cannot
                // tell it from the knife by its force, so its name is not compared.
                let tool = if kind == profile::StrokeKind::Draw {
                    String::new()
                } else {
                    sim_name(&p, kind.name())
                };
                for _ in 0..passes {
                    expected.push((tool.clone(), pts.clone()));
                }
            }
            assert_eq!(rep.paths.len(), expected.len(), "{at}: path count");
            for (i, (got, (tool, want))) in rep.paths.iter().zip(&expected).enumerate() {
                if !tool.is_empty() {
                    assert_eq!(&got.tool, tool, "{at}: path {i}");
                }
                let want = if want.len() == 1 {
                    vec![want[0], want[0]]
                } else {
                    want.clone()
                };
                assert_eq!(got.points.len(), want.len(), "{at}: path {i} points");
                for (a, b) in got.points.iter().zip(&want) {
                    assert!(
                        (a[0] - b[0]).abs() <= 1.0 && (a[1] - b[1]).abs() <= 1.0,
                        "{at}: path {i}: {a:?} is more than one step from {b:?}"
                    );
                }
                paths_checked += 1;
            }
            sheets_checked += 1;
        }
    }
    eprintln!(
        "gpgl: {} patterns, {sheets_checked} sheets, {paths_checked} paths within one step",
        patterns.len()
    );
    assert!(paths_checked > 1000, "{paths_checked} paths");
    assert!(sheets_checked >= patterns.len());
}

#[test]
fn flatcut_devices_names_each_language() {
    let o = flatcut(&["devices"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    for (name, lang) in [
        ("graphtec-ce6000-gpgl", "GP-GL"),
        ("graphtec-ce6000", "HP-GL"),
        ("grbl-laser", "G-code"),
        ("sim", "HP-GL"),
    ] {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("{name} not listed: {text}"));
        assert_eq!(line.split_whitespace().nth(1), Some(lang), "{line}");
    }
}

#[test]
fn cut_and_send_speak_gpgl() {
    let out = scratch("gpgl-cut");
    let o = flatcut(&[
        "cut",
        "patterns/tetrahedron.toml",
        "--device",
        "graphtec-ce6000-gpgl",
        "--simulate",
        "--sim-speed",
        "0",
        "--baud",
        "115200",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let program = std::fs::read(out.join("tetrahedron.gpgl")).unwrap();
    assert!(program.starts_with(b"H\x03\n") && program.ends_with(b"H\x03\n"));
    let back = flatcut::output::gpgl::parse(&program).unwrap();
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("sim.json")).unwrap()).unwrap();
    assert_eq!(rep["language"], "gpgl");
    assert_eq!(rep["paths"].as_array().unwrap().len(), back.len());
    // `send` takes the .gpgl file, and refuses it for an HP-GL device.
    let file = out.join("tetrahedron.gpgl");
    let o = flatcut(&[
        "send",
        file.to_str().unwrap(),
        "--device",
        "graphtec-ce6000",
        "--simulate",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("HP-GL"), "{}", stderr(&o));
}
