//! Joint-space RRT-Connect (Kuffner & LaValle, 2000) with a seeded random number generator.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::checker::CollisionChecker;
use crate::error::{check_configuration, check_positive};
use crate::robot::PlanningRobot;
use crate::PlanError;

/// Settings of [`plan_rrt_connect`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RrtConfig {
    /// Largest number of sampling iterations before giving up.
    pub max_iterations: usize,
    /// Largest joint-space step (Euclidean norm over joints, rad or m) of one tree extension.
    pub step_size: f64,
    /// Largest per-joint step (rad or m) between configurations checked along a motion.
    pub collision_resolution: f64,
}

impl Default for RrtConfig {
    fn default() -> Self {
        Self {
            max_iterations: 20_000,
            step_size: 0.2,
            collision_resolution: 0.01,
        }
    }
}

/// A tree of configurations rooted at one end of the query.
struct Tree {
    nodes: Vec<Vec<f64>>,
    parents: Vec<usize>,
}

impl Tree {
    fn new(root: Vec<f64>) -> Self {
        Self {
            nodes: vec![root],
            parents: vec![0],
        }
    }

    fn nearest(&self, q: &[f64]) -> usize {
        let mut best = (0, f64::INFINITY);
        for (i, n) in self.nodes.iter().enumerate() {
            let d = squared_distance(n, q);
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0
    }

    fn add(&mut self, q: Vec<f64>, parent: usize) -> usize {
        self.nodes.push(q);
        self.parents.push(parent);
        self.nodes.len() - 1
    }

    /// Configurations from the root to node `i`.
    fn path_to(&self, mut i: usize) -> Vec<Vec<f64>> {
        let mut path = vec![self.nodes[i].clone()];
        while i != 0 {
            i = self.parents[i];
            path.push(self.nodes[i].clone());
        }
        path.reverse();
        path
    }
}

enum Extension {
    Reached(usize),
    Advanced(usize),
    Trapped,
}

fn squared_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Validates that `q` is a usable, collision-free configuration for a query.
pub(crate) fn check_query_configuration<R: PlanningRobot + ?Sized>(
    checker: &CollisionChecker<'_, R>,
    what: &'static str,
    q: &[f64],
) -> Result<(), PlanError> {
    let robot = checker.robot();
    check_configuration(what, q, robot.dof())?;
    for (joint, (&value, limits)) in q.iter().zip(robot.joint_limits()).enumerate() {
        if !limits.contains(value) {
            return Err(PlanError::OutOfLimits {
                what,
                joint,
                value,
                lower: limits.lower,
                upper: limits.upper,
            });
        }
    }
    if let Some(contact) = checker.first_contact(q)? {
        return Err(PlanError::InCollision {
            what,
            collision: contact.to_string(),
        });
    }
    Ok(())
}

/// Finds a collision-free joint-space path from `start` to `goal` with RRT-Connect.
///
/// Returns the waypoints (first = `start`, last = `goal`); consecutive waypoints are joined by
/// straight joint-space motions checked at `config.collision_resolution`. The result depends
/// only on the inputs and the state of `rng` (seed it for reproducible plans).
///
/// # Errors
/// Malformed, out-of-limit or colliding start/goal ([`PlanError::WrongDof`],
/// [`PlanError::OutOfLimits`], [`PlanError::InCollision`], ...), bad settings
/// ([`PlanError::InvalidParameter`]), or [`PlanError::NoPathFound`].
pub fn plan_rrt_connect<R: PlanningRobot + ?Sized>(
    checker: &CollisionChecker<'_, R>,
    start: &[f64],
    goal: &[f64],
    config: &RrtConfig,
    rng: &mut ChaCha8Rng,
) -> Result<Vec<Vec<f64>>, PlanError> {
    check_positive("step_size", config.step_size)?;
    check_positive("collision_resolution", config.collision_resolution)?;
    check_query_configuration(checker, "start configuration", start)?;
    check_query_configuration(checker, "goal configuration", goal)?;
    let resolution = config.collision_resolution;
    if checker.is_motion_valid(start, goal, resolution) {
        return Ok(vec![start.to_vec(), goal.to_vec()]);
    }
    let limits = checker.robot().joint_limits();
    let mut from_start = Tree::new(start.to_vec());
    let mut from_goal = Tree::new(goal.to_vec());
    // `true` while `a` is the start tree.
    let mut a_is_start = true;
    for _ in 0..config.max_iterations {
        let sample: Vec<f64> = limits
            .iter()
            .map(|l| rng.random_range(l.lower..=l.upper))
            .collect();
        let (a, b) = if a_is_start {
            (&mut from_start, &mut from_goal)
        } else {
            (&mut from_goal, &mut from_start)
        };
        let new_node = match extend(checker, a, &sample, config) {
            Extension::Trapped => None,
            Extension::Reached(i) | Extension::Advanced(i) => Some(i),
        };
        if let Some(new_a) = new_node {
            let target = a.nodes[new_a].clone();
            if let Some(new_b) = connect(checker, b, &target, config) {
                let (start_node, goal_node) = if a_is_start {
                    (new_a, new_b)
                } else {
                    (new_b, new_a)
                };
                let mut path = from_start.path_to(start_node);
                let mut tail = from_goal.path_to(goal_node);
                tail.reverse();
                // Both trees end at the same configuration: keep it once.
                path.pop();
                path.extend(tail);
                return Ok(path);
            }
        }
        a_is_start = !a_is_start;
    }
    Err(PlanError::NoPathFound {
        iterations: config.max_iterations,
    })
}

fn extend<R: PlanningRobot + ?Sized>(
    checker: &CollisionChecker<'_, R>,
    tree: &mut Tree,
    target: &[f64],
    config: &RrtConfig,
) -> Extension {
    let near = tree.nearest(target);
    let q_near = &tree.nodes[near];
    let distance = squared_distance(q_near, target).sqrt();
    let (q_new, reached) = if distance <= config.step_size {
        (target.to_vec(), true)
    } else {
        let t = config.step_size / distance;
        (
            q_near
                .iter()
                .zip(target)
                .map(|(a, b)| a + (b - a) * t)
                .collect(),
            false,
        )
    };
    if !checker.is_motion_valid(q_near, &q_new, config.collision_resolution) {
        return Extension::Trapped;
    }
    let i = tree.add(q_new, near);
    if reached {
        Extension::Reached(i)
    } else {
        Extension::Advanced(i)
    }
}

/// Extends `tree` towards `target` until it reaches it (returns the node) or gets stuck.
fn connect<R: PlanningRobot + ?Sized>(
    checker: &CollisionChecker<'_, R>,
    tree: &mut Tree,
    target: &[f64],
    config: &RrtConfig,
) -> Option<usize> {
    loop {
        match extend(checker, tree, target, config) {
            Extension::Reached(i) => return Some(i),
            Extension::Advanced(_) => continue,
            Extension::Trapped => return None,
        }
    }
}
