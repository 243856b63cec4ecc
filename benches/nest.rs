//! Nesting speed: one improvement iteration (a separator sweep: every overlapping item moves
//! once) on shirts after shrinking its bottom-left layout by 2 %, and the bottom-left
//! construction on each of the five ESICUP instances in ../shared/data/nesting.

use criterion::{criterion_group, criterion_main, Criterion};
use flatcut::nest::{bench::Search, esicup};
use std::hint::black_box;
use std::path::Path;

const NAMES: [&str; 5] = ["albano", "fu", "jakobs1", "shirts", "trousers"];

fn load(name: &str) -> esicup::Instance {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/nesting")
        .join(format!("{name}.json"));
    esicup::load(&p).expect("instance")
}

fn order(inst: &esicup::Instance) -> Vec<usize> {
    let mut o: Vec<usize> = (0..inst.problem.items.len()).collect();
    o.sort_by(|&a, &b| {
        inst.problem.items[b]
            .area
            .total_cmp(&inst.problem.items[a].area)
    });
    o
}

fn construction(c: &mut Criterion) {
    let mut g = c.benchmark_group("nest_construct");
    g.sample_size(10);
    for name in NAMES {
        let inst = load(name);
        let ord = order(&inst);
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut search = Search::new(&inst.problem, 1, 1.0);
                black_box(search.fill_strip(&ord))
            })
        });
    }
    g.finish();
}

fn improvement(c: &mut Criterion) {
    let inst = load("shirts");
    let ord = order(&inst);
    let mut search = Search::new(&inst.problem, 1, 1e6);
    let st = search.fill_strip(&ord).expect("fill");
    let len = st.extent();
    let shrunk = search.shrink(&st, len, 0.98 * len).expect("shrink");
    let mut g = c.benchmark_group("nest_improve");
    g.sample_size(20);
    g.bench_function("shirts_separator_sweep", |b| {
        b.iter(|| {
            let mut s = shrunk.clone();
            let mut search = Search::new(&inst.problem, 2, 1e6);
            black_box(search.sweep(&mut s, 0.98 * len))
        })
    });
    g.finish();
}

criterion_group!(benches, construction, improvement);
criterion_main!(benches);
