//! ManiSkill2's dense reward of `MoveBucket-v1` ([`super::move_bucket`]).
//!
//! With d the mean distance of the four finger tips to the bucket's surface (512 samples per
//! link with a visual), m₁, m₂ the two hands' finger-tip midpoints, c the body's centre of mass
//! raised by [`MoveBucket::bucket_center_offset`], tilt the root's tilt and v, ω the root's
//! velocity and angular velocity (world):
//!
//! −20 − d − clip(ln(d + 1e-5), −10, 0) − 0.2 · clip(ln(h + 1e-5), −10, 0) − 0.2 · tilt, with h
//! the height difference of m₁ and m₂ in the root's frame; then, when d < 0.1 m: stage +2 and
//! 2 · (1 − cos(m₁ − c, m₂ − c)) (hands on opposite sides); when moreover the body's centre of
//! mass is within 3 cm of its start height + 0.2 m: stage +2, −clip(ln(tilt + 1e-5), −4, 0);
//! then either (root within 0.3 m of the goal) stage +2, 2 e^(−10 |v|), stage +2 when
//! |v| ≤ 0.1 m/s and |ω| ≤ 0.2 rad/s, and stage +2 more when tilt ≤ 0.1π; or
//! 2 · max(−1, 1 − e^(−r)) − 2 · (distance to the goal), r = (cosine distance of v_xy to the
//! root's displacement from the goal − 1) · |v| (0 for a zero v_xy: the limit as v → 0); and
//! while not lifted: 2 · max(−1, 1 − e^(−v_z)) − 20 · |height − (start + 0.2)|. A tilt over
//! 0.4π costs stage −2. ManiSkill2's −1e-6 · ‖action‖ is left out (the task hooks do not see
//! the action). Cosines with a zero vector count as 0.

use nalgebra::{Vector2, Vector3};

use super::common::mobile_agent;
use super::move_bucket::{MoveBucket, SUCCESS_DISTANCE};
use crate::error::EnvError;
use crate::info::Evaluation;
use crate::task::TaskScene;

/// Raise (m) of the body's centre of mass that the reward's lifting stage aims at.
pub const LIFT_TARGET: f32 = 0.2;

/// The dense reward and its parts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BucketReward {
    /// The dense reward.
    pub total: f64,
    /// The stage term (ManiSkill2's `stage_reward`).
    pub stage: f64,
    /// Mean finger-tip distance (m) to the bucket's surface.
    pub dist_ee_to_bucket: f32,
}

/// Cosine of the angle between `a` and `b` (0 if either is zero).
fn cosine<const N: usize>(a: &nalgebra::SVector<f32, N>, b: &nalgebra::SVector<f32, N>) -> f32 {
    let n = a.norm() * b.norm();
    if n > 0.0 {
        a.dot(b) / n
    } else {
        0.0
    }
}

impl MoveBucket {
    /// ManiSkill2's dense reward (see the module docs); `eval` is this step's evaluation.
    pub fn reward(&self, scene: &TaskScene, eval: &Evaluation) -> Result<BucketReward, EnvError> {
        let world = scene.world.as_ref();
        let agent = mobile_agent(scene)?;
        let art = self.bucket();
        let tips = agent.finger_tips(world);
        let d = self.surface.mean_distance(world, art, &tips);
        let mut reward = -20.0 - d - (d + 1e-5).ln().clamp(-10.0, 0.0);
        let mid = |pair: &[Vector3<f32>]| pair.iter().sum::<Vector3<f32>>() / pair.len() as f32;
        let (m1, m2) = (mid(&tips[..2]), mid(&tips[2..]));
        let mut c = self.body_center_of_mass(world).coords;
        c.z += self.bucket_center_offset;
        let ees_oppo = 1.0 - cosine(&(m1 - c), &(m2 - c));
        let root = self.bucket_pose(world);
        let h = (root.rotation.inverse() * (m1 - m2)).z.abs();
        reward -= (h + 1e-5).ln().clamp(-10.0, 0.0) * 0.2;
        let tilt = eval.number("bucket_tilt").unwrap_or(std::f64::consts::PI) as f32;
        reward -= tilt * 0.2;
        let body = world.link_body(art, self.root_link)?;
        let v = world.body_linear_velocity(body)?;
        let w = world.body_angular_velocity(body)?.norm();
        let speed = v.norm();
        let p = root.translation.vector;
        let disp = Vector2::new(p.x - self.target_xy[0], p.y - self.target_xy[1]);
        let dist = disp.norm();
        let height = self.body_center_of_mass(world).z;
        let dist_height = (height - self.init_bucket_height - LIFT_TARGET).abs();
        let mut stage = 0.0_f32;
        if d < 0.1 {
            stage += 2.0;
            reward += ees_oppo * 2.0;
            if dist_height < 0.03 {
                stage += 2.0;
                reward -= (tilt + 1e-5).ln().clamp(-4.0, 0.0);
                if dist <= SUCCESS_DISTANCE {
                    stage += 2.0;
                    reward += (-speed * 10.0).exp() * 2.0;
                    if speed <= 0.1 && w <= 0.2 {
                        stage += 2.0;
                        if tilt <= 0.1 * std::f32::consts::PI {
                            stage += 2.0;
                        }
                    }
                } else {
                    let vel_dir = 1.0 - cosine(&v.xy(), &disp);
                    let r = (vel_dir - 1.0) * speed;
                    reward += (1.0 - (-r).exp()).max(-1.0) * 2.0 - dist * 2.0;
                }
            } else {
                reward += (1.0 - (-v.z).exp()).max(-1.0) * 2.0 - dist_height * 20.0;
            }
        }
        if tilt > 0.4 * std::f32::consts::PI {
            stage -= 2.0;
        }
        Ok(BucketReward {
            total: f64::from(reward + stage),
            stage: f64::from(stage),
            dist_ee_to_bucket: d,
        })
    }
}
