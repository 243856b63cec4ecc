//! `flatcut cut SPEC|OBJ`: the whole pipeline. Reads the spec (or a bare OBJ with defaults),
//! applies the device profile and the flags (flags win), unfolds, nests, orders the strokes and
//! writes into `-o DIR`: the program for the device (`<name>.plt`, or `<name>-<k>.plt` per sheet
//! when there are several), `<name>.svg`, `<name>-<k>.png` per sheet, `<name>.dxf` (or
//! `<name>-<k>.dxf`) per sheet and `report.json`, each
//! written whole or not at all. Then, unless `--dry-run`, the program is streamed to the
//! device: the simulated cutter for `sim` (the default) or with `--simulate`, else the serial
//! port given by `--port` (see [`super::link`]). The files are written before anything is
//! sent, so a failed or interrupted send loses nothing.

use crate::output::files::{create_dir, write_atomic};
use crate::output::report::{self, RunInfo};
use crate::spec::MaterialKind;
use crate::toolpath::{StrokeKind, ToolpathOptions};
use crate::Error;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
pub struct CutArgs {
    /// Spec file (`.toml`) or a mesh (`.obj`) to cut with default settings.
    pub input: PathBuf,
    /// Directory for the program, pictures and report (default: out/<name>).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Device profile (see devices/; default: the spec's, else `sim`).
    #[arg(long)]
    pub device: Option<String>,
    /// Material: paper, fabric or metal (overrides the spec).
    #[arg(long)]
    pub material: Option<MaterialKind>,
    /// Write the program and pictures but send nothing.
    #[arg(long)]
    pub dry_run: bool,
    #[command(flatten)]
    pub toolpath: ToolpathArgs,
    #[command(flatten)]
    pub pattern: super::PatternArgs,
    #[command(flatten)]
    pub link: super::link::LinkArgs,
    #[command(flatten)]
    pub search: super::nest::SearchArgs,
    /// Boundary surfaces: also write the N best distinct triangulations found, as
    /// `<surface>-alt-<k>.obj` (k = 1 is the one cut), to pick another by hand.
    #[arg(long, value_name = "N")]
    pub alternatives: Option<usize>,
    #[command(flatten)]
    pub smooth: super::flatten::SmoothArgs,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
    /// Also write the 3D surface mesh (all surfaces, mm) as a Wavefront OBJ file, to look at in
    /// a 3D viewer.
    #[arg(long, value_name = "FILE")]
    pub surface_obj: Option<PathBuf>,
}

/// Write the surfaces' meshes into one OBJ file (`--surface-obj`), atomically.
pub fn write_surface_obj(path: &Path, flats: &[crate::flatten::Flat]) -> Result<(), Error> {
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

/// `--alternatives N`: ask every boundary surface of the spec for its N best triangulations.
pub fn ask_alternatives(spec: &mut crate::spec::Spec, n: Option<usize>) {
    if let Some(n) = n {
        for s in &mut spec.surfaces {
            if let Some(b) = s.boundary.as_mut() {
                b.options.alternatives = n.max(1);
            }
        }
    }
}

/// `--alternatives N`: write `<surface>-alt-<k>.obj`, the surface's mesh first and then the
/// alternatives its source found; returns the file names.
pub fn write_alternatives(
    dir: &Path,
    flats: &[crate::flatten::Flat],
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
            write_atomic(&dir.join(&name), text.as_bytes())?;
            files.push(name);
        }
    }
    Ok(files)
}

/// Flags of the toolpath stage (ordering, folds, weeding, drag knife).
#[derive(Debug, Clone, Default, Args)]
pub struct ToolpathArgs {
    /// How folds are made: score, perforate (dashes), draw or none (default: score if the
    /// device has a scoring tool, else perforate, else draw).
    #[arg(long, value_enum)]
    pub folds: Option<FoldChoice>,
    /// Finish each piece before the next (default: on for fabric, which may shift).
    #[arg(long, num_args = 0..=1, default_missing_value = "true")]
    pub per_piece: Option<bool>,
    /// Cut weed lines (vinyl): a border round the used area and lines through the waste.
    #[arg(long)]
    pub weed: bool,
    /// Drag-knife blade offset in mm (overrides the profile's `knife_offset`; 0: no
    /// compensation).
    #[arg(long)]
    pub knife_offset: Option<f64>,
}

/// `--folds`: the tool that makes folds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FoldChoice {
    Score,
    Perforate,
    Draw,
    None,
}

/// Make the profile's tool table say how folds are made: the tools that would be picked before
/// the chosen one are taken out of this job's copy of the profile (folds take the scoring tool,
/// else the perforating one, else the pen; nothing else uses the first two). A knife offset
/// given on the command line replaces the profile's.
pub fn apply_flags(
    profile: &mut crate::profile::Profile,
    folds: Option<FoldChoice>,
    knife_offset: Option<f64>,
) -> Result<(), Error> {
    if let Some(v) = knife_offset {
        if !(v.is_finite() && v >= 0.0) {
            return Err(Error::Usage(format!(
                "--knife-offset must be 0 (off) or a length in mm, got {v}"
            )));
        }
        profile.knife_offset = v;
    }
    let (kind, drop): (StrokeKind, &[&str]) = match folds {
        // `none` leaves the folds out of the job (`ToolpathOptions::skip_folds`).
        None | Some(FoldChoice::None) => return Ok(()),
        Some(FoldChoice::Score) => (StrokeKind::Score, &[]),
        Some(FoldChoice::Perforate) => (StrokeKind::Perforate, &["score"]),
        Some(FoldChoice::Draw) => (StrokeKind::Draw, &["score", "perforate"]),
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
    Ok(())
}

/// The job as the device makes it: folds as the profile's tools make them (perforation
/// dashes), overcut, drag-knife compensation with its alignment precut in the sheet margin.
pub fn machine_job(
    job: &crate::toolpath::Job,
    profile: &crate::profile::Profile,
    spec: &crate::spec::Spec,
) -> crate::toolpath::Job {
    crate::toolpath::knife::prepare(
        job,
        &crate::toolpath::knife::MachineOptions::from_profile(profile, spec.sheet.margin),
    )
}

/// Default output directory for a job name.
pub fn default_dir(name: &str) -> PathBuf {
    Path::new("out").join(name)
}

/// Spec → pieces → layout → job for a device: what `cut` sends (the device decides which
/// stroke kinds are drawn at all), with the default nesting search.
#[allow(clippy::type_complexity)]
pub fn plan_job(
    spec: &crate::spec::Spec,
    profile: &crate::profile::Profile,
    quiet: bool,
) -> Result<
    (
        Vec<crate::flatten::Flat>,
        crate::nest::Layout,
        crate::toolpath::Job,
    ),
    Error,
> {
    plan_job_with(spec, profile, &Default::default(), quiet, |_| {})
}

/// [`plan_job`] with the nesting search flags (`--nest-time`, `--seed`, `--threads`) and the
/// toolpath options adjusted by `adjust` (flags).
pub fn plan_job_with(
    spec: &crate::spec::Spec,
    profile: &crate::profile::Profile,
    search: &super::nest::SearchArgs,
    quiet: bool,
    adjust: impl FnOnce(&mut ToolpathOptions),
) -> Result<
    (
        Vec<crate::flatten::Flat>,
        crate::nest::Layout,
        crate::toolpath::Job,
    ),
    Error,
> {
    let (flats, pieces) = super::pieces(spec, quiet)?;
    let mut nest_opts = crate::nest::NestOptions {
        width: spec.sheet.width,
        height: spec.sheet.height,
        margin: spec.sheet.margin,
        spacing: spec.sheet.spacing,
        ..Default::default()
    };
    search.apply(&mut nest_opts)?;
    let layout = crate::nest::nest(pieces, &nest_opts).map_err(|e| Error::In {
        file: spec.path.clone(),
        source: Box::new(e.into()),
    })?;
    let mut tp = ToolpathOptions {
        skip_folds: crate::toolpath::fold_kind(|k| profile.has(k)).is_none(),
        skip_drawing: !profile.has(StrokeKind::Draw),
        per_piece: spec.material.kind == MaterialKind::Fabric,
        weed: None,
    };
    adjust(&mut tp);
    let job = crate::toolpath::plan(&layout, &spec.name, &tp);

    Ok((flats, layout, job))
}

pub fn run(a: &CutArgs) -> Result<(), Error> {
    let mut spec = crate::spec::load(&a.input)?;
    if let Some(m) = a.material {
        spec.material.kind = m;
    }
    run_spec(spec, a)
}

/// The rest of `cut` for a spec already in hand (`cut` reads it from a file, `fitting` builds
/// it from its flags): the pattern flags on top, plan, write the files, send.
pub fn run_spec(mut spec: crate::spec::Spec, a: &CutArgs) -> Result<(), Error> {
    a.pattern.apply(&mut spec)?;
    ask_alternatives(&mut spec, a.alternatives);
    a.smooth.apply(&mut spec);
    let device = a
        .device
        .clone()
        .or_else(|| spec.device.clone())
        .unwrap_or_else(|| "sim".to_string());
    let mut profile = crate::profile::find(&device)?;
    let t = &a.toolpath;
    apply_flags(&mut profile, t.folds, t.knife_offset)?;
    if !a.dry_run && !super::link::simulated(&profile, &a.link) && a.link.port.is_none() {
        return Err(Error::Usage(format!(
            "device `{}` is a real machine: give its serial port with --port (see `flatcut ports`), or use --simulate or --dry-run",
            profile.name
        )));
    }
    let (flats, layout, job) = plan_job_with(&spec, &profile, &a.search, a.quiet, |tp| {
        if let Some(p) = t.per_piece {
            tp.per_piece = p;
        }
        if t.folds == Some(FoldChoice::None) {
            tp.skip_folds = true;
        }
        if t.weed {
            tp.weed = Some(crate::toolpath::weed::WeedOptions::default());
        }
    })?;
    let machine = machine_job(&job, &profile, &spec);
    if let Some(p) = &a.surface_obj {
        write_surface_obj(p, &flats)?;
    }
    a.smooth.write_uv(&flats)?;

    let dir = a.output.clone().unwrap_or_else(|| default_dir(&spec.name));
    create_dir(&dir)?;
    let mut files = Vec::new();
    let mut programs = Vec::new();
    let ext = profile.language.extension();
    let n = job.sheets.len();
    for (i, sheet) in machine.sheets.iter().enumerate() {
        let name = sheet_file(&spec.name, i, n, ext);
        let bytes = crate::output::program(sheet, &profile).map_err(|e| e.on_sheet(i + 1))?;
        write_atomic(&dir.join(&name), &bytes)?;
        files.push(name.clone());
        programs.push((name, bytes));
    }
    files.extend(super::flatten::write_pictures(&dir, &spec.name, &job)?);
    files.extend(write_dxf(&dir, &spec.name, &layout)?);
    files.extend(write_alternatives(&dir, &flats, a.alternatives)?);
    files.push("report.json".into());
    let info = RunInfo {
        name: spec.name.clone(),
        spec: spec.path.display().to_string(),
        device: profile.name.clone(),
        material: spec.material.kind.to_string(),
        thickness_mm: spec.material.thickness,
        files: files.clone(),
    };
    let rep = report::build(&info, &flats, &layout);
    let text = serde_json::to_string_pretty(&rep).unwrap_or_default() + "\n";
    write_atomic(&dir.join("report.json"), text.as_bytes())?;

    if !a.quiet {
        let cut: f64 = layout.pieces.iter().map(|p| p.cut_length()).sum();
        let fold: f64 = layout.pieces.iter().map(|p| p.fold_length()).sum::<f64>() + 0.0; // not -0
        println!(
            "{}: {} pieces on {} {} ({:.0} mm cut, {:.0} mm folds), device {}",
            spec.name,
            layout.pieces.len(),
            layout.sheets.len(),
            if layout.roll {
                "roll"
            } else if n == 1 {
                "sheet"
            } else {
                "sheets"
            },
            cut,
            fold,
            profile.name
        );
        for i in 0..layout.sheets.len() {
            println!(
                "  {} {}: {:.0} × {:.0} mm, {:.1} % used",
                if layout.roll { "roll" } else { "sheet" },
                i + 1,
                layout.sheets[i].width,
                layout.sheets[i].height,
                100.0 * layout.utilisation(i)
            );
        }
        if let Some(len) = layout.roll_length() {
            println!("  roll length used: {len:.1} mm");
        }
        if let Some((lo, hi)) = layout.remnant {
            println!(
                "  left on the last sheet: {:.0} × {:.0} mm at ({:.0}, {:.0})",
                hi.x - lo.x,
                hi.y - lo.y,
                lo.x,
                lo.y
            );
        }
        println!("wrote {}: {}", dir.display(), files.join(", "));
        if a.dry_run {
            println!("dry run: nothing sent");
        }
    }
    if !a.dry_run {
        for line in super::link::deliver(&programs, &profile, &a.link, &dir, a.quiet)? {
            if !a.quiet {
                println!("{line}");
            }
        }
    }
    Ok(())
}

/// `<name>.<ext>` for a one-sheet job, else `<name>-<k>.<ext>` for sheet `k` (1-based).
fn sheet_file(name: &str, i: usize, n: usize, ext: &str) -> String {
    if n == 1 {
        format!("{name}.{ext}")
    } else {
        format!("{name}-{}.{ext}", i + 1)
    }
}

/// Write `<name>.dxf` (or `<name>-<k>.dxf` per sheet); returns the file names.
pub fn write_dxf(
    dir: &Path,
    name: &str,
    layout: &crate::nest::Layout,
) -> Result<Vec<String>, Error> {
    let n = layout.sheets.len();
    let mut files = Vec::new();
    for i in 0..n {
        let file = sheet_file(name, i, n, "dxf");
        write_atomic(
            &dir.join(&file),
            crate::output::dxf::render(layout, i).as_bytes(),
        )?;
        files.push(file);
    }
    Ok(files)
}
