//! The scene's VE on one axis, built from its scene file, and the scope's
//! changes to it while it runs.

use super::SceneVe;
use crate::engine::blocks::{Blocks, LineBlock};
use crate::engine::scene::{Discretization, Integration, LayerPort, Scene, VeSpec};
use crate::Error;
use twoport_control::passivity::{ParallelLimits, PassiveVe};
use twoport_control::ve::{
    BilateralConstraint, CursorMass, ExplicitCursor, LosslessCursor, Spring, UnilateralWall,
};
use twoport_control::{Position, Real, SafetyConfig};

/// One axis's VE: the scene's, behind the passivity layer at its port
/// where the scene puts one there.
pub(crate) fn axis_ve<R: Real>(scene: &Scene, safety: &SafetyConfig) -> Result<SceneVe<R>, Error> {
    let ve = scene_ve(scene, safety.period_s)?;
    Ok(match (&scene.passivity, &scene.ve) {
        (Some(p), VeSpec::Cursor { mass_kg, .. }) if p.enabled && p.port == LayerPort::Ve => {
            let limits = ParallelLimits::for_display(
                *mass_kg as f32,
                safety.period_s,
                safety.max_velocity_mps,
            )
            .map_err(|e| e.to_string())?;
            SceneVe::Passive(Box::new(
                PassiveVe::new(ve, limits).map_err(|e| e.to_string())?,
            ))
        }
        _ => ve,
    })
}

/// Move the wall `ve` to `surface` at stiffness `k_npm` (N/m), keeping its
/// damping; an error if it is not a wall.
pub(crate) fn set_wall<R: Real>(
    ve: &mut SceneVe<R>,
    surface: Position,
    k_npm: f32,
) -> Result<(), Error> {
    let SceneVe::Wall(w) = ve else {
        return Err("the scene's VE is not a wall".into());
    };
    let (_, b) = w.spring();
    w.set_spring(k_npm, b).map_err(|e| e.to_string())?;
    w.set_surface(surface);
    Ok(())
}

/// The scene's VE, computing in `R`.
fn scene_ve<R: Real>(scene: &Scene, t32: f32) -> Result<SceneVe<R>, Error> {
    let pos = |m: f64| {
        Position::from_m_f64(m).ok_or(format!("position {m} m is out of range (±2.147 m)"))
    };
    Ok(match &scene.ve {
        VeSpec::Cursor {
            mass_kg,
            integration: Integration::Implicit,
        } => SceneVe::Cursor(
            CursorMass::new_in(*mass_kg as f32, t32, Position::ZERO).map_err(|e| e.to_string())?,
        ),
        VeSpec::Cursor {
            mass_kg,
            integration: Integration::Lossless,
        } => SceneVe::LosslessCursor(
            LosslessCursor::new_in(*mass_kg as f32, t32, Position::ZERO)
                .map_err(|e| e.to_string())?,
        ),
        VeSpec::Cursor {
            mass_kg,
            integration: Integration::Explicit,
        } => SceneVe::ExplicitCursor(
            ExplicitCursor::new_in(*mass_kg as f32, t32, Position::ZERO)
                .map_err(|e| e.to_string())?,
        ),
        VeSpec::Wall {
            position_m,
            stiffness_npm,
            damping_nspm,
            solid,
        } => {
            let side = *solid;
            SceneVe::Wall(
                UnilateralWall::new_in(
                    *stiffness_npm as f32,
                    *damping_nspm as f32,
                    pos(*position_m)?,
                    side,
                    t32,
                    Position::ZERO,
                )
                .map_err(|e| e.to_string())?,
            )
        }
        VeSpec::Bilateral => SceneVe::Bilateral(BilateralConstraint::new(Position::ZERO)),
        VeSpec::Spring {
            anchor_m,
            stiffness_npm,
            damping_nspm,
            discretization,
        } => {
            let (k, b, a) = (*stiffness_npm as f32, *damping_nspm as f32, pos(*anchor_m)?);
            let spring = Spring::new_in(k, b, a, t32, Position::ZERO).map_err(|e| e.to_string())?;
            match discretization {
                Discretization::BackwardEuler => SceneVe::Spring(spring),
                Discretization::Trapezoidal => SceneVe::TrapezoidalSpring(spring.into()),
            }
        }
        VeSpec::World { .. } => {
            return Err("ve.kind = \"world\" is a 3-D world, not one axis's VE".into())
        }
        VeSpec::Blocks(w) => {
            let bs = w
                .blocks
                .iter()
                .map(|b| {
                    Ok(LineBlock {
                        left: pos(b.at_m)?,
                        width_nm: pos(b.width_m)?.nm(),
                        mass_kg: b.mass_kg as f32,
                        velocity_mps: 0.0,
                    })
                })
                .collect::<Result<Vec<_>, Error>>()?;
            SceneVe::Blocks(Box::new(Blocks::new(
                t32,
                w.cursor_mass_kg as f32,
                bs,
                [pos(w.limits_m[0])?, pos(w.limits_m[1])?],
                w.stick_force_n as f32,
                w.floor_damping_nspm as f32,
                w.grab_at_s,
                w.release_at_s,
            )?))
        }
    })
}
