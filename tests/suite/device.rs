//! Devices end to end through real pseudo-terminals: flatcut's serial transport on the slave
//! side, the simulated cutter on the master side. Flow control under load (XON/XOFF and
//! RTS/CTS into a 256-byte buffer), GRBL character counting against its 128-byte buffer,
//! `error:N` mid-job, faults (hang-up, silent device, stall, lost XON, garbage, missing port),
//! and a plain program using the kernel's XON/XOFF streaming into `flatcut sim`.

use crate::common::*;
use flatcut::device::serial;
use flatcut::device::sim::{self, Faults, SimConfig, SimReport};
use flatcut::device::stream::{self, StreamError, StreamOptions};
use flatcut::profile::{self, Profile, StatusQuery};
use std::time::Duration;

fn hpgl_profile(baud: u32, flow: &str, buffer: usize) -> Profile {
    profile::parse(
        &format!(
            "name='t'\ndescription='test cutter'\nlanguage='hpgl'\ndialect='hp-gl'\nunits_per_mm=40\n\
             buffer={buffer}\n[serial]\nbaud={baud}\nflow_control='{flow}'\n\
             [tools.cut]\npen=1\nspeed=20\n"
        ),
        "test.toml",
    )
    .unwrap()
}

fn opts(timeout_s: f64) -> StreamOptions {
    StreamOptions {
        timeout: Duration::from_secs_f64(timeout_s),
        // The simulator answers the reset at once; a loaded test machine can hold its thread
        // for a second or more.
        wake_timeout: Duration::from_secs(5),
        progress: false,
        ..StreamOptions::default()
    }
}

/// Stream `program` into a simulator of `profile`; returns what the host and the device saw.
fn run(
    profile: &Profile,
    program: &[u8],
    time_factor: Option<f64>,
    faults: Faults,
    o: &StreamOptions,
) -> (Result<stream::StreamReport, StreamError>, SimReport) {
    let mut cfg = SimConfig::new(profile.clone());
    cfg.time_factor = time_factor;
    cfg.faults = faults;
    stream::stream_job(cfg, program, o, Duration::from_secs(120)).unwrap()
}

/// About `size` bytes of HP-GL: 1 mm pen-down steps zig-zagging over a 100 mm square.
fn big_hpgl(size: usize) -> (Vec<u8>, usize) {
    let mut s = String::from("IN;SP1;PU0,0;\n");
    let mut k = 0usize;
    while s.len() < size {
        let x = (k % 100) * 40;
        let y = ((k / 100) % 100) * 40;
        s.push_str(&format!("PD{x},{y};\n"));
        k += 1;
    }
    s.push_str("PU;SP0;\n");
    (s.into_bytes(), k)
}

fn check_flow(flow: &str) {
    // A fast line (pty) and a device that draws slower than the line delivers, so the
    // buffer fills and flow control must act again and again.
    let p = hpgl_profile(2_000_000, flow, 256);
    let (prog, moves) = big_hpgl(1 << 20);
    // 1 mm at 20 cm/s is 5 ms; at ×40 it is 0.125 ms a ~12-byte instruction (~100 kB/s).
    let (r, rep) = run(&p, &prog, Some(40.0), Faults::default(), &opts(20.0));
    let r = r.unwrap();
    assert_eq!(r.bytes, prog.len());
    assert_eq!(rep.bytes_received, prog.len(), "no byte lost");
    assert_eq!(rep.overruns, 0, "{flow}: overruns");
    assert_eq!(rep.flow_violations, 0, "{flow}: host ignored a stop");
    if flow == "xon-xoff" {
        assert!(
            rep.xoff_sent > 10,
            "flow control never acted: {}",
            rep.xoff_sent
        );
        assert!(r.xoff_received > 10);
    }
    // Every move was drawn: one path, one step per PD after the first (which is at 0,0).
    assert_eq!(rep.paths.len(), 1);
    assert_eq!(rep.paths[0].points.len() - 1, moves - 1);
    assert_eq!(rep.tool_down_at_end, None);
}

#[test]
fn one_megabyte_over_xon_xoff_into_256_bytes() {
    check_flow("xon-xoff");
}

#[test]
fn one_megabyte_over_rts_cts_into_256_bytes() {
    check_flow("rts-cts");
}

#[test]
fn a_host_that_ignores_xoff_is_caught() {
    // Write straight into the pty, ignoring XOFF: the simulator must see the violation, also
    // when it reads on to answer `ESC . B` (status_query = "esc-b").
    // A slow device (×0.2): each stop lasts longer than the grace the simulator allows a host
    // to react, which is what makes a violation measurable.
    for query in [StatusQuery::None, StatusQuery::EscB] {
        let mut p = hpgl_profile(115_200, "xon-xoff", 256);
        p.serial.status_query = query;
        let mut cfg = SimConfig::new(p.clone());
        cfg.time_factor = Some(0.2);
        let h = sim::spawn(cfg).unwrap();
        let mut port = serial::open(&p, &h.path, None).unwrap();
        // Steadily, as a host pacing at a line rate but deaf to XOFF would (the pty shows at
        // most 4 kB waiting, so a flood all at once would hide the growth).
        let (prog, _) = big_hpgl(6_400);
        for c in prog.chunks(64) {
            let _ = port.write_some(c);
            std::thread::sleep(Duration::from_millis(10));
        }
        // The simulator counts the bytes that keep coming once its grace for reacting to XOFF
        // is over: wait for that count rather than a fixed time.
        assert!(h.wait_for_violation(Duration::from_secs(10)), "{query:?}");
        let rep = h.stop().unwrap();
        assert!(rep.xoff_sent >= 1);
        assert!(rep.violations() > 0, "{query:?}: {rep:?}");
        let _ = port.flush();
    }
}

fn grbl_profile(protocol: &str) -> Profile {
    profile::parse(
        &format!(
            "name='g'\ndescription='grbl knife'\nlanguage='gcode'\ndialect='grbl'\nunits_per_mm=1\n\
             buffer=128\nprotocol='{protocol}'\n[serial]\nbaud=115200\n\
             [tools.cut]\nz_down=-1\nz_up=2\nspeed=3000\n"
        ),
        "grbl.toml",
    )
    .unwrap()
}

/// A G-code job of `n` cut strokes (squares of 10 mm).
fn gcode_job(n: usize) -> String {
    let mut s = String::from("G21\nG90\nG94\n");
    for k in 0..n {
        let (x, y) = ((k % 10) as f64 * 12.0, (k / 10) as f64 * 12.0);
        s.push_str(&format!("G0 Z2\nG0 X{x} Y{y}\nG1 Z-1 F3000\n"));
        for (dx, dy) in [(10.0, 0.0), (10.0, 10.0), (0.0, 10.0), (0.0, 0.0)] {
            s.push_str(&format!("G1 X{} Y{}\n", x + dx, y + dy));
        }
        s.push_str("G0 Z2\n");
    }
    s.push_str("M5\nM2\n");
    s
}

#[test]
fn grbl_character_counting_never_exceeds_128_bytes() {
    let p = grbl_profile("grbl-character-counting");
    let job = gcode_job(60);
    // ×20: a 10 mm side takes 10 ms, so the planner fills and lines wait in the buffer.
    let (r, rep) = run(
        &p,
        job.as_bytes(),
        Some(20.0),
        Faults::default(),
        &opts(10.0),
    );
    let r = r.unwrap();
    assert_eq!(rep.overruns, 0, "more than 128 bytes outstanding");
    assert!(
        rep.max_buffer_fill > 64,
        "character counting should keep the buffer full: {}",
        rep.max_buffer_fill
    );
    assert!(rep.errors_sent.is_empty(), "{:?}", rep.errors_sent);
    assert_eq!(r.lines, job.lines().count());
    assert_eq!(rep.paths.len(), 60);
    for (k, path) in rep.paths.iter().enumerate() {
        assert_eq!(path.tool, "cut");
        let (x, y) = ((k % 10) as f64 * 12.0, (k / 10) as f64 * 12.0);
        assert_eq!(path.points[0], [x, y]);
        assert_eq!(path.points.len(), 5);
    }
    assert_eq!(rep.tool_down_at_end, None);
}

#[test]
fn a_naive_grbl_host_overruns_the_simulated_buffer() {
    // The check must be able to fail: pour a job in without counting.
    let p = grbl_profile("grbl-character-counting");
    let mut cfg = SimConfig::new(p.clone());
    cfg.time_factor = Some(1.0);
    let h = sim::spawn(cfg).unwrap();
    let mut port = serial::open(&p, &h.path, None).unwrap();
    let job = gcode_job(30);
    for c in job.as_bytes().chunks(256) {
        let _ = port.write_some(c);
    }
    assert!(h.wait_for_violation(Duration::from_secs(10)));
    let rep = h.stop().unwrap();
    assert!(rep.overruns > 0, "{rep:?}");
    let _ = port.flush();
}

#[test]
fn grbl_send_response_streams_too() {
    let p = grbl_profile("grbl-send-response");
    let job = gcode_job(5);
    let (r, rep) = run(&p, job.as_bytes(), None, Faults::default(), &opts(10.0));
    r.unwrap();
    assert_eq!(rep.overruns, 0);
    assert!(rep.max_buffer_fill <= 30, "one line at a time");
    assert_eq!(rep.paths.len(), 5);
}

#[test]
fn grbl_error_stops_the_job_with_line_meaning_and_tool_up() {
    let p = grbl_profile("grbl-character-counting");
    let job = gcode_job(20);
    // Line 30 of the job (the reset line does not count: it is a real-time byte).
    let faults = Faults {
        grbl_error: Some((30, 20)),
        ..Faults::default()
    };
    let (r, rep) = run(&p, job.as_bytes(), Some(50.0), faults, &opts(10.0));
    let e = r.unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(
            e,
            StreamError::Grbl {
                code: 20,
                line: 30,
                ..
            }
        ),
        "{msg}"
    );
    assert!(
        msg.contains("error:20") && msg.contains("unsupported"),
        "{msg}"
    );
    let text = job.lines().nth(29).unwrap();
    assert!(msg.contains(text), "{msg}");
    assert!(msg.contains("tool lifted"), "{msg}");
    assert!(msg.contains("last acknowledged line 29"), "{msg}");
    assert_eq!(rep.tool_down_at_end, None, "{rep:?}");
    assert!(rep.paths.len() < 20);
}

#[test]
fn hang_up_mid_job_says_how_far_it_got() {
    let p = hpgl_profile(115_200, "xon-xoff", 1024);
    // Far more than the pseudo-terminal's queues hold (about 64 kB): a simulator thread held
    // off the CPU cannot let the whole program through before it hangs up.
    let (prog, _) = big_hpgl(200_000);
    let faults = Faults {
        hang_up_after: Some(5000),
        ..Faults::default()
    };
    let (r, rep) = run(&p, &prog, None, faults, &opts(5.0));
    let e = r.unwrap_err();
    assert!(matches!(e, StreamError::HungUp { .. }), "{e}");
    let at = e.position().unwrap();
    assert!(at.bytes >= 5000 && at.bytes < 200_000, "{at:?}");
    assert!(e.to_string().contains("byte"), "{e}");
    assert_eq!(rep.ended, "hung up (fault)");

    let g = grbl_profile("grbl-character-counting");
    let faults = Faults {
        hang_up_after: Some(700),
        ..Faults::default()
    };
    let (r, _) = run(&g, gcode_job(30).as_bytes(), None, faults, &opts(5.0));
    let e = r.unwrap_err();
    assert!(matches!(e, StreamError::HungUp { .. }), "{e}");
    assert!(e.position().unwrap().line.unwrap() > 0, "{e}");
}

#[test]
fn silent_and_stalled_devices_time_out_naming_the_operation() {
    // GRBL that never answers: no welcome.
    let g = grbl_profile("grbl-character-counting");
    let faults = Faults {
        stall_after: Some(0),
        ..Faults::default()
    };
    let (r, _) = run(&g, gcode_job(3).as_bytes(), None, faults, &opts(1.0));
    let e = r.unwrap_err();
    assert!(matches!(e, StreamError::NoWelcome { .. }), "{e}");

    // GRBL that stops answering mid-job.
    let faults = Faults {
        stall_after: Some(400),
        ..Faults::default()
    };
    let (r, _) = run(&g, gcode_job(30).as_bytes(), None, faults, &opts(1.0));
    let e = r.unwrap_err();
    assert!(e.to_string().contains("waiting for GRBL to answer"), "{e}");

    // HP-GL device that jams: buffer fills, XOFF, no XON ever.
    let p = hpgl_profile(115_200, "xon-xoff", 256);
    let faults = Faults {
        stall_after: Some(100),
        ..Faults::default()
    };
    // Far more than the pty's queues hold, so that a late XOFF (a loaded machine holding the
    // simulator's thread) still finds the host sending.
    let (prog, _) = big_hpgl(200_000);
    let (r, _) = run(&p, &prog, None, faults, &opts(1.0));
    let e = r.unwrap_err();
    assert!(e.to_string().contains("waiting for XON"), "{e}");
    assert!(e.position().unwrap().bytes < 200_000);

    // A lost XON is the same to the host: it says so after the timeout.
    let faults = Faults {
        lose_xon: true,
        ..Faults::default()
    };
    let (r, rep) = run(&p, &prog, Some(5.0), faults, &opts(1.0));
    let e = r.unwrap_err();
    assert!(e.to_string().contains("waiting for XON"), "{e}");
    assert_eq!(rep.xon_sent, 0);
}

#[test]
fn garbage_on_the_line_does_not_stop_a_job() {
    let p = hpgl_profile(115_200, "xon-xoff", 1024);
    let (prog, _) = big_hpgl(8000);
    let faults = Faults {
        garbage_after: Some(2000),
        ..Faults::default()
    };
    let (r, rep) = run(&p, &prog, None, faults.clone(), &opts(5.0));
    let r = r.unwrap();
    assert!(r.garbage_bytes > 0);
    assert_eq!(rep.bytes_received, prog.len());

    let g = grbl_profile("grbl-character-counting");
    let job = gcode_job(10);
    assert!(job.len() > 600);
    let faults = Faults {
        garbage_after: Some(300),
        ..Faults::default()
    };
    let (r, rep) = run(&g, job.as_bytes(), None, faults, &opts(5.0));
    let r = r.unwrap();
    assert!(r.garbage_bytes > 0, "the garbage was sent mid-job");
    assert_eq!(rep.paths.len(), 10);
}

#[test]
fn missing_port_is_exit_1_with_one_line() {
    let dir = scratch("missing-port");
    let plt = dir.join("x.plt");
    std::fs::write(&plt, "IN;SP1;PU0,0;PD100,0;PU;SP0;\n").unwrap();
    let o = flatcut(&[
        "send",
        plt.to_str().unwrap(),
        "--device",
        "hpgl-pens",
        "--port",
        "/dev/ttyNOPE0",
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("/dev/ttyNOPE0"), "{err}");
    // A real device with no port given.
    let o = flatcut(&["send", plt.to_str().unwrap(), "--device", "hpgl-pens"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--port"), "{}", stderr(&o));
    // G-code file to an HP-GL device.
    let nc = dir.join("x.gcode");
    std::fs::write(&nc, "G0 X1\n").unwrap();
    let o = flatcut(&["send", nc.to_str().unwrap(), "--device", "sim"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("x.gcode"), "{}", stderr(&o));
}

#[test]
fn a_plain_program_with_kernel_xon_xoff_streams_into_flatcut_sim() {
    use std::io::{BufRead, BufReader};
    use std::process::{Command, Stdio};
    let dir = scratch("external-client");
    let mut child = Command::new(env!("CARGO_BIN_EXE_flatcut"))
        .args(["sim", "--device", "sim", "--speed", "2", "--for", "8", "-o"])
        .arg(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut first = String::new();
    out.read_line(&mut first).unwrap();
    let path = first
        .trim()
        .strip_prefix("listening on ")
        .unwrap_or_else(|| panic!("first line: {first}"))
        .to_string();
    // 12 kB of HP-GL into a 1024-byte buffer, by `stty ixon` and `cat`: the kernel honours
    // the simulator's XOFF, no flatcut code on this side.
    let (prog, moves) = big_hpgl(12_000);
    let file = dir.join("job.plt");
    std::fs::write(&file, &prog).unwrap();
    let st = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "stty -F {path} raw -echo ixon 115200 && cat {} > {path}",
            file.display()
        ))
        .status()
        .unwrap();
    assert!(st.success());
    let mut rest = String::new();
    for l in out.lines() {
        rest.push_str(&l.unwrap());
        rest.push('\n');
    }
    assert!(child.wait().unwrap().success(), "{rest}");
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("sim.json")).unwrap()).unwrap();
    assert_eq!(rep["bytes_received"], prog.len());
    assert_eq!(rep["overruns"], 0);
    assert_eq!(rep["flow_violations"], 0);
    assert!(rep["xoff_sent"].as_u64().unwrap() >= 1, "{rest}");
    let steps: usize = rep["paths"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["points"].as_array().unwrap().len() - 1)
        .sum();
    assert_eq!(steps, moves - 1);
    assert!(dir.join("sim.png").is_file());
}

/// The name the simulator gives the tool of `kind`: the first tool (in the profile's order)
/// it cannot tell apart from it — same pen and force (HP-GL), same Z, servo or power (G-code).
fn sim_name(p: &Profile, kind: &str) -> String {
    let t = &p.tools[kind];
    let key = |u: &profile::Tool| (u.pen, u.force, u.z_down, u.servo_down, u.power);
    p.tools
        .iter()
        .find(|(_, u)| key(u) == key(t))
        .map(|(k, _)| k.clone())
        .unwrap()
}

#[test]
fn every_bundled_profile_cuts_the_house_through_the_simulator() {
    let spec = flatcut::spec::load(&manifest("patterns/house.toml")).unwrap();
    for (file, _) in profile::BUNDLED {
        let name = file.trim_end_matches(".toml");
        let p = profile::find(name).unwrap();
        let out = scratch(&format!("profile-{name}"));
        let o = flatcut(&[
            "cut",
            "patterns/house.toml",
            "--device",
            name,
            "--simulate",
            "--sim-speed",
            "0",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let rep: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("sim.json")).unwrap()).unwrap();
        assert_eq!(rep["overruns"], 0, "{name}");
        assert_eq!(rep["flow_violations"], 0, "{name}");
        assert!(rep["tool_down_at_end"].is_null(), "{name}");
        assert!(out.join("sim.png").is_file(), "{name}");

        // What the job asked for, in device units, per tool, with passes: the machine's job
        // (overcut, drag-knife holder path and precut included).
        let (_, _, design) = flatcut::pipeline::plan_job(&spec, &p, true).unwrap();
        let job = flatcut::pipeline::machine_job(&design, &p, &spec);
        assert_eq!(job.sheets.len(), 1);
        let sheet = &job.sheets[0];
        // With a drag knife the simulator records the trailing blade tip: what the design
        // asked for, not the holder's path. The precut comes first.
        let precut = usize::from(sheet.strokes.len() == design.sheets[0].strokes.len() + 1);
        let hpgl = p.language != flatcut::profile::Language::Gcode;
        let round = |v: f64| {
            if hpgl {
                v.round()
            } else {
                (v * 1000.0).round() / 1000.0
            }
        };
        let dev = |q: glam::DVec2| {
            let d = flatcut::output::to_device(&p, sheet.width, sheet.height, q);
            [round(d.x), round(d.y)]
        };
        // (tool, points, drag knife: the design's points instead)
        type Pts = Vec<[f64; 2]>;
        let mut expected: Vec<(String, Pts, Option<Pts>)> = Vec::new();
        for (i, s) in sheet.strokes.iter().enumerate() {
            let Some(kind) = flatcut::toolpath::tool_kind(s.role, |k| p.has(k)) else {
                continue;
            };
            let Some(tool) = p.tool(kind) else { continue };
            let mut pts: Vec<[f64; 2]> = s.points.iter().map(|q| dev(*q)).collect();
            pts.dedup();
            let tip: Option<Vec<[f64; 2]>> = p.is_drag_knife(kind).then(|| {
                if i < precut {
                    pts.clone()
                } else {
                    design.sheets[0].strokes[i - precut]
                        .points
                        .iter()
                        .map(|q| dev(*q))
                        .collect()
                }
            });
            let passes = tool.passes.unwrap_or(1) as usize;
            let tool_name = sim_name(&p, kind.name());
            if pts.len() > 1 && pts.first() == pts.last() {
                let mut all = pts.clone();
                for _ in 1..passes {
                    all.extend_from_slice(&pts[1..]);
                }
                expected.push((tool_name, all, tip));
            } else {
                for _ in 0..passes {
                    expected.push((tool_name.clone(), pts.clone(), tip.clone()));
                }
            }
        }
        let got = rep["paths"].as_array().unwrap();
        assert_eq!(got.len(), expected.len(), "{name}: path count");
        let tol = if hpgl { 1.0 } else { 0.002 };
        for (k, (g, (tool, pts, tip))) in got.iter().zip(&expected).enumerate() {
            assert_eq!(g["tool"].as_str().unwrap(), tool, "{name}: path {k}");
            let gp: Vec<[f64; 2]> = g["points"]
                .as_array()
                .unwrap()
                .iter()
                .map(|q| [q[0].as_f64().unwrap(), q[1].as_f64().unwrap()])
                .collect();
            if let Some(tip) = tip {
                // The blade tip stays within 0.06 mm of the line the design asked for (the
                // precut: within the offset of the holder's line, the blade aligning on it).
                let upm = p.units_per_mm;
                let slack = if k == 0 && precut == 1 {
                    p.knife_offset
                } else {
                    0.0
                };
                let line: Vec<glam::DVec2> = tip.iter().map(|q| glam::DVec2::from(*q)).collect();
                for a in &gp {
                    let a = glam::DVec2::from(*a);
                    let d = if line.len() == 1 {
                        a.distance(line[0])
                    } else {
                        line.windows(2)
                            .map(|w| flatcut::geom::polygon::segment_distance(a, w[0], w[1]))
                            .fold(f64::INFINITY, f64::min)
                    };
                    assert!(
                        d <= (0.06 + slack) * upm + tol,
                        "{name}: path {k}: blade tip {a} is {} mm off the design",
                        d / upm
                    );
                }
                continue;
            }
            assert_eq!(gp.len(), pts.len(), "{name}: path {k} points");
            for (a, b) in gp.iter().zip(pts) {
                assert!(
                    (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol,
                    "{name}: path {k}: {a:?} vs {b:?}"
                );
            }
        }
    }
}

#[test]
fn ctrl_c_stops_the_stream_lifts_the_tool_and_says_where() {
    use std::process::{Command, Stdio};
    let dir = scratch("ctrl-c");
    let (prog, _) = big_hpgl(60_000);
    let file = dir.join("long.plt");
    std::fs::write(&file, &prog).unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_flatcut"))
        .args([
            "send",
            file.to_str().unwrap(),
            "--device",
            "sim",
            "--sim-speed",
            "1",
            "-o",
        ])
        .arg(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let st = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(st.success());
    let o = child.wait_with_output().unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("stopped by Ctrl-C"), "{err}");
    assert!(err.contains("machine lifts the tool"), "{err}");
    assert!(err.contains("byte"), "{err}");
    // The simulator's record is still written, and the knife is up.
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("sim.json")).unwrap()).unwrap();
    assert!(rep["tool_down_at_end"].is_null(), "{rep}");
    assert!(rep["bytes_received"].as_u64().unwrap() < prog.len() as u64);
}

#[test]
fn user_profiles_add_and_replace_bundled_ones() {
    use std::process::Command;
    let home = scratch("xdg");
    let dir = home.join("flatcut").join("devices");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("my-cutter.toml"),
        "name='my-cutter'\ndescription='the one in the basement'\nlanguage='hpgl'\ndialect='hp-gl'\n\
         units_per_mm=40\n[serial]\nbaud=38400\nflow_control='xon-xoff'\n[tools.cut]\npen=1\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("sim.toml"),
        "name='sim'\ndescription='my own sim'\nlanguage='hpgl'\ndialect='hp-gl'\nunits_per_mm=40\n\
         [serial]\nbaud=57600\nflow_control='xon-xoff'\n[tools.cut]\npen=1\n",
    )
    .unwrap();
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_flatcut"))
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .env("XDG_CONFIG_HOME", &home)
            .output()
            .unwrap()
    };
    let o = run(&["devices"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("my-cutter") && out.contains("the one in the basement"),
        "{out}"
    );
    assert!(
        out.contains("my own sim") && out.contains("grbl-laser"),
        "{out}"
    );
    let scratch_out = home.join("out");
    let o = run(&[
        "cut",
        "patterns/tetrahedron.toml",
        "--device",
        "my-cutter",
        "--simulate",
        "--sim-speed",
        "0",
        "-o",
        scratch_out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(scratch_out.join("sim.json")).unwrap())
            .unwrap();
    assert_eq!(rep["baud"], 38400);
    assert_eq!(rep["device"], "my-cutter");
    // A broken user profile names its file and line.
    std::fs::write(dir.join("broken.toml"), "name='b'\nspeeed=3\n").unwrap();
    let o = run(&["devices"]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.contains("broken.toml") && err.contains("line 2"),
        "{err}"
    );
}

#[test]
fn without_flow_control_the_buffer_paces_the_stream() {
    // 1.5 kB of 1 mm moves into a 512-byte device with no handshake, executing at the real
    // speed (20 cm/s): sending at the line rate would overrun it many times over.
    let mut p = hpgl_profile(9600, "none", 512);
    p.serial.flow_control = flatcut::profile::FlowControl::None;
    let (prog, moves) = big_hpgl(1500);
    let (r, rep) = run(&p, &prog, Some(1.0), Faults::default(), &opts(10.0));
    r.unwrap();
    assert_eq!(rep.overruns, 0, "{}", rep.max_buffer_fill);
    assert_eq!(rep.paths[0].points.len(), moves);
    // The same device five times slower than its program says: the check sees the overruns.
    // The bytes it lost run numbers together into far moves, so it is not left to finish them.
    let mut cfg = SimConfig::new(p.clone());
    cfg.time_factor = Some(0.2);
    // Five times slower, it cannot work off its 1.5 kB in the 2 s it is given: the job is not
    // reported finished while the device still holds bytes.
    let (r, rep) = stream::stream_job(cfg, &prog, &opts(10.0), Duration::from_secs(2)).unwrap();
    assert!(rep.overruns > 0);
    assert!(rep.unexecuted_bytes > 0, "{rep:?}");
    assert!(matches!(r, Err(StreamError::Timeout { .. })), "{r:?}");
}

/// A controller that takes the first lines, then reports `Run` at one position for ever and
/// never answers `ok` again (a stuck machine, as grbl-sim is when its stepper starves on a
/// loaded host): the job times out instead of waiting for ever.
#[test]
fn a_grbl_that_says_run_but_never_moves_times_out() {
    use serialport::SerialPort;
    use std::io::{Read, Write};
    let p = grbl_profile("grbl-character-counting");
    let (mut master, slave) = serialport::TTYPort::pair().expect("pty pair");
    serial::close_on_exec(&master);
    serial::close_on_exec(&slave);
    let path = slave.name().unwrap();
    let peer = std::thread::spawn(move || {
        master.set_timeout(Duration::from_millis(20)).ok();
        let started = std::time::Instant::now();
        let (mut lines, mut buf) = (0usize, [0u8; 256]);
        while started.elapsed() < Duration::from_secs(20) {
            let n = match master.read(&mut buf) {
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => continue,
                Err(_) => break,
            };
            for &b in &buf[..n] {
                let answer: &[u8] = match b {
                    0x18 => b"\r\nGrbl 1.1h ['$' for help]\r\n",
                    b'?' => b"<Run|MPos:1.000,2.000,0.000|FS:3000,0>\r\n",
                    b'\n' => {
                        lines += 1;
                        if lines <= 5 {
                            b"ok\r\n"
                        } else {
                            b""
                        }
                    }
                    _ => b"",
                };
                if master.write_all(answer).is_err() {
                    return lines;
                }
            }
        }
        lines
    });
    let mut link = serial::open(&p, &path, None).unwrap();
    let t = std::time::Instant::now();
    let r = stream::send(&mut link, &p, gcode_job(3).as_bytes(), &opts(1.0));
    let took = t.elapsed();
    drop(link);
    drop(slave);
    let e = r.unwrap_err();
    assert!(matches!(e, StreamError::Timeout { .. }), "{e}");
    assert!(e.to_string().contains("neither answered nor moved"), "{e}");
    assert!(took < Duration::from_secs(10), "{took:?}");
    assert!(peer.join().unwrap() > 5);
}

/// An HP-GL device that holds the host off (XOFF) for longer than the timeout while it works
/// off long moves: without an output channel that is a stop; with `status_query = "esc-b"`
/// the host asks `ESC . B` and a growing free space is progress, so the job completes, and
/// the queries are neither violations nor garbage.
#[test]
fn a_busy_hpgl_device_that_answers_esc_b_outlasts_the_timeout() {
    // 40 moves of 100 mm at 20 cm/s (0.5 s each), ×4: a hold works off ~13 of them, 1.6 s.
    let mut s = String::from("IN;SP1;PU0,0;\n");
    for k in 0..40 {
        s.push_str(&format!("PD{},0;\n", if k % 2 == 0 { 4000 } else { 0 }));
    }
    s.push_str("PU;SP0;\n");
    let plain = hpgl_profile(115_200, "xon-xoff", 256);
    let (r, rep) = run(
        &plain,
        s.as_bytes(),
        Some(4.0),
        Faults::default(),
        &opts(0.8),
    );
    let e = r.unwrap_err();
    assert!(e.to_string().contains("waiting for XON"), "{e}");
    assert_eq!(rep.flow_violations, 0);

    let mut asking = plain.clone();
    asking.serial.status_query = StatusQuery::EscB;
    let t = std::time::Instant::now();
    let (r, rep) = run(
        &asking,
        s.as_bytes(),
        Some(4.0),
        Faults::default(),
        &opts(0.8),
    );
    let r = r.unwrap_or_else(|e| panic!("{e}"));
    assert!(t.elapsed() > Duration::from_secs(3), "{:?}", t.elapsed());
    assert_eq!(r.bytes, s.len());
    assert!(r.xoff_received > 0);
    assert_eq!(r.garbage_bytes, 0);
    assert_eq!(rep.violations(), 0, "{rep:?}");
    assert_eq!(rep.bytes_received, s.len(), "the queries are not data");
}

/// A program started while flatcut streams (another thread spawning it, as this test suite
/// does all the time) inherits none of the simulator's pseudo-terminal or the host's port:
/// serialport opens them without `O_CLOEXEC`, and a child holding the master open hid the
/// simulator's hang-up from the host (`hang_up_mid_job_says_how_far_it_got` timed out on CI
/// at "stroke 9 of 30, byte 688" with the line silent instead of hung up).
#[test]
fn programs_started_meanwhile_inherit_no_port() {
    let p = grbl_profile("grbl-character-counting");
    let h = sim::spawn(SimConfig::new(p.clone())).unwrap();
    let port = serial::open(&p, &h.path, None).unwrap();
    let mut child = std::process::Command::new("sleep")
        .arg("30")
        .spawn()
        .expect("sleep");
    // Once it runs `sleep` (descriptors are closed on exec, not on fork).
    let proc_dir = format!("/proc/{}", child.id());
    let start = std::time::Instant::now();
    while std::fs::read_to_string(format!("{proc_dir}/comm")).map_or(true, |c| c.trim() != "sleep")
        && start.elapsed() < Duration::from_secs(10)
    {
        std::thread::sleep(Duration::from_millis(5));
    }
    // Each descriptor's target and, for a pty master, the index of its pty (other tests'
    // ptys are theirs to mind; this one's slave is /dev/pts/INDEX).
    let fds: Vec<(String, Option<String>)> = std::fs::read_dir(format!("{proc_dir}/fd"))
        .map(|d| {
            d.filter_map(|e| {
                let e = e.ok()?;
                let link = std::fs::read_link(e.path()).ok()?;
                let info = std::fs::read_to_string(format!(
                    "{proc_dir}/fdinfo/{}",
                    e.file_name().to_string_lossy()
                ))
                .unwrap_or_default();
                let tty = info
                    .lines()
                    .find_map(|l| l.strip_prefix("tty-index:"))
                    .map(|v| v.trim().to_string());
                Some((link.to_string_lossy().into_owned(), tty))
            })
            .collect()
        })
        .unwrap_or_default();
    let h_path = h.path.clone();
    let index = h_path.strip_prefix("/dev/pts/").map(str::to_string);
    let _ = child.kill();
    let _ = child.wait();
    drop(port);
    h.stop().unwrap();
    let leaked: Vec<&String> = fds
        .iter()
        .filter(|(link, tty)| *link == h_path || (link.as_str() == "/dev/ptmx" && *tty == index))
        .map(|(link, _)| link)
        .collect();
    assert!(
        leaked.is_empty(),
        "the child holds {leaked:?}: ports must be close-on-exec"
    );
}
