//! Reading a profile: TOML into [`Profile`], then the checks the output and device stages
//! rely on, with errors that name the file, the line and the key.

use super::tools::check_tool;
use super::{
    problem, Language, Problem, Profile, ProfileError, Protocol, GCODE_DIALECTS, GPGL_DIALECTS,
    GPGL_UNITS_PER_MM, HPGL_DIALECTS, TOOL_KINDS,
};

/// Parse one profile and check it. Errors name `source_name` and the key at fault, with its
/// line when the key is written as `key = value` under its table header.
pub fn parse(text: &str, source_name: &str) -> Result<Profile, ProfileError> {
    let invalid = |message: String| ProfileError::Invalid {
        source_name: source_name.to_string(),
        message,
    };
    let mut p: Profile = toml::from_str(text).map_err(|e| {
        let at = e.span().map(|s| s.start.min(text.len()));
        let line = at.map(|s| text[..s].matches('\n').count() + 1);
        let key = at
            .and_then(|s| key_at(text, s))
            .map(|k| format!("`{k}` "))
            .unwrap_or_default();
        invalid(format!(
            "{}{key}{}",
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

pub(super) fn positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// The media sizes and the serial line's status query.
fn check_media_and_line(p: &Profile) -> Result<(), Problem> {
    for (key, v) in [
        ("media_width", p.media_width),
        ("media_length", p.media_length),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(problem(
                "",
                key,
                format!("must be 0 (unknown) or a size in mm, got {v}"),
            ));
        }
    }
    if p.serial.status_query != super::StatusQuery::None && p.language != Language::Hpgl {
        return Err(problem(
            "serial",
            "status_query",
            "`esc-b` is HP's RS-232 device control, for HP-GL devices only",
        ));
    }
    Ok(())
}

/// The checks of [`parse`] on a profile that deserialised.
fn check(p: &Profile) -> Result<(), Problem> {
    super::grbl::check(&p.grbl).map_err(|(key, m)| problem("grbl", key, m))?;
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
        Language::Gpgl => (GPGL_DIALECTS, false),
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
            "must be buffered for an HP-GL or GP-GL profile (the grbl-* protocols are for G-code)",
        ));
    }
    if p.language == Language::Gpgl && !GPGL_UNITS_PER_MM.contains(&p.units_per_mm) {
        return Err(problem(
            "",
            "units_per_mm",
            format!(
                "must be 10, 20, 40 or 100 for GP-GL (the cutter's step size of 0.1, 0.05, \
                 0.025 or 0.01 mm), got {}",
                p.units_per_mm
            ),
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
    check_media_and_line(p)?;
    super::registration::check(&p.registration)
        .map_err(|(key, m)| problem("registration", key, m))?;
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
    if !(50..=4_000_000).contains(&s.baud) {
        return Err(problem(
            "serial",
            "baud",
            format!("must be a baud rate from 50 to 4000000, got {}", s.baud),
        ));
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

/// The key (`table.key`) set on the line holding byte `at`, when that line reads `key = …`
/// under a `[table]` header (or at the top level).
fn key_at(text: &str, at: usize) -> Option<String> {
    let start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    let line = text[start..].lines().next().unwrap_or("");
    let (key, _) = line.split_once('=')?;
    let key = key.trim().trim_matches('"');
    let bare = |s: &str| {
        !s.is_empty()
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
    };
    if !bare(key) {
        return None;
    }
    let table = text[..start]
        .lines()
        .rev()
        .map(str::trim)
        .find_map(|l| l.strip_prefix('[').and_then(|r| r.split(']').next()))
        .map(|t| t.trim_start_matches('[').trim().to_string())
        .unwrap_or_default();
    Some(if table.is_empty() {
        key.to_string()
    } else {
        format!("{table}.{key}")
    })
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
