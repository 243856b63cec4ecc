//! Issue 23, deliverables 6–8, through the real binary and a simulated cutter on a
//! pseudo-terminal: the pen pass and knife pass of `--tool-change` with the pause between them,
//! the warning (stderr and report.json) naming the marks a knife-only cutter leaves out, fabric
//! folds kept from the knife, the wait between sheets when standard input is not a terminal
//! (the simulator receives nothing of sheet 2 until a line arrives), `--sheets`, and the media
//! check before the first byte.

use crate::common::*;
use flatcut::device::sim::{self, SimConfig, SimHandle};
use flatcut::profile;
use std::io::{BufRead, Write};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

/// A simulated cutter for `device`, its line at 115200 baud, motion taking no time.
fn sim_for(device: &str) -> SimHandle {
    let mut p = profile::find(device).unwrap();
    p.serial.baud = 115_200;
    sim::spawn(SimConfig::new(p)).unwrap()
}

/// `flatcut` with piped standard input and its standard error read line by line.
fn spawn_flatcut(args: &[&str]) -> (Child, Receiver<String>) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_flatcut"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env(
            "XDG_CONFIG_HOME",
            std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("no-config"),
        )
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let err = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in std::io::BufReader::new(err).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    (child, rx)
}

/// Wait (at most 60 s) for a line of standard error containing `part`; returns it.
fn wait_line(rx: &Receiver<String>, part: &str) -> String {
    let deadline = Instant::now() + Duration::from_secs(60);
    while Instant::now() < deadline {
        if let Ok(line) = rx.recv_timeout(Duration::from_millis(100)) {
            if line.contains(part) {
                return line;
            }
        }
    }
    panic!("no `{part}` on standard error");
}

/// Wait until the simulator has received `n` bytes (at most 30 s), then check for half a
/// second that nothing more arrives.
fn received_exactly(h: &SimHandle, n: usize) {
    let deadline = Instant::now() + Duration::from_secs(30);
    while h.bytes_received() < n && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(10));
    }
    std::thread::sleep(Duration::from_millis(500));
    assert_eq!(h.bytes_received(), n);
}

/// A job of two sheets: two tetrahedra, each sheet too small for both nets.
fn two_sheet_spec(dir: &std::path::Path) -> std::path::PathBuf {
    let mesh = manifest("patterns/tetrahedron.obj");
    let m = mesh.display();
    let text = format!(
        "name = \"two\"\n[[surface]]\nkind = \"mesh\"\npath = \"{m}\"\n[[surface]]\nkind = \"mesh\"\n\
         path = \"{m}\"\n[material]\nkind = \"paper\"\nthickness = 0.25\n\
         [sheet]\nwidth = 250\nheight = 110\nmargin = 5\nspacing = 3\n"
    );
    let path = dir.join("two.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn sheet_two_waits_for_a_line_on_stdin() {
    let dir = scratch("sheets-wait");
    let spec = two_sheet_spec(&dir);
    let out = dir.join("out");
    let h = sim_for("sim");
    let (mut child, rx) = spawn_flatcut(&[
        "cut",
        spec.to_str().unwrap(),
        "--device",
        "sim",
        "--port",
        &h.path,
        "--baud",
        "115200",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    let prompt = wait_line(&rx, "load sheet 2 of 2");
    assert!(prompt.contains("tool is up"), "{prompt}");
    let one = std::fs::read(out.join("two-1.plt")).unwrap();
    let two = std::fs::read(out.join("two-2.plt")).unwrap();
    // Sheet 1 arrived whole, and nothing of sheet 2 while flatcut waits.
    received_exactly(&h, one.len());
    std::thread::sleep(Duration::from_secs(1));
    assert_eq!(
        h.bytes_received(),
        one.len(),
        "sheet 2 was sent before the line"
    );
    child.stdin.as_mut().unwrap().write_all(b"\n").unwrap();
    let status = child.wait().unwrap();
    assert!(status.success());
    let rep = h
        .finish(one.len() + two.len(), Duration::from_secs(30))
        .unwrap();
    assert_eq!(rep.bytes_received, one.len() + two.len());
    let parsed = |b: &[u8]| flatcut::output::hpgl::parse(std::str::from_utf8(b).unwrap()).unwrap();
    assert_eq!(rep.paths.len(), parsed(&one).len() + parsed(&two).len());
    assert_eq!(rep.violations(), 0);
}

#[test]
fn closed_stdin_stops_before_sheet_two_and_sheets_sends_it_later() {
    let dir = scratch("sheets-closed");
    let spec = two_sheet_spec(&dir);
    let out = dir.join("out");
    let h = sim_for("sim");
    let args = |sheets: Option<&'static str>| {
        let mut v = vec![
            "cut".to_string(),
            spec.display().to_string(),
            "--device".into(),
            "sim".into(),
            "--port".into(),
            h.path.clone(),
            "--baud".into(),
            "115200".into(),
            "-q".into(),
            "-o".into(),
            out.display().to_string(),
        ];
        if let Some(s) = sheets {
            v.extend(["--sheets".to_string(), s.to_string()]);
        }
        v
    };
    // Standard input at its end (`Command::output` gives none): sheet 1, then a clear stop.
    let a = args(None);
    let o = flatcut(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("load sheet 2 of 2") && e.contains("standard input is closed"),
        "{e}"
    );
    assert!(
        e.contains("not sent: two-2.plt") && e.contains("--sheets"),
        "{e}"
    );
    let one = std::fs::read(out.join("two-1.plt")).unwrap().len();
    let two = std::fs::read(out.join("two-2.plt")).unwrap().len();
    received_exactly(&h, one);
    // `--sheets 2` sends sheet 2 alone, with no wait.
    let a = args(Some("2"));
    let o = flatcut(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", stderr(&o));
    received_exactly(&h, one + two);
    let a = args(Some("3"));
    let o = flatcut(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("sheets 1 to 2"), "{}", stderr(&o));
    let rep = h.finish(one + two, Duration::from_secs(30)).unwrap();
    assert_eq!(rep.bytes_received, one + two);
}

#[test]
fn tool_change_draws_then_pauses_then_cuts() {
    let dir = scratch("tool-change");
    let out = dir.join("out");
    // A knife-only cutter without RTS/CTS: a pseudo-terminal has no CTS line to read, and
    // since issue 22 CTS that cannot be read is an error (roland-gx24 uses RTS/CTS).
    let h = sim_for("uscutter-mh");
    let (mut child, rx) = spawn_flatcut(&[
        "cut",
        "patterns/house.toml",
        "--device",
        "uscutter-mh",
        "--tool-change",
        "--port",
        &h.path,
        "--baud",
        "115200",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    let prompt = wait_line(&rx, "put the knife in");
    assert!(prompt.contains("tool is up"), "{prompt}");
    let pen = std::fs::read_to_string(out.join("house-pen.plt")).unwrap();
    let knife = std::fs::read_to_string(out.join("house.plt")).unwrap();
    // Pass 1 arrived whole and nothing of pass 2 while flatcut waits for the knife.
    received_exactly(&h, pen.len());
    child.stdin.as_mut().unwrap().write_all(b"\n").unwrap();
    assert!(child.wait().unwrap().success());
    let rep = h
        .finish(pen.len() + knife.len(), Duration::from_secs(30))
        .unwrap();
    assert_eq!(rep.bytes_received, pen.len() + knife.len());
    assert!(rep.tool_down_at_end.is_none());
    // Pass 1 is every mark and label, with the holder's tool and no force; pass 2 the cuts.
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert!(report.get("dropped").is_none(), "nothing is left out");
    let p1 = flatcut::output::hpgl::parse(&pen).unwrap();
    let p2 = flatcut::output::hpgl::parse(&knife).unwrap();
    assert!(p1.len() > 10, "{} pen strokes", p1.len());
    assert!(p1.iter().all(|s| s.pen == 1 && s.force.is_none()));
    assert!(p2.iter().all(|s| s.force.is_some()));
    assert_eq!(rep.paths.len(), p1.len() + p2.len());
    // Without the flag the same job names what it leaves out, on stderr and in the report.
    let plain = dir.join("plain");
    let o = flatcut(&[
        "cut",
        "patterns/house.toml",
        "--device",
        "roland-gx24",
        "--dry-run",
        "-o",
        plain.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    let e = stderr(&o);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(plain.join("report.json")).unwrap()).unwrap();
    let ids = report["pieces"][0]["edge_ids"].as_u64().unwrap();
    assert!(ids > 0);
    let d = &report["dropped"][0];
    assert_eq!(d["left_out"]["edge_ids"].as_u64(), Some(ids));
    assert_eq!(d["left_out"]["label"].as_u64(), Some(1));
    assert!(d["reason"].as_str().unwrap().contains("--tool-change"));
    assert!(report["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w["kind"] == "left-out" && w["message"].as_str().unwrap().contains("edge ids")));
    assert!(
        e.contains("warning: left out") && e.contains(&format!("{ids} edge ids")),
        "{e}"
    );
    assert!(!std::fs::read_dir(&plain).unwrap().any(|f| f
        .unwrap()
        .file_name()
        .to_string_lossy()
        .contains("-pen")));
}

#[test]
fn fabric_folds_never_reach_the_knife_unless_asked() {
    let dir = scratch("fabric-folds");
    let run = |device: &str, extra: &[&str], name: &str| {
        let out = dir.join(name);
        let mut a = vec![
            "cut",
            "patterns/dress-panel.toml",
            "--device",
            device,
            "--dry-run",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        let o = flatcut(&a);
        assert!(o.status.success(), "{}", stderr(&o));
        let plt = std::fs::read_to_string(out.join("dress-panel.plt")).unwrap();
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        (flatcut::output::hpgl::parse(&plt).unwrap(), report)
    };
    let score = profile::find("roland-gx24").unwrap().tools["score"]
        .force
        .unwrap();
    let (strokes, report) = run("roland-gx24", &[], "roland");
    let folds = report["pieces"][0]["folds"]["mountain"].as_u64().unwrap()
        + report["pieces"][0]["folds"]["valley"].as_u64().unwrap();
    assert!(folds >= 20, "{folds} folds");
    assert!(
        strokes.iter().all(|s| s.force != Some(score)),
        "a fold went to the knife"
    );
    assert_eq!(
        report["dropped"][0]["left_out"]["folds"].as_u64(),
        Some(folds)
    );
    assert!(report["dropped"][0]["reason"]
        .as_str()
        .unwrap()
        .contains("--folds score"));
    // `--folds score` still asks for them.
    let (asked, _) = run("roland-gx24", &["--folds", "score"], "asked");
    let scored = asked.iter().filter(|s| s.force == Some(score)).count() as u64;
    assert_eq!(scored, folds);
    // A device with a pen draws them (sim: pen 3), none with the scoring tool (pen 2).
    let (drawn, report) = run("sim", &[], "sim");
    assert!(report.get("dropped").is_none());
    assert_eq!(drawn.iter().filter(|s| s.pen == 2).count(), 0);
    assert!(drawn.iter().filter(|s| s.pen == 3).count() as u64 >= folds);
}

/// A dry run writes the files but says at once that the device would refuse them: the cube's
/// spec nests on a 610 mm roll, twice grbl-pen's 300 mm bed.
#[test]
fn a_dry_run_warns_of_a_job_wider_than_the_media() {
    let out = scratch("media-wide-dry");
    let args = |device: &'static str| {
        [
            "cut",
            "patterns/cube.toml",
            "--device",
            device,
            "--dry-run",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ]
        .map(String::from)
    };
    let a = args("grbl-pen");
    let o = flatcut(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("warning") && e.contains("wider than the 300 mm media"),
        "{e}"
    );
    assert!(out.join("cube.gcode").exists());
    // On the 610 mm roll's own cutter there is nothing to say.
    let a = args("sim-dragknife");
    let o = flatcut(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
}

#[test]
fn a_blank_wider_than_the_media_is_refused_before_the_first_byte() {
    let out = scratch("media-wide");
    let h = sim_for("roland-gx24");
    let o = flatcut(&[
        "fitting",
        "cone",
        "--bottom-diameter",
        "800",
        "--top-diameter",
        "400",
        "--height",
        "600",
        "--thickness",
        "1",
        // Kept whole: split to fit, it would no longer be wider than the media.
        "--split",
        "none",
        "--device",
        "roland-gx24",
        "--port",
        &h.path,
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    let media = profile::find("roland-gx24").unwrap().media_width;
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let bbox = &report["pieces"][0]["bbox_mm"];
    let wide = bbox[2].as_f64().unwrap();
    assert!(wide > 1000.0, "{wide}");
    assert!(
        e.contains(&format!("{wide:.1} mm across the media"))
            && e.contains(&format!("{media:.0} mm media"))
            && e.contains("nothing was sent"),
        "{e}"
    );
    // `send` reads the program's own extent and refuses it too.
    let plt = out.join("cone.plt");
    let o = flatcut(&[
        "send",
        plt.to_str().unwrap(),
        "--device",
        "roland-gx24",
        "--port",
        &h.path,
    ]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(
        e.contains("mm across the media") && e.contains("584 mm media"),
        "{e}"
    );
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(h.bytes_received(), 0);
    let rep = h.stop().unwrap();
    assert_eq!(rep.bytes_received, 0);
}

/// A flatbed has a length as well as a width: `send` reads a G-code program's moves and
/// refuses one that leaves the bed (longer than `media_length`, wider than `media_width`, or
/// below the work zero) before the first byte; one inside the bed goes.
#[test]
fn a_gcode_program_off_the_bed_is_refused_before_the_first_byte() {
    let out = scratch("media-long");
    let p = profile::find("grbl-pen").unwrap();
    assert!(p.media_length > 0.0 && p.media_width > 0.0);
    let cases = [
        (
            "long",
            format!("G21\nG90\nG0 X10 Y{:.1}\nM2\n", p.media_length + 50.0),
            Some(format!(
                "{:.1} mm along the media), longer than the {:.0} mm",
                p.media_length + 50.0,
                p.media_length
            )),
        ),
        (
            "inches",
            // 20 in = 508 mm across, wider than the bed though the number is small.
            "G20\nG90\nG0 X20 Y1\nM2\n".to_string(),
            Some(format!("wider than the {:.0} mm media", p.media_width)),
        ),
        (
            "below",
            "G21\nG91\nG0 X10 Y10\nG0 X-25\nG90\nM2\n".to_string(),
            Some("15.0 mm below the work zero".to_string()),
        ),
        (
            "fits",
            "G21\nG90\nG0 X10 Y20\nG0 X0 Y0\nM2\n".to_string(),
            None,
        ),
    ];
    for (name, program, refusal) in cases {
        let file = out.join(format!("{name}.gcode"));
        std::fs::write(&file, &program).unwrap();
        let h = sim_for("grbl-pen");
        let o = flatcut(&[
            "send",
            file.to_str().unwrap(),
            "--device",
            "grbl-pen",
            "--port",
            &h.path,
            "--timeout",
            "10",
        ]);
        let e = stderr(&o);
        match refusal {
            Some(want) => {
                assert_eq!(o.status.code(), Some(1), "{name}: {e}");
                assert!(
                    e.contains(&want) && e.contains("nothing was sent") && e.contains(name),
                    "{name}: {e}"
                );
                std::thread::sleep(Duration::from_millis(200));
                assert_eq!(h.stop().unwrap().bytes_received, 0, "{name}");
            }
            None => {
                assert!(o.status.success(), "{name}: {e}");
                assert!(h.stop().unwrap().bytes_received > 0, "{name}");
            }
        }
    }
}

/// `fitting` takes `--tool-change` as `cut` does: on a knife-only cutter the bend notes and
/// labels are a pen pass of their own instead of being left out.
#[test]
fn a_fitting_on_a_knife_only_cutter_gets_a_pen_pass_with_tool_change() {
    let fit = |name: &str, extra: &[&str]| {
        let out = scratch(name);
        let mut args = vec![
            "fitting",
            "cone",
            "--bottom-diameter",
            "300",
            "--top-diameter",
            "160",
            "--height",
            "200",
            "--device",
            "roland-gx24",
            "--dry-run",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = flatcut(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        (out, report)
    };
    let (plain, report) = fit("fitting-plain", &[]);
    assert!(!plain.join("cone-pen.plt").exists());
    assert!(report["dropped"][0]["reason"]
        .as_str()
        .unwrap()
        .contains("--tool-change"));
    let (changed, report) = fit("fitting-pen", &["--tool-change"]);
    assert!(report.get("dropped").is_none(), "{report}");
    let pen = std::fs::read_to_string(changed.join("cone-pen.plt")).unwrap();
    let strokes = flatcut::output::hpgl::parse(&pen).unwrap();
    assert!(strokes.len() > 5, "{} pen strokes", strokes.len());
    assert!(strokes.iter().all(|s| s.force.is_none()));
}
