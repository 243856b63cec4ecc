//! Streaming throughput on the simulated cutter through a real pseudo-terminal, no artificial
//! slowness (motion takes no time), at 115200 baud:
//! - HP-GL with XON/XOFF: delivered bytes per second against the link's capacity (baud / 10);
//!   the target is ≥ 95 %.
//! - GRBL: lines per second with character counting against send-response.
//!
//! Run: `cargo bench --bench stream`. Each case also prints its rate once, measured outside
//! criterion, so the closing note can quote it.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use flatcut::device::sim::SimConfig;
use flatcut::device::stream;
use flatcut::profile::{self, Profile};
use std::time::Duration;

fn hpgl(size: usize) -> Vec<u8> {
    let mut s = String::from("IN;SP1;PU0,0;\n");
    let mut k = 0usize;
    while s.len() < size {
        s.push_str(&format!(
            "PD{},{};\n",
            (k % 100) * 40,
            ((k / 100) % 100) * 40
        ));
        k += 1;
    }
    s.push_str("PU;SP0;\n");
    s.into_bytes()
}

fn gcode(lines: usize) -> Vec<u8> {
    let mut s = String::from("G21\nG90\nG94\nG0 Z2\nG1 Z-1 F3000\n");
    for k in 0..lines {
        s.push_str(&format!("G1 X{} Y{}\n", k % 100, (k / 100) % 100));
    }
    s.push_str("G0 Z2\nM2\n");
    s.into_bytes()
}

fn grbl_profile(protocol: &str) -> Profile {
    profile::parse(
        &format!(
            "name='g'\ndescription='grbl'\nlanguage='gcode'\ndialect='grbl'\nunits_per_mm=1\n\
             buffer=128\nprotocol='{protocol}'\n[serial]\nbaud=115200\n\
             [tools.cut]\nz_down=-1\nz_up=2\nspeed=3000\n"
        ),
        "bench.toml",
    )
    .expect("profile")
}

/// Stream once; seconds taken by the host.
fn once(p: &Profile, program: &[u8]) -> f64 {
    let o = stream::StreamOptions {
        progress: false,
        ..Default::default()
    };
    let (r, rep) = stream::stream_job(
        SimConfig::new(p.clone()),
        program,
        &o,
        Duration::from_secs(30),
    )
    .expect("simulator");
    let r = r.expect("stream");
    assert_eq!(rep.violations(), 0);
    assert_eq!(r.bytes, program.len());
    // Host time: from the first byte until the stream returned with the last one written.
    r.seconds
}

fn bench(c: &mut Criterion) {
    let sim_profile = profile::find("sim").expect("sim profile");
    assert_eq!(sim_profile.serial.baud, 115_200);
    let prog = hpgl(32 * 1024);
    let capacity = sim_profile.serial.baud as f64 / 10.0;
    let s = once(&sim_profile, &prog);
    eprintln!(
        "hpgl xon-xoff 115200: {:.0} bytes/s = {:.1} % of {:.0} bytes/s",
        prog.len() as f64 / s,
        100.0 * prog.len() as f64 / s / capacity,
        capacity
    );
    let mut g = c.benchmark_group("stream");
    g.sample_size(10);
    g.measurement_time(Duration::from_secs(30));
    g.throughput(Throughput::Bytes(prog.len() as u64));
    g.bench_function("hpgl_xonxoff_115200", |b| {
        b.iter(|| once(&sim_profile, &prog))
    });

    let lines = 1500;
    let job = gcode(lines);
    g.throughput(Throughput::Elements(lines as u64 + 7));
    for protocol in ["grbl-character-counting", "grbl-send-response"] {
        let p = grbl_profile(protocol);
        let s = once(&p, &job);
        eprintln!(
            "{protocol} 115200: {:.0} lines/s ({:.0} bytes/s)",
            (lines + 7) as f64 / s,
            job.len() as f64 / s
        );
        g.bench_function(protocol, |b| b.iter(|| once(&p, &job)));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
