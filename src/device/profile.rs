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

/// How one kind of stroke is made.
#[derive(Debug, Clone, PartialEq, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Tool {
    /// HP-GL pen (tool holder) number.
    pub pen: Option<u32>,
}

/// A machine.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Profile {
    pub name: String,
    pub description: String,
    pub language: Language,
    pub dialect: String,
    pub units_per_mm: f64,
    #[serde(default)]
    pub tools: BTreeMap<String, Tool>,
    /// Where the profile was read from (not in the file).
    #[serde(skip)]
    pub source: String,
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
