//! `twoport teleop`: two devices through one teleoperator law.

use crate::args::{TeleopArgs, TeleopLaw};
use crate::run::{reported, Reported};
use twoport_control::teleop::FourChannelGains;
use twoport_design::verify::verify_four_channel;
use twoport_design::DeviceModel;

/// The law's gains as the control crate holds them.
fn gains(law: &TeleopLaw) -> FourChannelGains {
    match *law {
        TeleopLaw::PositionPosition { k, b } => FourChannelGains::position_position(k, b),
        TeleopLaw::PositionForce { k, b, k_f, b_m } => {
            FourChannelGains::position_force(k, b, k_f, b_m)
        }
        TeleopLaw::FourChannel {
            k_m,
            b_m,
            b_local,
            k_s,
            b_s,
            c2,
            c3,
            c5,
            c6,
        } => FourChannelGains {
            k_m_npm: k_m,
            b_m_nspm: b_m,
            b_local_nspm: b_local,
            k_s_npm: k_s,
            b_s_nspm: b_s,
            c2,
            c3,
            c5,
            c6,
        },
    }
}

/// `teleop verify`: the exact loop's counterexample search.
pub(crate) fn verify(a: &TeleopArgs) -> Reported {
    let load = |flag: &str, path: &std::path::Path| {
        DeviceModel::load(path).map_err(|e| format!("--{flag} {}: {e}", path.display()))
    };
    let (master, slave) = (load("master", &a.master)?, load("slave", &a.slave)?);
    if master.period_s != slave.period_s {
        return Err(format!(
            "--master samples every {} s and --slave every {} s: a teleoperator runs both at one period",
            master.period_s, slave.period_s
        ));
    }
    reported(
        verify_four_channel(&master, &slave, gains(&a.law), a.delay).map_err(|e| e.to_string())?,
    )
}
