//! Path shortening: drop waypoints and replace random sub-paths by straight motions when those
//! are collision-free.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::checker::CollisionChecker;
use crate::robot::PlanningRobot;

/// Joint-space length of a path (sum of Euclidean segment lengths, rad or m).
pub fn path_length(path: &[Vec<f64>]) -> f64 {
    path.windows(2).map(|w| segment_length(&w[0], &w[1])).sum()
}

fn segment_length(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

fn lerp(a: &[f64], b: &[f64], t: f64) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x + (y - x) * t).collect()
}

/// Shortens a valid path: first greedily skips waypoints (from each waypoint, jump to the
/// farthest one reachable in a straight valid motion), then tries `iterations` random
/// shortcuts between two points on the path. Every new straight motion is checked at
/// `collision_resolution` (rad or m per joint), so a valid input stays valid. End points are
/// kept.
pub fn shortcut_path<R: PlanningRobot + ?Sized>(
    checker: &CollisionChecker<'_, R>,
    path: &[Vec<f64>],
    iterations: usize,
    collision_resolution: f64,
    rng: &mut ChaCha8Rng,
) -> Vec<Vec<f64>> {
    if path.len() <= 2 {
        return path.to_vec();
    }
    // Greedy waypoint skipping.
    let mut short = vec![path[0].clone()];
    let mut i = 0;
    while i < path.len() - 1 {
        let mut j = path.len() - 1;
        while j > i + 1 && !checker.is_motion_valid(&path[i], &path[j], collision_resolution) {
            j -= 1;
        }
        short.push(path[j].clone());
        i = j;
    }
    // Random shortcuts between points inside segments.
    for _ in 0..iterations {
        if short.len() < 3 {
            break;
        }
        let lengths: Vec<f64> = short
            .windows(2)
            .map(|w| segment_length(&w[0], &w[1]))
            .collect();
        let total: f64 = lengths.iter().sum();
        if total <= 0.0 {
            break;
        }
        let s1 = rng.random_range(0.0..total);
        let s2 = rng.random_range(0.0..total);
        let (s1, s2) = if s1 < s2 { (s1, s2) } else { (s2, s1) };
        let (i, t1) = locate(&lengths, s1);
        let (j, t2) = locate(&lengths, s2);
        if j <= i {
            continue; // same segment: already straight
        }
        let a = lerp(&short[i], &short[i + 1], t1);
        let b = lerp(&short[j], &short[j + 1], t2);
        let old = segment_length(&a, &short[i + 1])
            + lengths[i + 1..j].iter().sum::<f64>()
            + segment_length(&short[j], &b);
        if segment_length(&a, &b) >= old - 1e-9 {
            continue;
        }
        if !checker.is_motion_valid(&a, &b, collision_resolution) {
            continue;
        }
        let mut next = short[..=i].to_vec();
        next.push(a);
        next.push(b);
        next.extend_from_slice(&short[j + 1..]);
        next.dedup_by(|x, y| segment_length(x, y) < 1e-9);
        short = next;
    }
    short
}

/// Segment index and fraction within it of arc length `s`.
fn locate(lengths: &[f64], mut s: f64) -> (usize, f64) {
    for (i, &l) in lengths.iter().enumerate() {
        if s <= l || i == lengths.len() - 1 {
            return (
                i,
                if l > 0.0 {
                    (s / l).clamp(0.0, 1.0)
                } else {
                    0.0
                },
            );
        }
        s -= l;
    }
    (0, 0.0)
}
