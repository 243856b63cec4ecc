//! Serial line settings and the protocol that paces a program into the device.

use serde::Deserialize;

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
    /// How a buffered (HP-GL) device can be asked, while it holds the host off, whether it is
    /// still working: `esc-b` for HP's RS-232 device-control query `ESC . B` (output buffer
    /// space), which the device answers at once, even with its buffer full.
    #[serde(default)]
    pub status_query: StatusQuery,
}

/// A buffered device's output channel, for asking it how it is doing while it holds the host off.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum StatusQuery {
    /// No output channel (or none flatcut uses): a hold longer than the timeout is a stop.
    #[default]
    None,
    /// `ESC . B`: the device answers its free buffer space in bytes, then CR.
    EscB,
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
            status_query: StatusQuery::None,
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
