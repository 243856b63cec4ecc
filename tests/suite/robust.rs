//! Issue 22's reproducers, each a regression test: inputs that once ran out of memory or time,
//! left the knife down, wrote outside the output folder or echoed a file, now end within
//! 10 s and 1 GB with exit 1 and a message (or 0 and a correct result).
//!
//! The binary runs under `ulimit -v` (1 GiB of address space) and `ulimit -t` (10 s of CPU)
//! ([`bounded`]); library-level cases check the same bounds on the function at fault.

use crate::common::*;
use flatcut::device::sim::{Faults, SimConfig};
use flatcut::device::stream::{self, StreamError, StreamOptions};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Run `flatcut` in `cwd` under 1 GiB of address space and 10 s of CPU (`ulimit -t`: the
/// bound holds on a loaded machine too, where wall time would not); a run that sleeps instead
/// (a hang waiting on something) fails the test after 60 s of wall time.
fn bounded_in(cwd: &Path, args: &[&str]) -> Output {
    use std::os::unix::process::ExitStatusExt;
    let mut child = Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 1048576; ulimit -t 10; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_flatcut"))
        .args(args)
        .current_dir(cwd)
        .env(
            "XDG_CONFIG_HOME",
            Path::new(env!("CARGO_TARGET_TMPDIR")).join("no-config"),
        )
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run flatcut");
    let t0 = Instant::now();
    loop {
        if child.try_wait().expect("wait").is_some() {
            break;
        }
        if t0.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("flatcut {args:?} ran over 60 s of wall time");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let o = child.wait_with_output().expect("output");
    // SIGXCPU (24) from `ulimit -t`, or SIGKILL once past the hard limit.
    if matches!(o.status.signal(), Some(24) | Some(9)) {
        panic!("flatcut {args:?} used over 10 s of CPU");
    }
    o
}

fn bounded(args: &[&str]) -> Output {
    bounded_in(Path::new(env!("CARGO_MANIFEST_DIR")), args)
}

/// Exit 1 with one `flatcut:` message that contains every needle.
fn refused(o: &Output, needles: &[&str]) -> String {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("flatcut:"), "{e}");
    for n in needles {
        assert!(e.contains(n), "{n:?} not in {e}");
    }
    e
}

fn s(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

#[test]
fn needle_obj_is_refused_before_any_stage_allocates() {
    let dir = scratch("robust-needle");
    std::fs::write(
        dir.join("needle.obj"),
        "v 0 0 0\nv 10 0 0\nv 0 0 1e9\nf 1 2 3\n",
    )
    .unwrap();
    // Refused as implausibly large (issue 21's size check) before any stage allocates by it.
    let o = bounded_in(&dir, &["cut", "needle.obj", "--dry-run", "-o", "out"]);
    refused(&o, &["needle.obj", "larger than 10 m"]);
}

#[test]
fn the_pole_of_a_needle_costs_what_a_square_costs() {
    // geom::polygon::pole on a ring 1e9 × 10 mm: its first grid is bounded.
    let ring = vec![
        glam::DVec2::new(0.0, 0.0),
        glam::DVec2::new(1e9, 0.0),
        glam::DVec2::new(1e9, 10.0),
        glam::DVec2::new(0.0, 10.0),
    ];
    let t0 = Instant::now();
    let (c, r) = flatcut::geom::polygon::pole(&[ring], 1.0).expect("a pole");
    assert!(t0.elapsed() < Duration::from_secs(2));
    assert!((r - 5.0).abs() < 1.0, "radius {r}");
    assert!((c.y - 5.0).abs() < 1.0, "{c}");
}

#[test]
fn rect_to_rect_with_a_huge_top_is_refused() {
    let o = bounded(&[
        "fitting",
        "rect-to-rect",
        "--width",
        "400",
        "--depth",
        "300",
        "--top-width",
        "1e19",
        "--top-depth",
        "150",
        "--height",
        "200",
        "--dry-run",
        "-o",
        &s(&scratch("robust-rect").join("out")),
    ]);
    refused(&o, &["coordinate"]);
}

/// The 160-point three-lobed outline 80·(1 + 0.3 cos 3a), its plane tilted 0.5 rad about x.
fn lobes() -> Vec<glam::DVec3> {
    (0..160)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / 160.0;
            let r = 80.0 * (1.0 + 0.3 * (3.0 * a).cos());
            let (x, y) = (r * a.cos(), r * a.sin());
            glam::DVec3::new(x, y * 0.5f64.cos(), y * 0.5f64.sin())
        })
        .collect()
}

#[test]
fn a_tilted_planar_loop_is_its_flat_polygon() {
    use flatcut::surface::boundary::{triangulate, Input, Options};
    let pts = lobes();
    let input = Input {
        loops: vec![pts.clone()],
        ..Input::default()
    };
    let t0 = Instant::now();
    let out = triangulate(&input, &Options::default()).expect("triangulates");
    assert!(t0.elapsed() < Duration::from_secs(5));
    assert_eq!(out.mesh.faces.len(), 158);
    assert!(out.figures.largest_dihedral_deg < 1e-6, "{:?}", out.figures);
    // The triangles' area is the polygon's: 0.5 ∮ r² da.
    let area: f64 = out
        .mesh
        .faces
        .iter()
        .map(|f| {
            let [a, b, c] = [f.verts[0], f.verts[1], f.verts[2]].map(|v| out.mesh.vertices[v]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    let n = pts.len();
    let mut exact = glam::DVec3::ZERO;
    for i in 0..n {
        exact += pts[i].cross(pts[(i + 1) % n]);
    }
    let exact = 0.5 * exact.length();
    assert!((area - exact).abs() < 1e-6 * exact, "{area} vs {exact}");

    // Through the CLI, from a CSV loop.
    let dir = scratch("robust-lobes");
    let mut csv = String::from("x,y,z\n");
    for p in &pts {
        csv.push_str(&format!("{},{},{}\n", p.x, p.y, p.z));
    }
    std::fs::write(dir.join("lobes.csv"), csv).unwrap();
    std::fs::write(
        dir.join("lobes.toml"),
        "name = \"lobes\"\n[[surface]]\nkind = \"boundary\"\nloop_csv = \"lobes.csv\"\n[sheet]\nwidth = 610\nroll = true\n",
    )
    .unwrap();
    let o = bounded_in(&dir, &["cut", "lobes.toml", "--dry-run", "-o", "out"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

fn far_program(dir: &Path) -> PathBuf {
    let p = dir.join("pa.plt");
    std::fs::write(&p, "SP2;PD;PA1e300,0;PU1,1;").unwrap();
    p
}

#[test]
fn a_far_coordinate_is_refused_before_the_first_byte() {
    let dir = scratch("robust-pa");
    let pa = s(&far_program(&dir));
    let out = s(&dir.join("out"));
    let o = bounded(&[
        "send",
        &pa,
        "--device",
        "sim-dragknife",
        "--simulate",
        "--sim-speed",
        "0",
        "-o",
        &out,
    ]);
    refused(&o, &["pa.plt", "instruction 3", "coordinate range"]);
    // To a real port: checked before the port is opened, so before any byte.
    let o = bounded(&[
        "send",
        &pa,
        "--device",
        "uscutter-mh",
        "--port",
        "/dev/flatcut-no-such-port",
    ]);
    refused(&o, &["pa.plt", "coordinate range"]);
}

#[test]
fn flatcut_sim_fed_a_far_coordinate_writes_its_report() {
    let dir = scratch("robust-sim");
    let mut child = Command::new(env!("CARGO_BIN_EXE_flatcut"))
        .args(["sim", "--device", "roland-gx24", "--for", "3", "-o"])
        .arg(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("flatcut sim");
    let mut out = std::io::BufReader::new(child.stdout.take().expect("stdout"));
    let mut line = String::new();
    std::io::BufRead::read_line(&mut out, &mut line).expect("listening line");
    let path = line.trim().trim_start_matches("listening on ").to_string();
    let profile = flatcut::profile::find("roland-gx24").unwrap();
    let mut link = flatcut::device::serial::open(&profile, &path, None).expect("open pty");
    link.write_some(b"IN;SP1;PD;PA1e300,0;PU1,1;SP0;")
        .expect("write");
    let _ = link.flush();
    drop(link);
    let t0 = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        assert!(t0.elapsed() < Duration::from_secs(10), "flatcut sim hangs");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(status.code(), Some(0));
    let json = std::fs::read_to_string(dir.join("sim.json")).expect("sim.json");
    assert!(json.contains("PA (out of range)"), "{json}");
    assert!(json.contains("\"tool_down_at_end\": null"), "{json}");
}

/// cylinder.obj with each face's first vertex replaced by a copy shifted by 1e-13: 2262
/// separate triangles.
fn shifted_cylinder(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(shared_data("meshes/cylinder.obj")).unwrap();
    let verts: Vec<&str> = text.lines().filter(|l| l.starts_with("v ")).collect();
    let mut out: Vec<String> = verts.iter().map(|v| v.to_string()).collect();
    let mut faces = Vec::new();
    for l in text.lines().filter(|l| l.starts_with("f ")) {
        let idx: Vec<&str> = l.split_whitespace().skip(1).collect();
        let i: usize = idx[0].split('/').next().unwrap().parse().unwrap();
        let c: Vec<f64> = verts[i - 1]
            .split_whitespace()
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect();
        out.push(format!("v {:e} {:e} {:e}", c[0] + 1e-13, c[1], c[2]));
        faces.push(format!("f {} {}", out.len(), idx[1..].join(" ")));
    }
    out.extend(faces);
    let p = dir.join("shifted.obj");
    std::fs::write(&p, out.join("\n") + "\n").unwrap();
    p
}

#[test]
fn nesting_thousands_of_loose_triangles_is_bounded() {
    require_shared!();
    let dir = scratch("robust-shifted");
    let obj = s(&shifted_cylinder(&dir));
    // The bottom-left construction alone (no improvement budget): once over 90 s of CPU.
    let o = bounded(&[
        "cut",
        &obj,
        // At its size as read (3 mm across), as the reproducer was.
        "--size",
        "3",
        "--dry-run",
        "--nest-time",
        "0",
        "-q",
        "-o",
        &s(&dir.join("out")),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn a_tiny_pipe_miter_orders_its_strokes_quickly() {
    let o = bounded(&[
        "fitting",
        "pipe-miter",
        "--diameter",
        "0.001",
        "--length",
        "300",
        "--angle",
        "45",
        "--dry-run",
        "-o",
        &s(&scratch("robust-miter").join("out")),
    ]);
    let e = stderr(&o);
    assert!(matches!(o.status.code(), Some(0) | Some(1)), "{e}");
}

#[test]
fn the_nearest_neighbour_grid_does_not_scan_the_whole_square() {
    use flatcut::toolpath::{Stroke, StrokeRole};
    // A tight cluster far from the pen (the pipe-miter case): the rings start at the grid.
    let strokes: Vec<Stroke> = (0..2000)
        .map(|k| {
            let p = glam::DVec2::new(
                5000.0 + (k % 50) as f64 * 1e-4,
                5000.0 + (k / 50) as f64 * 1e-4,
            );
            Stroke {
                role: StrokeRole::Cut,
                points: vec![p, p + glam::DVec2::new(1e-5, 0.0)],
                closed: false,
                piece: None,
                outer: false,
            }
        })
        .collect();
    let mut pen = glam::DVec2::ZERO;
    let t0 = Instant::now();
    let out = flatcut::toolpath::order::order_with(strokes, &mut pen, 1);
    assert_eq!(out.len(), 2000);
    assert!(t0.elapsed() < Duration::from_secs(5), "{:?}", t0.elapsed());
}

#[test]
fn baud_zero_is_refused() {
    let o = bounded(&["send", "patterns/cube.toml", "--baud", "0", "--simulate"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--baud"), "{}", stderr(&o));
    let o = bounded(&["cut", "patterns/cube.toml", "--baud", "0", "--dry-run"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--baud"), "{}", stderr(&o));
}

#[test]
fn inputs_must_be_regular_files() {
    let dir = scratch("robust-devzero");
    std::fs::write(
        dir.join("mesh.toml"),
        "name = \"z\"\n[[surface]]\nkind = \"mesh\"\npath = \"/dev/zero\"\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("loop.toml"),
        "name = \"z\"\n[[surface]]\nkind = \"boundary\"\nloop_csv = \"/dev/zero\"\n",
    )
    .unwrap();
    for args in [
        vec!["cut", "mesh.toml", "--dry-run", "-o", "out"],
        vec!["cut", "loop.toml", "--dry-run", "-o", "out"],
        vec!["check", "/dev/zero"],
        vec!["nest", "/dev/zero", "-o", "out"],
        vec!["cut", "/dev/zero", "--dry-run", "-o", "out"],
    ] {
        let o = bounded_in(&dir, &args);
        refused(&o, &["/dev/zero", "regular file"]);
    }
    let fifo = dir.join("fifo.obj");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        let o = bounded_in(&dir, &["check", "fifo.obj"]);
        refused(&o, &["fifo.obj", "FIFO"]);
    }
}

#[test]
fn a_program_ending_tool_down_gets_a_tool_up() {
    let dir = scratch("robust-down");
    let plt = dir.join("down.plt");
    std::fs::write(&plt, "IN;SP1;PU0,0;PD400,400;").unwrap();
    let o = bounded(&[
        "send",
        &s(&plt),
        "--simulate",
        "--sim-speed",
        "0",
        "-o",
        &s(&dir),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("tool-up"), "{}", stderr(&o));
    let json = std::fs::read_to_string(dir.join("sim.json")).unwrap();
    assert!(json.contains("\"tool_down_at_end\": null"), "{json}");
}

/// A G-code line over GRBL's 80 characters in the middle of a program once stopped the job
/// after 58 lines with the tool down: the streamer checks every line before the first byte.
#[test]
fn a_gcode_line_over_grbls_80_characters_is_refused_before_the_first_byte() {
    let dir = scratch("robust-long-line");
    let mut prog = String::from("G21\nG90\nG0 Z5\n");
    for i in 0..60 {
        if i == 30 {
            prog.push_str(&format!(
                "G1 X{:.6} Y{:.6} Z0.000000 F1500.000000 ; {}\n",
                10.0,
                10.0,
                "x".repeat(5)
            ));
            prog.push_str("G1 X10.0000000000001 Y20.0000000000001 Z-0.0000000000001 F1500.0000000000001 S1000.000\n");
        }
        prog.push_str(&format!("G1 X{} Y{} Z0 F1500\n", i % 7, i % 5));
    }
    prog.push_str("G0 Z5\n");
    let file = dir.join("long.gcode");
    std::fs::write(&file, &prog).unwrap();
    let line = prog
        .lines()
        .position(|l| l.starts_with("G1 X10.0000000000001"))
        .unwrap()
        + 1;
    let o = bounded(&[
        "send",
        &s(&file),
        "--device",
        "grbl-pen",
        "--simulate",
        "--sim-speed",
        "0",
        "-o",
        &s(&dir.join("out")),
    ]);
    refused(
        &o,
        &[&format!("line {line}"), "79 GRBL keeps", "nothing was sent"],
    );
    assert!(!stderr(&o).contains("resume"), "{}", stderr(&o));
    if let Ok(json) = std::fs::read_to_string(dir.join("out/sim.json")) {
        assert!(json.contains("\"tool_down_at_end\": null"), "{json}");
        assert!(json.contains("\"paths\": []"), "{json}");
    }
}

fn sim_opts(timeout: f64, cancel: Arc<AtomicBool>) -> StreamOptions {
    StreamOptions {
        timeout: Duration::from_secs_f64(timeout),
        progress: false,
        cancel,
        ..StreamOptions::default()
    }
}

/// A long slow job that fits in the device's buffer: 40 pen-down moves of 100 mm at 1 cm/s.
fn slow_job() -> Vec<u8> {
    let mut s = String::from("IN;SP1;VS1;PU0,0;");
    for k in 0..40 {
        s.push_str(if k % 2 == 0 { "PD4000,0;" } else { "PD0,0;" });
    }
    s.push_str("PU;SP0;");
    s.into_bytes()
}

#[test]
fn simulate_obeys_ctrl_c_while_the_device_works_off_its_buffer() {
    let profile = flatcut::profile::find("sim").unwrap();
    let mut cfg = SimConfig::new(profile);
    cfg.time_factor = Some(1.0);
    let cancel = Arc::new(AtomicBool::new(false));
    let c2 = cancel.clone();
    let t0 = Instant::now();
    let stopper = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(1500));
        c2.store(true, Ordering::SeqCst);
    });
    let (r, rep) = stream::stream_job(
        cfg,
        &slow_job(),
        &sim_opts(60.0, cancel),
        Duration::from_secs(3600),
    )
    .unwrap();
    stopper.join().unwrap();
    assert!(t0.elapsed() < Duration::from_secs(8), "{:?}", t0.elapsed());
    let e = r.unwrap_err();
    assert!(matches!(e, StreamError::Cancelled { .. }), "{e}");
    let at = e.position().unwrap();
    let done = rep.bytes_received - rep.unexecuted_bytes;
    assert_eq!(at.confirmed, Some(done), "{e}");
}

#[test]
fn a_stalled_device_is_reported_with_the_bytes_it_executed() {
    let mut profile = flatcut::profile::find("sim").unwrap();
    profile.serial.flow_control = flatcut::profile::FlowControl::XonXoff;
    profile.buffer = 256;
    let mut cfg = SimConfig::new(profile);
    cfg.faults = Faults {
        stall_after: Some(100),
        ..Faults::default()
    };
    let prog = slow_job();
    let t0 = Instant::now();
    let (r, rep) = stream::stream_job(
        cfg,
        &prog,
        &sim_opts(1.0, Arc::new(AtomicBool::new(false))),
        Duration::from_secs(3600),
    )
    .unwrap();
    assert!(t0.elapsed() < Duration::from_secs(10));
    let e = r.unwrap_err();
    let text = e.to_string();
    assert!(text.contains("timed out"), "{text}");
    assert!(text.contains("known executed by the device"), "{text}");
    assert!(!text.contains("the line is gone"), "{text}");
    let at = e.position().unwrap();
    assert!(at.confirmed.unwrap() <= 100, "{text}");
    assert!(at.confirmed.unwrap() <= rep.bytes_received);
}

#[test]
fn a_device_that_stalls_after_taking_the_whole_program_is_not_a_finished_job() {
    // A buffer larger than the program: the host writes it all before the device stalls, so
    // only the device's end can tell that the job did not run.
    let mut profile = flatcut::profile::find("sim").unwrap();
    profile.buffer = 4096;
    let mut cfg = SimConfig::new(profile);
    cfg.faults = Faults {
        stall_after: Some(100),
        ..Faults::default()
    };
    let prog = slow_job();
    let (r, rep) = stream::stream_job(
        cfg,
        &prog,
        &sim_opts(1.0, Arc::new(AtomicBool::new(false))),
        Duration::from_secs(3600),
    )
    .unwrap();
    assert_eq!(rep.ended, "stalled (fault)");
    let e = r.unwrap_err();
    let text = e.to_string();
    assert!(text.contains("timed out"), "{text}");
    assert!(text.contains("known executed by the device"), "{text}");
    let at = e.position().unwrap();
    assert!(at.confirmed.unwrap() <= 100, "{text}");
}

#[test]
fn cts_that_cannot_be_read_is_an_error() {
    // A pseudo-terminal has no modem lines: read for real (no virtual CTS), CTS fails.
    let profile = flatcut::profile::find("graphtec-ce6000").unwrap();
    assert_eq!(
        profile.serial.flow_control,
        flatcut::profile::FlowControl::RtsCts
    );
    let handle = flatcut::device::sim::spawn(SimConfig::new(profile.clone())).unwrap();
    let mut link = flatcut::device::serial::open(&profile, &handle.path, None).unwrap();
    let r = stream::send(
        &mut link,
        &profile,
        b"IN;SP1;PU0,0;PD400,400;PU;SP0;",
        &sim_opts(2.0, Arc::new(AtomicBool::new(false))),
    );
    let e = r.unwrap_err();
    assert!(matches!(e, StreamError::Cts { .. }), "{e}");
    drop(link);
    let _ = handle.stop();
}

#[test]
fn a_busy_port_says_it_is_busy() {
    let profile = flatcut::profile::find("sim").unwrap();
    let handle = flatcut::device::sim::spawn(SimConfig::new(profile.clone())).unwrap();
    let first = flatcut::device::serial::open(&profile, &handle.path, None).unwrap();
    let second = flatcut::device::serial::open(&profile, &handle.path, None);
    let e = second.err().expect("the port is taken").to_string();
    assert!(e.contains("busy"), "{e}");
    assert!(!e.contains("plugged in"), "{e}");
    drop(first);
    let _ = handle.stop();
}

#[test]
fn names_from_specs_and_flags_are_file_names() {
    let dir = scratch("robust-names");
    std::fs::create_dir_all(dir.join("a/b")).unwrap();
    let spec = std::fs::read_to_string(manifest("patterns/cube.toml"))
        .unwrap()
        .replace("name = \"cube\"", "name = \"../../escaped\"")
        .replace("cube.obj", &s(&manifest("patterns/cube.obj")));
    std::fs::write(dir.join("a/b/evil.toml"), spec).unwrap();
    let o = bounded_in(
        &dir.join("a/b"),
        &["cut", "evil.toml", "--dry-run", "-o", "out"],
    );
    refused(&o, &["evil.toml", "`name`", "file name"]);
    assert!(!dir.join("escaped.plt").exists());
    let o = bounded(&[
        "fitting",
        "cone",
        "--bottom-diameter",
        "300",
        "--top-diameter",
        "160",
        "--height",
        "200",
        "--name",
        "/tmp/flatcut-abs",
        "--dry-run",
        "-o",
        &s(&dir.join("out")),
    ]);
    refused(&o, &["--name", "file name"]);
}

#[test]
fn a_run_replaces_the_previous_run_in_its_folder() {
    let dir = scratch("robust-sets");
    let out = s(&dir.join("out"));
    // Two cubes: one sheet each on 400 mm sheets, both on one 1000 mm sheet.
    let spec = |w: u32| {
        let cube = s(&manifest("patterns/cube.obj"));
        let text = format!(
            "name = \"job\"\n[[surface]]\nkind = \"mesh\"\npath = \"{cube}\"\nname = \"a\"\n[[surface]]\nkind = \"mesh\"\npath = \"{cube}\"\nname = \"b\"\n[sheet]\nwidth = {w}\nheight = {w}\nmargin = 10\nspacing = 5\n"
        );
        let p = dir.join(format!("cube-{w}.toml"));
        std::fs::write(&p, text).unwrap();
        s(&p)
    };
    let small = spec(400);
    let o = bounded(&["cut", &small, "--dry-run", "-q", "-o", &out]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let many = std::fs::read_dir(&out).unwrap().count();
    assert!(
        dir.join("out/job-2.plt").exists(),
        "several sheets expected"
    );
    std::fs::write(dir.join("out/.job.svg.partial-deadbeef"), "stale").unwrap();
    std::fs::write(dir.join("out/notes.txt"), "the user's").unwrap();
    let big = spec(1000);
    let o = bounded(&["cut", &big, "--dry-run", "-q", "-o", &out]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        vec![
            ".flatcut-files",
            "job-1.png",
            "job.dxf",
            "job.pdf",
            "job.plt",
            "job.svg",
            "notes.txt",
            "report.json"
        ],
        "before: {many} files"
    );
}

#[test]
fn messages_name_file_line_and_key_and_never_echo_content() {
    let dir = scratch("robust-messages");
    for (n, line) in [(5, "v 1 2 3 4 5"), (7, "v 1 2 3 4 5 6 7")] {
        let obj = dir.join(format!("v{n}.obj"));
        std::fs::write(&obj, format!("v 0 0 0\nv 1 0 0\n{line}\nf 1 2 3\n")).unwrap();
        let o = bounded(&["check", &s(&obj)]);
        let e = refused(&o, &[&format!("v{n}.obj:3"), &format!("{n} numbers")]);
        assert!(!e.contains("color parse error"), "{e}");
    }
    // A profile type error names the key.
    let text = std::fs::read_to_string(manifest("devices/sim.toml")).unwrap();
    let bad = text.replacen("baud = 115200", "baud = \"fast\"", 1);
    assert_ne!(bad, text, "sim.toml sets baud = 115200");
    let e = flatcut::profile::parse(&bad, "bad.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("`serial.baud`"), "{e}");
    // Invalid UTF-8 has a position.
    let spec = dir.join("bin.toml");
    std::fs::write(&spec, b"name = \"x\"\n# caf\xe9\n").unwrap();
    let o = bounded(&["cut", &s(&spec), "--dry-run", "-o", &s(&dir.join("out"))]);
    refused(&o, &["bin.toml", "line 2, column 6"]);
    // A bad loop_csv never echoes the file.
    std::fs::write(
        dir.join("secret.csv"),
        "daemon:x:1:1:daemon:/usr/sbin\n1,2,3\nroot:x:0:0\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("loop.toml"),
        "name = \"l\"\n[[surface]]\nkind = \"boundary\"\nloop_csv = \"secret.csv\"\n",
    )
    .unwrap();
    let o = bounded_in(&dir, &["cut", "loop.toml", "--dry-run", "-o", "out"]);
    let e = refused(&o, &["secret.csv:3"]);
    assert!(!e.contains("root:x"), "{e}");
    assert!(!e.contains("daemon"), "{e}");
}

/// The fuzz harness's find: `jakobs1.json` with one item's demand mutated to 2^32 expanded it
/// into four billion items (out of memory). The reader refuses more than `MAX_ITEMS` in all,
/// naming the item.
#[test]
fn an_esicup_demand_beyond_the_item_bound_is_refused() {
    require_shared!();
    let dir = scratch("robust-esicup-demand");
    let text = std::fs::read_to_string(shared_data("nesting/jakobs1.json")).unwrap();
    let at = text.find("\"demand\": 1").expect("a demand of 1");
    let huge = format!("{}\"demand\": 4294967296{}", &text[..at], &text[at + 11..]);
    let file = dir.join("huge-demand.json");
    std::fs::write(&file, huge).unwrap();
    let o = bounded(&[
        "nest",
        &s(&file),
        "-o",
        &s(&dir.join("out")),
        "--nest-time",
        "1",
    ]);
    refused(&o, &["huge-demand.json", "item 0", "4294967296", "10000"]);
    assert!(!dir.join("out").join("solution.json").exists());
}

/// Fuzz finds (issue 22 item 6): a G-code program holding a character GRBL takes as a
/// real-time command (`G!` for `G1`: a feed hold) or a program pause written `M-0` held the
/// simulated GRBL for ever, past `--timeout`. Both are refused before the first byte.
#[test]
fn gcode_that_would_hold_grbl_for_ever_is_refused_before_the_first_byte() {
    let dir = scratch("robust-hold");
    let cases = [
        (
            "G21\nG90\nG0 X10\nG! X20 F1000\nG0 X0\n",
            "line 4",
            "`!` (feed hold)",
        ),
        ("G21\nG90\nG0 X10 (why?)\nG0 X0\n", "line 3", "`?`"),
        (
            "G21\nG90\nG0 X10\nM-0 S100\nG0 X0\n",
            "line 4",
            "program pause (M0)",
        ),
        ("G21\nG90\nM00\nG0 X0\n", "line 3", "program pause (M0)"),
    ];
    for (k, (prog, line, what)) in cases.iter().enumerate() {
        let file = dir.join(format!("hold{k}.gcode"));
        std::fs::write(&file, prog).unwrap();
        let t = Instant::now();
        let o = bounded(&[
            "send",
            &s(&file),
            "--device",
            "grbl-pen",
            "--simulate",
            "--sim-speed",
            "0",
            "--timeout",
            "5",
            "-o",
            &s(&dir.join(format!("out{k}"))),
        ]);
        assert!(t.elapsed() < Duration::from_secs(10), "{prog}");
        refused(&o, &[line, what, "nothing was sent"]);
        let json = std::fs::read_to_string(dir.join(format!("out{k}/sim.json"))).unwrap();
        assert!(json.contains("\"tool_down_at_end\": null"), "{json}");
    }
}

/// Fuzz find: a GP-GL program cut short after a `D` (tool-down move) exited 0 with the knife
/// down in sim.json; it now gets a tool-up where the tool stands, with a warning.
#[test]
fn a_gpgl_program_ending_tool_down_gets_a_tool_up() {
    let dir = scratch("robust-gpgl-down");
    let file = dir.join("down.gpgl");
    std::fs::write(&file, b"J1\x03M100,100\x03D400,400\x03D400,800").unwrap();
    let o = bounded(&[
        "send",
        &s(&file),
        "--device",
        "graphtec-ce6000-gpgl",
        "--simulate",
        "--sim-speed",
        "0",
        "-o",
        &s(&dir.join("out")),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("tool down") && e.contains("ETX"), "{e}");
    let json = std::fs::read_to_string(dir.join("out/sim.json")).unwrap();
    assert!(json.contains("\"tool_down_at_end\": null"), "{json}");
}

/// Fuzz find: the elbow segment at spacing 0 on a sheet too narrow for its blank (split into
/// three parts along rulings) exited 2, "pieces 1a and 1c overlap": parts that touch along a
/// straight edge overlapped by rounding. The search keeps a hair of a gap (`MIN_GAP_MM`).
#[test]
fn split_parts_at_spacing_zero_nest_apart() {
    let dir = scratch("robust-spacing-zero");
    let spec = std::fs::read_to_string(manifest("patterns/elbow-segment.toml")).unwrap();
    let spec = spec
        .replace("width = 1250\n", "")
        .replace("spacing = 5", "spacing = 0");
    assert!(spec.contains("spacing = 0"));
    std::fs::write(dir.join("elbow.toml"), spec).unwrap();
    std::fs::copy(
        manifest("patterns/elbow-cut.csv"),
        dir.join("elbow-cut.csv"),
    )
    .unwrap();
    let o = bounded_in(&dir, &["cut", "elbow.toml", "--dry-run", "-q", "-o", "out"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/report.json")).unwrap())
            .unwrap();
    assert!(report["pieces"].as_array().unwrap().len() >= 2, "{report}");
}

/// Issue 20, item 1: a piece whose faces overlap when laid flat is the flatten stage's own
/// fault, reported as a flatcut bug (exit code 2), never output.
#[test]
fn a_flatten_overlap_is_a_bug() {
    let e = flatcut::Error::from(flatcut::flatten::FlattenError::Overlap {
        surface: "s".into(),
        piece: 3,
        a: 10,
        b: 12,
    });
    assert_eq!(e.exit_code(), 2);
    let text = e.to_string();
    assert!(
        text.contains("piece 3") && text.contains("faces 10 and 12"),
        "{text}"
    );
}
