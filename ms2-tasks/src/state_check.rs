//! Bounds checks of a state vector before [`crate::Env::set_state`] restores it.
//!
//! A finite but impossible state (a joint far outside its limits, a body moving at 10 km/s, a
//! body 10^10 m away) would make the solver produce NaN in the next steps, so `set_state`
//! refuses it with [`EnvError::StateOutOfBounds`], naming the index, the value, its meaning
//! and the accepted range. The bounds are generous: every state the simulator itself produces
//! (fingers pressed slightly past their limits by a grasp, fast falls) is accepted.
//!
//! | quantity | accepted |
//! |---|---|
//! | position of an actor or articulation root | within ±[`MAX_POSITION_M`] m per axis |
//! | pose quaternion (w, x, y, z) | norm within [`QUATERNION_NORM_TOLERANCE`] of 1 (used as given, not renormalised) |
//! | linear velocity | within ±[`MAX_LINEAR_SPEED`] m/s per axis |
//! | angular velocity | within ±[`MAX_ANGULAR_SPEED`] rad/s per axis |
//! | joint position | joint limits widened by [`JOINT_LIMIT_TOLERANCE_RAD`] rad / [`JOINT_LIMIT_TOLERANCE_M`] m |
//! | joint velocity, drive velocity target | within ±[`MAX_JOINT_SPEED_RAD`] rad/s / ±[`MAX_JOINT_SPEED_M`] m/s |
//! | drive position target | joint limits widened by [`DRIVE_TARGET_TOLERANCE_RAD`] rad / [`DRIVE_TARGET_TOLERANCE_M`] m (accumulating controllers may aim past a limit) |
//! | controller state (accumulated targets), task state (goals, soft-body state) | within ±[`MAX_EXTRA_STATE`] |

use ms2_physics::{StateField, StateQuantity};

use crate::error::EnvError;

/// Largest accepted position coordinate (m) of a body.
pub const MAX_POSITION_M: f32 = 100.0;
/// Largest accepted magnitude of a controller or task state value (their meanings vary by task:
/// targets, goals, particle counts).
pub const MAX_EXTRA_STATE: f32 = 1e6;
/// Accepted deviation of a pose quaternion's norm from 1.
pub const QUATERNION_NORM_TOLERANCE: f32 = 1e-3;
/// Largest accepted linear velocity component (m/s).
pub const MAX_LINEAR_SPEED: f32 = 100.0;
/// Largest accepted angular velocity component (rad/s).
pub const MAX_ANGULAR_SPEED: f32 = 1000.0;
/// How far (rad) a revolute joint may sit past its limits (contacts push joints slightly past).
pub const JOINT_LIMIT_TOLERANCE_RAD: f32 = 0.05;
/// How far (m) a prismatic joint may sit past its limits.
pub const JOINT_LIMIT_TOLERANCE_M: f32 = 0.01;
/// Largest accepted revolute joint speed (rad/s). Far above any drive's limit: the bound must
/// accept every state the simulation itself produces (contacts kick joints well past their
/// drive limits: the soak recorded a Panda finger at 6 m/s under random actions).
pub const MAX_JOINT_SPEED_RAD: f32 = 500.0;
/// Largest accepted prismatic joint speed (m/s); see [`MAX_JOINT_SPEED_RAD`].
pub const MAX_JOINT_SPEED_M: f32 = 50.0;
/// How far (rad) a revolute drive's position target may lie past the joint limits.
pub const DRIVE_TARGET_TOLERANCE_RAD: f32 = std::f32::consts::TAU;
/// How far (m) a prismatic drive's position target may lie past the joint limits.
pub const DRIVE_TARGET_TOLERANCE_M: f32 = 1.0;

/// The meaning of every element of an env's state vector: the world's fields, then the
/// controller's and the task's (named generically).
pub(crate) struct StateLayout {
    fields: Vec<StateField>,
    /// Index where the world part ends (fields after it are controller / task state).
    world_len: usize,
    /// Whether the world part has physical meanings (else only finiteness is checked there).
    world_known: bool,
}

impl StateLayout {
    /// A layout of `world` fields (or `world_len` unknown ones) followed by `extra` named,
    /// magnitude-bounded entries (controller and task state).
    pub(crate) fn new(
        world: Option<Vec<StateField>>,
        world_len: usize,
        extra: impl IntoIterator<Item = String>,
    ) -> Self {
        let world_known = world.as_ref().is_some_and(|w| w.len() == world_len);
        let mut fields = match world {
            Some(w) if world_known => w,
            _ => (0..world_len)
                .map(|i| StateField {
                    name: format!("world state element {i}"),
                    quantity: StateQuantity::Position,
                })
                .collect(),
        };
        fields.extend(extra.into_iter().map(|name| StateField {
            name,
            quantity: StateQuantity::Position,
        }));
        Self {
            fields,
            world_len,
            world_known,
        }
    }

    /// Checks `state` (length already checked) against the bounds in the module docs.
    pub(crate) fn check(&self, state: &[f32]) -> Result<(), EnvError> {
        for (index, (field, &value)) in self.fields.iter().zip(state).enumerate() {
            if index < self.world_len && !self.world_known {
                continue;
            }
            let out = |low: f32, high: f32, unit: &str, why: &str| {
                if value >= low && value <= high {
                    Ok(())
                } else {
                    Err(EnvError::StateOutOfBounds {
                        index,
                        value,
                        meaning: field.name.clone(),
                        expected: format!("[{low}, {high}] {unit}{why}"),
                    })
                }
            };
            let (tol_joint, tol_target, max_speed, unit, speed_unit) = if is_prismatic(field) {
                (
                    JOINT_LIMIT_TOLERANCE_M,
                    DRIVE_TARGET_TOLERANCE_M,
                    MAX_JOINT_SPEED_M,
                    "m",
                    "m/s",
                )
            } else {
                (
                    JOINT_LIMIT_TOLERANCE_RAD,
                    DRIVE_TARGET_TOLERANCE_RAD,
                    MAX_JOINT_SPEED_RAD,
                    "rad",
                    "rad/s",
                )
            };
            match field.quantity {
                StateQuantity::Position if index < self.world_len => {
                    out(-MAX_POSITION_M, MAX_POSITION_M, "m", "")?
                }
                StateQuantity::Position => out(-MAX_EXTRA_STATE, MAX_EXTRA_STATE, "", "")?,
                StateQuantity::Quaternion { index: 0 } => {
                    check_quaternion(state, index, &field.name)?
                }
                StateQuantity::Quaternion { .. } => {}
                StateQuantity::LinearVelocity => {
                    out(-MAX_LINEAR_SPEED, MAX_LINEAR_SPEED, "m/s", "")?
                }
                StateQuantity::AngularVelocity => {
                    out(-MAX_ANGULAR_SPEED, MAX_ANGULAR_SPEED, "rad/s", "")?
                }
                StateQuantity::JointPosition { limits, .. } => out(
                    limits[0] - tol_joint,
                    limits[1] + tol_joint,
                    unit,
                    &format!(
                        " (joint limits [{}, {}] ± {tol_joint})",
                        limits[0], limits[1]
                    ),
                )?,
                StateQuantity::DriveTarget { limits, .. } => out(
                    limits[0] - tol_target,
                    limits[1] + tol_target,
                    unit,
                    &format!(
                        " (joint limits [{}, {}] ± {tol_target})",
                        limits[0], limits[1]
                    ),
                )?,
                StateQuantity::JointVelocity { .. } | StateQuantity::DriveVelocityTarget { .. } => {
                    out(-max_speed, max_speed, speed_unit, "")?
                }
            }
        }
        Ok(())
    }
}

/// Whether `field` belongs to a prismatic (translating) joint.
fn is_prismatic(field: &StateField) -> bool {
    matches!(
        field.quantity,
        StateQuantity::JointPosition {
            prismatic: true,
            ..
        } | StateQuantity::JointVelocity { prismatic: true }
            | StateQuantity::DriveTarget {
                prismatic: true,
                ..
            }
            | StateQuantity::DriveVelocityTarget { prismatic: true }
    )
}

/// Checks that the quaternion whose `w` is at `state[index]` has a norm within
/// [`QUATERNION_NORM_TOLERANCE`] of 1.
fn check_quaternion(state: &[f32], index: usize, name: &str) -> Result<(), EnvError> {
    let q = &state[index..index + 4];
    let norm = q.iter().map(|v| v * v).sum::<f32>().sqrt();
    if (norm - 1.0).abs() <= QUATERNION_NORM_TOLERANCE {
        return Ok(());
    }
    Err(EnvError::StateOutOfBounds {
        index,
        value: q[0],
        meaning: format!("{name}; the quaternion [w, x, y, z] = {q:?} has norm {norm}"),
        expected: format!("norm 1 ± {QUATERNION_NORM_TOLERANCE} (unit quaternions only)"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout() -> StateLayout {
        let mut fields = Vec::new();
        for name in ["x", "y", "z"] {
            fields.push(StateField {
                name: format!("position {name} of actor cube"),
                quantity: StateQuantity::Position,
            });
        }
        for index in 0..4 {
            fields.push(StateField {
                name: format!("quaternion {} of actor cube", ["w", "x", "y", "z"][index]),
                quantity: StateQuantity::Quaternion { index },
            });
        }
        fields.push(StateField {
            name: "qpos of panda_joint1".to_owned(),
            quantity: StateQuantity::JointPosition {
                limits: [-2.8973, 2.8973],
                prismatic: false,
            },
        });
        fields.push(StateField {
            name: "qvel of panda_joint1".to_owned(),
            quantity: StateQuantity::JointVelocity { prismatic: false },
        });
        StateLayout::new(Some(fields), 9, ["goal x".to_owned()])
    }

    #[test]
    fn accepts_a_sane_state_and_names_each_bad_value() {
        let l = layout();
        let good = [0.1, 0.0, 0.02, 1.0, 0.0, 0.0, 0.0, 2.9, -3.0, 0.3];
        l.check(&good).unwrap();
        let cases: [(usize, f32, &str); 5] = [
            (7, 10.0, "qpos of panda_joint1"),
            (8, 1e4, "qvel of panda_joint1"),
            (0, 1e10, "position x of actor cube"),
            (3, 2.0, "quaternion"),
            (9, -5e6, "goal x"),
        ];
        for (index, value, meaning) in cases {
            let mut bad = good;
            bad[index] = value;
            let err = l.check(&bad).unwrap_err();
            let msg = err.to_string();
            assert!(
                msg.contains(&format!("state[{index}]")) && msg.contains(meaning),
                "{msg}"
            );
        }
    }

    #[test]
    fn unknown_world_layout_is_not_bounded() {
        let l = StateLayout::new(None, 2, []);
        l.check(&[1e20, -1e20]).unwrap();
    }
}
