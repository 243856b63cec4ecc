//! Device profiles: one TOML file per machine in `devices/`, compiled into the binary so that
//! flatcut works from any directory, plus the user's own in `$XDG_CONFIG_HOME/flatcut/devices`
//! (or `~/.config/flatcut/devices`), which add profiles or replace bundled ones of the same name.
//!
//! A profile says which language the machine speaks, how many device units make a millimetre,
//! and which tool makes each kind of stroke (cut, score, perforate, draw, etch). A kind the
//! profile has no tool for is left out of the program, with a note to the user.

use crate::toolpath::StrokeKind;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Profiles shipped with flatcut: (file name, contents).
pub const BUNDLED: &[(&str, &str)] = &[
    ("sim.toml", include_str!("../../devices/sim.toml")),
    (
        "hpgl-pens.toml",
        include_str!("../../devices/hpgl-pens.toml"),
    ),
];

/// Machine language.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Language {
    Hpgl,
    Gcode,
}

impl Language {
    /// File extension of programs in this language.
    pub fn extension(self) -> &'static str {
        match self {
            Language::Hpgl => "plt",
            Language::Gcode => "gcode",
        }
    }
}

/// How one kind of stroke is made. Which fields matter depends on the language: HP-GL uses
/// `pen`, `force` (FS) and `speed` (VS); G-code uses `speed` (feed), `z_down`/`z_up` (knife),
/// `servo_down`/`servo_up` (pen servo, `M3 S`) or `power` (laser, `M4 S`).
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
    /// Laser power, spindle `S` units (0 to the profile's `max_power`).
    pub power: Option<f64>,
    /// G-code knife: Z height (mm) with the blade in the material, and lifted.
    pub z_down: Option<f64>,
    pub z_up: Option<f64>,
    /// G-code servo pen: `M3 S` value that lowers and lifts the pen.
    pub servo_down: Option<f64>,
    pub servo_up: Option<f64>,
    /// Seconds to wait after a servo move (`G4 P`).
    pub dwell: Option<f64>,
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
    /// `hp-gl`, `camm-gl2` (Roland CAMM-GL mode 2), `grbl`.
    pub dialect: String,
    pub units_per_mm: f64,
    /// Largest width the machine can cut (mm); 0 when unknown.
    #[serde(default)]
    pub media_width: f64,
    #[serde(default)]
    pub axes: Axes,
    #[serde(default)]
    pub serial: SerialSettings,
    /// Device input buffer in bytes (what may be in flight unacknowledged).
    #[serde(default = "default_buffer")]
    pub buffer: usize,
    #[serde(default)]
    pub protocol: Protocol,
    /// G-code laser: the `S` value of full power (GRBL `$30`).
    #[serde(default)]
    pub max_power: Option<f64>,
    #[serde(default)]
    pub tools: BTreeMap<String, Tool>,
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

impl Profile {
    /// The tool for a kind of stroke, if the machine has one.
    pub fn tool(&self, kind: StrokeKind) -> Option<&Tool> {
        self.tools.get(kind.name())
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

/// Parse one profile.
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
    if !(p.units_per_mm.is_finite() && p.units_per_mm > 0.0) {
        return Err(invalid(format!(
            "`units_per_mm` must be a positive number, got {}",
            p.units_per_mm
        )));
    }
    for key in p.tools.keys() {
        if !["cut", "score", "perforate", "draw", "etch"].contains(&key.as_str()) {
            return Err(invalid(format!(
                "unknown tool kind `{key}`; expected cut, score, perforate, draw or etch"
            )));
        }
    }
    if p.serial.baud == 0 || !(5..=8).contains(&p.serial.data_bits) || !(1..=2).contains(&p.serial.stop_bits) {
        return Err(invalid(format!(
            "serial settings: baud must be > 0, data_bits 5–8, stop_bits 1–2 (got {}, {}, {})",
            p.serial.baud, p.serial.data_bits, p.serial.stop_bits
        )));
    }
    if p.buffer == 0 {
        return Err(invalid("`buffer` must be at least 1 byte".into()));
    }
    if !p.tools.contains_key("cut") {
        return Err(invalid("the tool table has no `cut` tool".into()));
    }
    p.source = source_name.to_string();
    Ok(p)
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

    #[test]
    fn every_bundled_profile_loads() {
        for (file, text) in BUNDLED {
            let p = parse(text, file).unwrap();
            assert_eq!(format!("{}.toml", p.name), *file);
            assert!(p.tool(StrokeKind::Cut).is_some());
        }
        let p = parse(BUNDLED[1].1, "x").unwrap();
        assert_eq!(p.tool(StrokeKind::Cut).and_then(|t| t.pen), Some(1));
        assert_eq!(p.tool(StrokeKind::Score).and_then(|t| t.pen), Some(2));
        assert_eq!(p.tool(StrokeKind::Draw).and_then(|t| t.pen), Some(3));
        assert_eq!(p.units_per_mm, 40.0);
    }

    #[test]
    fn bad_profiles_say_why() {
        let e = parse("name = \"x\"\ncolour = 1\n", "x.toml").unwrap_err();
        assert!(e.to_string().contains("x.toml: line 2"), "{e}");
        let e = parse(
            "name='x'\ndescription='d'\nlanguage='hpgl'\ndialect='hp-gl'\nunits_per_mm=0\n[tools.cut]\npen=1\n",
            "x.toml",
        )
        .unwrap_err();
        assert!(e.to_string().contains("units_per_mm"), "{e}");
        assert!(find("no-such-machine")
            .unwrap_err()
            .to_string()
            .contains("hpgl-pens"));
    }
}
