//! `twoport teleop`: two devices through one teleoperator law.

use crate::args::{TeleopArgs, TeleopLaw};
use crate::run::{reported, Reported};
use num_complex::Complex64;
use twoport_control::teleop::FourChannelGains;
use twoport_design::designer::TeleopDesigner;
use twoport_design::network::HumanBound;
use twoport_design::verify::{verify_law, TeleopLaw as Law, WaveGains};
use twoport_design::{plot, DeviceModel};

/// The law as the designer names it, `free` standing in for the gain a
/// design finds; `None` where that gain is left out.
fn law_with(law: &TeleopLaw, free: Option<f32>) -> Option<Law> {
    Some(Law::FourChannel(match *law {
        TeleopLaw::PositionPosition { k, b } => FourChannelGains::position_position(k.or(free)?, b),
        TeleopLaw::PositionForce { k, b, k_f, b_m } => {
            FourChannelGains::position_force(k, b, k_f.or(free)?, b_m)
        }
        TeleopLaw::Wave { b, filter_pole } => {
            return Some(Law::Wave(WaveGains {
                b_nspm: b.or(free)?,
                filter_pole,
            }))
        }
        TeleopLaw::FourChannel { ref gains } => {
            return four_channel(gains).ok().map(Law::FourChannel)
        }
    }))
}

/// `--gain NAME=VALUE`s as four-channel gains, the others off.
fn four_channel(gains: &[String]) -> Result<FourChannelGains, String> {
    let mut g = FourChannelGains::OFF;
    for given in gains {
        let (name, value) = given
            .split_once('=')
            .ok_or_else(|| format!("--gain {given}: give NAME=VALUE"))?;
        let value: f32 = value
            .trim()
            .parse()
            .map_err(|_| format!("--gain {given}: `{}` is not a number", value.trim()))?;
        if !g.set(name.trim(), value) {
            let names: Vec<&str> = g.named().iter().map(|(n, _)| *n).collect();
            return Err(format!(
                "--gain {given}: no gain `{}`; the gains are {}",
                name.trim(),
                names.join(", ")
            ));
        }
    }
    Ok(g)
}

/// The law, every gain given.
fn law(law: &TeleopLaw) -> Result<Law, String> {
    if let TeleopLaw::FourChannel { gains } = law {
        return four_channel(gains).map(Law::FourChannel);
    }
    law_with(law, None).ok_or_else(|| {
        match law {
            TeleopLaw::PositionForce { .. } => {
                "position-force: give --k-f (teleop design finds it)"
            }
            TeleopLaw::Wave { .. } => "wave: give --b (teleop design finds it)",
            _ => "position-position: give --k (teleop design finds it)",
        }
        .to_string()
    })
}

/// The law a design varies, with `x` for the left-out gain.
fn law_at(law: &TeleopLaw, x: f64) -> Law {
    law_with(law, Some(x as f32)).unwrap_or(Law::FourChannel(FourChannelGains::OFF))
}

/// Both models, which must sample at one period.
fn models(a: &TeleopArgs) -> Result<(DeviceModel, DeviceModel), String> {
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
    Ok((master, slave))
}

/// `teleop verify`: the exact loop's counterexample search.
pub(crate) fn verify(a: &TeleopArgs) -> Reported {
    let (master, slave) = models(a)?;
    reported(verify_law(&master, &slave, law(&a.law)?, a.delay).map_err(|e| e.to_string())?)
}

fn designer(a: &TeleopArgs) -> Result<TeleopDesigner, String> {
    let (master, slave) = models(a)?;
    let human = a.human_bound.then_some(HumanBound::PAPER);
    TeleopDesigner::new(&master, &slave, a.delay, human).map_err(|e| e.to_string())
}

/// `teleop check`: the proof at the given gains.
pub(crate) fn check(a: &TeleopArgs) -> Reported {
    let l = law(&a.law)?;
    let d = designer(a)?;
    let report = d.check_law(l).map_err(|e| e.to_string())?;
    plot_felt(a, &d, l)?;
    reported(report)
}

/// With `--plot`, draw what the operator feels through `law`: `|Z|` (N s/m)
/// through free space and against a rigid wall, against frequency.
fn plot_felt(a: &TeleopArgs, d: &TeleopDesigner, law: Law) -> Result<(), String> {
    let Some(out) = &a.plot else {
        return Ok(());
    };
    let range = d.range(law).map_err(|e| e.to_string())?;
    let curve =
        |label: &str, color, pick: fn(&(f64, Complex64, Complex64)) -> Complex64| plot::Curve {
            label: label.into(),
            width: 2,
            dashed: false,
            color,
            points: range
                .iter()
                .map(|r| (r.0 / (2.0 * std::f64::consts::PI), pick(r).norm()))
                .collect(),
        };
    let fig = plot::Figure {
        title: "What the operator feels through the teleoperator".into(),
        x_label: "frequency (Hz)".into(),
        y_label: "|Z| at the master's handle (N s/m)".into(),
        legend: plot::LegendAt::UpperLeft,
        curves: vec![
            curve("slave in free space", plot::BLUE, |r| r.1),
            curve("slave against a rigid wall", plot::RED, |r| r.2),
        ],
    };
    plot::render(&fig, out).map_err(|e| format!("--plot {}: {e}", out.display()))
}

/// The most a designed gain is searched up to: a stiffness (N/m), a
/// force scale or a wave impedance (N s/m).
fn design_limit(law: &TeleopLaw) -> f64 {
    match law {
        TeleopLaw::PositionForce { .. } => 100.0,
        TeleopLaw::Wave { .. } => 1e5,
        _ => 1e7,
    }
}

/// `teleop design`: the largest left-out gain the proof allows, and its
/// proof.
pub(crate) fn design(a: &TeleopArgs) -> Reported {
    if law_with(&a.law, None).is_some() {
        let given = match a.law {
            TeleopLaw::PositionForce { .. } => "--k-f",
            TeleopLaw::Wave { .. } => "--b",
            _ => "--k",
        };
        return Err(match a.law {
            TeleopLaw::FourChannel { .. } => {
                "four-channel: design finds position-position's --k, position-force's --k-f \
                 or the wave channel's --b; check a four-channel law's given gains"
                    .to_string()
            }
            _ => format!("design finds {given}: leave it out"),
        });
    }
    let d = designer(a)?;
    let at = |x: f64| law_at(&a.law, x);
    match d
        .largest_law(at, design_limit(&a.law))
        .map_err(|e| e.to_string())?
    {
        Some((_, report)) => {
            plot_felt(a, &d, report.law)?;
            reported(report)
        }
        None => Err(format!(
            "no gain is proven for these devices and this law (down to {:e}): \
             `teleop check` with a small gain says where the proof fails",
            design_limit(&a.law) * 1e-8
        )),
    }
}
