//! What GRBL 1.1 and 0.9 say on the wire, shared by the streaming host ([`super::stream`]) and
//! the simulated GRBL device ([`super::sim`]): the meaning of `error:N` and `ALARM:N`, the
//! real-time command bytes, the receive-buffer size, the line-length rule, and the parsing of a
//! response line.
//!
//! Source: the GRBL 1.1 wiki, "Interface" (messages, real-time commands, streaming protocols)
//! and `grbl/doc/csv/error_codes_en_US.csv`, `alarm_codes_en_US.csv`; GRBL 0.9j's `report.c`
//! for its text messages (`error: Unsupported command`, `ALARM: Abort during cycle`) and its
//! status `<Idle,MPos:…,WPos:…>`. GRBL's serial receive buffer is 128 bytes (`RX_BUFFER_SIZE`
//! in `serial.h`). Its line buffer (`LINE_BUFFER_SIZE` 80, `protocol.c`) keeps at most 79
//! significant characters: spaces and control characters, `/`, `( … )` comments and what
//! follows `;` are dropped as the line arrives and do not count; the 80th is `error:11`.

/// GRBL's serial receive buffer, bytes.
pub const RX_BUFFER: usize = 128;
/// GRBL's line-length rule, which the G-code writer keeps too.
pub(crate) use crate::profile::{significant_len, LINE_MAX};

/// Real-time commands: picked out of the byte stream as they arrive, never buffered.
pub(crate) const STATUS_QUERY: u8 = b'?';
pub(crate) const FEED_HOLD: u8 = b'!';
pub(crate) const CYCLE_START: u8 = b'~';
pub(crate) const SOFT_RESET: u8 = 0x18;

/// The welcome line GRBL prints after a reset.
pub(crate) const WELCOME: &str = "Grbl 1.1h ['$' for help]";
/// GRBL 0.9j's.
pub(crate) const WELCOME_0_9: &str = "Grbl 0.9j ['$' for help]";

/// GRBL 0.9j's text for an error code (`report.c`), the other way round from the reading.
pub(crate) fn error_text_0_9(code: u32) -> String {
    let t = match code {
        1 => "Expected command letter",
        2 => "Bad number format",
        3 => "Invalid statement",
        4 => "Value < 0",
        5 => "Setting disabled",
        6 => "Value < 3 usec",
        7 => "EEPROM read fail. Using defaults",
        8 => "Not idle",
        9 => "Alarm lock",
        10 => "Homing not enabled",
        11 => "Line overflow",
        12 => "Step rate > 30kHz",
        20 => "Unsupported command",
        21 => "Modal group violation",
        22 => "Undefined feed rate",
        _ => return format!("Invalid gcode ID:{code}"),
    };
    t.to_string()
}

/// GRBL 1.1's meaning of `error:N`.
pub(crate) fn error_meaning(code: u32) -> &'static str {
    match code {
        1 => "G-code words consist of a letter and a value; letter was not found",
        2 => "numeric value format is not valid or missing an expected value",
        3 => "GRBL '$' system command was not recognized or supported",
        4 => "negative value received for an expected positive value",
        5 => "homing cycle is not enabled via settings",
        6 => "minimum step pulse time must be greater than 3 µs",
        7 => "EEPROM read failed; reset and restored to default values",
        8 => "GRBL '$' command cannot be used unless GRBL is idle",
        9 => "G-code locked out during alarm or jog state",
        10 => "soft limits cannot be enabled without homing also enabled",
        11 => "max characters per line exceeded; line was not processed",
        12 => "GRBL '$' setting value exceeds the maximum step rate supported",
        13 => "safety door detected as opened and door state initiated",
        14 => "build info or startup line exceeded EEPROM line length limit",
        15 => "jog target exceeds machine travel",
        16 => "jog command with no '=' or contains prohibited g-code",
        17 => "laser mode requires PWM output",
        20 => "unsupported or invalid g-code command found in block",
        21 => "more than one g-code command from same modal group found in block",
        22 => "feed rate has not yet been set or is undefined",
        23 => "g-code command in block requires an integer value",
        24 => "two g-code commands that both require the use of the XYZ axis words",
        25 => "a g-code word was repeated in the block",
        26 => "a g-code command requires XYZ axis words in the block, but none were found",
        27 => "N line number value is not within the valid range of 1 - 9,999,999",
        28 => "a g-code command was sent, but is missing some required P or L value words",
        29 => "GRBL supports six work coordinate systems G54-G59; G59.1-G59.3 are not supported",
        30 => "the G53 g-code command requires either a G0 seek or G1 feed motion mode",
        31 => "there are unused axis words in the block and G80 motion mode cancel is active",
        32 => "a G2 or G3 arc was commanded but there are no XYZ axis words in the plane",
        33 => "the motion command has an invalid target",
        34 => "arc radius value is invalid",
        35 => "a G2 or G3 arc in offset mode needs at least one in-plane offset word",
        36 => "there are unused, leftover g-code words that aren't used by any command",
        37 => "the G43.1 dynamic tool length offset command cannot apply an offset to a non-configured axis",
        38 => "tool number greater than max supported value",
        _ => "unknown error code",
    }
}

/// GRBL 1.1's meaning of `ALARM:N`.
pub(crate) fn alarm_meaning(code: u32) -> &'static str {
    match code {
        1 => "hard limit triggered; position lost, re-homing is highly recommended",
        2 => "soft limit alarm: motion target exceeds machine travel",
        3 => "reset while in motion; position lost, re-homing is highly recommended",
        4 => "probe fail: the probe is not in the expected initial state",
        5 => "probe fail: the probe did not contact the workpiece",
        6 => "homing fail: reset during active homing cycle",
        7 => "homing fail: safety door was opened during active homing cycle",
        8 => "homing fail: cycle failed to clear limit switch when pulling off",
        9 => "homing fail: could not find limit switch within search distance",
        _ => "unknown alarm code",
    }
}

/// The firmware generation, read off the welcome (`Grbl 1.1h […]`, `Grbl 0.9j […]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Version {
    V1_1,
    /// 0.9 and older: text errors and alarms, `<State,MPos:…>` status.
    V0_9,
}

/// A status report: the state word and the machine position when given.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Status {
    /// `Idle`, `Run`, `Hold:0`, `Hold`, `Alarm`, `Jog`, `Door:1`, `Queue` (0.9)…
    pub state: String,
    pub mpos: Option<[f64; 3]>,
}

impl Status {
    /// Whether the state says the machine is busy with a job: running, or held (by the user or
    /// an `M0`) and waiting to resume.
    pub(crate) fn busy(&self) -> bool {
        let s = self.state.as_str();
        s == "Run" || s.starts_with("Hold") || s == "Jog" || s == "Queue" || s.starts_with("Door")
    }
}

/// One line GRBL sends back.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Response {
    Ok,
    Error(u32),
    /// GRBL 0.9's `error: <text>`.
    ErrorText(String),
    Alarm(u32),
    /// GRBL 0.9's `ALARM: <text>`.
    AlarmText(String),
    /// `<State|MPos:…|…>` (1.1) or `<State,MPos:…,WPos:…>` (0.9).
    Status(Status),
    /// The welcome message after a reset.
    Welcome(Version),
    /// Anything else: `[MSG:…]`, `$` setting echoes, or garbage.
    Other(String),
}

/// Parse one response line (without its line ending), of GRBL 1.1 or 0.9.
pub(crate) fn parse_response(line: &str) -> Response {
    let line = line.trim();
    if line == "ok" {
        return Response::Ok;
    }
    if let Some(n) = line.strip_prefix("error:") {
        let n = n.trim();
        return match n.parse() {
            Ok(n) => Response::Error(n),
            Err(_) if n.chars().next().is_some_and(|c| c.is_ascii_alphabetic()) => {
                error_code_0_9(n).map_or(Response::ErrorText(n.to_string()), Response::Error)
            }
            Err(_) => Response::Other(line.to_string()),
        };
    }
    if let Some(n) = line.strip_prefix("ALARM:") {
        let n = n.trim();
        return match n.parse() {
            Ok(n) => Response::Alarm(n),
            Err(_) if n.chars().next().is_some_and(|c| c.is_ascii_alphabetic()) => {
                alarm_code_0_9(n).map_or(Response::AlarmText(n.to_string()), Response::Alarm)
            }
            Err(_) => Response::Other(line.to_string()),
        };
    }
    if let Some(body) = line.strip_prefix('<').and_then(|l| l.strip_suffix('>')) {
        return Response::Status(parse_status(body));
    }
    if let Some(v) = line.strip_prefix("Grbl ") {
        return Response::Welcome(if v.starts_with("0.") {
            Version::V0_9
        } else {
            Version::V1_1
        });
    }
    Response::Other(line.to_string())
}

/// GRBL 0.9j's error text (`report.c`) as the status code it stands for, which 1.1 kept:
/// 0.9's `STATUS_*` numbers are 1.1's `error:N`.
fn error_code_0_9(text: &str) -> Option<u32> {
    if let Some(n) = text.strip_prefix("Invalid gcode ID:") {
        return n.trim().parse().ok();
    }
    Some(match text {
        "Expected command letter" => 1,
        "Bad number format" => 2,
        "Invalid statement" => 3,
        "Value < 0" => 4,
        "Setting disabled" => 5,
        "Value < 3 usec" => 6,
        "EEPROM read fail. Using defaults" => 7,
        "Not idle" => 8,
        "Alarm lock" => 9,
        "Homing not enabled" => 10,
        "Line overflow" => 11,
        "Step rate > 30kHz" => 12,
        "Modal group violation" => 21,
        "Unsupported command" => 20,
        "Undefined feed rate" => 22,
        _ => return None,
    })
}

/// GRBL 0.9j's alarm text as 1.1's `ALARM:N`.
fn alarm_code_0_9(text: &str) -> Option<u32> {
    Some(match text {
        "Hard limit" => 1,
        "Soft limit" => 2,
        "Abort during cycle" => 3,
        "Probe fail" => 4,
        "Homing fail" => 9,
        _ => return None,
    })
}

/// The inside of `<…>`: 1.1 separates fields with `|`, 0.9 with `,` (and its coordinates too).
fn parse_status(body: &str) -> Status {
    let state_end = body.find(['|', ',']).unwrap_or(body.len());
    let state = body[..state_end].to_string();
    let mpos = body.find("MPos:").and_then(|i| {
        let v: Vec<f64> = body[i + 5..]
            .split([',', '|'])
            .take(3)
            .map_while(|w| w.trim().parse().ok())
            .collect();
        (v.len() == 3).then(|| [v[0], v[1], v[2]])
    });
    Status { state, mpos }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn responses() {
        assert_eq!(parse_response("ok\r"), Response::Ok);
        assert_eq!(parse_response("error:20"), Response::Error(20));
        assert_eq!(parse_response("ALARM:3"), Response::Alarm(3));
        assert_eq!(
            parse_response("<Hold:0|MPos:1.000,2.000,0.000|FS:0,0>"),
            Response::Status(Status {
                state: "Hold:0".into(),
                mpos: Some([1.0, 2.0, 0.0])
            })
        );
        assert_eq!(
            parse_response("<Idle,MPos:5.000,-2.500,1.000,WPos:5.000,-2.500,1.000>"),
            Response::Status(Status {
                state: "Idle".into(),
                mpos: Some([5.0, -2.5, 1.0])
            })
        );
        assert_eq!(parse_response(WELCOME), Response::Welcome(Version::V1_1));
        assert_eq!(
            parse_response("Grbl 0.9j ['$' for help]"),
            Response::Welcome(Version::V0_9)
        );
        assert_eq!(
            parse_response("error: Unsupported command"),
            Response::Error(20)
        );
        assert_eq!(
            parse_response("error: Invalid gcode ID:33"),
            Response::Error(33)
        );
        assert_eq!(
            parse_response("error: Something new"),
            Response::ErrorText("Something new".into())
        );
        assert_eq!(
            parse_response("ALARM: Abort during cycle"),
            Response::Alarm(3)
        );
        assert_eq!(parse_response("error:x"), Response::ErrorText("x".into()));
        assert_eq!(parse_response("error:#"), Response::Other("error:#".into()));
        assert_eq!(significant_len("G1 X10 Y20 (a comment) ; rest"), 8);
        assert_eq!(significant_len(&"G1 X1 ".repeat(20)), 80);
        assert!(error_meaning(22).contains("feed rate"));
        assert!(alarm_meaning(3).contains("reset while in motion"));
    }
}
