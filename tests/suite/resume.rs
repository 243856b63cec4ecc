//! Resume (issue 22): a job interrupted on the simulated cutter and resumed from the journal's
//! stroke cuts every stroke once; `flatcut resume` reads the journal, refuses a changed program
//! and a stream whose end is unknown.

use flatcut::device::journal::{self, Journal, State};
use flatcut::device::sim::{Faults, SimConfig, SimPath};
use flatcut::device::stream::{self, StreamOptions};
use flatcut::profile::Language;
use std::process::Command;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

/// 30 strokes of 4 pen-down moves each, in HP-GL.
fn program() -> Vec<u8> {
    let mut s = String::from("IN;SP1;");
    for k in 0..30 {
        let x = 100 * k;
        s.push_str(&format!(
            "PU{x},0;PD{},0;PD{},40;PD{x},40;PD{x},0;",
            x + 40,
            x + 40
        ));
    }
    s.push_str("PU;SP0;");
    s.into_bytes()
}

fn run(
    bytes: &[u8],
    hang_up_after: Option<usize>,
) -> (Result<(), stream::StreamError>, Vec<SimPath>) {
    let profile = flatcut::profile::find("sim").unwrap();
    let mut cfg = SimConfig::new(profile);
    cfg.faults = Faults {
        hang_up_after,
        ..Faults::default()
    };
    let opts = StreamOptions {
        timeout: Duration::from_secs(5),
        progress: false,
        cancel: Arc::new(AtomicBool::new(false)),
        ..StreamOptions::default()
    };
    let (r, rep) = stream::stream_job(cfg, bytes, &opts, Duration::from_secs(60)).unwrap();
    (r.map(|_| ()), rep.paths)
}

fn same(a: &SimPath, b: &SimPath) -> bool {
    a.tool == b.tool
        && a.points.len() == b.points.len()
        && a.points
            .iter()
            .zip(&b.points)
            .all(|(p, q)| (p[0] - q[0]).abs() <= 1.0 && (p[1] - q[1]).abs() <= 1.0)
}

#[test]
fn a_job_hung_up_at_40_percent_and_resumed_cuts_every_stroke_once() {
    let prog = program();
    let (ok, full) = run(&prog, None);
    ok.unwrap();
    assert_eq!(full.len(), 30);
    let (r, first) = run(&prog, Some(prog.len() * 2 / 5));
    let e = r.unwrap_err();
    let at = e.position().expect("a position");
    let done = journal::finished_strokes(&prog, Language::Hpgl, at);
    assert!((5..25).contains(&done), "{done} strokes finished: {e}");
    // What the first run cut is the job's first strokes, and at most the start of one more.
    assert!(
        first.len() >= done && first.len() <= done + 1,
        "{} vs {done}",
        first.len()
    );
    for (a, b) in first.iter().zip(&full) {
        if !same(a, b) {
            let part = SimPath {
                tool: b.tool.clone(),
                points: b.points[..a.points.len().min(b.points.len())].to_vec(),
            };
            assert!(same(a, &part), "{a:?} is not the start of {b:?}");
        }
    }
    let again = journal::resume_program(&prog, Language::Hpgl, done).unwrap();
    let (ok, second) = run(&again, None);
    ok.unwrap();
    assert_eq!(second.len(), 30 - done);
    for (a, b) in second.iter().zip(&full[done..]) {
        assert!(same(a, b), "{a:?} vs {b:?}");
    }
}

fn flatcut(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_flatcut"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn flatcut_resume_goes_on_from_the_journals_stroke() {
    let dir = crate::common::scratch("resume-cli");
    let d = dir.to_str().unwrap();
    let prog = dir.join("job.plt");
    std::fs::write(&prog, program()).unwrap();
    let out = flatcut(&[
        "send",
        prog.to_str().unwrap(),
        "--sim-speed",
        "0",
        "-q",
        "-o",
        d,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut j = Journal::load(&dir).unwrap();
    assert_eq!(j.streams.len(), 1);
    assert_eq!(j.streams[0].state, State::Done);
    assert_eq!(j.streams[0].strokes, 30);
    let out = flatcut(&["resume", d]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("nothing to resume"));

    // As a stopped job would leave it: 12 strokes known finished.
    j.streams[0].state = State::Stopped;
    j.streams[0].finished = 12;
    j.save(&dir).unwrap();
    let out = flatcut(&["resume", d, "--sim-speed", "0"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("from stroke 13 of 30"));
    let sim: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("sim.json")).unwrap()).unwrap();
    let paths = sim["paths"].as_array().expect("paths in sim.json");
    assert_eq!(paths.len(), 18);
    assert_eq!(Journal::load(&dir).unwrap().streams[0].state, State::Done);

    // A stream whose end is not known needs the operator's stroke.
    j.streams[0].state = State::Sending;
    j.save(&dir).unwrap();
    let out = flatcut(&["resume", d, "--sim-speed", "0"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--from-stroke"));
    let out = flatcut(&["resume", d, "--sim-speed", "0", "--from-stroke", "29"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    // A program changed since it was sent is refused.
    j.save(&dir).unwrap();
    std::fs::write(&prog, b"IN;SP1;PU0,0;PD10,10;PU;SP0;").unwrap();
    let out = flatcut(&["resume", d, "--from-stroke", "1"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not the program that was sent"));
}
