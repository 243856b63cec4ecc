//! Wang–Tang strip triangulation at m = n = 2000 (issue 4): GODT+GMBT (fewest invalid bridges,
//! then least bending energy, one dynamic program on the dual-node graph), and GODT and GMBT
//! alone. Target: GODT + GMBT under 100 ms. Run: `cargo bench --bench strip`.

use criterion::{criterion_group, criterion_main, Criterion};
use flatcut::surface::strip::{Method, Strip};
use glam::DVec3;
use std::f64::consts::PI;

/// A lace-like strip: two wavy 3D curves along half a hem, `m` points each.
fn lace(m: usize) -> Strip {
    let curve = |r0: f64, z0: f64, a: f64, f: f64, ph: f64, za: f64| -> Vec<DVec3> {
        (0..m)
            .map(|k| {
                let u = PI * k as f64 / (m - 1) as f64;
                let r = r0 + a * (f * u + ph).sin();
                DVec3::new(r * u.cos(), r * u.sin(), z0 + za * (1.3 * f * u).sin())
            })
            .collect()
    };
    Strip::raw(
        curve(150.0, 0.0, 6.0, 90.0, 0.0, 4.0),
        curve(170.0, 30.0, 8.0, 70.0, 1.0, 6.0),
    )
}

fn bench(c: &mut Criterion) {
    let s = lace(2000);
    let mt = s.metrics(&s.triangulate(Method::GodtGmbt));
    eprintln!(
        "m = n = 2000: GODT+GMBT {} of {} interior bridges locally convex",
        mt.convex, mt.interior
    );
    // On a shared machine wall time overstates the cost: also report CPU time, of this thread
    // (the recurrence; Linux: /proc/thread-self/schedstat, ns) and of the whole process (all
    // threads; /proc/self/stat utime + stime, clock ticks of 10 ms).
    let thread_cpu = || -> Option<f64> {
        let t = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
        Some(t.split_whitespace().next()?.parse::<f64>().ok()? / 1e6)
    };
    let process_cpu = || -> Option<f64> {
        let t = std::fs::read_to_string("/proc/self/stat").ok()?;
        let rest = &t[t.rfind(')')? + 2..];
        let f: Vec<&str> = rest.split_whitespace().collect();
        Some((f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?) * 10.0)
    };
    if let (Some(t0), Some(p0)) = (thread_cpu(), process_cpu()) {
        const RUNS: u32 = 20;
        let w0 = std::time::Instant::now();
        for _ in 0..RUNS {
            std::hint::black_box(s.triangulate(Method::GodtGmbt));
        }
        let wall = w0.elapsed().as_secs_f64() * 1e3 / f64::from(RUNS);
        if let (Some(t1), Some(p1)) = (thread_cpu(), process_cpu()) {
            eprintln!(
                "godt+gmbt 2000x2000 per run: {wall:.1} ms wall, {:.1} ms CPU in all threads, {:.1} ms in the recurrence's thread",
                (p1 - p0) / f64::from(RUNS),
                (t1 - t0) / f64::from(RUNS)
            );
        }
    }
    let mut g = c.benchmark_group("strip");
    g.sample_size(10);
    g.bench_function("godt+gmbt 2000x2000", |b| {
        b.iter(|| s.triangulate(Method::GodtGmbt))
    });
    g.bench_function("godt 2000x2000", |b| b.iter(|| s.triangulate(Method::Godt)));
    g.bench_function("gmbt 2000x2000", |b| b.iter(|| s.triangulate(Method::Gmbt)));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
