//! What GRBL 1.1 says on the wire, shared by the streaming host ([`super::stream`]) and the
//! simulated GRBL device ([`super::sim`]): the meaning of `error:N` and `ALARM:N`, the
//! real-time command bytes, the receive-buffer size, and the parsing of a response line.
//!
//! Source: the GRBL 1.1 wiki, "Interface" (messages, real-time commands, streaming protocols)
//! and `grbl/doc/csv/error_codes_en_US.csv`, `alarm_codes_en_US.csv`. GRBL's serial receive
//! buffer is 128 bytes (`RX_BUFFER_SIZE` in `serial.h`); a line may hold at most 80 characters
//! (`LINE_BUFFER_SIZE`), more is `error:11`.

/// GRBL's serial receive buffer, bytes.
pub const RX_BUFFER: usize = 128;
/// Longest line GRBL accepts, characters (without the newline).
pub(crate) const LINE_MAX: usize = 80;

/// Real-time commands: picked out of the byte stream as they arrive, never buffered.
pub(crate) const STATUS_QUERY: u8 = b'?';
pub(crate) const FEED_HOLD: u8 = b'!';
pub(crate) const CYCLE_START: u8 = b'~';
pub(crate) const SOFT_RESET: u8 = 0x18;

/// The welcome line GRBL prints after a reset.
pub(crate) const WELCOME: &str = "Grbl 1.1h ['$' for help]";

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

/// One line GRBL sends back.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Response {
    Ok,
    Error(u32),
    Alarm(u32),
    /// `<State|MPos:…|…>`: the machine state word (`Idle`, `Run`, `Hold:0`, `Alarm`, …).
    Status(String),
    /// The welcome message after a reset.
    Welcome,
    /// Anything else: `[MSG:…]`, `$` setting echoes, or garbage.
    Other(String),
}

/// Parse one response line (without its line ending).
pub(crate) fn parse_response(line: &str) -> Response {
    let line = line.trim();
    if line == "ok" {
        return Response::Ok;
    }
    if let Some(n) = line.strip_prefix("error:") {
        if let Ok(n) = n.trim().parse() {
            return Response::Error(n);
        }
    }
    if let Some(n) = line.strip_prefix("ALARM:") {
        if let Ok(n) = n.trim().parse() {
            return Response::Alarm(n);
        }
    }
    if let Some(body) = line.strip_prefix('<').and_then(|l| l.strip_suffix('>')) {
        let state = body.split('|').next().unwrap_or("").to_string();
        return Response::Status(state);
    }
    if line.starts_with("Grbl ") {
        return Response::Welcome;
    }
    Response::Other(line.to_string())
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
            Response::Status("Hold:0".into())
        );
        assert_eq!(parse_response(WELCOME), Response::Welcome);
        assert_eq!(parse_response("error:x"), Response::Other("error:x".into()));
        assert!(error_meaning(22).contains("feed rate"));
        assert!(alarm_meaning(3).contains("reset while in motion"));
    }
}
