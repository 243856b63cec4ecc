//! Flag groups shared by several subcommands (`cut`, `flatten`, `fitting`, `nest`): each is a
//! clap struct that checks its values, names the flag in its error, and turns into the
//! pipeline's options or puts itself into the spec (flags win over the spec and the profile).

use crate::pipeline::{Folds, Search, Toolpath};
use crate::spec::Spec;
use crate::surface::strip::BendLines;
use crate::Error;
use clap::Args;
use std::path::PathBuf;

/// How a metal sheet bends, on the command line (`cut`, `flatten`); they override the spec's
/// `[material]` table (`--k-factor` also the `k_factor` of its strips and spline surfaces,
/// as `flatcut fitting --k-factor` does for a fitting).
#[derive(Debug, Clone, Default, Args)]
pub struct MetalArgs {
    /// Sheet thickness in mm (default: the spec's, else by material: paper 0.25, fabric 0.5,
    /// metal 1).
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    pub thickness: Option<f64>,
    /// K factor of the metal's bends: the neutral surface's depth below the inside face over
    /// the thickness, 0 to 1 (default 0.4).
    #[arg(long, value_name = "K", allow_negative_numbers = true)]
    pub k_factor: Option<f64>,
    /// Inside bend radius in mm of the folds of metal meshes (default: the thickness).
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    pub bend_radius: Option<f64>,
}

impl MetalArgs {
    /// Puts the flags into the spec (flags win), refusing values that make no sense.
    pub fn apply(&self, spec: &mut Spec) -> Result<(), Error> {
        let bad = |flag: &str, v: f64, what: &str| {
            Err(Error::Usage(format!("--{flag} {v}: must be {what}")))
        };
        if let Some(t) = self.thickness {
            if !(t.is_finite() && t > 0.0) {
                return bad("thickness", t, "a thickness in mm, more than 0");
            }
            spec.material.thickness = t;
            spec.material.thickness_given = true;
        }
        if let Some(k) = self.k_factor {
            if !(0.0..=1.0).contains(&k) {
                return bad("k-factor", k, "a number from 0 to 1");
            }
            spec.material.k_factor = k;
            for s in &mut spec.surfaces {
                if let Some((_, sk)) = s.strip.as_mut().and_then(|st| st.sheet.as_mut()) {
                    *sk = k;
                }
                if let Some(sp) = &mut s.spline {
                    sp.sheet.1 = k;
                }
            }
        }
        if let Some(r) = self.bend_radius {
            if !(r.is_finite() && r >= 0.0) {
                return bad("bend-radius", r, "a radius in mm, at least 0");
            }
            spec.material.bend_radius = Some(r);
        }
        Ok(())
    }
}

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
    /// Pieces too large for the sheet: auto (split them along their fold lines, interior
    /// edges or rulings so that every part fits) or none (refuse them). Default: auto.
    #[arg(long, value_enum)]
    pub split: Option<crate::pattern::split::Split>,
    /// Which rulings of strips, bent sheets and spline surfaces are scored: all, none, one
    /// every MM millimetres (the angles in between summed) or shop (equal shares of the bend
    /// on lines at least 20 mm apart); overrides their `bend_lines`. Creases of spline
    /// surfaces are folds whatever this says.
    #[arg(long, value_name = "all|none|shop|MM", value_parser = parse_bend_lines)]
    pub bend_lines: Option<BendLines>,
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
        p.split = self.split.or(p.split);
        if let Some(lines) = self.bend_lines {
            spec.set_bend_lines(lines);
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

/// `--size`, `--scale`, `--units`: the model's size (`cut`, `flatten`); they override the
/// spec's `size`, `scale` and `units`, and apply to a bare mesh file as its model.
#[derive(Debug, Clone, Default, Args)]
pub struct SizeArgs {
    /// The assembled model's largest dimension in mm (all surfaces together, aspect kept;
    /// over the spec's `size`, `scale` and `units`).
    #[arg(long, value_name = "MM", allow_negative_numbers = true, value_parser = positive_number)]
    pub size: Option<f64>,
    /// Factor on every surface's coordinates (over the spec's `scale`).
    #[arg(long, value_name = "F", allow_negative_numbers = true, value_parser = positive_number)]
    pub scale: Option<f64>,
    /// Units of the model's coordinates: mm, cm, m or in (over the spec's `units`).
    #[arg(long, value_name = "mm|cm|m|in", value_parser = parse_units)]
    pub units: Option<crate::spec::Units>,
}

impl SizeArgs {
    /// Puts the flags into the spec (flags win: `--scale` and `--units` replace every
    /// surface's own `size`, `--size` the job's).
    pub fn apply(&self, spec: &mut Spec) {
        if self.size.is_some() {
            spec.size = self.size;
        }
        for s in &mut spec.surfaces {
            if let Some(f) = self.scale {
                s.scale = f;
                s.size = None;
            }
            if let Some(u) = self.units {
                s.units = u;
                s.size = None;
            }
        }
    }
}

/// A number more than 0 (`--size`, `--scale`).
pub fn positive_number(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("must be a number more than 0, got {s:?}")),
    }
}

/// A number at least 0 (`--margin`, `--spacing`).
pub fn non_negative_mm(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("must be a length in mm, at least 0, got {s:?}")),
    }
}

/// `mm`, `cm`, `m` or `in`.
pub fn parse_units(s: &str) -> Result<crate::spec::Units, String> {
    use crate::spec::Units;
    match s.trim().to_ascii_lowercase().as_str() {
        "mm" => Ok(Units::Mm),
        "cm" => Ok(Units::Cm),
        "m" => Ok(Units::M),
        "in" | "inch" | "inches" => Ok(Units::In),
        _ => Err(format!("expected mm, cm, m or in, got {s:?}")),
    }
}

/// Named sheets, portrait (width × height, mm): ISO 216 A sizes, ANSI letter, legal and
/// tabloid, and the 12 × 12 in and 12 × 24 in mats of desktop cutters.
pub const SHEETS: [(&str, f64, f64); 10] = [
    ("a4", 210.0, 297.0),
    ("a3", 297.0, 420.0),
    ("a2", 420.0, 594.0),
    ("a1", 594.0, 841.0),
    ("a0", 841.0, 1189.0),
    ("letter", 215.9, 279.4),
    ("legal", 215.9, 355.6),
    ("tabloid", 279.4, 431.8),
    ("mat12x12", 304.8, 304.8),
    ("mat12x24", 304.8, 609.6),
];

/// A length in mm, or in inches with `in` after it (`610`, `24in`).
pub fn parse_length(s: &str) -> Result<f64, String> {
    let t = s.trim().to_ascii_lowercase();
    let (num, k) = match t.strip_suffix("in") {
        Some(n) => (n.trim().to_string(), 25.4),
        None => (t.strip_suffix("mm").unwrap_or(&t).trim().to_string(), 1.0),
    };
    match num.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v * k),
        _ => Err(format!(
            "expected a width in mm more than 0, or in inches like `24in`, got {s:?}"
        )),
    }
}

/// A sheet name or `WxH` in mm (`300x200`) or inches (`12x18in`): (width, height) in mm.
pub fn parse_sheet(s: &str) -> Result<(f64, f64), String> {
    let t = s.trim().to_ascii_lowercase();
    if let Some(&(_, w, h)) = SHEETS.iter().find(|(n, _, _)| *n == t) {
        return Ok((w, h));
    }
    let names: Vec<&str> = SHEETS.iter().map(|s| s.0).collect();
    let bad = || {
        format!(
            "expected {} or WIDTHxHEIGHT in mm (300x200) or inches (12x18in), got {s:?}",
            names.join(", ")
        )
    };
    let (dims, k) = match t.strip_suffix("in") {
        Some(d) => (d, 25.4),
        None => (t.strip_suffix("mm").unwrap_or(&t), 1.0),
    };
    let (w, h) = dims.split_once(['x', '×']).ok_or_else(bad)?;
    let num = |v: &str| {
        v.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
    };
    match (num(w), num(h)) {
        (Some(w), Some(h)) => Ok((w * k, h * k)),
        _ => Err(bad()),
    }
}

/// Sheet flags (`cut`, `flatten`, `fitting`): over the spec's `[sheet]`, which is over a
/// roll-fed device's roll.
#[derive(Debug, Clone, Default, Args)]
pub struct SheetArgs {
    /// The sheet: a4, a3, a2, a1, a0, letter, legal, tabloid, mat12x12, mat12x24 (cutter
    /// mats), or WIDTHxHEIGHT in mm (300x200) or inches (12x18in); portrait unless
    /// --landscape.
    #[arg(long, value_name = "NAME|WxH", value_parser = parse_sheet)]
    pub sheet: Option<(f64, f64)>,
    /// Turn the sheet so that its long side runs along x.
    #[arg(long)]
    pub landscape: bool,
    /// A roll WIDTH mm wide (or `24in`), of unlimited length, instead of a sheet.
    #[arg(long, value_name = "WIDTH", allow_negative_numbers = true, value_parser = parse_length, conflicts_with = "sheet")]
    pub roll: Option<f64>,
    /// Blank border kept on every side of the sheet, mm.
    #[arg(long, value_name = "MM", allow_negative_numbers = true, value_parser = non_negative_mm)]
    pub margin: Option<f64>,
    /// Smallest gap between two pieces, mm.
    #[arg(long, value_name = "MM", allow_negative_numbers = true, value_parser = non_negative_mm)]
    pub spacing: Option<f64>,
}

impl SheetArgs {
    /// The sheet of a job: the spec's, else a roll-fed device's roll (`profile`: its
    /// `media_width`, when its x and y are exchanged because the media is fed along x), then
    /// the flags on top; refuses a margin that leaves no room.
    pub fn apply(
        &self,
        spec: &mut Spec,
        profile: Option<&crate::profile::Profile>,
    ) -> Result<(), Error> {
        let sheet = &mut spec.sheet;
        if let Some(p) = profile.filter(|p| !spec.sheet_given && p.axes.swap_xy) {
            if p.media_width > 0.0 {
                sheet.width = p.media_width;
                sheet.height = None;
            }
        }
        if let Some((w, h)) = self.sheet {
            sheet.width = w;
            sheet.height = Some(h);
        }
        if let Some(w) = self.roll {
            sheet.width = w;
            sheet.height = None;
        }
        if self.landscape {
            match sheet.height {
                Some(h) if h > sheet.width => {
                    sheet.height = Some(sheet.width);
                    sheet.width = h;
                }
                Some(_) => {}
                None => {
                    return Err(Error::Usage(
                        "--landscape: the job is on a roll, which has no landscape; give --sheet"
                            .into(),
                    ))
                }
            }
        }
        if let Some(m) = self.margin {
            sheet.margin = m;
        }
        if let Some(s) = self.spacing {
            sheet.spacing = s;
        }
        let short = sheet.height.map_or(sheet.width, |h| h.min(sheet.width));
        if 2.0 * sheet.margin >= short {
            return Err(Error::Usage(format!(
                "--margin {}: must be less than half the sheet's {} mm side",
                sheet.margin, short
            )));
        }
        Ok(())
    }
}

/// The largest `--dpi`: 1200 dpi, a photo printer's; more only makes huge pictures.
pub const MAX_DPI: f64 = 1200.0;

/// Picture flags (`cut`, `flatten`).
#[derive(Debug, Clone, Default, Args)]
pub struct PictureArgs {
    /// Resolution of the PNG pictures in dots per inch, more than 0 and at most 1200, written
    /// into each PNG (`pHYs`); default: 300 with `--print`, else the preview's 4 px/mm
    /// (101.6 dpi). A picture whose
    /// longer side would pass 6000 px is drawn coarser and says so in its `pHYs`.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = parse_dpi)]
    pub dpi: Option<f64>,
    /// Also write `<name>-print.pdf`: each sheet tiled 1:1 onto printer pages (a4, a3, letter,
    /// legal, tabloid or WxH in mm or inches) with overlaps, match lines and an assembly map
    /// per sheet, for a home printer.
    #[arg(long, value_name = "PAPER", value_parser = parse_paper)]
    pub print: Option<(String, f64, f64)>,
    /// The printer's unprintable margin at each page edge for `--print`, mm (default 6.35,
    /// rounded up to 0.254 mm).
    #[arg(long, value_name = "MM", requires = "print", allow_negative_numbers = true, value_parser = parse_non_negative)]
    pub print_margin: Option<f64>,
    /// How far neighbouring `--print` pages overlap, mm (default 10.16, rounded to 0.254 mm).
    #[arg(long, value_name = "MM", requires = "print", allow_negative_numbers = true, value_parser = parse_non_negative)]
    pub overlap: Option<f64>,
}

/// The PNGs' resolution when printing (`--print` without `--dpi`), dots per inch.
pub const PRINT_DPI: f64 = 300.0;

impl PictureArgs {
    /// The PNGs' resolution: `--dpi`, else [`PRINT_DPI`] with `--print`, else the preview's.
    pub fn dpi(&self) -> Option<f64> {
        self.dpi.or(self.print.as_ref().map(|_| PRINT_DPI))
    }

    /// The tiling asked for with `--print`, if any.
    pub fn print_options(&self) -> Option<crate::output::print::PrintOptions> {
        let (paper, width, height) = self.print.clone()?;
        let d = crate::output::print::PrintOptions::default();
        Some(crate::output::print::PrintOptions {
            paper,
            width,
            height,
            margin_mm: self.print_margin.unwrap_or(d.margin_mm),
            overlap_mm: self.overlap.unwrap_or(d.overlap_mm),
        })
    }
}

/// A printer paper: a name of [`crate::output::print::PAPERS`] or `WxH` as for `--sheet`;
/// (name as given, width, height) in mm.
pub fn parse_paper(s: &str) -> Result<(String, f64, f64), String> {
    let t = s.trim().to_ascii_lowercase();
    if let Some(&(n, w, h)) = crate::output::print::PAPERS.iter().find(|p| p.0 == t) {
        return Ok((n.to_string(), w, h));
    }
    let names: Vec<&str> = crate::output::print::PAPERS.iter().map(|p| p.0).collect();
    match parse_sheet(&t) {
        Ok((w, h)) if !SHEETS.iter().any(|p| p.0 == t) && w <= 2000.0 && h <= 2000.0 => {
            Ok((t, w, h))
        }
        _ => Err(format!(
            "expected a printer paper ({}) or WIDTHxHEIGHT in mm (200x250) or inches (8.5x11in) up to 2000 mm, got {s:?}",
            names.join(", ")
        )),
    }
}

/// A number of millimetres, 0 or more.
pub fn parse_non_negative(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("expected a number of mm, 0 or more, got {s:?}")),
    }
}

/// A resolution in dots per inch: more than 0, at most [`MAX_DPI`] (`--dpi`).
pub fn parse_dpi(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= MAX_DPI => Ok(v),
        _ => Err(format!(
            "must be a number of dots per inch more than 0 and at most {MAX_DPI}, got {s:?}"
        )),
    }
}

/// `all`, `none`, `shop` or a positive number of millimetres.
pub fn parse_bend_lines(s: &str) -> Result<BendLines, String> {
    match s.trim().to_ascii_lowercase().as_str() {
        "all" => Ok(BendLines::All),
        "none" => Ok(BendLines::None),
        "shop" => Ok(BendLines::Shop),
        t => match t.parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(BendLines::Spacing(v)),
            _ => Err(format!(
                "expected all, none, shop or a spacing in mm more than 0, got {s:?}"
            )),
        },
    }
}

/// `--spline-json FILE`, refused when the spec has no spline surface to write.
pub fn spline_json(spec: &Spec, path: &Option<PathBuf>) -> Result<Option<PathBuf>, Error> {
    let has = spec
        .surfaces
        .iter()
        .any(|s| s.kind == crate::spec::SurfaceKind::Spline);
    match path {
        Some(p) if !has => Err(Error::Usage(format!(
            "--spline-json {}: {} has no spline surface (kind = \"spline\") to write",
            p.display(),
            spec.path.display()
        ))),
        _ => Ok(path.clone()),
    }
}
