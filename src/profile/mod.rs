//! Device profiles, the configuration several stages read (toolpath, output, device): a leaf
//! module that imports no stage. One TOML file per machine in `devices/`, compiled into the binary so that
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
//!
//! Files: this one holds the schema ([`Profile`], [`Language`], [`Axes`]) and finding profiles
//! ([`find`], [`all`]); `read.rs` the TOML reader and its checks with `FILE: line N` errors;
//! `tools.rs` the tool table and the stroke kinds it maps ([`StrokeKind`]); `serial.rs` the
//! serial line settings and the streaming protocol; `registration.rs` the print-and-cut
//! sensor and marks (`[registration]`).

mod grbl;
pub use grbl::{significant_len, LINE_MAX};
mod read;
pub mod registration;
mod serial;
mod tools;

pub use grbl::GrblMachine;
pub use read::parse;
pub use serial::{FlowControl, Parity, Protocol, SerialSettings, StatusQuery};
pub use tools::DEFAULT_PERFORATION;
pub(crate) use tools::TOOL_KINDS;
pub use tools::{StrokeKind, Tool};

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
        "graphtec-ce6000-gpgl.toml",
        include_str!("../../devices/graphtec-ce6000-gpgl.toml"),
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
pub(crate) const HPGL_DIALECTS: &[&str] = &["hp-gl", "camm-gl2"];
pub(crate) const GCODE_DIALECTS: &[&str] = &["grbl"];
/// GP-GL: Graphtec's own language (CE6000 / CE7000 / FC series in native mode).
pub(crate) const GPGL_DIALECTS: &[&str] = &["graphtec"];
/// GP-GL step sizes a Graphtec cutter can be set to, as units per mm: 0.1 mm (the default),
/// 0.05, 0.025 and 0.01 mm.
pub(crate) const GPGL_UNITS_PER_MM: &[f64] = &[10.0, 20.0, 40.0, 100.0];

/// Machine language.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Language {
    Hpgl,
    Gcode,
    /// Graphtec GP-GL (`output::gpgl`).
    Gpgl,
}

impl Language {
    /// The language's name for people: `HP-GL`, `G-code`, `GP-GL`.
    pub fn label(self) -> &'static str {
        match self {
            Language::Hpgl => "HP-GL",
            Language::Gcode => "G-code",
            Language::Gpgl => "GP-GL",
        }
    }

    /// File extension of programs in this language.
    pub fn extension(self) -> &'static str {
        self.extensions()[0]
    }

    /// File extensions a program in this language is sent from (`flatcut send`), the one
    /// flatcut writes first.
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            Language::Hpgl => &["plt", "hpgl", "hpg"],
            Language::Gcode => &["gcode", "nc", "ngc", "gc"],
            Language::Gpgl => &["gpgl", "gp"],
        }
    }

    /// Whether the language moves a pen or knife with plotter instructions under the buffered
    /// protocol (HP-GL and GP-GL), rather than G-code lines.
    pub fn is_plotter(self) -> bool {
        matches!(self, Language::Hpgl | Language::Gpgl)
    }
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
    /// Roland's cutters; see `HPGL_DIALECTS`). G-code: `grbl`. GP-GL: `graphtec`.
    pub dialect: String,
    pub units_per_mm: f64,
    /// Largest width the machine can cut (mm); 0 when unknown.
    #[serde(default)]
    pub media_width: f64,
    /// Longest the machine can cut along the media (mm): a flatbed's or a mat's length, or a
    /// roll cutter's longest tracked cut; 0 when unknown or unlimited.
    #[serde(default)]
    pub media_length: f64,
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
    /// GRBL: the controller's version and motion settings (`[grbl]`, see [`GrblMachine`]).
    #[serde(default)]
    pub grbl: GrblMachine,
    /// Print-and-cut: the registration sensor and the marks (`[registration]`).
    #[serde(default)]
    pub registration: registration::Registration,
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
            (Some(_), Language::Hpgl | Language::Gpgl) => true,
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

/// The user's profile directory, if one can be named.
pub(crate) fn user_dir() -> Option<PathBuf> {
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
                let text = crate::geom::input::read_text(&f, crate::geom::input::TEXT_LIMIT)
                    .map_err(|e| ProfileError::Invalid {
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
                    Language::Gpgl => {
                        assert!(t.pen.is_some(), "{file}: GP-GL {kind:?} has no pen");
                        assert_eq!(p.units_per_mm, 10.0, "{file}: GP-GL's 0.1 mm step");
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
            "graphtec-ce6000-gpgl",
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

    /// The error reading `text` contains `part`.
    fn says(text: &str, part: &str) {
        let e = error(text);
        assert!(e.contains(part), "{e}");
    }

    /// The error reading `text` starts with `prefix`.
    fn begins(text: &str, prefix: &str) {
        let e = error(text);
        assert!(e.starts_with(prefix), "{e}");
    }

    #[test]
    fn status_query_is_for_hpgl_and_media_sizes_are_sizes() {
        says(
            &format!("{GCODE}[serial]\nbaud=115200\nstatus_query='esc-b'\n"),
            "status_query",
        );
        says(
            &format!("{GCODE}[serial]\nbaud=115200\nstatus_query='oa'\n"),
            "status_query",
        );
        let hpgl = format!("{HPGL}[serial]\nbaud=9600\nstatus_query='esc-b'\n[tools.cut]\npen=1\n");
        assert_eq!(
            parse(&hpgl, "x.toml").unwrap().serial.status_query,
            StatusQuery::EscB
        );
        says(&format!("{HPGL}media_length=-1\n"), "media_length");
        assert_eq!(bundled("grbl-pen").media_length, 400.0);
        assert_eq!(bundled("roland-gx24").media_length, 0.0);
    }

    #[test]
    fn bad_profiles_say_why() {
        says("name = \"x\"\ncolour = 1\n", "x.toml: line 2");
        says(
            &format!("{}\n[tools.cut]\npen=1\n", HPGL.replace("=40", "=0")),
            "x.toml: line 5: `units_per_mm`",
        );
        assert!(find("no-such-machine")
            .unwrap_err()
            .to_string()
            .contains("hpgl-pens"));
    }

    #[test]
    fn bad_tools_name_file_and_key() {
        // A G-code tool with no way down.
        begins(
            &format!("{GCODE}[tools.cut]\nspeed=600\n"),
            "x.toml: line 8: `tools.cut` has no way down",
        );
        // Half a pair names the missing half.
        says(
            &format!("{GCODE}[tools.cut]\nz_down=-1\nspeed=600\n"),
            "`tools.cut.z_up` is missing",
        );
        // Two ways down.
        says(
            &format!("{GCODE}max_power=1000\n[tools.cut]\nz_down=-1\nz_up=2\npower=10\n"),
            "`tools.cut` has more than one way down",
        );
        // An HP-GL tool without a pen.
        begins(
            &format!("{HPGL}[tools.cut]\npen=1\n[tools.score]\nforce=50\n"),
            "x.toml: line 8: `tools.score.pen` is missing",
        );
        // A negative speed, with its line.
        begins(
            &format!("{HPGL}[tools.cut]\npen=1\nspeed=-3\n"),
            "x.toml: line 8: `tools.cut.speed` must be a positive",
        );
        // Not finite, zero force, no passes.
        says(
            &format!("{HPGL}[tools.cut]\npen=1\nspeed=nan\n"),
            "`tools.cut.speed` must be a finite number",
        );
        says(
            &format!("{HPGL}[tools.cut]\npen=1\nforce=0\n"),
            "`tools.cut.force` must be a positive",
        );
        says(
            &format!("{HPGL}[tools.cut]\npen=1\npasses=0\n"),
            "line 8: `tools.cut.passes` must be at least 1",
        );
        // Laser power beyond $30, or without it.
        says(
            &format!("{GCODE}max_power=1000\n[tools.cut]\npower=1200\n"),
            "line 10: `tools.cut.power` must be more than 0 and at most",
        );
        says(
            &format!("{GCODE}[tools.cut]\npower=100\n"),
            "`tools.cut.power` needs the profile's `max_power`",
        );
        // The other language's fields.
        says(
            &format!("{HPGL}[tools.cut]\npen=1\nz_down=-1\n"),
            "`tools.cut.z_down` is for G-code tools",
        );
        says(
            &format!("{GCODE}[tools.cut]\npen=1\nz_down=-1\nz_up=1\n"),
            "`tools.cut.pen` is for HP-GL tools",
        );
        // Knife upside down, servo that does not move, dwell without a servo.
        says(
            &format!("{GCODE}[tools.cut]\nz_down=2\nz_up=-1\n"),
            "`tools.cut.z_down` must be below z_up",
        );
        says(
            &format!("{GCODE}[tools.cut]\nservo_down=30\nservo_up=30\n"),
            "`tools.cut.servo_down` must differ",
        );
        says(
            &format!("{GCODE}[tools.cut]\nz_down=-1\nz_up=1\ndwell=0.2\n"),
            "`tools.cut.dwell`",
        );
        // Unknown kind, missing cut.
        says(
            &format!("{HPGL}[tools.cut]\npen=1\n[tools.glue]\npen=2\n"),
            "line 8: `tools.glue` is not a tool kind",
        );
        says(
            &format!("{HPGL}[tools.draw]\npen=3\n"),
            "`tools.cut` is missing",
        );
    }

    #[test]
    fn knife_keys_are_checked() {
        for name in [
            "roland-gx24",
            "graphtec-ce6000",
            "graphtec-ce6000-gpgl",
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

        begins(
            &format!("{HPGL}knife_offset=-0.25\n[tools.cut]\npen=1\n"),
            "x.toml: line 6: `knife_offset` must be 0 (off) or a length",
        );
        says(
            &format!("{HPGL}knife_offset=nan\n[tools.cut]\npen=1\n"),
            "line 6: `knife_offset` must be",
        );
        says(
            &format!("{HPGL}overcut=-1\n[tools.cut]\npen=1\n"),
            "line 6: `overcut` must be",
        );
        says(
            &format!("{HPGL}swivel_threshold_deg=200\n[tools.cut]\npen=1\n"),
            "line 6: `swivel_threshold_deg` must be an angle",
        );
        begins(
            &format!("{HPGL}[tools.cut]\npen=1\n[tools.perforate]\npen=1\nperforation=[0, 1]\n"),
            "x.toml: line 10: `tools.perforate.perforation` must be [cut_mm, skip_mm]",
        );
        says(
            &format!("{HPGL}[tools.cut]\npen=1\nperforation=[3, 1]\n"),
            "line 8: `tools.cut.perforation` is for the perforate tool",
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
        says(
            &format!(
                "{}{knife}",
                GCODE.replace("grbl-character-counting", "buffered")
            ),
            "line 6: `protocol` must be grbl-character-counting",
        );
        says(
            &format!(
                "{}{knife}",
                GCODE.replace("units_per_mm=1", "units_per_mm=40")
            ),
            "line 5: `units_per_mm` must be 1 for G-code",
        );
        says(
            &format!("{HPGL}protocol='grbl-send-response'\n[tools.cut]\npen=1\n"),
            "`protocol` must be buffered",
        );
        says(
            &format!("{}[tools.cut]\npen=1\n", HPGL.replace("hp-gl", "camm-gl3")),
            "line 4: `dialect` `camm-gl3` is not a dialect",
        );
        let gpgl = HPGL
            .replace("'hpgl'", "'gpgl'")
            .replace("'hp-gl'", "'graphtec'");
        says(
            &format!("{}[tools.cut]\npen=1\n", gpgl.replace("=40", "=25")),
            "line 5: `units_per_mm` must be 10, 20, 40 or 100 for GP-GL",
        );
        let ok = parse(
            &format!(
                "{}[tools.cut]\npen=1\nforce=14\n",
                gpgl.replace("=40", "=10")
            ),
            "x.toml",
        )
        .unwrap();
        assert_eq!(
            (ok.language.label(), ok.language.extension()),
            ("GP-GL", "gpgl")
        );
        says(
            &format!("{}[tools.cut]\nforce=14\n", gpgl.replace("=40", "=10")),
            "`tools.cut.pen` is missing",
        );
        says(
            &format!("{}[tools.cut]\npen=1\n", gpgl.replace("graphtec", "hp-gl")),
            "`dialect` `hp-gl` is not a dialect",
        );
        says(
            &format!("{HPGL}buffer=0\n[tools.cut]\npen=1\n"),
            "line 6: `buffer` must be at least 1 byte",
        );
        says(
            &format!("{HPGL}[serial]\nbaud=9600\nstop_bits=3\n[tools.cut]\npen=1\n"),
            "line 8: `serial.stop_bits` must be 1 or 2",
        );
        says(
            &format!("{HPGL}max_power=1000\n[tools.cut]\npen=1\n"),
            "`max_power` is for G-code lasers only",
        );
        // GRBL with a bigger buffer than its 128 bytes is accepted (no check, no warning).
        assert!(parse(
            &format!("{}{knife}", GCODE.replace("=128", "=256")),
            "x.toml"
        )
        .is_ok());
    }
}
