//! Flag groups shared by several subcommands (`cut`, `flatten`, `fitting`, `nest`): each is a
//! clap struct that checks its values, names the flag in its error, and turns into the
//! pipeline's options or puts itself into the spec (flags win over the spec and the profile).

use crate::pipeline::{Folds, Search, Toolpath};
use crate::spec::Spec;
use crate::Error;
use clap::Args;
use std::path::PathBuf;

/// Pattern settings on the command line; they override the spec's `[pattern]` table.
#[derive(Debug, Clone, Default, Args)]
pub struct PatternArgs {
    /// Glue tabs: none, one-side or both (default: one-side for paper, else none).
    #[arg(long, value_enum)]
    pub tabs: Option<crate::pattern::Tabs>,
    /// Notches along every seam, every MM millimetres (default 50 with the flag; fabric has
    /// them at 50 mm anyway; 0 turns them off).
    #[arg(long, value_name = "MM", num_args = 0..=1, default_missing_value = "50")]
    pub notches: Option<f64>,
    /// Seam allowance in mm (default: 10 for fabric, else 0).
    #[arg(long, value_name = "MM")]
    pub allowance: Option<f64>,
    /// Width of the cut in mm: cut contours move half of it away from the piece.
    #[arg(long, value_name = "MM")]
    pub kerf: Option<f64>,
    /// V notches in the outline where bend lines meet it (sheet metal).
    #[arg(long)]
    pub bend_notches: bool,
}

impl PatternArgs {
    /// Puts the flags into the spec (flags win), refusing values that make no sense.
    pub fn apply(&self, spec: &mut Spec) -> Result<(), Error> {
        let check = |v: Option<f64>, flag: &str| match v {
            Some(x) if !(x.is_finite() && x >= 0.0) => Err(Error::Usage(format!(
                "--{flag} {x}: must be a length in mm, at least 0"
            ))),
            _ => Ok(()),
        };
        check(self.notches, "notches")?;
        check(self.allowance, "allowance")?;
        check(self.kerf, "kerf")?;
        let p = &mut spec.pattern;
        p.tabs = self.tabs.or(p.tabs);
        p.notches = self.notches.or(p.notches);
        p.allowance = self.allowance.or(p.allowance);
        p.kerf = self.kerf.or(p.kerf);
        if self.bend_notches {
            p.bend_notches = Some(true);
        }
        Ok(())
    }
}

/// Search flags shared by `nest`, `cut` and `flatten`.
#[derive(Debug, Args, Clone, Copy, Default)]
pub struct SearchArgs {
    /// Time for the nesting search in seconds (a deterministic work budget calibrated to
    /// seconds on a 2-core machine; default 1 for cut and flatten, 60 for nest).
    #[arg(long, value_name = "SECONDS")]
    pub nest_time: Option<f64>,
    /// Seed of the nesting search: the same seed and thread count give the same layout.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Independent nesting searches run in parallel (default 2).
    #[arg(long)]
    pub threads: Option<usize>,
}

impl SearchArgs {
    /// The search settings the flags give, refusing a budget that is not a time.
    pub fn search(&self) -> Result<Search, Error> {
        if let Some(t) = self.nest_time {
            if !(t.is_finite() && t >= 0.0) {
                return Err(Error::Usage(format!(
                    "--nest-time must be a number of seconds ≥ 0, got {t}"
                )));
            }
        }
        Ok(Search {
            seconds: self.nest_time,
            seed: self.seed,
            threads: self.threads,
        })
    }
}

/// Flags of the toolpath stage (ordering, folds, weeding, drag knife).
#[derive(Debug, Clone, Default, Args)]
pub struct ToolpathArgs {
    /// How folds are made: score, perforate (dashes), draw or none (default: score if the
    /// device has a scoring tool, else perforate, else draw).
    #[arg(long, value_enum)]
    pub folds: Option<Folds>,
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

impl ToolpathArgs {
    /// The device profile `name` as this job uses it (folds, knife offset from the flags).
    pub fn device(&self, name: &str) -> Result<crate::profile::Profile, Error> {
        if let Some(v) = self.knife_offset {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::Usage(format!(
                    "--knife-offset must be 0 (off) or a length in mm, got {v}"
                )));
            }
        }
        crate::pipeline::device(name, self.folds, self.knife_offset)
    }

    /// The toolpath choices the flags make.
    pub fn choices(&self) -> Toolpath {
        Toolpath {
            folds: self.folds,
            per_piece: self.per_piece,
            weed: self.weed,
            ..Toolpath::default()
        }
    }
}

/// Smooth-mesh flags, shared by `flatten` and `cut`.
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
    pub fn apply(&self, spec: &mut Spec) {
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
}

/// `--alternatives N`: ask every boundary surface of the spec for its N best triangulations.
pub fn ask_alternatives(spec: &mut Spec, n: Option<usize>) {
    if let Some(n) = n {
        for s in &mut spec.surfaces {
            if let Some(b) = s.boundary.as_mut() {
                b.options.alternatives = n.max(1);
            }
        }
    }
}
