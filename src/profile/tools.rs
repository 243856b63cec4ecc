//! The tool table: which tool makes each kind of stroke, and the checks of one tool.

use super::{problem, Problem};
use serde::{Deserialize, Serialize};

/// Tool classes of a device's tool table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StrokeKind {
    Cut,
    Score,
    Perforate,
    Draw,
    Etch,
}

impl StrokeKind {
    /// The kind's key in a tool table (`[tools.cut]`).
    pub fn name(self) -> &'static str {
        match self {
            StrokeKind::Cut => "cut",
            StrokeKind::Score => "score",
            StrokeKind::Perforate => "perforate",
            StrokeKind::Draw => "draw",
            StrokeKind::Etch => "etch",
        }
    }
}

/// Stroke kinds a tool table may name (see [`StrokeKind::name`]).
pub(crate) const TOOL_KINDS: &[&str] = &["cut", "score", "perforate", "draw", "etch"];

/// How one kind of stroke is made. Which fields matter depends on the language:
///
/// - HP-GL: `pen` (required), `force` (`FS`, grams) and `speed` (`VS`, cm/s).
/// - GP-GL (Graphtec): the same fields as HP-GL: `pen` (`J`, the tool holder / condition
///   number), `force` (`FX`, the cutter's force level, not grams) and `speed` (`!`, cm/s).
/// - G-code: `speed` (feed, mm/min) and exactly one way of putting the tool down: a knife on Z
///   (`z_down` and `z_up`), a servo pen (`servo_down` and `servo_up`, `M3 S`, with `dwell`), or
///   a laser (`power`, `M4 S`, more than 0 and at most the profile's `max_power`).
///
/// Both: `passes`. [`parse`](super::parse) refuses fields of the other language, so that a value a user wrote
/// is never silently ignored.
#[derive(Debug, Clone, PartialEq, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Tool {
    /// HP-GL pen (tool holder) number; GP-GL `J` number.
    pub pen: Option<u32>,
    /// Knife force in grams (HP-GL `FS`; dialects scale it, see `output::hpgl`); GP-GL: the
    /// `FX` force level of the cutter.
    pub force: Option<f64>,
    /// HP-GL: velocity in cm/s (`VS`); GP-GL: cm/s (`!`). G-code: feed rate in mm/min.
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

/// The checks of one tool, `[table]`: its numbers, then the fields of its language.
pub(super) fn check_tool(
    table: &str,
    t: &Tool,
    max_power: Option<f64>,
    gcode: bool,
) -> Result<(), Problem> {
    check_numbers(table, t)?;
    if gcode {
        check_gcode_tool(table, t, max_power)
    } else {
        check_hpgl_tool(table, t)
    }
}

/// Numbers of a tool that hold whatever its language: finite, positive where they must be.
fn check_numbers(table: &str, t: &Tool) -> Result<(), Problem> {
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
    Ok(())
}

/// An HP-GL tool: a pen, and no G-code field.
fn check_hpgl_tool(table: &str, t: &Tool) -> Result<(), Problem> {
    let err = |key: &str, message: String| Err(problem(table, key, message));
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
    Ok(())
}

/// A G-code tool: no HP-GL field and exactly one way down.
fn check_gcode_tool(table: &str, t: &Tool, max_power: Option<f64>) -> Result<(), Problem> {
    let err = |key: &str, message: String| Err(problem(table, key, message));
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
    let ways = ways_down(table, t, max_power)?;
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

/// The ways down a G-code tool gives (`z_down/z_up`, `servo_down/servo_up`, `power`), each
/// checked; a half-given pair names its missing half.
fn ways_down(table: &str, t: &Tool, max_power: Option<f64>) -> Result<Vec<&'static str>, Problem> {
    let err = |key: &str, message: String| Err(problem(table, key, message));
    let mut ways = Vec::new();
    let knife = ("z_down", "z_up", "a knife on Z");
    if let Some((down, up)) = both(table, (t.z_down, t.z_up), knife)? {
        if down >= up {
            return err(
                "z_down",
                format!("must be below z_up ({down} is not below {up})"),
            );
        }
        ways.push("z_down/z_up");
    }
    let servo = ("servo_down", "servo_up", "a servo pen");
    if let Some((down, up)) = both(table, (t.servo_down, t.servo_up), servo)? {
        if down < 0.0 || up < 0.0 {
            return err(
                "servo_down",
                format!("and servo_up are `M3 S` values, 0 or more; got {down} and {up}"),
            );
        }
        if down == up {
            return err(
                "servo_down",
                format!("must differ from servo_up (both are {down})"),
            );
        }
        ways.push("servo_down/servo_up");
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
    Ok(ways)
}

/// A pair of settings that go together, `(down, up)` under the keys `(down_key, up_key)` of
/// `what`: both values, or `None` when neither is given; one without the other is an error
/// that names the missing one.
fn both(
    table: &str,
    (down, up): (Option<f64>, Option<f64>),
    (down_key, up_key, what): (&str, &str, &str),
) -> Result<Option<(f64, f64)>, Problem> {
    let missing = |key: &str| {
        Err(problem(
            table,
            key,
            format!("is missing: {what} needs {down_key} and {up_key}"),
        ))
    };
    match (down, up) {
        (Some(d), Some(u)) => Ok(Some((d, u))),
        (Some(_), None) => missing(up_key),
        (None, Some(_)) => missing(down_key),
        (None, None) => Ok(None),
    }
}
