//! Device profiles: one TOML file per machine in `devices/`, compiled into the binary so that
//! flatcut works from any directory, plus the user's own in `$XDG_CONFIG_HOME/flatcut/devices`
//! (or `~/.config/flatcut/devices`), which add profiles or replace bundled ones of the same name.
//!
//! A profile says which language the machine speaks, how many device units make a millimetre,
//! and which tool makes each kind of stroke (cut, score, perforate, draw, etch). A kind the
//! profile has no tool for is left out of the program, with a note to the user.
//!
//! Profiles are data: each value in a bundled file carries a comment saying where it comes from
//! (a document and section, or "typical value, not documented"). [`parse`] checks what the
//! output and device stages rely on: G-code profiles speak millimetres (`units_per_mm = 1`) over
//! a GRBL streaming protocol; every HP-GL tool has a pen; every G-code tool has exactly one way
//! down (Z knife, servo pen or laser power within `max_power`); speeds and forces are positive
//! and finite, passes at least 1, the buffer at least 1 byte. Errors name the file and the key.

use crate::toolpath::StrokeKind;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Profiles shipped with flatcut: (file name, contents). `sim` first: it is the default.
pub const BUNDLED: &[(&str, &str)] = &[
    ("sim.toml", include_str!("../../devices/sim.toml")),
    (
        "sim-dragknife.toml",
        include_str!("../../devices/sim-dragknife.toml"),
    ),
    (
        "hpgl-pens.toml",
        include_str!("../../devices/hpgl-pens.toml"),
    ),
    (
        "roland-gx24.toml",
        include_str!("../../devices/roland-gx24.toml"),
    ),
    (
        "graphtec-ce6000.toml",
        include_str!("../../devices/graphtec-ce6000.toml"),
    ),
    (
        "uscutter-mh.toml",
        include_str!("../../devices/uscutter-mh.toml"),
    ),
    (
        "grbl-dragknife.toml",
        include_str!("../../devices/grbl-dragknife.toml"),
    ),
    ("grbl-pen.toml", include_str!("../../devices/grbl-pen.toml")),
    (
        "grbl-laser.toml",
        include_str!("../../devices/grbl-laser.toml"),
    ),
];

/// Dialects the output stage knows, per language.
pub const HPGL_DIALECTS: &[&str] = &["hp-gl", "camm-gl2"];
pub const GCODE_DIALECTS: &[&str] = &["grbl"];

/// Stroke kinds a tool table may name (see [`StrokeKind::name`]).
pub const TOOL_KINDS: &[&str] = &["cut", "score", "perforate", "draw", "etch"];

/// Machine language.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Language {
    Hpgl,
    Gcode,
}

impl Language {
    /// The language's name for people: `HP-GL`, `G-code`.
    pub fn label(self) -> &'static str {
        match self {
            Language::Hpgl => "HP-GL",
            Language::Gcode => "G-code",
        }
    }

    /// File extension of programs in this language.
    pub fn extension(self) -> &'static str {
        match self {
            Language::Hpgl => "plt",
            Language::Gcode => "gcode",
        }
    }
}

/// How one kind of stroke is made. Which fields matter depends on the language:
///
/// - HP-GL: `pen` (required), `force` (`FS`, grams) and `speed` (`VS`, cm/s).
/// - G-code: `speed` (feed, mm/min) and exactly one way of putting the tool down: a knife on Z
///   (`z_down` and `z_up`), a servo pen (`servo_down` and `servo_up`, `M3 S`, with `dwell`), or
///   a laser (`power`, `M4 S`, more than 0 and at most the profile's `max_power`).
///
/// Both: `passes`. [`parse`] refuses fields of the other language, so that a value a user wrote
/// is never silently ignored.
#[derive(Debug, Clone, PartialEq, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Tool {
    /// HP-GL pen (tool holder) number.
    pub pen: Option<u32>,
    /// Knife force in grams (HP-GL `FS`; dialects scale it, see `output::hpgl`).
    pub force: Option<f64>,
    /// HP-GL: velocity in cm/s (`VS`). G-code: feed rate in mm/min.
    pub speed: Option<f64>,
    /// Times each stroke is repeated (default 1).
    pub passes: Option<u32>,
    /// Laser power, spindle `S` units (more than 0, at most the profile's `max_power`).
    pub power: Option<f64>,
    /// G-code knife: Z height (mm) with the blade in the material, and lifted (`z_down < z_up`).
    pub z_down: Option<f64>,
    pub z_up: Option<f64>,
    /// G-code servo pen: `M3 S` value that lowers and lifts the pen.
    pub servo_down: Option<f64>,
    pub servo_up: Option<f64>,
    /// Seconds to wait after a servo move (`G4 P`).
    pub dwell: Option<f64>,
    /// Perforate tool: `[cut_mm, skip_mm]`, the length of each cut dash and of the gap after it
    /// (default [`DEFAULT_PERFORATION`]).
    pub perforation: Option<[f64; 2]>,
}

/// Dashes of a perforated fold when the perforate tool does not say: 3 mm cut, 1 mm uncut
/// (flatcut's choice: paper folds cleanly along it and still holds while it is handled).
pub const DEFAULT_PERFORATION: [f64; 2] = [3.0, 1.0];

impl Tool {
    /// Times each stroke is made.
    pub fn passes(&self) -> u32 {
        self.passes.unwrap_or(1)
    }

    /// `[cut_mm, skip_mm]` of a perforation made with this tool.
    pub fn perforation(&self) -> [f64; 2] {
        self.perforation.unwrap_or(DEFAULT_PERFORATION)
    }
}

/// Serial line settings.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SerialSettings {
    pub baud: u32,
    #[serde(default = "default_data_bits")]
    pub data_bits: u8,
    #[serde(default)]
    pub parity: Parity,
    #[serde(default = "default_stop_bits")]
    pub stop_bits: u8,
    #[serde(default)]
    pub flow_control: FlowControl,
}

fn default_data_bits() -> u8 {
    8
}
fn default_stop_bits() -> u8 {
    1
}

impl Default for SerialSettings {
    fn default() -> Self {
        SerialSettings {
            baud: 9600,
            data_bits: 8,
            parity: Parity::None,
            stop_bits: 1,
            flow_control: FlowControl::None,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Parity {
    #[default]
    None,
    Odd,
    Even,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum FlowControl {
    #[default]
    None,
    XonXoff,
    RtsCts,
}

/// How the host paces the program into the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Protocol {
    /// Write as flow control and `buffer` allow (HP-GL devices).
    #[default]
    Buffered,
    /// GRBL: keep at most `buffer` bytes of unacknowledged lines in flight, one `ok` per line.
    GrblCharacterCounting,
    /// GRBL: send a line, wait for its `ok`.
    GrblSendResponse,
}

/// Axes of the machine relative to the sheet (x right, y up, origin lower-left).
#[derive(Debug, Clone, PartialEq, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Axes {
    /// Exchange x and y (roll-fed cutters whose x axis is the feed direction).
    #[serde(default)]
    pub swap_xy: bool,
    /// Mirror x / y after swapping (origin at the other side).
    #[serde(default)]
    pub flip_x: bool,
    #[serde(default)]
    pub flip_y: bool,
    /// Where the machine's origin is, in words (documentation for users).
    #[serde(default)]
    pub origin: String,
}

/// A machine.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Profile {
    pub name: String,
    pub description: String,
    pub language: Language,
    /// HP-GL: `hp-gl` or `camm-gl2` (Roland CAMM-GL, mode 2: the HP-GL-like instruction set of
    /// Roland's cutters; see [`HPGL_DIALECTS`]). G-code: `grbl`.
    pub dialect: String,
    pub units_per_mm: f64,
    /// Largest width the machine can cut (mm); 0 when unknown.
    #[serde(default)]
    pub media_width: f64,
    #[serde(default)]
    pub axes: Axes,
    #[serde(default)]
    pub serial: SerialSettings,
    /// Device input buffer in bytes (what may be in flight unacknowledged). GRBL: its serial
    /// receive buffer, 128.
    #[serde(default = "default_buffer")]
    pub buffer: usize,
    #[serde(default)]
    pub protocol: Protocol,
    /// G-code laser: the `S` value of full power (GRBL `$30`).
    #[serde(default)]
    pub max_power: Option<f64>,
    #[serde(default)]
    pub tools: BTreeMap<String, Tool>,
    /// Drag knife: distance (mm) from the holder's axis to the blade tip, which trails it; the
    /// toolpath stage compensates it (`toolpath::knife`). 0 (default): no compensation.
    #[serde(default)]
    pub knife_offset: f64,
    /// Drag knife: corners that turn more than this (degrees) get a swivel arc (default 10).
    #[serde(default = "default_swivel")]
    pub swivel_threshold_deg: f64,
    /// Knife: closed contours are cut this much (mm) past their start so that they come free
    /// (default 0).
    #[serde(default)]
    pub overcut: f64,
    /// Commands sent before and after the job, verbatim.
    #[serde(default)]
    pub init: Vec<String>,
    #[serde(default)]
    pub end: Vec<String>,
    /// Where the profile was read from (not in the file).
    #[serde(skip)]
    pub source: String,
}

fn default_buffer() -> usize {
    256
}

fn default_swivel() -> f64 {
    10.0
}

impl Profile {
    /// The tool for a kind of stroke, if the machine has one.
    pub fn tool(&self, kind: StrokeKind) -> Option<&Tool> {
        self.tools.get(kind.name())
    }

    /// Whether the profile has a tool for `kind`.
    pub fn has(&self, kind: StrokeKind) -> bool {
        self.tool(kind).is_some()
    }

    /// What the toolpath stage's machine preparation needs from this profile
    /// ([`crate::toolpath::knife`]); `margin` is the sheet margin (mm), where the alignment
    /// precut goes.
    pub fn machine_options(&self, margin: f64) -> crate::toolpath::knife::MachineOptions {
        let fold_kind = crate::toolpath::fold_kind(|k| self.has(k));
        let kinds = [
            StrokeKind::Cut,
            StrokeKind::Score,
            StrokeKind::Perforate,
            StrokeKind::Draw,
            StrokeKind::Etch,
        ];
        let m = if margin.is_finite() {
            margin.max(0.0)
        } else {
            0.0
        };
        crate::toolpath::knife::MachineOptions {
            fold_kind,
            perforation: self
                .tool(StrokeKind::Perforate)
                .map(|t| t.perforation())
                .unwrap_or(DEFAULT_PERFORATION),
            knife_offset: self.knife_offset,
            swivel_threshold_deg: self.swivel_threshold_deg,
            knife_kinds: kinds
                .into_iter()
                .filter(|k| self.is_drag_knife(*k))
                .collect(),
            multi_pass_kinds: kinds
                .into_iter()
                .filter(|k| self.tool(*k).is_some_and(|t| t.passes() > 1))
                .collect(),
            overcut: self.overcut,
            // Half way into the margin, far enough right that the trailing tip stays on it.
            precut_at: glam::DVec2::new(0.5 * m + self.knife_offset, 0.5 * m),
        }
    }

    /// Whether strokes of `kind` are made by a drag knife whose offset is to be compensated:
    /// the profile has a `knife_offset`, and the kind is cut, score or perforate with a tool
    /// that is not a pen or a laser (G-code: a Z knife; HP-GL: any such tool, the holder
    /// being the knife's).
    pub fn is_drag_knife(&self, kind: StrokeKind) -> bool {
        if self.knife_offset.is_nan() || self.knife_offset <= 0.0 {
            return false;
        }
        if !matches!(
            kind,
            StrokeKind::Cut | StrokeKind::Score | StrokeKind::Perforate
        ) {
            return false;
        }
        match (self.tool(kind), self.language) {
            (Some(_), Language::Hpgl) => true,
            (Some(t), Language::Gcode) => t.z_down.is_some(),
            (None, _) => false,
        }
    }
}

/// Errors finding or reading a profile.
#[derive(Debug, thiserror::Error)]
pub enum ProfileError {
    #[error("{source_name}: {message}")]
    Invalid {
        source_name: String,
        message: String,
    },
    #[error("no device profile named `{name}`; known profiles: {known}")]
    Unknown { name: String, known: String },
}

/// Parse one profile and check it. Errors name `source_name` and the key at fault, with its
/// line when the key is written as `key = value` under its table header.
pub fn parse(text: &str, source_name: &str) -> Result<Profile, ProfileError> {
    let invalid = |message: String| ProfileError::Invalid {
        source_name: source_name.to_string(),
        message,
    };
    let mut p: Profile = toml::from_str(text).map_err(|e| {
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        invalid(format!(
            "{}{}",
            line.map(|l| format!("line {l}: ")).unwrap_or_default(),
            e.message()
        ))
    })?;
    check(&p).map_err(|pr| {
        // A missing key points at its table.
        let line = line_of(text, &pr.table, &pr.key)
            .or_else(|| line_of(text, &pr.table, ""))
            .map(|l| format!("line {l}: "))
            .unwrap_or_default();
        let name = match (pr.table.is_empty(), pr.key.is_empty()) {
            (true, _) => pr.key,
            (false, true) => pr.table,
            (false, false) => format!("{}.{}", pr.table, pr.key),
        };
        invalid(format!("{line}`{name}` {}", pr.message))
    })?;
    p.source = source_name.to_string();
    Ok(p)
}

/// What is wrong with a profile, and where: `table` is `""` for top-level keys, `key` is `""`
/// when the whole table is at fault.
struct Problem {
    table: String,
    key: String,
    message: String,
}

fn problem(table: &str, key: &str, message: impl Into<String>) -> Problem {
    Problem {
        table: table.to_string(),
        key: key.to_string(),
        message: message.into(),
    }
}

fn positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// The checks of [`parse`] on a profile that deserialised.
fn check(p: &Profile) -> Result<(), Problem> {
    if !positive(p.units_per_mm) {
        return Err(problem(
            "",
            "units_per_mm",
            format!("must be a positive number, got {}", p.units_per_mm),
        ));
    }
    let (dialects, gcode) = match p.language {
        Language::Hpgl => (HPGL_DIALECTS, false),
        Language::Gcode => (GCODE_DIALECTS, true),
    };
    if !dialects.contains(&p.dialect.as_str()) {
        return Err(problem(
            "",
            "dialect",
            format!(
                "`{}` is not a dialect of this language; expected {}",
                p.dialect,
                dialects.join(" or ")
            ),
        ));
    }
    let grbl = matches!(
        p.protocol,
        Protocol::GrblCharacterCounting | Protocol::GrblSendResponse
    );
    if gcode && !grbl {
        return Err(problem(
            "",
            "protocol",
            "must be grbl-character-counting or grbl-send-response for a G-code profile",
        ));
    }
    if !gcode && grbl {
        return Err(problem(
            "",
            "protocol",
            "must be buffered for an HP-GL profile (the grbl-* protocols are for G-code)",
        ));
    }
    if gcode && p.units_per_mm != 1.0 {
        return Err(problem(
            "",
            "units_per_mm",
            format!(
                "must be 1 for G-code (programs are in millimetres, G21), got {}",
                p.units_per_mm
            ),
        ));
    }
    if !(p.media_width.is_finite() && p.media_width >= 0.0) {
        return Err(problem(
            "",
            "media_width",
            format!(
                "must be 0 (unknown) or a width in mm, got {}",
                p.media_width
            ),
        ));
    }
    if p.buffer == 0 {
        return Err(problem("", "buffer", "must be at least 1 byte"));
    }
    for (key, v) in [("knife_offset", p.knife_offset), ("overcut", p.overcut)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(problem(
                "",
                key,
                format!("must be 0 (off) or a length in mm, got {v}"),
            ));
        }
    }
    if !(p.swivel_threshold_deg.is_finite() && (0.0..=180.0).contains(&p.swivel_threshold_deg)) {
        return Err(problem(
            "",
            "swivel_threshold_deg",
            format!(
                "must be an angle from 0 to 180 degrees, got {}",
                p.swivel_threshold_deg
            ),
        ));
    }
    let s = &p.serial;
    if s.baud == 0 {
        return Err(problem("serial", "baud", "must be more than 0"));
    }
    if !(5..=8).contains(&s.data_bits) {
        return Err(problem(
            "serial",
            "data_bits",
            format!("must be 5 to 8, got {}", s.data_bits),
        ));
    }
    if !(1..=2).contains(&s.stop_bits) {
        return Err(problem(
            "serial",
            "stop_bits",
            format!("must be 1 or 2, got {}", s.stop_bits),
        ));
    }
    if let Some(m) = p.max_power {
        if !gcode {
            return Err(problem("", "max_power", "is for G-code lasers only"));
        }
        if !positive(m) {
            return Err(problem(
                "",
                "max_power",
                format!("must be a positive number, got {m}"),
            ));
        }
    }
    for (kind, t) in &p.tools {
        let table = format!("tools.{kind}");
        if !TOOL_KINDS.contains(&kind.as_str()) {
            return Err(problem(
                &table,
                "",
                "is not a tool kind; expected cut, score, perforate, draw or etch",
            ));
        }
        check_tool(&table, t, p.max_power, gcode)?;
    }
    if !p.tools.contains_key("cut") {
        return Err(problem(
            "tools",
            "cut",
            "is missing: every profile needs a `[tools.cut]`",
        ));
    }
    Ok(())
}

/// The checks of one tool, `[table]`.
fn check_tool(table: &str, t: &Tool, max_power: Option<f64>, gcode: bool) -> Result<(), Problem> {
    let err = |key: &str, message: String| Err(problem(table, key, message));
    let numbers = [
        ("force", t.force),
        ("speed", t.speed),
        ("power", t.power),
        ("z_down", t.z_down),
        ("z_up", t.z_up),
        ("servo_down", t.servo_down),
        ("servo_up", t.servo_up),
        ("dwell", t.dwell),
    ];
    for (key, v) in numbers {
        if let Some(v) = v.filter(|v| !v.is_finite()) {
            return err(key, format!("must be a finite number, got {v}"));
        }
    }
    for (key, v) in [("force", t.force), ("speed", t.speed)] {
        if let Some(v) = v.filter(|&v| v <= 0.0) {
            return err(key, format!("must be a positive number, got {v}"));
        }
    }
    if t.passes == Some(0) {
        return err("passes", "must be at least 1".into());
    }
    if let Some([cut, skip]) = t.perforation {
        if !(cut.is_finite() && cut > 0.0 && skip.is_finite() && skip > 0.0) {
            return err(
                "perforation",
                format!(
                    "must be [cut_mm, skip_mm] with both lengths positive, got [{cut}, {skip}]"
                ),
            );
        }
        if !table.ends_with(".perforate") {
            return err(
                "perforation",
                "is for the perforate tool only (`[tools.perforate]`)".into(),
            );
        }
    }
    if let Some(d) = t.dwell.filter(|&d| d < 0.0) {
        return err("dwell", format!("must be 0 or more seconds, got {d}"));
    }
    if !gcode {
        let gcode_only = [
            ("z_down", t.z_down.is_some()),
            ("z_up", t.z_up.is_some()),
            ("servo_down", t.servo_down.is_some()),
            ("servo_up", t.servo_up.is_some()),
            ("dwell", t.dwell.is_some()),
            ("power", t.power.is_some()),
        ];
        if let Some((key, _)) = gcode_only.into_iter().find(|(_, set)| *set) {
            return err(
                key,
                "is for G-code tools; an HP-GL tool has pen, force, speed and passes".into(),
            );
        }
        if t.pen.is_none() {
            return err(
                "pen",
                "is missing: an HP-GL tool needs a pen (tool holder) number".into(),
            );
        }
        return Ok(());
    }
    if let Some((key, _)) = [("pen", t.pen.is_some()), ("force", t.force.is_some())]
        .into_iter()
        .find(|(_, set)| *set)
    {
        return err(
            key,
            "is for HP-GL tools; a G-code tool goes down by z_down/z_up, servo_down/servo_up or power"
                .into(),
        );
    }
    // Exactly one way down; a half-given pair names its missing half.
    let mut ways = Vec::new();
    match (t.z_down, t.z_up) {
        (Some(down), Some(up)) if down >= up => {
            return err(
                "z_down",
                format!("must be below z_up ({down} is not below {up})"),
            )
        }
        (Some(_), Some(_)) => ways.push("z_down/z_up"),
        (Some(_), None) => {
            return err(
                "z_up",
                "is missing: a knife on Z needs z_down and z_up".into(),
            )
        }
        (None, Some(_)) => {
            return err(
                "z_down",
                "is missing: a knife on Z needs z_down and z_up".into(),
            )
        }
        (None, None) => {}
    }
    match (t.servo_down, t.servo_up) {
        (Some(down), Some(up)) if down < 0.0 || up < 0.0 => {
            return err(
                "servo_down",
                format!("and servo_up are `M3 S` values, 0 or more; got {down} and {up}"),
            )
        }
        (Some(down), Some(up)) if down == up => {
            return err(
                "servo_down",
                format!("must differ from servo_up (both are {down})"),
            )
        }
        (Some(_), Some(_)) => ways.push("servo_down/servo_up"),
        (Some(_), None) => {
            return err(
                "servo_up",
                "is missing: a servo pen needs servo_down and servo_up".into(),
            )
        }
        (None, Some(_)) => {
            return err(
                "servo_down",
                "is missing: a servo pen needs servo_down and servo_up".into(),
            )
        }
        (None, None) => {}
    }
    if let Some(power) = t.power {
        let Some(max) = max_power else {
            return err(
                "power",
                "needs the profile's `max_power` (GRBL `$30`, the S value of full power)".into(),
            );
        };
        if !(power > 0.0 && power <= max) {
            return err(
                "power",
                format!("must be more than 0 and at most max_power ({max}), got {power}"),
            );
        }
        ways.push("power");
    }
    match ways.len() {
        1 => {}
        0 => {
            return err(
                "",
                "has no way down: a G-code tool needs z_down and z_up (knife), servo_down and \
                 servo_up (pen) or power (laser)"
                    .into(),
            )
        }
        _ => {
            return err(
                "",
                format!(
                    "has more than one way down ({}); give exactly one",
                    ways.join(", ")
                ),
            )
        }
    }
    if t.dwell.is_some() && t.servo_down.is_none() {
        return err(
            "dwell",
            "is the wait after a servo move; only a servo pen has one".into(),
        );
    }
    Ok(())
}

/// Line (1-based) where `key` is set under `[table]` (`""`: top level), or where `[table]`
/// starts when `key` is `""`. Best effort: it knows `[table]` headers and `key = …` lines; a key
/// written inline or dotted is not found, and the message goes without a line.
fn line_of(text: &str, table: &str, key: &str) -> Option<usize> {
    let mut current = "";
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if let Some(header) = line.strip_prefix('[').and_then(|r| r.split(']').next()) {
            current = header.trim();
            if key.is_empty() && current == table {
                return Some(i + 1);
            }
            continue;
        }
        if current == table && !key.is_empty() {
            let rest = line.strip_prefix(key).map(str::trim_start);
            if rest.is_some_and(|r| r.starts_with('=')) {
                return Some(i + 1);
            }
        }
    }
    None
}

/// The user's profile directory, if one can be named.
pub fn user_dir() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_CONFIG_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".config")))?;
    Some(base.join("flatcut").join("devices"))
}

/// Every profile: bundled ones, then the user's (which replace bundled ones of the same name).
pub fn all() -> Result<Vec<Profile>, ProfileError> {
    let mut map: BTreeMap<String, Profile> = BTreeMap::new();
    for (file, text) in BUNDLED {
        let p = parse(text, &format!("devices/{file} (bundled)"))?;
        map.insert(p.name.clone(), p);
    }
    if let Some(dir) = user_dir() {
        if let Ok(entries) = std::fs::read_dir(&dir) {
            let mut files: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect();
            files.sort();
            for f in files {
                let text = std::fs::read_to_string(&f).map_err(|e| ProfileError::Invalid {
                    source_name: f.display().to_string(),
                    message: e.to_string(),
                })?;
                let p = parse(&text, &f.display().to_string())?;
                map.insert(p.name.clone(), p);
            }
        }
    }
    Ok(map.into_values().collect())
}

/// The profile called `name`.
pub fn find(name: &str) -> Result<Profile, ProfileError> {
    let all = all()?;
    let known = all
        .iter()
        .map(|p| p.name.as_str())
        .collect::<Vec<_>>()
        .join(", ");
    all.into_iter()
        .find(|p| p.name == name)
        .ok_or(ProfileError::Unknown {
            name: name.to_string(),
            known,
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    const KINDS: [StrokeKind; 5] = [
        StrokeKind::Cut,
        StrokeKind::Score,
        StrokeKind::Perforate,
        StrokeKind::Draw,
        StrokeKind::Etch,
    ];

    fn bundled(name: &str) -> Profile {
        let file = format!("{name}.toml");
        let (_, text) = BUNDLED.iter().find(|(f, _)| *f == file).unwrap();
        parse(text, &file).unwrap()
    }

    #[test]
    fn every_bundled_profile_loads() {
        assert_eq!(BUNDLED[0].0, "sim.toml");
        for (file, text) in BUNDLED {
            let p = parse(text, file).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(format!("{}.toml", p.name), *file);
            assert!(p.tool(StrokeKind::Cut).is_some(), "{file}: no cut tool");
            assert!(!p.description.is_empty(), "{file}");
            assert!(p.buffer >= 1 && p.serial.baud > 0, "{file}");
            for kind in KINDS {
                let Some(t) = p.tool(kind) else { continue };
                assert!(t.passes() >= 1, "{file}");
                assert!(
                    t.speed.is_some_and(|v| v > 0.0),
                    "{file}: {kind:?} has no speed"
                );
                match p.language {
                    Language::Hpgl => {
                        assert!(t.pen.is_some(), "{file}: HP-GL {kind:?} has no pen");
                        assert_eq!(p.units_per_mm, 40.0, "{file}");
                        assert_eq!(p.protocol, Protocol::Buffered, "{file}");
                    }
                    Language::Gcode => {
                        let knife = t.z_down.is_some() && t.z_up.is_some();
                        let servo = t.servo_down.is_some() && t.servo_up.is_some();
                        let laser = t.power.is_some();
                        assert_eq!(
                            [knife, servo, laser].iter().filter(|w| **w).count(),
                            1,
                            "{file}: G-code {kind:?} needs exactly one way down"
                        );
                        assert_eq!(p.units_per_mm, 1.0, "{file}");
                        assert_eq!(p.protocol, Protocol::GrblCharacterCounting, "{file}");
                        assert_eq!(p.buffer, 128, "{file}: GRBL's receive buffer");
                    }
                }
            }
        }
        let names: Vec<String> = all().unwrap().into_iter().map(|p| p.name).collect();
        for name in [
            "sim",
            "sim-dragknife",
            "hpgl-pens",
            "roland-gx24",
            "graphtec-ce6000",
            "uscutter-mh",
            "grbl-dragknife",
            "grbl-pen",
            "grbl-laser",
        ] {
            assert!(names.iter().any(|n| n == name), "{name} missing");
        }
    }

    #[test]
    fn the_pens_users_rely_on() {
        // DESIGN.md: hpgl-pens maps cut = SP1, score/fold = SP2, draw = SP3.
        for name in ["hpgl-pens", "sim"] {
            let p = bundled(name);
            assert_eq!(p.tool(StrokeKind::Cut).and_then(|t| t.pen), Some(1));
            assert_eq!(p.tool(StrokeKind::Score).and_then(|t| t.pen), Some(2));
            assert_eq!(p.tool(StrokeKind::Draw).and_then(|t| t.pen), Some(3));
            assert_eq!(p.units_per_mm, 40.0);
        }
        let sim = bundled("sim");
        assert_eq!(sim.serial.baud, 115200);
        assert_eq!(sim.serial.flow_control, FlowControl::XonXoff);
        assert_eq!(sim.buffer, 1024);

        let gx = bundled("roland-gx24");
        assert_eq!(
            (gx.language, gx.dialect.as_str()),
            (Language::Hpgl, "camm-gl2")
        );
        assert!(gx.axes.swap_xy, "roll-fed: the machine's x is the feed");
        let laser = bundled("grbl-laser");
        assert_eq!(laser.max_power, Some(1000.0));
        assert!(laser.tools.values().all(|t| t.power.is_some()));
        let pen = bundled("grbl-pen");
        assert!(pen
            .tools
            .values()
            .all(|t| t.servo_down.is_some() && t.dwell.is_some()));
        let knife = bundled("grbl-dragknife");
        assert!(knife.tools.values().all(|t| t.z_down < t.z_up));
    }

    const HPGL: &str =
        "name='x'\ndescription='d'\nlanguage='hpgl'\ndialect='hp-gl'\nunits_per_mm=40\n";
    const GCODE: &str =
        "name='x'\ndescription='d'\nlanguage='gcode'\ndialect='grbl'\nunits_per_mm=1\n\
                         protocol='grbl-character-counting'\nbuffer=128\n";

    fn error(text: &str) -> String {
        parse(text, "x.toml").unwrap_err().to_string()
    }

    #[test]
    fn bad_profiles_say_why() {
        let e = error("name = \"x\"\ncolour = 1\n");
        assert!(e.contains("x.toml: line 2"), "{e}");
        let e = error(&format!(
            "{}\n[tools.cut]\npen=1\n",
            HPGL.replace("=40", "=0")
        ));
        assert!(e.contains("x.toml: line 5: `units_per_mm`"), "{e}");
        assert!(find("no-such-machine")
            .unwrap_err()
            .to_string()
            .contains("hpgl-pens"));
    }

    #[test]
    fn bad_tools_name_file_and_key() {
        // A G-code tool with no way down.
        let e = error(&format!("{GCODE}[tools.cut]\nspeed=600\n"));
        assert!(
            e.starts_with("x.toml: line 8: `tools.cut` has no way down"),
            "{e}"
        );
        // Half a pair names the missing half.
        let e = error(&format!("{GCODE}[tools.cut]\nz_down=-1\nspeed=600\n"));
        assert!(e.contains("`tools.cut.z_up` is missing"), "{e}");
        // Two ways down.
        let e = error(&format!(
            "{GCODE}max_power=1000\n[tools.cut]\nz_down=-1\nz_up=2\npower=10\n"
        ));
        assert!(e.contains("`tools.cut` has more than one way down"), "{e}");
        // An HP-GL tool without a pen.
        let e = error(&format!(
            "{HPGL}[tools.cut]\npen=1\n[tools.score]\nforce=50\n"
        ));
        assert!(
            e.starts_with("x.toml: line 8: `tools.score.pen` is missing"),
            "{e}"
        );
        // A negative speed, with its line.
        let e = error(&format!("{HPGL}[tools.cut]\npen=1\nspeed=-3\n"));
        assert!(
            e.starts_with("x.toml: line 8: `tools.cut.speed` must be a positive"),
            "{e}"
        );
        // Not finite, zero force, no passes.
        let e = error(&format!("{HPGL}[tools.cut]\npen=1\nspeed=nan\n"));
        assert!(
            e.contains("`tools.cut.speed` must be a finite number"),
            "{e}"
        );
        let e = error(&format!("{HPGL}[tools.cut]\npen=1\nforce=0\n"));
        assert!(e.contains("`tools.cut.force` must be a positive"), "{e}");
        let e = error(&format!("{HPGL}[tools.cut]\npen=1\npasses=0\n"));
        assert!(
            e.contains("line 8: `tools.cut.passes` must be at least 1"),
            "{e}"
        );
        // Laser power beyond $30, or without it.
        let e = error(&format!("{GCODE}max_power=1000\n[tools.cut]\npower=1200\n"));
        assert!(
            e.contains("line 10: `tools.cut.power` must be more than 0 and at most"),
            "{e}"
        );
        let e = error(&format!("{GCODE}[tools.cut]\npower=100\n"));
        assert!(
            e.contains("`tools.cut.power` needs the profile's `max_power`"),
            "{e}"
        );
        // The other language's fields.
        let e = error(&format!("{HPGL}[tools.cut]\npen=1\nz_down=-1\n"));
        assert!(e.contains("`tools.cut.z_down` is for G-code tools"), "{e}");
        let e = error(&format!("{GCODE}[tools.cut]\npen=1\nz_down=-1\nz_up=1\n"));
        assert!(e.contains("`tools.cut.pen` is for HP-GL tools"), "{e}");
        // Knife upside down, servo that does not move, dwell without a servo.
        let e = error(&format!("{GCODE}[tools.cut]\nz_down=2\nz_up=-1\n"));
        assert!(e.contains("`tools.cut.z_down` must be below z_up"), "{e}");
        let e = error(&format!("{GCODE}[tools.cut]\nservo_down=30\nservo_up=30\n"));
        assert!(e.contains("`tools.cut.servo_down` must differ"), "{e}");
        let e = error(&format!(
            "{GCODE}[tools.cut]\nz_down=-1\nz_up=1\ndwell=0.2\n"
        ));
        assert!(e.contains("`tools.cut.dwell`"), "{e}");
        // Unknown kind, missing cut.
        let e = error(&format!("{HPGL}[tools.cut]\npen=1\n[tools.glue]\npen=2\n"));
        assert!(e.contains("line 8: `tools.glue` is not a tool kind"), "{e}");
        let e = error(&format!("{HPGL}[tools.draw]\npen=3\n"));
        assert!(e.contains("`tools.cut` is missing"), "{e}");
    }

    #[test]
    fn knife_keys_are_checked() {
        for name in [
            "roland-gx24",
            "graphtec-ce6000",
            "uscutter-mh",
            "grbl-dragknife",
        ] {
            let p = bundled(name);
            assert_eq!(p.knife_offset, 0.25, "{name}");
            assert_eq!(p.overcut, 1.0, "{name}");
            assert!(p.is_drag_knife(StrokeKind::Cut), "{name}");
            assert!(!p.is_drag_knife(StrokeKind::Draw), "{name}");
        }
        // `sim` is unchanged: no offset, no overcut; `sim-dragknife` is `sim` with them.
        let sim = bundled("sim");
        assert_eq!((sim.knife_offset, sim.overcut), (0.0, 0.0));
        assert_eq!(sim.swivel_threshold_deg, 10.0);
        assert!(!sim.is_drag_knife(StrokeKind::Cut));
        let drag = bundled("sim-dragknife");
        assert_eq!(drag.knife_offset, 0.25);
        assert_eq!(drag.tools, sim.tools);
        assert_eq!(drag.serial, sim.serial);
        // Pens and lasers are not knives.
        assert!(!bundled("grbl-laser").is_drag_knife(StrokeKind::Cut));
        assert!(!bundled("hpgl-pens").is_drag_knife(StrokeKind::Cut));

        let e = error(&format!("{HPGL}knife_offset=-0.25\n[tools.cut]\npen=1\n"));
        assert!(
            e.starts_with("x.toml: line 6: `knife_offset` must be 0 (off) or a length"),
            "{e}"
        );
        let e = error(&format!("{HPGL}knife_offset=nan\n[tools.cut]\npen=1\n"));
        assert!(e.contains("line 6: `knife_offset` must be"), "{e}");
        let e = error(&format!("{HPGL}overcut=-1\n[tools.cut]\npen=1\n"));
        assert!(e.contains("line 6: `overcut` must be"), "{e}");
        let e = error(&format!(
            "{HPGL}swivel_threshold_deg=200\n[tools.cut]\npen=1\n"
        ));
        assert!(
            e.contains("line 6: `swivel_threshold_deg` must be an angle"),
            "{e}"
        );
        let e = error(&format!(
            "{HPGL}[tools.cut]\npen=1\n[tools.perforate]\npen=1\nperforation=[0, 1]\n"
        ));
        assert!(
            e.starts_with(
                "x.toml: line 10: `tools.perforate.perforation` must be [cut_mm, skip_mm]"
            ),
            "{e}"
        );
        let e = error(&format!("{HPGL}[tools.cut]\npen=1\nperforation=[3, 1]\n"));
        assert!(
            e.contains("line 8: `tools.cut.perforation` is for the perforate tool"),
            "{e}"
        );
        let ok = parse(
            &format!(
                "{HPGL}[tools.cut]\npen=1\n[tools.perforate]\npen=1\nperforation=[2.5, 0.5]\n"
            ),
            "x.toml",
        )
        .unwrap();
        assert_eq!(
            ok.tool(StrokeKind::Perforate).unwrap().perforation(),
            [2.5, 0.5]
        );
        assert_eq!(Tool::default().perforation(), DEFAULT_PERFORATION);
    }

    #[test]
    fn language_protocol_and_units_agree() {
        let knife = "[tools.cut]\nz_down=-1\nz_up=2\n";
        let e = error(&format!(
            "{}{knife}",
            GCODE.replace("grbl-character-counting", "buffered")
        ));
        assert!(
            e.contains("line 6: `protocol` must be grbl-character-counting"),
            "{e}"
        );
        let e = error(&format!(
            "{}{knife}",
            GCODE.replace("units_per_mm=1", "units_per_mm=40")
        ));
        assert!(
            e.contains("line 5: `units_per_mm` must be 1 for G-code"),
            "{e}"
        );
        let e = error(&format!(
            "{HPGL}protocol='grbl-send-response'\n[tools.cut]\npen=1\n"
        ));
        assert!(e.contains("`protocol` must be buffered"), "{e}");
        let e = error(&format!(
            "{}[tools.cut]\npen=1\n",
            HPGL.replace("hp-gl", "camm-gl3")
        ));
        assert!(
            e.contains("line 4: `dialect` `camm-gl3` is not a dialect"),
            "{e}"
        );
        let e = error(&format!("{HPGL}buffer=0\n[tools.cut]\npen=1\n"));
        assert!(
            e.contains("line 6: `buffer` must be at least 1 byte"),
            "{e}"
        );
        let e = error(&format!(
            "{HPGL}[serial]\nbaud=9600\nstop_bits=3\n[tools.cut]\npen=1\n"
        ));
        assert!(
            e.contains("line 8: `serial.stop_bits` must be 1 or 2"),
            "{e}"
        );
        let e = error(&format!("{HPGL}max_power=1000\n[tools.cut]\npen=1\n"));
        assert!(e.contains("`max_power` is for G-code lasers only"), "{e}");
        // GRBL with a bigger buffer than its 128 bytes is accepted (no check, no warning).
        assert!(parse(
            &format!("{}{knife}", GCODE.replace("=128", "=256")),
            "x.toml"
        )
        .is_ok());
    }
}
