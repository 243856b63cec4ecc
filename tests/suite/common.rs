//! Helpers shared by the integration tests: run the real binary, make scratch directories.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh, empty scratch directory for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// Run `flatcut` with arguments from the crate root.
pub fn flatcut(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flatcut"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env(
            "XDG_CONFIG_HOME",
            Path::new(env!("CARGO_TARGET_TMPDIR")).join("no-config"),
        )
        .output()
        .expect("run flatcut")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn manifest(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The shared test data directory (`../shared/data` beside the checkout).
pub fn shared_data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data")
        .join(rel)
}

/// The acceptance mesh `fandisk.obj` as a spec: scaled to about 300 mm, on A3 portrait, unfolded
/// face by face (`segment = "faces"`: its tests are the exact unfolder's on a real mesh; left
/// to itself the mesh is segmented into charts).
pub const FANDISK_SPEC: &str = r#"
name = "fandisk"
[[surface]]
kind = "mesh"
path = "fandisk.obj"
scale = 100
units = "mm"
segment = "faces"
[sheet]
width = 297
height = 420
margin = 5
spacing = 3
"#;

/// Writes [`FANDISK_SPEC`], pointing at the shared mesh, into `dir`; returns its path.
pub fn fandisk_spec(dir: &Path) -> PathBuf {
    let path = dir.join("fandisk.toml");
    let text = FANDISK_SPEC.replace(
        "fandisk.obj",
        &shared_data("meshes/fandisk.obj").to_string_lossy(),
    );
    std::fs::write(&path, text).expect("write fandisk spec");
    path
}

/// Whether `../shared/data` is missing: on a developer's clone without it the tests that read
/// it skip (say so on stderr and return); when `CI` is set they must run, so this panics.
pub fn shared_missing() -> bool {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    if dir.is_dir() {
        return false;
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "{} is missing and CI is set: the tests that read it must run",
        dir.display()
    );
    eprintln!("skipped: {} is absent", dir.display());
    true
}

/// First line of a test that reads `../shared/data`: skips it when the data is absent (not
/// under CI, see [`shared_missing`]).
macro_rules! require_shared {
    () => {
        if $crate::common::shared_missing() {
            return;
        }
    };
}

/// Each pen-1 (cut) contour of an HP-GL program at 40 units/mm, as its points in mm.
pub fn hpgl_cut_contours(plt: &str) -> Vec<Vec<(f64, f64)>> {
    flatcut::output::hpgl::parse(plt)
        .expect("valid HPGL")
        .iter()
        .filter(|s| s.pen == 1)
        .map(|s| {
            s.points
                .iter()
                .map(|&(x, y)| (x as f64 / 40.0, y as f64 / 40.0))
                .collect()
        })
        .collect()
}

/// Area (mm², by the shoelace formula) and length (mm) of a polyline taken as a ring.
pub fn area_and_length(pts: &[(f64, f64)]) -> (f64, f64) {
    let mut area = 0.0;
    let mut per = 0.0;
    for w in pts.windows(2) {
        area += w[0].0 * w[1].1 - w[1].0 * w[0].1;
        per += ((w[1].0 - w[0].0).powi(2) + (w[1].1 - w[0].1).powi(2)).sqrt();
    }
    (0.5 * area.abs(), per)
}

/// The spec `flatcut fitting ARGS` would cut.
pub fn fitting_spec(args: &[&str]) -> flatcut::spec::Spec {
    use clap::Parser;
    let mut all = vec!["flatcut", "fitting"];
    all.extend_from_slice(args);
    let cli = flatcut::cli::Cli::try_parse_from(all).expect("valid flags");
    match cli.command {
        flatcut::cli::Command::Fitting(a) => {
            flatcut::cli::fitting::spec(&a).expect("valid fitting")
        }
        _ => unreachable!(),
    }
}
