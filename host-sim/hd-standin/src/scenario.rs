//! The scenario a test names the device by.

use host_sim::emulate::{EmulatedHand, Fault, PRESSING};
use twoport_hd::{HdErrorCode, HD_COMM_CONFIG_ERROR, HD_DEVICE_ALREADY_INITIATED};

/// What the device does.
pub struct Scenario {
    pub trace: Option<String>,
    pub hand: Option<EmulatedHand>,
    /// The fault, and how many periods after the motors are enabled.
    pub fault: Option<(u64, Fault)>,
    pub refuse_open: Option<HdErrorCode>,
}

impl Scenario {
    /// The words of a device name (README.md).
    pub fn parse(name: &str) -> Result<Self, String> {
        let mut s = Scenario {
            trace: None,
            hand: Some(PRESSING),
            fault: None,
            refuse_open: None,
        };
        for word in name.split_whitespace() {
            let (key, value) = word.split_once('=').unwrap_or((word, ""));
            match key {
                "trace" => s.trace = Some(value.to_string()),
                "hand" if value == "none" => s.hand = None,
                "fault" => {
                    let (kind, at) = value.split_once('@').ok_or(word)?;
                    let kind = match kind {
                        "unplug" => Fault::Unplug,
                        "garbled" => Fault::Garbled,
                        "short" => Fault::ShortReply,
                        "silent" => Fault::Silent,
                        _ => return Err(word.into()),
                    };
                    s.fault = Some((at.parse().map_err(|_| word)?, kind));
                }
                "open" if value == "denied" => s.refuse_open = Some(HD_COMM_CONFIG_ERROR),
                "open" if value == "busy" => s.refuse_open = Some(HD_DEVICE_ALREADY_INITIATED),
                _ => return Err(word.into()),
            }
        }
        Ok(s)
    }
}
