//! Time-optimal parameterization of a joint-space path under joint velocity and acceleration
//! limits (reachability analysis, "TOPP-RA", Pham & Pham 2018), and sampling of the result at
//! a fixed control period: [`JointTrajectory`].
//!
//! The path `q(s)` is discretized on a grid of `s`; at each grid point the squared path speed
//! `x = ṡ²` and the path acceleration `u = s̈` must satisfy, for every joint `j`,
//! `q'_j² x ≤ v_j²` and `|q'_j u + q''_j x| ≤ a_j`. A backward pass computes the interval of
//! `x` from which the end can still be reached at rest; a forward pass then picks the largest
//! feasible acceleration at each step. Motions start and end at rest.

use crate::error::check_positive;
use crate::robot::JointLimits;
use crate::spline::CubicSplinePath;
use crate::PlanError;

/// A trajectory sampled every `timestep` seconds: joint targets at the control frequency.
#[derive(Debug, Clone, PartialEq)]
pub struct JointTrajectory {
    /// Time between samples (s), `1 / control frequency`.
    pub timestep: f64,
    /// Joint positions (rad or m) at times `0, timestep, 2·timestep, …`; the first is the
    /// start configuration, the last the goal.
    pub positions: Vec<Vec<f64>>,
    /// Joint velocities (rad/s or m/s) at the same times; zero at both ends.
    pub velocities: Vec<Vec<f64>>,
}

impl JointTrajectory {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Time of the last sample (s).
    pub fn duration(&self) -> f64 {
        self.positions.len().saturating_sub(1) as f64 * self.timestep
    }

    /// Appends `other` (which must start where `self` ends, same timestep); its first sample
    /// is dropped as it repeats `self`'s last.
    pub fn append(&mut self, other: &JointTrajectory) {
        let skip = usize::from(!self.positions.is_empty());
        self.positions
            .extend(other.positions.iter().skip(skip).cloned());
        self.velocities
            .extend(other.velocities.iter().skip(skip).cloned());
    }
}

/// Result of the velocity-profile computation: squared path speeds on a grid.
#[derive(Debug, Clone)]
pub struct PathProfile {
    /// Grid of path parameters `s`, increasing from 0 to the path length.
    pub grid: Vec<f64>,
    /// Squared path speed `ṡ²` at each grid point (zero at both ends).
    pub speed_squared: Vec<f64>,
    /// Time at each grid point (s).
    pub times: Vec<f64>,
}

impl PathProfile {
    /// Total duration (s).
    pub fn duration(&self) -> f64 {
        self.times.last().copied().unwrap_or(0.0)
    }

    /// Path parameter `s` and path speed `ṡ` at time `t` (clamped to `[0, duration]`).
    pub fn at_time(&self, t: f64) -> (f64, f64) {
        let t = t.clamp(0.0, self.duration());
        let n = self.grid.len();
        if n < 2 {
            return (0.0, 0.0);
        }
        let i = match self.times.binary_search_by(|x| x.total_cmp(&t)) {
            Ok(i) => i.min(n - 2),
            Err(i) => i.saturating_sub(1).min(n - 2),
        };
        let delta = self.grid[i + 1] - self.grid[i];
        let x0 = self.speed_squared[i];
        let u = (self.speed_squared[i + 1] - x0) / (2.0 * delta);
        let tau = t - self.times[i];
        let v0 = x0.max(0.0).sqrt();
        let s =
            (self.grid[i] + v0 * tau + 0.5 * u * tau * tau).clamp(self.grid[i], self.grid[i + 1]);
        (s, (v0 + u * tau).max(0.0))
    }
}

/// One linear constraint `cu·u + cx·x ≤ c` on path acceleration `u` and squared speed `x`.
#[derive(Debug, Clone, Copy)]
struct Constraint {
    cu: f64,
    cx: f64,
    c: f64,
}

const BIG: f64 = 1e12;

/// Interval of `x ≥ 0` for which some `u` satisfies all constraints (Fourier–Motzkin
/// elimination of `u`), or `None` if empty.
fn feasible_x(constraints: &[Constraint]) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (0.0_f64, BIG);
    let mut uppers = Vec::new(); // u <= alpha + beta x
    let mut lowers = Vec::new(); // u >= gamma + delta x
    for k in constraints {
        if k.cu.abs() < 1e-12 {
            bound_x(k.cx, k.c, &mut lo, &mut hi)?;
        } else if k.cu > 0.0 {
            uppers.push((k.c / k.cu, -k.cx / k.cu));
        } else {
            lowers.push((k.c / k.cu, -k.cx / k.cu));
        }
    }
    for &(alpha, beta) in &uppers {
        for &(gamma, delta) in &lowers {
            // gamma + delta x <= alpha + beta x
            bound_x(delta - beta, alpha - gamma, &mut lo, &mut hi)?;
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// Applies `a·x ≤ b` to the interval `[lo, hi]`; `None` if it cannot hold.
fn bound_x(a: f64, b: f64, lo: &mut f64, hi: &mut f64) -> Option<()> {
    if a.abs() < 1e-12 {
        return (b >= -1e-9).then_some(());
    }
    if a > 0.0 {
        *hi = hi.min(b / a);
    } else {
        *lo = lo.max(b / a);
    }
    Some(())
}

/// Interval of `u` allowed at fixed `x`.
fn feasible_u(constraints: &[Constraint], x: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (-BIG, BIG);
    for k in constraints {
        if k.cu.abs() < 1e-12 {
            continue;
        }
        let bound = (k.c - k.cx * x) / k.cu;
        if k.cu > 0.0 {
            hi = hi.min(bound);
        } else {
            lo = lo.max(bound);
        }
    }
    (lo, hi)
}

/// Computes the time-optimal rest-to-rest velocity profile of `path` under `limits`
/// (each joint's `max_velocity` and `max_acceleration`, already scaled as wanted), on a grid of
/// `grid_points` (≥ 2) points.
///
/// # Errors
/// [`PlanError::InvalidParameter`] for non-positive limits or a limit count different from the
/// path's joint count; [`PlanError::TimeParameterization`] if no feasible profile exists.
pub fn compute_profile(
    path: &CubicSplinePath,
    limits: &[JointLimits],
    grid_points: usize,
) -> Result<PathProfile, PlanError> {
    let dof = path.dof();
    if limits.len() != dof {
        return Err(PlanError::WrongDof {
            what: "joint limits",
            got: limits.len(),
            expected: dof,
        });
    }
    for l in limits {
        check_positive("max_velocity", l.max_velocity)?;
        check_positive("max_acceleration", l.max_acceleration)?;
    }
    let length = path.length();
    if length <= 0.0 {
        return Ok(PathProfile {
            grid: vec![0.0],
            speed_squared: vec![0.0],
            times: vec![0.0],
        });
    }
    let n = grid_points.max(2);
    let grid: Vec<f64> = (0..n).map(|i| length * i as f64 / (n - 1) as f64).collect();
    let (mut q, mut dq, mut ddq) = (vec![0.0; dof], vec![0.0; dof], vec![0.0; dof]);
    let stage_constraints: Vec<Vec<Constraint>> = grid
        .iter()
        .map(|&s| {
            path.eval(s, &mut q, &mut dq, &mut ddq);
            let mut cs = Vec::with_capacity(3 * dof);
            for j in 0..dof {
                let (v, a) = (limits[j].max_velocity, limits[j].max_acceleration);
                cs.push(Constraint {
                    cu: 0.0,
                    cx: dq[j] * dq[j],
                    c: v * v,
                });
                cs.push(Constraint {
                    cu: dq[j],
                    cx: ddq[j],
                    c: a,
                });
                cs.push(Constraint {
                    cu: -dq[j],
                    cx: -ddq[j],
                    c: a,
                });
            }
            cs
        })
        .collect();

    // Backward pass: controllable sets K_i.
    let mut controllable = vec![(0.0, 0.0); n];
    for i in (0..n - 1).rev() {
        let delta = grid[i + 1] - grid[i];
        let (next_lo, next_hi) = controllable[i + 1];
        let mut cs = stage_constraints[i].clone();
        // next_lo <= x + 2 delta u <= next_hi
        cs.push(Constraint {
            cu: 2.0 * delta,
            cx: 1.0,
            c: next_hi,
        });
        cs.push(Constraint {
            cu: -2.0 * delta,
            cx: -1.0,
            c: -next_lo,
        });
        controllable[i] = feasible_x(&cs).ok_or_else(|| {
            PlanError::TimeParameterization(format!(
                "no feasible path speed at s = {:.4} of {length:.4}",
                grid[i]
            ))
        })?;
    }
    if controllable[0].0 > 1e-9 {
        return Err(PlanError::TimeParameterization(
            "the path cannot start at rest under these limits".into(),
        ));
    }

    // Forward pass: greedy largest acceleration.
    let mut speed_squared = vec![0.0; n];
    for i in 0..n - 1 {
        let delta = grid[i + 1] - grid[i];
        let x = speed_squared[i];
        let (next_lo, next_hi) = controllable[i + 1];
        let (mut lo, mut hi) = feasible_u(&stage_constraints[i], x);
        lo = lo.max((next_lo - x) / (2.0 * delta));
        hi = hi.min((next_hi - x) / (2.0 * delta));
        // Rounding can make the interval empty by a hair; then keep the end reachable.
        let u = if hi >= lo { hi } else { lo };
        speed_squared[i + 1] = (x + 2.0 * delta * u).clamp(0.0, next_hi.max(0.0));
    }
    speed_squared[n - 1] = 0.0;

    let mut times = vec![0.0; n];
    for i in 0..n - 1 {
        let delta = grid[i + 1] - grid[i];
        let speed_sum = speed_squared[i].sqrt() + speed_squared[i + 1].sqrt();
        if speed_sum <= 0.0 {
            return Err(PlanError::TimeParameterization(format!(
                "path speed is zero inside the path at s = {:.4}",
                grid[i]
            )));
        }
        times[i + 1] = times[i] + 2.0 * delta / speed_sum;
    }
    Ok(PathProfile {
        grid,
        speed_squared,
        times,
    })
}

/// Time-parameterizes `path` under `limits` and samples it every `timestep` seconds.
///
/// The grid has one point per `grid_resolution` of path parameter (rad or m), at least 50.
/// The last sample is the path's end; it is reached at the first multiple of `timestep` at or
/// after the optimal duration.
///
/// ```
/// use ms2_plan::{parameterize, CubicSplinePath, JointLimits};
/// let path = CubicSplinePath::new(&[vec![0.0], vec![1.0]]).unwrap();
/// let limits = [JointLimits { lower: -2.0, upper: 2.0, max_velocity: 1.0, max_acceleration: 2.0 }];
/// let trajectory = parameterize(&path, &limits, 0.05, 0.005).unwrap();
/// // Trapezoid: 1 rad at up to 1 rad/s with 2 rad/s² ramps takes 1.5 s.
/// assert!((trajectory.duration() - 1.5).abs() <= 0.05);
/// assert_eq!(trajectory.positions.last().unwrap(), &vec![1.0]);
/// ```
///
/// # Errors
/// As [`compute_profile`]; [`PlanError::InvalidParameter`] for a non-positive `timestep` or
/// `grid_resolution`.
pub fn parameterize(
    path: &CubicSplinePath,
    limits: &[JointLimits],
    timestep: f64,
    grid_resolution: f64,
) -> Result<JointTrajectory, PlanError> {
    check_positive("timestep", timestep)?;
    check_positive("grid_resolution", grid_resolution)?;
    let grid_points = ((path.length() / grid_resolution).ceil() as usize + 1).clamp(50, 20_000);
    let profile = compute_profile(path, limits, grid_points)?;
    Ok(sample(path, &profile, timestep))
}

/// Samples a profiled path every `timestep` seconds.
pub fn sample(path: &CubicSplinePath, profile: &PathProfile, timestep: f64) -> JointTrajectory {
    let dof = path.dof();
    let steps = (profile.duration() / timestep - 1e-9).ceil().max(0.0) as usize;
    let (mut q, mut dq, mut ddq) = (vec![0.0; dof], vec![0.0; dof], vec![0.0; dof]);
    let mut positions = Vec::with_capacity(steps + 1);
    let mut velocities = Vec::with_capacity(steps + 1);
    for k in 0..=steps {
        let (s, speed) = if k == steps {
            (path.length(), 0.0)
        } else {
            profile.at_time(k as f64 * timestep)
        };
        path.eval(s, &mut q, &mut dq, &mut ddq);
        positions.push(q.clone());
        velocities.push(dq.iter().map(|d| d * speed).collect());
    }
    JointTrajectory {
        timestep,
        positions,
        velocities,
    }
}
