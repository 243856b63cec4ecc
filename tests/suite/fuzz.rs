//! Fuzzing that stays: a deterministic mutation test over the bundled inputs for every reader a
//! user's file reaches — the spec (TOML), OBJ, device profile, ESICUP, HP-GL, G-code and GP-GL
//! readers and the simulated GRBL's interpreter in process; and through the real binary, the
//! simulator's HP-GL, GRBL and GP-GL interpreters (`flatcut send --simulate`) and the whole
//! pipeline from a spec or an OBJ file (`flatcut cut --dry-run`), where an exit code other than
//! 0 or 1, a run over 2 GiB of address space, or an exit 0 that left the tool down is a finding.
//!
//! Each case is a seed file mutated by a seeded generator (`flatcut::geom::rng::Rng`): bytes
//! flipped, deleted, repeated or inserted, numbers replaced by extreme values (1e300, -0, NaN,
//! 1e-300, huge integers), lines duplicated or dropped. A reader must return (Ok or an error)
//! without panicking, within [`CASE_LIMIT`]; the runs of the binary must exit 0 or 1 within it.
//!
//! `cargo test` runs a bounded pass (a few seconds per target). The long run is the ignored
//! test [`fuzz_long`]: `FLATCUT_FUZZ_SECS=300 cargo test --release --test suite fuzz_long --
//! --ignored --nocapture` runs each target for that many seconds and prints, per target, the
//! cases run, the exit codes other than 0/1 (panics in process), the runs over the limit and the
//! in-process peak memory; `FLATCUT_FUZZ_TARGET=sim-grbl,cut-obj` runs only those targets.

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
                // Mostly characters a text reader parses, sometimes any byte.
                const TEXT: &[u8] = b"0123456789.-+eE \n\t;,=[]\"/#abcfvxyzPADUSGMXYZF";
                let junk: Vec<u8> = (0..1 + rng.below(8))
                    .map(|_| {
                        if rng.below(4) == 0 {
                            rng.below(256) as u8
                        } else {
                            TEXT[rng.below(TEXT.len())]
                        }
                    })
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
    /// Runs of the binary that exited 0 (the rest exited 1 or are in `bad`).
    exit0: usize,
    /// Peak resident memory of the in-process run (MiB), where Linux reports it.
    peak_mib: Option<f64>,
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

fn read_gcode(b: &[u8], _dir: &Path) {
    let _ = flatcut::output::gcode_reach(b);
    if let Ok(p) = flatcut::profile::find("grbl-laser") {
        // The simulated GRBL's interpreter, line by line, as the controller would take them.
        let mut m = flatcut::device::sim::grbl::Grbl::new(&p);
        for line in String::from_utf8_lossy(b).lines() {
            let _ = m.execute(line, false);
        }
    }
}

fn read_gpgl(b: &[u8], _dir: &Path) {
    let _ = flatcut::output::gpgl::parse(b);
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

/// The program flatcut makes for the cube at 60 mm on one 290 × 390 mm sheet (within every
/// bundled device's media), for a device.
fn program_seed(device: &str, dir: &Path) -> Vec<u8> {
    let out = dir.join(format!("seed-{device}"));
    let o = flatcut(&[
        "cut",
        "patterns/cube.toml",
        "--device",
        device,
        "--sheet",
        "290x390",
        "--size",
        "60",
        "--dry-run",
        "-q",
        "-o",
        &out.to_string_lossy(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let ext = if device.starts_with("grbl") {
        "gcode"
    } else if device.ends_with("gpgl") {
        "gpgl"
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
        // On disk before it runs: a case that aborts the process (out of memory) is kept.
        let _ = std::fs::write(dir.join("current.bin"), &case);
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

/// Memory one run of the binary may use: its address space is limited to this under `sh -c
/// ulimit -v`, so a run that would grow past it fails to allocate and exits with a bad code.
const MEMORY_LIMIT_KIB: u64 = 2 * 1024 * 1024;

/// A target run through the release (or test) binary: each case is written to `case.{ext}` in
/// the target's folder and `args(case, out)` is run under [`MEMORY_LIMIT_KIB`] and a hard kill
/// after twice [`CASE_LIMIT`]. A run that exits 0 and wrote a `sim.json` must have ended with the
/// tool up.
struct BinTarget {
    name: &'static str,
    seeds: Vec<Vec<u8>>,
    ext: &'static str,
    /// Files the cases refer to (a spec's `loop_csv`, `path`), copied beside them.
    beside: Vec<std::path::PathBuf>,
    args: fn(&str, &str) -> Vec<String>,
}

fn sim_args(device: &str, case: &str, out: &str) -> Vec<String> {
    [
        "send",
        case,
        "--device",
        device,
        "--simulate",
        "--sim-speed",
        "0",
        "--baud",
        "115200",
        "--timeout",
        "5",
        "-q",
        "-o",
        out,
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

fn cut_args(case: &str, out: &str) -> Vec<String> {
    ["cut", case, "--dry-run", "-q", "-o", out]
        .iter()
        .map(|s| s.to_string())
        .collect()
}

fn run_bin(t: &BinTarget, budget: Duration, max: usize) -> Tally {
    let dir = scratch(&format!("fuzz-{}", t.name));
    for f in &t.beside {
        if let Some(n) = f.file_name() {
            let _ = std::fs::copy(f, dir.join(n));
        }
    }
    let mut rng = Rng::new(0x51 ^ t.name.len() as u64);
    let mut tally = Tally::default();
    let start = Instant::now();
    let case = dir.join(format!("case.{}", t.ext));
    let out = dir.join("out");
    let (case_s, out_s) = (case.to_string_lossy(), out.to_string_lossy());
    let kill_after = (2 * CASE_LIMIT.as_secs()).to_string();
    while tally.cases < max && start.elapsed() < budget {
        let bytes = mutate(&t.seeds[tally.cases % t.seeds.len()], &mut rng);
        std::fs::write(&case, &bytes).expect("write case");
        let _ = std::fs::remove_dir_all(&out);
        let t0 = Instant::now();
        let o = std::process::Command::new("sh")
            .arg("-c")
            .arg(format!(
                "ulimit -v {MEMORY_LIMIT_KIB}; exec timeout -s KILL {kill_after} \"$@\""
            ))
            .arg("sh")
            .arg(env!("CARGO_BIN_EXE_flatcut"))
            .args((t.args)(&case_s, &out_s))
            .stdin(std::process::Stdio::null())
            .output()
            .expect("run flatcut");
        let secs = t0.elapsed().as_secs_f64();
        let mut bad = match o.status.code() {
            Some(0) | Some(1) => None,
            code => Some(format!("exit {code:?}: {}", stderr(&o))),
        };
        if o.status.code() == Some(0) {
            tally.exit0 += 1;
            if let Ok(sim) = std::fs::read_to_string(out.join("sim.json")) {
                if !sim.contains("\"tool_down_at_end\": null") {
                    bad = Some("exit 0 with the tool down at the end".into());
                }
            }
        }
        if let Some(why) = bad {
            let _ = std::fs::write(dir.join(format!("bad-{}.{}", tally.cases, t.ext)), &bytes);
            tally.bad.push((tally.cases, why));
        }
        if secs > CASE_LIMIT.as_secs_f64() {
            tally.slow.push((tally.cases, secs));
        }
        tally.slowest = tally.slowest.max(secs);
        tally.cases += 1;
    }
    tally
}

/// Resets this process's peak resident memory (Linux `clear_refs` 5); false where it cannot.
fn reset_peak_memory() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// This process's peak resident memory in MiB since the last reset (`VmHWM`).
fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// The targets to run: all, or those named in `FLATCUT_FUZZ_TARGET` (comma-separated).
fn wanted(name: &str) -> bool {
    match std::env::var("FLATCUT_FUZZ_TARGET") {
        Ok(list) if !list.is_empty() => list.split(',').any(|t| t.trim() == name),
        _ => true,
    }
}

/// Every target for `budget` each (and at most `max` cases in process, `bin_max` through the
/// binary); returns (target, tally).
fn all_targets(budget: Duration, max: usize, bin_max: usize) -> Vec<(&'static str, Tally)> {
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
    let work = scratch("fuzz-seeds");
    let gcode = vec![
        program_seed("grbl-pen", &work),
        program_seed("grbl-laser", &work),
        program_seed("grbl-dragknife", &work),
    ];
    let gpgl = vec![program_seed("graphtec-ce6000-gpgl", &work)];
    let readers: [(&'static str, Vec<Vec<u8>>, Reader); 7] = [
        ("spec", specs.clone(), read_spec),
        ("obj", objs.clone(), read_obj),
        ("profile", profiles, read_profile),
        ("esicup", esicup_seeds(), read_esicup),
        ("hpgl", hpgl, read_hpgl),
        ("gcode", gcode.clone(), read_gcode),
        ("gpgl", gpgl.clone(), read_gpgl),
    ];
    let mut out = Vec::new();
    for (name, seeds, read) in readers {
        if !wanted(name) {
            continue;
        }
        assert!(!seeds.is_empty(), "{name}: no seeds");
        let measured = reset_peak_memory();
        let mut t = run_reader(name, &seeds, read, budget, max);
        t.peak_mib = peak_memory_mib().filter(|_| measured);
        out.push((name, t));
    }
    let mut beside: Vec<_> = std::fs::read_dir(manifest("patterns"))
        .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_else(|_| Vec::new());
    beside.retain(|p| p.extension().is_some_and(|x| x != "toml"));
    beside.sort();
    let bins = [
        BinTarget {
            name: "sim-hpgl",
            seeds: vec![program_seed("sim-dragknife", &work)],
            ext: "plt",
            beside: Vec::new(),
            args: |c, o| sim_args("sim-dragknife", c, o),
        },
        BinTarget {
            name: "sim-grbl",
            seeds: gcode,
            ext: "gcode",
            beside: Vec::new(),
            args: |c, o| sim_args("grbl-pen", c, o),
        },
        BinTarget {
            name: "sim-gpgl",
            seeds: gpgl,
            ext: "gpgl",
            beside: Vec::new(),
            args: |c, o| sim_args("graphtec-ce6000-gpgl", c, o),
        },
        BinTarget {
            name: "cut-spec",
            seeds: specs,
            ext: "toml",
            beside: beside.clone(),
            args: cut_args,
        },
        BinTarget {
            name: "cut-obj",
            seeds: objs,
            ext: "obj",
            beside: Vec::new(),
            args: cut_args,
        },
    ];
    for t in &bins {
        if wanted(t.name) {
            out.push((t.name, run_bin(t, budget, bin_max)));
        }
    }
    out
}

fn check(results: &[(&str, Tally)]) {
    let mut failed = Vec::new();
    for (name, t) in results {
        let memory = match t.peak_mib {
            Some(m) => format!(", peak memory {m:.0} MiB"),
            None => format!(", {} exited 0", t.exit0),
        };
        eprintln!(
            "fuzz {name}: {} cases, {} bad exits/panics, {} over {} s, slowest {:.2} s{memory}",
            t.cases,
            t.bad.len(),
            t.slow.len(),
            CASE_LIMIT.as_secs(),
            t.slowest
        );
        if t.peak_mib
            .is_some_and(|m| m > (MEMORY_LIMIT_KIB / 1024) as f64)
        {
            failed.push(format!("{name}: peak memory {:?} MiB", t.peak_mib));
        }
        if !t.bad.is_empty() || !t.slow.is_empty() {
            failed.push(format!("{name}: {:?} {:?}", t.bad, t.slow));
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

#[test]
fn fuzz_bounded() {
    // A few seconds per target: readers up to 400 cases, runs of the binary up to 12.
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
