//! `flatcut flatten SPEC|OBJ`: stops after the pattern stage and writes the pieces as SVG and
//! PNG (laid side by side on one long strip, no sheet limits) plus `report.json`.

use crate::output::files::{create_dir, write_atomic};
use crate::output::report::{self, RunInfo};
use crate::toolpath::{Job, ToolpathOptions};
use crate::Error;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
pub struct FlattenArgs {
    /// Spec file (`.toml`) or a mesh (`.obj`).
    pub input: PathBuf,
    /// Directory for the pictures and report (default: out/<name>).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Material: paper, fabric or metal (overrides the spec).
    #[arg(long)]
    pub material: Option<crate::spec::MaterialKind>,
    #[command(flatten)]
    pub pattern: super::PatternArgs,
    #[command(flatten)]
    pub search: super::nest::SearchArgs,
    /// Boundary surfaces: also write the N best distinct triangulations found, as
    /// `<surface>-alt-<k>.obj` (k = 1 is the one flattened).
    #[arg(long, value_name = "N")]
    pub alternatives: Option<usize>,
    #[command(flatten)]
    pub smooth: SmoothArgs,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
    /// Also write the 3D surface mesh (all surfaces, mm) as a Wavefront OBJ file.
    #[arg(long, value_name = "FILE")]
    pub surface_obj: Option<PathBuf>,
}

/// Write `<name>.svg` and `<name>-<k>.png` per sheet; returns the file names.
pub fn write_pictures(dir: &Path, name: &str, job: &Job) -> Result<Vec<String>, Error> {
    let mut files = Vec::new();
    let svg = format!("{name}.svg");
    write_atomic(&dir.join(&svg), crate::output::svg::render(job).as_bytes())?;
    files.push(svg);
    for (i, sheet) in job.sheets.iter().enumerate() {
        let png = format!("{name}-{}.png", i + 1);
        let bytes =
            crate::output::png::render(sheet, i + 1, crate::output::png::DEFAULT_PX_PER_MM)?;
        write_atomic(&dir.join(&png), &bytes)?;
        files.push(png);
    }
    Ok(files)
}

pub fn run(a: &FlattenArgs) -> Result<(), Error> {
    let mut spec = crate::spec::load(&a.input)?;
    if let Some(m) = a.material {
        spec.material.kind = m;
    }
    a.pattern.apply(&mut spec)?;
    super::cut::ask_alternatives(&mut spec, a.alternatives);
    a.smooth.apply(&mut spec);
    let (flats, pieces) = super::pieces(&spec, a.quiet)?;
    if let Some(p) = &a.surface_obj {
        super::cut::write_surface_obj(p, &flats)?;
    }
    a.smooth.write_uv(&flats)?;
    // One strip wide enough for the widest piece: the pieces, not the sheets, are the result.
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
    a.search.apply(&mut opts)?;
    let layout = crate::nest::nest(pieces, &opts).map_err(|e| Error::In {
        file: spec.path.clone(),
        source: Box::new(e.into()),
    })?;
    let job = crate::toolpath::plan(&layout, &spec.name, &ToolpathOptions::default());
    let dir = a
        .output
        .clone()
        .unwrap_or_else(|| super::cut::default_dir(&spec.name));
    create_dir(&dir)?;
    let mut files = write_pictures(&dir, &spec.name, &job)?;
    files.extend(super::cut::write_alternatives(
        &dir,
        &flats,
        a.alternatives,
    )?);
    files.push("report.json".into());
    let info = RunInfo {
        name: spec.name.clone(),
        spec: spec.path.display().to_string(),
        device: String::new(),
        material: spec.material.kind.to_string(),
        thickness_mm: spec.material.thickness,
        files: files.clone(),
    };
    let text = serde_json::to_string_pretty(&report::build(&info, &flats, &layout))
        .unwrap_or_default()
        + "\n";
    write_atomic(&dir.join("report.json"), text.as_bytes())?;
    if !a.quiet {
        println!(
            "{}: {} pieces; wrote {}: {}",
            spec.name,
            layout.pieces.len(),
            dir.display(),
            files.join(", ")
        );
    }
    Ok(())
}

/// Smooth-mesh flags (issue 7), shared by `flatten` and `cut`.
#[derive(Debug, Clone, Default, Args)]
pub struct SmoothArgs {
    /// How mesh surfaces are cut into pieces: `faces` (exact unfolding of flat panels) or
    /// `dcharts` (nearly developable charts of a smooth mesh); default: the spec's `segment`,
    /// else dcharts for smooth meshes.
    #[arg(long, value_name = "faces|dcharts")]
    pub segment: Option<crate::spec::Segment>,
    /// Also write the mesh with its flat layout (mm) as texture coordinates `vt` (Wavefront
    /// OBJ); with several surfaces, FILE gets `-<k>` before its extension from the second on.
    #[arg(long, value_name = "FILE")]
    pub uv_obj: Option<PathBuf>,
}

impl SmoothArgs {
    /// Puts `--segment` into every mesh surface of the spec (flags win).
    pub fn apply(&self, spec: &mut crate::spec::Spec) {
        if let Some(mode) = self.segment {
            for s in spec
                .surfaces
                .iter_mut()
                .filter(|s| s.kind == crate::spec::SurfaceKind::Mesh)
            {
                s.segment.mode = Some(mode);
            }
        }
    }

    /// Writes `--uv-obj` (atomically), if asked.
    pub fn write_uv(&self, flats: &[crate::flatten::Flat]) -> Result<(), Error> {
        let Some(path) = &self.uv_obj else {
            return Ok(());
        };
        for (k, flat) in flats.iter().enumerate() {
            let file = if k == 0 {
                path.clone()
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
}
