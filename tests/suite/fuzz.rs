//! Fuzzing that stays: a deterministic mutation test over the bundled inputs for every reader a
//! user's file reaches — the spec (TOML), OBJ, device profile, ESICUP, HP-GL readers in process,
//! and the simulator's HP-GL and GRBL interpreters through the real binary (`flatcut send
//! --simulate`), where an exit code other than 0 or 1 is a finding.
//!
//! Each case is a seed file mutated by a seeded generator (`flatcut::geom::rng::Rng`): bytes
//! flipped, deleted, repeated or inserted, numbers replaced by extreme values (1e300, -0, NaN,
//! 1e-300, huge integers), lines duplicated or dropped. A reader must return (Ok or an error)
//! without panicking, within [`CASE_LIMIT`]; the simulator runs must exit 0 or 1 within it.
//!
//! `cargo test` runs a bounded pass (a few seconds per target). The long run is the ignored
//! test [`fuzz_long`]: `FLATCUT_FUZZ_SECS=300 cargo test --release --test suite fuzz_long --
//! --ignored --nocapture` runs each target for that many seconds and prints, per target, the
//! cases run, the exit codes other than 0/1 (panics in process), and the runs over the limit.

use crate::common::*;
use flatcut::geom::rng::Rng;
use std::path::Path;
use std::time::{Duration, Instant};

/// Longest one case may take.
const CASE_LIMIT: Duration = Duration::from_secs(60);

/// Extreme values a number may be replaced by.
const EXTREMES: &[&str] = &[
    "1e300",
    "-1e300",
    "1e-300",
    "-0",
    "NaN",
    "inf",
    "99999999999999999999",
    "0",
    "-1",
    "1e19",
    "4294967296",
    "1e-13",
    "",
];

/// One mutation of `seed`.
fn mutate(seed: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut v = seed.to_vec();
    let rounds = 1 + rng.below(4);
    for _ in 0..rounds {
        let n = v.len().max(1);
        match rng.below(7) {
            0 => {
                if !v.is_empty() {
                    let i = rng.below(v.len());
                    v[i] ^= 1 << rng.below(8);
                }
            }
            1 => {
                let i = rng.below(n);
                let len = rng.below(16).min(v.len().saturating_sub(i));
                v.drain(i.min(v.len())..(i + len).min(v.len()));
            }
            2 => {
                let i = rng.below(n).min(v.len());
                let junk: Vec<u8> = (0..1 + rng.below(8))
                    .map(|_| rng.below(256) as u8)
                    .collect();
                v.splice(i..i, junk);
            }
            3 => {
                // A number replaced by an extreme value.
                let starts: Vec<usize> = (0..v.len())
                    .filter(|&i| v[i].is_ascii_digit() && (i == 0 || !v[i - 1].is_ascii_digit()))
                    .collect();
                if !starts.is_empty() {
                    let i = starts[rng.below(starts.len())];
                    let mut j = i;
                    while j < v.len() && (v[j].is_ascii_digit() || v[j] == b'.') {
                        j += 1;
                    }
                    let x = EXTREMES[rng.below(EXTREMES.len())].as_bytes().to_vec();
                    v.splice(i..j, x);
                }
            }
            4 => {
                // A line duplicated.
                let lines: Vec<&[u8]> = v.split(|&b| b == b'\n').collect();
                if !lines.is_empty() {
                    let k = rng.below(lines.len());
                    let mut out = Vec::new();
                    for (i, l) in lines.iter().enumerate() {
                        out.extend_from_slice(l);
                        out.push(b'\n');
                        if i == k {
                            out.extend_from_slice(l);
                            out.push(b'\n');
                        }
                    }
                    v = out;
                }
            }
            5 => {
                // A line dropped.
                let lines: Vec<&[u8]> = v.split(|&b| b == b'\n').collect();
                if lines.len() > 1 {
                    let k = rng.below(lines.len());
                    let kept: Vec<&[u8]> = lines
                        .iter()
                        .enumerate()
                        .filter(|(i, _)| *i != k)
                        .map(|(_, l)| *l)
                        .collect();
                    v = kept.join(&b'\n');
                }
            }
            _ => {
                // A range repeated.
                if !v.is_empty() {
                    let i = rng.below(v.len());
                    let len = (1 + rng.below(64)).min(v.len() - i);
                    let part = v[i..i + len].to_vec();
                    v.splice(i..i, part);
                }
            }
        }
    }
    v
}

/// What a target's run found.
#[derive(Debug, Default)]
struct Tally {
    cases: usize,
    /// Panics in process, or exit codes other than 0 and 1 (with the case and the code).
    bad: Vec<(usize, String)>,
    /// Cases over [`CASE_LIMIT`].
    slow: Vec<(usize, f64)>,
    slowest: f64,
}

/// The readers run in process: (name, seeds, reader). A reader returns whatever it likes; it
/// must not panic.
type Reader = fn(&[u8], &Path);

fn read_spec(b: &[u8], dir: &Path) {
    let text = String::from_utf8_lossy(b);
    let _ = flatcut::spec::parse(&text, &dir.join("fuzz.toml"));
}

fn read_obj(b: &[u8], dir: &Path) {
    let text = String::from_utf8_lossy(b);
    if let Ok(raw) = flatcut::surface::obj::parse(&text, &dir.join("fuzz.obj")) {
        let _ = flatcut::surface::obj::stats(&raw);
        let _ = flatcut::surface::obj::validate(raw, 1.0);
    }
}

fn read_profile(b: &[u8], _dir: &Path) {
    let _ = flatcut::profile::parse(&String::from_utf8_lossy(b), "fuzz.toml");
}

fn read_esicup(b: &[u8], dir: &Path) {
    let _ = flatcut::nest::esicup::parse(&String::from_utf8_lossy(b), &dir.join("fuzz.json"));
}

fn read_hpgl(b: &[u8], _dir: &Path) {
    let _ = flatcut::output::hpgl::parse(&String::from_utf8_lossy(b));
    if let Ok(p) = flatcut::profile::find("sim-dragknife") {
        // The simulated cutter's HP-GL interpreter, run over the whole program.
        let _ = flatcut::device::check::check_hpgl(b, &p);
    }
}

fn seeds_of(dir: &str, ext: &str) -> Vec<Vec<u8>> {
    let mut files: Vec<_> = std::fs::read_dir(manifest(dir))
        .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_else(|_| Vec::new());
    files.retain(|p: &std::path::PathBuf| p.extension().is_some_and(|x| x == ext));
    files.sort();
    files.iter().filter_map(|p| std::fs::read(p).ok()).collect()
}

fn esicup_seeds() -> Vec<Vec<u8>> {
    let mut v: Vec<Vec<u8>> = ["fu.json", "jakobs1.json"]
        .iter()
        .filter_map(|f| std::fs::read(shared_data(&format!("nesting/{f}"))).ok())
        .collect();
    v.push(
        br#"{"name":"t","strip_height":10,"items":[{"demand":2,"allowed_orientations":[0,90],"shape":{"type":"simple_polygon","data":[[0,0],[4,0],[4,3],[0,3]]}}]}"#
            .to_vec(),
    );
    v
}

/// Programs made by flatcut for the cube, for a device.
fn program_seed(device: &str, dir: &Path) -> Vec<u8> {
    let out = dir.join(format!("seed-{device}"));
    let o = flatcut(&[
        "cut",
        "patterns/cube.toml",
        "--device",
        device,
        "--dry-run",
        "-q",
        "-o",
        &out.to_string_lossy(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let ext = if device.starts_with("grbl") {
        "gcode"
    } else {
        "plt"
    };
    std::fs::read(out.join(format!("cube.{ext}"))).expect("seed program")
}

fn run_reader(name: &str, seeds: &[Vec<u8>], read: Reader, budget: Duration, max: usize) -> Tally {
    let dir = scratch(&format!("fuzz-{name}"));
    let mut rng = Rng::new(0x5eed ^ name.len() as u64);
    let mut t = Tally::default();
    let start = Instant::now();
    while t.cases < max && start.elapsed() < budget {
        let seed = &seeds[t.cases % seeds.len()];
        let case = mutate(seed, &mut rng);
        let t0 = Instant::now();
        let r = std::panic::catch_unwind(|| read(&case, &dir));
        let secs = t0.elapsed().as_secs_f64();
        if r.is_err() {
            let _ = std::fs::write(dir.join(format!("panic-{}.bin", t.cases)), &case);
            t.bad.push((t.cases, "panic".into()));
        }
        if secs > CASE_LIMIT.as_secs_f64() {
            t.slow.push((t.cases, secs));
        }
        t.slowest = t.slowest.max(secs);
        t.cases += 1;
    }
    t
}

/// A simulator target: each case is sent with `flatcut send --simulate --sim-speed 0`.
fn run_sim(name: &str, device: &str, ext: &str, budget: Duration, max: usize) -> Tally {
    let dir = scratch(&format!("fuzz-{name}"));
    let seed = program_seed(device, &dir);
    let mut rng = Rng::new(0x51 ^ name.len() as u64);
    let mut t = Tally::default();
    let start = Instant::now();
    while t.cases < max && start.elapsed() < budget {
        let case = mutate(&seed, &mut rng);
        let file = dir.join(format!("case.{ext}"));
        std::fs::write(&file, &case).expect("write case");
        let t0 = Instant::now();
        let o = flatcut(&[
            "send",
            &file.to_string_lossy(),
            "--device",
            device,
            "--simulate",
            "--sim-speed",
            "0",
            "--timeout",
            "5",
            "-q",
            "-o",
            &dir.join("out").to_string_lossy(),
        ]);
        let secs = t0.elapsed().as_secs_f64();
        match o.status.code() {
            Some(0) | Some(1) => {}
            code => {
                let _ = std::fs::write(dir.join(format!("bad-{}.{ext}", t.cases)), &case);
                t.bad.push((t.cases, format!("{code:?}: {}", stderr(&o))));
            }
        }
        if secs > CASE_LIMIT.as_secs_f64() {
            t.slow.push((t.cases, secs));
        }
        t.slowest = t.slowest.max(secs);
        t.cases += 1;
    }
    t
}

/// Every target for `budget` each (and at most `max` cases); returns (target, tally).
fn all_targets(budget: Duration, max: usize, sim_max: usize) -> Vec<(&'static str, Tally)> {
    let mut specs = seeds_of("patterns", "toml");
    specs.push(
        br#"name = "x"
[[surface]]
kind = "boundary"
loop_csv = "taco.csv"
"#
        .to_vec(),
    );
    let objs = seeds_of("patterns", "obj");
    let profiles = seeds_of("devices", "toml");
    let hpgl = vec![
        b"IN;SP1;PU0,0;PD400,400,800,0;PU;SP0;".to_vec(),
        b"IN;VS20;SP2;PA;PU100,100;PD200,100,200,200;PR;PD-100,0;PU;SP0;".to_vec(),
        b"IN;SP3;!FS120;PU40,40;PD80,40;SP0;".to_vec(),
    ];
    let readers: [(&'static str, Vec<Vec<u8>>, Reader); 5] = [
        ("spec", specs, read_spec),
        ("obj", objs, read_obj),
        ("profile", profiles, read_profile),
        ("esicup", esicup_seeds(), read_esicup),
        ("hpgl", hpgl, read_hpgl),
    ];
    let mut out = Vec::new();
    for (name, seeds, read) in readers {
        assert!(!seeds.is_empty(), "{name}: no seeds");
        out.push((name, run_reader(name, &seeds, read, budget, max)));
    }
    out.push((
        "sim-hpgl",
        run_sim("sim-hpgl", "sim-dragknife", "plt", budget, sim_max),
    ));
    out.push((
        "sim-grbl",
        run_sim("sim-grbl", "grbl-pen", "gcode", budget, sim_max),
    ));
    out
}

fn check(results: &[(&str, Tally)]) {
    let mut failed = Vec::new();
    for (name, t) in results {
        eprintln!(
            "fuzz {name}: {} cases, {} bad exits/panics, {} over {} s, slowest {:.2} s",
            t.cases,
            t.bad.len(),
            t.slow.len(),
            CASE_LIMIT.as_secs(),
            t.slowest
        );
        if !t.bad.is_empty() || !t.slow.is_empty() {
            failed.push(format!("{name}: {:?} {:?}", t.bad, t.slow));
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

#[test]
fn fuzz_bounded() {
    // A few seconds per target: readers up to 400 cases, simulator runs up to 12.
    check(&all_targets(Duration::from_secs(3), 400, 12));
}

#[test]
#[ignore = "the long fuzz run: FLATCUT_FUZZ_SECS per target (default 600)"]
fn fuzz_long() {
    let secs: u64 = std::env::var("FLATCUT_FUZZ_SECS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(600);
    check(&all_targets(
        Duration::from_secs(secs),
        usize::MAX,
        usize::MAX,
    ));
}
