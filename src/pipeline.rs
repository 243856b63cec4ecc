//! The one composer of the pipeline: spec → surfaces → flats → pieces → layout → job →
//! programs → files. Every subcommand (`cli`) and the integration tests run the stages
//! through these functions (the benches time single stages on their own inputs); no stage calls another stage's entry point, and `cli`
//! only parses flags, fills the options below and prints.
//!
//! - [`pieces`]: spec → surfaces → flats → pieces (surface, flatten and pattern stages);
//!   pieces too large for the spec's sheet are split to fit unless `split = none`.
//! - [`plan`] / [`plan_job`]: pieces → layout → job (nest and toolpath stages), with the
//!   device deciding which stroke kinds are drawn at all.
//! - [`machine_job`]: the job as the device makes it (perforation dashes, overcut, drag-knife
//!   offset).
//! - [`cut`] and [`flatten`]: the whole run of `flatcut cut` / `flatcut flatten`, up to the
//!   files in the output folder; sending the programs is the caller's (`cli::link`), after the
//!   files are written, so a failed send loses nothing.
//! - [`nest_instance`]: an ESICUP instance → solution files (`flatcut nest`).
//! - [`printcut`]: print-and-cut (`Toolpath::print_and_cut`): registration marks, the margin
//!   that clears them, the cutter's job, the fit of measured marks and the registered program.
//!
//! Choices: options a user did not give are `None` and leave the stage's default; the
//! command-line flags were checked by `cli` before they get here; warnings of the surface and
//! flatten stages go to standard error unless `quiet`.

use crate::flatten::Flat;
use crate::nest::Layout;
pub use crate::output::files::{check_file_name, create_dir, write_atomic, RunFiles};
use crate::output::report::{self, RunInfo};
use crate::profile::Profile;
use crate::spec::{MaterialKind, Spec};
use crate::toolpath::{Job, StrokeKind, ToolpathOptions};
use crate::Error;
use std::path::{Path, PathBuf};

pub mod printcut;
mod surfaces;

pub use surfaces::{pieces, sized_surfaces};

/// Nesting search settings (`--nest-time`, `--seed`, `--threads`); `None` keeps the default.
#[derive(Debug, Clone, Copy, Default)]
pub struct Search {
    /// Search budget in seconds (a deterministic work budget).
    pub seconds: Option<f64>,
    /// Seed of the search.
    pub seed: Option<u64>,
    /// Independent searches run in parallel (clamped to 1..=64).
    pub threads: Option<usize>,
}

impl Search {
    /// Put the settings that were given into the nest options.
    pub fn apply(&self, opts: &mut crate::nest::NestOptions) {
        if let Some(t) = self.seconds {
            opts.seconds = t;
        }
        if let Some(s) = self.seed {
            opts.seed = s;
        }
        if let Some(t) = self.threads {
            opts.threads = t.clamp(1, 64);
        }
    }
}

/// How folds are made (`--folds`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Folds {
    Score,
    Perforate,
    Draw,
    None,
}

/// Toolpath choices a run can make over the defaults (`--folds`, `--per-piece`, `--weed`,
/// `--tool-change`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Toolpath {
    /// A device with no draw tool draws the marks in a first pass with a pen in the knife
    /// holder, then cuts after a tool change (`toolpath::passes`).
    pub tool_change: bool,
    /// The tool that makes folds; `None`: the device's best (score, else perforate, else draw).
    pub folds: Option<Folds>,
    /// Finish each piece before the next; `None`: on for fabric, which may shift.
    pub per_piece: Option<bool>,
    /// Cut weed lines.
    pub weed: bool,
    /// Print-and-cut ([`printcut`]): registration marks on each sheet, everything printed in
    /// the pictures, only the cut (and score) in the program.
    pub print_and_cut: bool,
}

/// The sheet's sizes within [`crate::geom::input::MAX_COORD`] (a roll's length may be open).
fn plausible_sheet(spec: &Spec) -> Result<(), Error> {
    let max = crate::geom::input::MAX_COORD;
    let s = &spec.sheet;
    let sizes = [
        ("width", Some(s.width)),
        ("height", s.height),
        ("margin", Some(s.margin)),
        ("spacing", Some(s.spacing)),
    ];
    for (key, v) in sizes {
        if let Some(v) = v.filter(|v| v.is_nan() || v.abs() > max) {
            return Err(Error::In {
                file: spec.path.clone(),
                source: Box::new(Error::Usage(format!(
                    "sheet.{key} = {v:.3e} mm is beyond the {max:.0} mm (1 km) flatcut works in"
                ))),
            });
        }
    }
    Ok(())
}

/// Find a device profile and make its tool table say how folds are made: the tools that
/// would be picked before the chosen one are taken out of this job's copy of the profile
/// (folds take the scoring tool, else the perforating one, else the pen; nothing else uses
/// the first two). A knife offset given replaces the profile's (checked by the caller).
pub fn device(
    name: &str,
    folds: Option<Folds>,
    knife_offset: Option<f64>,
) -> Result<Profile, Error> {
    let mut profile = crate::profile::find(name)?;
    if let Some(v) = knife_offset {
        profile.knife_offset = v;
    }
    let (kind, drop): (StrokeKind, &[&str]) = match folds {
        // `none` leaves the folds out of the job (`ToolpathOptions::skip_folds`).
        None | Some(Folds::None) => return Ok(profile),
        Some(Folds::Score) => (StrokeKind::Score, &[]),
        Some(Folds::Perforate) => (StrokeKind::Perforate, &["score"]),
        Some(Folds::Draw) => (StrokeKind::Draw, &["score", "perforate"]),
    };
    if !profile.has(kind) {
        return Err(Error::Usage(format!(
            "--folds {}: device `{}` has no {} tool (its tools: {})",
            kind.name(),
            profile.name,
            kind.name(),
            profile.tools.keys().cloned().collect::<Vec<_>>().join(", ")
        )));
    }
    for k in drop {
        profile.tools.remove(*k);
    }
    Ok(profile)
}

/// Spec → pieces → layout → job for a device: what `cut` sends (the device decides which
/// stroke kinds are drawn at all), with the default nesting search and toolpath.
pub fn plan_job(
    spec: &Spec,
    profile: &Profile,
    quiet: bool,
) -> Result<(Vec<Flat>, Layout, Job), Error> {
    plan(
        spec,
        profile,
        &Search::default(),
        &Toolpath::default(),
        quiet,
    )
}

/// [`plan_job`] with the nesting search and toolpath choices given.
pub fn plan(
    spec: &Spec,
    profile: &Profile,
    search: &Search,
    choices: &Toolpath,
    quiet: bool,
) -> Result<(Vec<Flat>, Layout, Job), Error> {
    plausible_sheet(spec)?;
    // Print-and-cut: pieces are split and nested inside the margin that clears the marks.
    let with_marks;
    let spec = if choices.print_and_cut {
        with_marks = printcut::spec_with_margin(spec, profile);
        &with_marks
    } else {
        spec
    };
    let (flats, pieces) = pieces(spec, quiet)?;
    let mut nest_opts = crate::nest::NestOptions {
        width: spec.sheet.width,
        height: spec.sheet.height,
        margin: spec.sheet.margin,
        spacing: spec.sheet.spacing,
        ..Default::default()
    };
    search.apply(&mut nest_opts);
    let layout = crate::nest::nest(pieces, &nest_opts).map_err(|e| Error::In {
        file: spec.path.clone(),
        source: Box::new(e.into()),
    })?;
    let profile = &job_profile(profile, spec, choices);
    let tp = toolpath_options(spec, profile, choices);
    let mut job = crate::toolpath::plan(&layout, &spec.name, &tp);
    if choices.print_and_cut {
        printcut::add_marks(&mut job, profile)?;
    }
    Ok((flats, layout, job))
}

/// The device profile as a job uses it (encode the job with this one):
/// - with `--tool-change` on a device without a draw tool, the knife holder's tool doubles as
///   the pen (`toolpath::passes::with_pen`);
/// - fabric, unless `--folds` says how: folds are not given to a knife (the scoring and
///   perforating tools are taken out of the job's copy), so they are drawn when the device has
///   a draw tool (a pen or chalk), else left out with a note ([`dropped`]).
pub fn job_profile(profile: &Profile, spec: &Spec, choices: &Toolpath) -> Profile {
    let mut p = if choices.tool_change {
        crate::toolpath::passes::with_pen(profile)
    } else {
        profile.clone()
    };
    if spec.material.kind == MaterialKind::Fabric && choices.folds.is_none() {
        p.tools.remove(StrokeKind::Score.name());
        p.tools.remove(StrokeKind::Perforate.name());
    }
    p
}

/// The toolpath stage's options for a job on `profile` (the job's, [`job_profile`]).
fn toolpath_options(spec: &Spec, profile: &Profile, choices: &Toolpath) -> ToolpathOptions {
    let mut tp = ToolpathOptions {
        skip_folds: crate::toolpath::fold_kind(|k| profile.has(k)).is_none(),
        skip_drawing: !profile.has(StrokeKind::Draw),
        per_piece: spec.material.kind == MaterialKind::Fabric,
        weed: None,
    };
    if let Some(p) = choices.per_piece {
        tp.per_piece = p;
    }
    if choices.folds == Some(Folds::None) {
        tp.skip_folds = true;
    }
    if choices.weed {
        tp.weed = Some(crate::toolpath::weed::WeedOptions::default());
    }
    if choices.print_and_cut {
        printcut::printed_options(&mut tp, choices);
    }
    tp
}

/// What the job leaves out, per piece, because `profile` (the job's) has no tool for it:
/// drawn marks on a device without a draw tool, folds on one that cannot make them (or on
/// fabric, which does not give them to a knife). `--folds none` is the user's choice and is
/// not listed.
pub fn dropped(
    spec: &Spec,
    profile: &Profile,
    choices: &Toolpath,
    layout: &Layout,
) -> Vec<crate::toolpath::passes::Dropped> {
    let tp = toolpath_options(spec, profile, choices);
    let folds = tp.skip_folds && choices.folds != Some(Folds::None);
    let why_drawing = format!(
        "device `{}` has no draw tool (use --tool-change to draw with a pen in the knife holder)",
        profile.name
    );
    let why_folds = if spec.material.kind == MaterialKind::Fabric {
        format!(
            "fabric folds are not given to the knife and device `{}` has no draw tool (--folds score cuts them)",
            profile.name
        )
    } else {
        format!("device `{}` has no tool for folds", profile.name)
    };
    crate::toolpath::passes::dropped(layout, tp.skip_drawing, folds, &why_drawing, &why_folds)
}

/// The job as the device makes it: folds as the profile's tools make them (perforation
/// dashes), overcut, drag-knife compensation with its alignment precut in the sheet margin.
pub fn machine_job(job: &Job, profile: &Profile, spec: &Spec) -> Job {
    crate::toolpath::knife::prepare(
        job,
        &crate::toolpath::knife::MachineOptions::from_profile(profile, spec.sheet.margin),
    )
}

/// Default output directory for a job name.
pub fn default_dir(name: &str) -> PathBuf {
    Path::new("out").join(name)
}

/// What a run writes besides its main files.
#[derive(Debug, Clone, Default)]
pub struct Extras {
    /// Output folder; `None`: `out/<name>`.
    pub output: Option<PathBuf>,
    /// Boundary surfaces: write the N best triangulations as `<surface>-alt-<k>.obj`.
    pub alternatives: Option<usize>,
    /// Write the surfaces' 3D mesh as OBJ here.
    pub surface_obj: Option<PathBuf>,
    /// Write each surface's mesh with its flat layout as `vt` here.
    pub uv_obj: Option<PathBuf>,
    /// Write the solved spline designs as JSON here (`output::design`).
    pub spline_json: Option<PathBuf>,
    /// Print no warnings.
    pub quiet: bool,
    /// Resolution of the PNG pictures in dots per inch (`--dpi`); `None`: the preview's
    /// [`crate::output::png::DEFAULT_PX_PER_MM`].
    pub dpi: Option<f64>,
    /// Also write `<name>-print.pdf`, the sheets tiled onto printer pages (`--print`).
    pub print: Option<crate::output::print::PrintOptions>,
}

/// What the operator does before a program of a run is sent (`cli::link` waits for it).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Before {
    /// Nothing: the first program.
    Start,
    /// Load sheet `k` (1-based) of `n`.
    Sheet { k: usize, n: usize },
    /// Tool change on sheet `k` (1-based): take the pen out of the holder and put the knife in.
    ToolChange { k: usize },
}

/// `cut` up to its files: what was made and written.
#[derive(Debug)]
pub struct CutRun {
    pub flats: Vec<Flat>,
    pub layout: Layout,
    /// The job as designed (one sheet per layout sheet).
    pub job: Job,
    /// The output folder.
    pub dir: PathBuf,
    /// Every file written, in the order written (report.json last).
    pub files: Vec<String>,
    /// The device programs, one per sheet, or two with a tool change: (file name, bytes).
    pub programs: Vec<(String, Vec<u8>)>,
    /// What comes before each program.
    pub before: Vec<Before>,
    /// What the job left out for want of a tool (also in report.json).
    pub dropped: Vec<crate::toolpath::passes::Dropped>,
    /// Print-and-cut: the marks and the cutter's job, for the send ([`printcut`]).
    pub print_cut: Option<printcut::PrintCut>,
}

/// The whole of `flatcut cut` but the sending: plan the job for the device, write the program
/// per sheet, the SVG, the PDF, a PNG and a DXF per sheet, the asked-for extras and report.json, each
/// file whole or not at all.
pub fn cut(
    spec: &Spec,
    profile: &Profile,
    search: &Search,
    choices: &Toolpath,
    extras: &Extras,
) -> Result<CutRun, Error> {
    // A tool change is for a device without a pen of its own.
    let pc = choices.print_and_cut;
    let tool_change = choices.tool_change && !profile.has(StrokeKind::Draw) && !pc;
    let profile = &job_profile(profile, spec, choices);
    let (flats, layout, job) = plan(spec, profile, search, choices, extras.quiet)?;
    let print_cut = pc
        .then(|| printcut::PrintCut::of(&job, spec, profile))
        .transpose()?;
    let machine = match &print_cut {
        Some(p) => machine_job(&p.cutter, profile, spec),
        None => machine_job(&job, profile, spec),
    };
    // Print-and-cut prints what the device has no tool for.
    let dropped = if pc {
        Vec::new()
    } else {
        dropped(spec, profile, choices, &layout)
    };
    if !extras.quiet {
        for d in &dropped {
            eprintln!(
                "flatcut: warning: left out of {}: {} ({})",
                spec.name,
                d.describe(),
                d.reason
            );
        }
    }
    write_extras(&flats, extras)?;
    let dir = extras
        .output
        .clone()
        .unwrap_or_else(|| default_dir(&spec.name));
    let mut run = RunFiles::begin(&dir)?;
    let mut files = Vec::new();
    let mut programs = Vec::new();
    let mut before = Vec::new();
    let ext = profile.language.extension();
    let n = job.sheets.len();
    for (i, sheet) in machine.sheets.iter().enumerate() {
        let name = sheet_file(&spec.name, i, n, ext);
        let (pen, knife) = if tool_change {
            crate::toolpath::passes::split(sheet, profile)
        } else {
            (sheet.clone(), sheet.clone())
        };
        before.push(if i == 0 {
            Before::Start
        } else {
            Before::Sheet { k: i + 1, n }
        });
        if tool_change && !pen.strokes.is_empty() {
            let pen_name = sheet_file(&format!("{}-pen", spec.name), i, n, ext);
            let bytes = crate::output::program(&pen, profile).map_err(|e| e.on_sheet(i + 1))?;
            run.write(&pen_name, &bytes)?;
            files.push(pen_name.clone());
            programs.push((pen_name, bytes));
            before.push(Before::ToolChange { k: i + 1 });
        }
        let bytes = crate::output::program(&knife, profile).map_err(|e| e.on_sheet(i + 1))?;
        run.write(&name, &bytes)?;
        files.push(name.clone());
        programs.push((name, bytes));
    }
    let paint = crate::output::texture::paint(&flats, &layout);
    let (pictures, print) = write_pictures(&mut run, &spec.name, &job, paint.as_ref(), extras)?;
    files.extend(pictures);
    files.extend(write_dxf(&mut run, &spec.name, &layout)?);
    files.extend(write_alternatives(&mut run, &flats, extras.alternatives)?);
    files.push("report.json".into());
    let info = RunInfo {
        dropped: dropped.clone(),
        warnings: cuttable(&layout, profile.knife_offset, spec, extras.quiet),
        print,
        ..run_info(spec, &profile.name, &files)
    };
    match &print_cut {
        Some(p) => {
            let mut rep = report::build(&info, &flats, &layout);
            rep["registration"] = printcut::report(p, profile, &[]);
            let text = serde_json::to_string_pretty(&rep).unwrap_or_default() + "\n";
            run.write("report.json", text.as_bytes())?;
        }
        None => write_report(&mut run, &info, &flats, &layout)?,
    }
    run.commit()?;
    Ok(CutRun {
        flats,
        layout,
        job,
        dir,
        files,
        programs,
        before,
        dropped,
        print_cut,
    })
}

/// `flatten` up to its files: the pieces laid side by side.
#[derive(Debug)]
pub struct FlattenRun {
    pub flats: Vec<Flat>,
    pub layout: Layout,
    pub dir: PathBuf,
    pub files: Vec<String>,
}

/// The whole of `flatcut flatten`: the pieces nested on one strip wide enough for the widest
/// piece (the pieces, not the sheets, are the result), written as SVG, PDF, PNG and report.json.
pub fn flatten(spec: &Spec, search: &Search, extras: &Extras) -> Result<FlattenRun, Error> {
    let (flats, pieces) = pieces(spec, extras.quiet)?;
    write_extras(&flats, extras)?;
    let widest = pieces
        .iter()
        .filter_map(|p| {
            let pts: Vec<_> = p.points().collect();
            let r = glam::DVec2::from_angle(crate::geom::polygon::min_area_rect_angle(&pts));
            crate::geom::polygon::bounds(pts.iter().map(|q| r.rotate(*q)))
                .map(|(lo, hi)| (hi - lo).x)
        })
        .fold(0.0, f64::max);
    let mut opts = crate::nest::NestOptions {
        width: spec.sheet.width.max(widest + 2.0 * spec.sheet.margin + 1.0),
        height: None,
        margin: spec.sheet.margin,
        spacing: spec.sheet.spacing,
        ..Default::default()
    };
    search.apply(&mut opts);
    let layout = crate::nest::nest(pieces, &opts).map_err(|e| Error::In {
        file: spec.path.clone(),
        source: Box::new(e.into()),
    })?;
    let job = crate::toolpath::plan(&layout, &spec.name, &ToolpathOptions::default());
    let dir = extras
        .output
        .clone()
        .unwrap_or_else(|| default_dir(&spec.name));
    let mut run = RunFiles::begin(&dir)?;
    let paint = crate::output::texture::paint(&flats, &layout);
    let (mut files, print) = write_pictures(&mut run, &spec.name, &job, paint.as_ref(), extras)?;
    files.extend(write_alternatives(&mut run, &flats, extras.alternatives)?);
    files.push("report.json".into());
    let info = RunInfo {
        warnings: cuttable(&layout, 0.0, spec, extras.quiet),
        print,
        ..run_info(spec, "", &files)
    };
    write_report(&mut run, &info, &flats, &layout)?;
    run.commit()?;
    Ok(FlattenRun {
        flats,
        layout,
        dir,
        files,
    })
}

/// An ESICUP instance nested: the instance, its solution and where they were written.
#[derive(Debug)]
pub struct NestRun {
    pub instance: crate::nest::esicup::Instance,
    pub solution: crate::nest::problem::Solution,
    pub dir: PathBuf,
}

/// `flatcut nest`: nest an ESICUP strip-packing instance (default budget 60 s) and write
/// `solution.json` and `layout.svg`.
pub fn nest_instance(
    path: &Path,
    search: &Search,
    output: Option<PathBuf>,
) -> Result<NestRun, Error> {
    use crate::nest::esicup;
    let inst = esicup::load(path)?;
    let mut opts = crate::nest::NestOptions {
        seconds: 60.0,
        ..Default::default()
    };
    search.apply(&mut opts);
    let cfg = crate::nest::problem::Config {
        seconds: opts.seconds,
        seed: opts.seed,
        threads: opts.threads,
    };
    let sol = esicup::solve(&inst, &cfg)?;
    let dir = output.unwrap_or_else(|| default_dir(&inst.name));
    let mut run = RunFiles::begin(&dir)?;
    let text = serde_json::to_string_pretty(&esicup::solution_json(&inst, &sol))
        .unwrap_or_default()
        + "\n";
    run.write("solution.json", text.as_bytes())?;
    run.write("layout.svg", esicup::svg(&inst, &sol).as_bytes())?;
    run.commit()?;
    Ok(NestRun {
        instance: inst,
        solution: sol,
        dir,
    })
}

/// `flatcut check`: a mesh read without repairs and its figures.
pub fn check_mesh(path: &Path) -> Result<crate::surface::obj::MeshStats, Error> {
    let raw = crate::surface::import::read(path)?;
    Ok(crate::surface::obj::stats(&raw))
}

/// `flatcut send`: an existing program file, checked against the device's language (by its
/// extension) and not empty.
pub fn read_program(path: &Path, profile: &Profile) -> Result<Vec<u8>, Error> {
    let bytes = crate::geom::input::read_bytes(path, crate::geom::input::DATA_LIMIT)
        .map_err(|e| Error::Usage(format!("{}: cannot read: {e}", path.display())))?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let expected = profile.language.extensions();
    if !expected.contains(&ext.as_str()) {
        return Err(Error::Usage(format!(
            "{}: device `{}` speaks {}, which is sent from a .{} file; this file is `.{ext}`",
            path.display(),
            profile.name,
            profile.language.label(),
            expected[0]
        )));
    }
    if bytes.is_empty() {
        return Err(Error::Usage(format!(
            "{}: the file is empty",
            path.display()
        )));
    }
    Ok(bytes)
}

/// `--surface-obj` and `--uv-obj`, written before the run's own files.
fn write_extras(flats: &[Flat], extras: &Extras) -> Result<(), Error> {
    if let Some(p) = &extras.surface_obj {
        write_surface_obj(p, flats)?;
    }
    if let Some(p) = &extras.uv_obj {
        write_uv_obj(p, flats)?;
    }
    if let Some(p) = &extras.spline_json {
        let text = crate::output::design::spline_json(flats).ok_or_else(|| {
            Error::Usage(format!(
                "--spline-json {}: no spline surface to write",
                p.display()
            ))
        })?;
        if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
            create_dir(dir)?;
        }
        write_atomic(p, text.as_bytes())?;
    }
    Ok(())
}

/// The features of the pieces a device with this knife offset cannot make, printed to stderr
/// unless `quiet` (`toolpath::cuttable`).
fn cuttable(
    layout: &Layout,
    knife_offset: f64,
    spec: &Spec,
    quiet: bool,
) -> Vec<crate::toolpath::cuttable::Warning> {
    use crate::toolpath::cuttable::{check, CuttableOptions};
    let o = CuttableOptions::for_device(knife_offset, spec.pattern_options().kerf);
    let mut warnings = check(&layout.pieces, &o);
    let kind = spec.material.kind;
    for (piece, message) in crate::pattern::marks::seam_mismatches(&layout.pieces, kind) {
        warnings.push(crate::toolpath::cuttable::Warning {
            piece,
            kind: "seam-mismatch",
            message,
        });
    }
    for (piece, message) in crate::pattern::develop::warnings(&layout.pieces) {
        warnings.push(crate::toolpath::cuttable::Warning {
            piece,
            kind: "bend-development",
            message,
        });
    }
    if !quiet {
        for w in &warnings {
            eprintln!("flatcut: warning: {}", w.message);
        }
    }
    warnings
}

/// What report.json says about a run of `spec` on `device` that wrote `files`.
fn run_info(spec: &Spec, device: &str, files: &[String]) -> RunInfo {
    RunInfo {
        name: spec.name.clone(),
        spec: spec.path.display().to_string(),
        device: device.to_string(),
        material: spec.material.kind.to_string(),
        thickness_mm: spec.material.thickness,
        files: files.to_vec(),
        warnings: Vec::new(),
        dropped: Vec::new(),
        print: None,
    }
}

/// report.json: the run, its pieces, seams, sheets and per-surface figures.
fn write_report(
    run: &mut RunFiles,
    info: &RunInfo,
    flats: &[Flat],
    layout: &Layout,
) -> Result<(), Error> {
    let rep = report::build(info, flats, layout);
    let text = serde_json::to_string_pretty(&rep).unwrap_or_default() + "\n";
    Ok(run.write("report.json", text.as_bytes())?)
}

/// Write the surfaces' meshes into one OBJ file (`--surface-obj`), atomically.
pub fn write_surface_obj(path: &Path, flats: &[Flat]) -> Result<(), Error> {
    let mut mesh = crate::geom::mesh::Mesh::default();
    let mut names = Vec::new();
    for f in flats {
        let m = &f.surface.mesh;
        let base = mesh.vertices.len();
        mesh.vertices.extend_from_slice(&m.vertices);
        mesh.faces
            .extend(m.faces.iter().map(|face| crate::geom::mesh::Face {
                verts: face.verts.iter().map(|v| v + base).collect(),
                line: face.line,
            }));
        names.push(f.surface.name.clone());
    }
    let comment = format!("flatcut surface mesh (mm): {}", names.join(", "));
    let text = crate::output::obj::write(&mesh, None, &comment).unwrap_or_default();
    Ok(write_atomic(path, text.as_bytes())?)
}

/// `--uv-obj FILE`: each surface's mesh with its flat layout (mm) as `vt`; with several
/// surfaces, FILE gets `-<k>` before its extension from the second on.
pub fn write_uv_obj(path: &Path, flats: &[Flat]) -> Result<(), Error> {
    for (k, flat) in flats.iter().enumerate() {
        let file = if k == 0 {
            path.to_path_buf()
        } else {
            let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
            let ext = path.extension().map(|s| s.to_string_lossy().into_owned());
            path.with_file_name(format!(
                "{}-{}{}",
                stem.unwrap_or_default(),
                k + 1,
                ext.map(|e| format!(".{e}")).unwrap_or_default()
            ))
        };
        let comment = format!(
            "{}: {} pieces, flat coordinates in mm as vt (one per face corner)\nwritten by flatcut {}",
            flat.surface.name,
            flat.islands.len(),
            env!("CARGO_PKG_VERSION")
        );
        let text = crate::output::obj::write(&flat.surface.mesh, Some(&flat.face_2d), &comment)
            .ok_or_else(|| {
                Error::Usage(format!(
                    "{}: the flat layout does not cover every face corner",
                    file.display()
                ))
            })?;
        if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty()) {
            create_dir(dir)?;
        }
        write_atomic(&file, text.as_bytes())?;
    }
    Ok(())
}

/// `--alternatives N`: write `<surface>-alt-<k>.obj`, the surface's mesh first and then the
/// alternatives its source found; returns the file names.
fn write_alternatives(
    run: &mut RunFiles,
    flats: &[Flat],
    n: Option<usize>,
) -> Result<Vec<String>, Error> {
    let mut files = Vec::new();
    let Some(n) = n else { return Ok(files) };
    for f in flats {
        if f.surface.figures.is_empty() && f.surface.alternatives.is_empty() {
            continue;
        }
        let meshes = std::iter::once(&f.surface.mesh).chain(&f.surface.alternatives);
        for (k, mesh) in meshes.take(n).enumerate() {
            let name = format!("{}-alt-{}.obj", f.surface.name, k + 1);
            let comment = format!(
                "{} triangulation {} of {} found for surface `{}`",
                if k == 0 { "chosen" } else { "alternative" },
                k + 1,
                1 + f.surface.alternatives.len(),
                f.surface.name
            );
            let text = crate::output::obj::write(mesh, None, &comment).unwrap_or_default();
            run.write(&name, text.as_bytes())?;
            files.push(name);
        }
    }
    Ok(files)
}

/// Write `<name>.svg`, `<name>.pdf`, `<name>-<k>.png` per sheet (at `--dpi`, else the
/// preview resolution; a sheet too large for that is drawn coarser, with a warning unless
/// quiet) and, with `--print`, `<name>-print.pdf`, the textured faces of `paint` under the
/// strokes of the PDFs and PNGs; returns the file names and the tiling.
fn write_pictures(
    run: &mut RunFiles,
    name: &str,
    job: &Job,
    paint: Option<&crate::output::texture::Paint>,
    extras: &Extras,
) -> Result<(Vec<String>, Option<crate::output::print::Tiling>), Error> {
    let dpi = extras.dpi;
    let mut files = Vec::new();
    let px_per_mm = dpi.map_or(crate::output::png::DEFAULT_PX_PER_MM, |d| d / 25.4);
    // The pictures are independent: drawn on the machine's cores, written in order.
    let images: Vec<_> = paint.map_or(Vec::new(), |p| p.images().collect());
    let sheets: Vec<usize> = (0..job.sheets.len()).collect();
    let (pdf_bytes, pngs) = crate::geom::par::join(
        || crate::output::pdf::render_painted(job, paint),
        || {
            crate::geom::par::map(sheets, &[], &|i| {
                let faces = paint.map_or(&[][..], |p| p.sheet(i));
                crate::output::png::render_painted(&job.sheets[i], i + 1, px_per_mm, faces, &images)
            })
        },
    );
    let svg = format!("{name}.svg");
    run.write(&svg, crate::output::svg::render(job).as_bytes())?;
    files.push(svg);
    let pdf = format!("{name}.pdf");
    run.write(&pdf, &pdf_bytes)?;
    files.push(pdf);
    let mut tiling = None;
    if let Some(opts) = &extras.print {
        let plan = crate::output::print::plan(job, opts)?;
        let file = format!("{name}-print.pdf");
        run.write(&file, &crate::output::print::render(job, &plan, paint))?;
        files.push(file);
        tiling = Some(plan);
    }
    for ((i, sheet), bytes) in job.sheets.iter().enumerate().zip(pngs) {
        let png = format!("{name}-{}.png", i + 1);
        let bytes = bytes?;
        let drawn = crate::output::png::drawn_px_per_mm(sheet, px_per_mm);
        if let (Some(d), false) = (dpi, extras.quiet) {
            if drawn < px_per_mm {
                eprintln!(
                    "flatcut: warning: --dpi {d}: {png} ({:.0} x {:.0} mm) is drawn at {:.0} dpi, the most a {} px picture holds; print from {name}.pdf, which is 1:1 at any size",
                    sheet.width,
                    sheet.height,
                    drawn * 25.4,
                    crate::output::png::MAX_SIDE_PX
                );
            }
        }
        run.write(&png, &bytes)?;
        files.push(png);
    }
    Ok((files, tiling))
}

/// Write `<name>.dxf` (or `<name>-<k>.dxf` per sheet); returns the file names.
fn write_dxf(run: &mut RunFiles, name: &str, layout: &Layout) -> Result<Vec<String>, Error> {
    let n = layout.sheets.len();
    let mut files = Vec::new();
    for i in 0..n {
        let file = sheet_file(name, i, n, "dxf");
        run.write(&file, crate::output::dxf::render(layout, i).as_bytes())?;
        files.push(file);
    }
    Ok(files)
}

/// `<name>.<ext>` for a one-sheet job, else `<name>-<k>.<ext>` for sheet `k` (1-based).
fn sheet_file(name: &str, i: usize, n: usize, ext: &str) -> String {
    if n == 1 {
        format!("{name}.{ext}")
    } else {
        format!("{name}-{}.{ext}", i + 1)
    }
}
