//! Pinch-v0's pinch sequences: what a level's pinches are ([`PinchMove`], sampled from a
//! level seed by [`sample_moves`]) and the one TCP/finger schedule ([`PinchPlan`]) that both
//! the level generator (kinematic fingers, `pinch_scene`) and the scripted policy (the robot,
//! closed loop, `pinch_policy`) follow.
//!
//! Frames and units: world frame (z up, the plasticine block centred on the origin on the
//! ground), metres, radians; times in control steps (20 Hz).

use glam::{Vec2, Vec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Half extents (m) of the plasticine block along x and y (a 6 × 6 cm footprint).
pub const BLOCK_HALF_XY: f32 = 0.03;
/// Height (m) of the plasticine block.
pub const BLOCK_HEIGHT: f32 = 0.04;
/// Distance (m) from the TCP down to the bottom of the fingertip pads (the Panda's URDF:
/// finger joint 5.84 cm + pad centre 4.4 cm + half pad 1 cm − TCP 10.34 cm along the hand's z).
pub const TIP_BELOW_TCP: f32 = 0.009;
/// Height (m) of the fingertips' bottom while travelling between pinches: 2.5 cm above the
/// block.
pub const TRAVEL_TIP_Z: f32 = BLOCK_HEIGHT + 0.025;
/// Finger opening (m per finger) while travelling: the Panda's widest (8 cm between the pads).
pub const OPEN_FINGER: f32 = 0.04;
/// Range (m) of a pinch centre's offset from the block's centre, per axis.
pub const CENTRE_RANGE: f32 = 0.015;
/// Range (m) of the fingertips' bottom height during a pinch.
pub const TIP_Z_RANGE: (f32, f32) = (0.008, 0.02);
/// Range (m) of the gap between the pads at the end of a pinch.
pub const GAP_RANGE: (f32, f32) = (0.014, 0.03);
/// Range of the number of pinches of a level.
pub const PINCH_COUNT_RANGE: (usize, usize) = (1, 3);
/// Control steps of the start (the robot settles before moving).
pub const START_STEPS: u32 = 4;
/// Control steps of each phase of a pinch: travel above the pinch, wait there, descend,
/// close, hold, open, rise. The wait lets the arm settle on the pinch whatever path brought
/// it there (the replay starts elsewhere than the level's generator); the hold and the open
/// leave the Panda's finger drives time to catch up with the schedule (they lag it by about
/// 0.3 s): a hand that rises while its fingers still squeeze lifts a lump of clay off the
/// block.
pub const PHASE_STEPS: [u32; 7] = [16, 6, 10, 16, 8, 12, 8];

/// One pinch: where (centre), which way (yaw of the fingers' closing axis), how deep (the
/// pads' bottom height) and how far the fingers close (the gap between the pads).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PinchMove {
    /// Pinch centre (m, world xy).
    pub centre: [f32; 2],
    /// Yaw (rad) of the TCP about world z (a top-down TCP; the fingers close along the TCP's
    /// y axis).
    pub yaw: f32,
    /// Height (m, world z) of the bottom of the pads at the pinch.
    pub tip_z: f32,
    /// Gap (m) between the pads' inner faces at the end of the close.
    pub gap: f32,
}

impl PinchMove {
    /// Whether every field is finite and within the ranges a level may hold (the pads stay
    /// above the ground, the gap within the gripper's travel).
    pub fn is_valid(&self) -> bool {
        let finite = self.centre.iter().all(|c| c.is_finite())
            && self.yaw.is_finite()
            && self.tip_z.is_finite()
            && self.gap.is_finite();
        finite
            && self.centre.iter().all(|c| c.abs() <= 0.1)
            && (0.0..=0.2).contains(&self.tip_z)
            && (0.0..=2.0 * OPEN_FINGER).contains(&self.gap)
    }
}

/// The pinches of level `seed`: 1-3 pinches, centres within ±1.5 cm of the block's centre per
/// axis, yaw U(−π/2, π/2), pads' bottom U(0.8, 2) cm above the ground, final gap U(1.4, 3) cm.
pub fn sample_moves(seed: u64) -> Vec<PinchMove> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let count = rng.random_range(PINCH_COUNT_RANGE.0..=PINCH_COUNT_RANGE.1);
    (0..count)
        .map(|_| PinchMove {
            centre: [
                rng.random_range(-CENTRE_RANGE..CENTRE_RANGE),
                rng.random_range(-CENTRE_RANGE..CENTRE_RANGE),
            ],
            yaw: rng.random_range(-std::f32::consts::FRAC_PI_2..std::f32::consts::FRAC_PI_2),
            tip_z: rng.random_range(TIP_Z_RANGE.0..TIP_Z_RANGE.1),
            gap: rng.random_range(GAP_RANGE.0..GAP_RANGE.1),
        })
        .collect()
}

/// A scheduled TCP pose and finger opening.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Waypoint {
    /// Control step at which it is reached.
    pub step: u32,
    /// TCP position (m, world).
    pub tcp: Vec3,
    /// TCP yaw (rad) about world z (top-down TCP).
    pub yaw: f32,
    /// Finger opening (m per finger).
    pub finger: f32,
}

/// The schedule of a pinch sequence: waypoints, linearly interpolated between (see the
/// [module docs](self)).
#[derive(Clone, Debug, PartialEq)]
pub struct PinchPlan {
    waypoints: Vec<Waypoint>,
}

impl PinchPlan {
    /// The schedule of `moves` from a TCP at `start_tcp` (m) with yaw `start_yaw` (rad): for
    /// each pinch, travel above it at [`TRAVEL_TIP_Z`] with the fingers open, descend to its
    /// `tip_z`, close to its `gap`, hold, open, rise; then stay.
    pub fn new(moves: &[PinchMove], start_tcp: Vec3, start_yaw: f32) -> Self {
        let mut waypoints = vec![Waypoint {
            step: 0,
            tcp: start_tcp,
            yaw: start_yaw,
            finger: OPEN_FINGER,
        }];
        let mut step = START_STEPS;
        waypoints.push(Waypoint {
            step,
            ..waypoints[0]
        });
        for m in moves {
            let above = Vec2::from(m.centre).extend(TRAVEL_TIP_Z + TIP_BELOW_TCP);
            let down = Vec2::from(m.centre).extend(m.tip_z + TIP_BELOW_TCP);
            let half_gap = 0.5 * m.gap;
            let phases = [
                (above, OPEN_FINGER),
                (above, OPEN_FINGER),
                (down, OPEN_FINGER),
                (down, half_gap),
                (down, half_gap),
                (down, OPEN_FINGER),
                (above, OPEN_FINGER),
            ];
            for ((tcp, finger), len) in phases.into_iter().zip(PHASE_STEPS) {
                step += len;
                waypoints.push(Waypoint {
                    step,
                    tcp,
                    yaw: m.yaw,
                    finger,
                });
            }
        }
        Self { waypoints }
    }

    /// Control steps until the last waypoint is reached.
    pub fn duration(&self) -> u32 {
        self.waypoints.last().map_or(0, |w| w.step)
    }

    /// The waypoints, in time order.
    pub fn waypoints(&self) -> &[Waypoint] {
        &self.waypoints
    }

    /// The commanded TCP position (m), yaw (rad) and finger opening (m) at time `t` (control
    /// steps, fractional), linearly interpolated; the last waypoint after the end.
    pub fn at(&self, t: f32) -> (Vec3, f32, f32) {
        for pair in self.waypoints.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            if t <= b.step as f32 {
                let span = (b.step - a.step).max(1) as f32;
                let s = ((t - a.step as f32) / span).clamp(0.0, 1.0);
                return (
                    a.tcp.lerp(b.tcp, s),
                    a.yaw + (b.yaw - a.yaw) * s,
                    a.finger + (b.finger - a.finger) * s,
                );
            }
        }
        let last = self.waypoints.last().copied().unwrap_or(Waypoint {
            step: 0,
            tcp: Vec3::ZERO,
            yaw: 0.0,
            finger: OPEN_FINGER,
        });
        (last.tcp, last.yaw, last.finger)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_draw_valid_seeded_pinches_that_fit_an_episode() {
        let mut counts = [0; 4];
        for seed in 0..200 {
            let moves = sample_moves(seed);
            assert_eq!(moves, sample_moves(seed), "seed {seed} repeats");
            assert!(moves.iter().all(PinchMove::is_valid), "{moves:?}");
            counts[moves.len()] += 1;
            let plan = PinchPlan::new(&moves, Vec3::new(0.0, 0.0, 0.2), 0.0);
            assert!(plan.duration() < 300, "seed {seed}: {}", plan.duration());
        }
        assert!(
            counts[1] > 0 && counts[2] > 0 && counts[3] > 0,
            "{counts:?}"
        );
        assert_ne!(sample_moves(0), sample_moves(1));
    }

    #[test]
    fn the_schedule_interpolates_and_closes_to_the_gap_at_depth() {
        let m = PinchMove {
            centre: [0.01, -0.01],
            yaw: 0.5,
            tip_z: 0.01,
            gap: 0.02,
        };
        let plan = PinchPlan::new(&[m], Vec3::new(0.0, 0.0, 0.2), 0.0);
        let close_end = START_STEPS + PHASE_STEPS[..4].iter().sum::<u32>();
        let close_end = close_end as f32;
        let (tcp, yaw, finger) = plan.at(close_end);
        assert!((tcp.z - (0.01 + TIP_BELOW_TCP)).abs() < 1e-6 && (finger - 0.01).abs() < 1e-6);
        assert!((yaw - 0.5).abs() < 1e-6 && (tcp.x - 0.01).abs() < 1e-6);
        let (_, _, half) = plan.at(close_end - 8.0);
        assert!((half - 0.025).abs() < 1e-6, "{half}");
        assert_eq!(plan.at(1e6).0.z, TRAVEL_TIP_Z + TIP_BELOW_TCP);
    }
}
