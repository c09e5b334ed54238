//! A smooth joint-space curve through waypoints: [`CubicSplinePath`].

use crate::PlanError;

/// Natural cubic spline through joint-space waypoints, parameterized by cumulative chord length
/// `s` (rad or m: the Euclidean joint-space distance between consecutive waypoints).
///
/// Passes through every waypoint; between waypoints it may bulge away from the straight
/// segments, so a collision-checked polyline must be re-checked along the spline. Two waypoints
/// give a straight segment.
#[derive(Debug, Clone)]
pub struct CubicSplinePath {
    /// Knot parameters, strictly increasing, `knots[0] = 0`.
    knots: Vec<f64>,
    /// Waypoints, one per knot.
    points: Vec<Vec<f64>>,
    /// Second derivatives d²q/ds² at the knots.
    second: Vec<Vec<f64>>,
}

impl CubicSplinePath {
    /// Builds the spline through `waypoints`; consecutive duplicates are merged.
    ///
    /// # Errors
    /// [`PlanError::InvalidParameter`] if fewer than one waypoint remains or waypoints differ
    /// in length.
    pub fn new(waypoints: &[Vec<f64>]) -> Result<Self, PlanError> {
        let dof = waypoints.first().map_or(0, Vec::len);
        if waypoints.is_empty() || waypoints.iter().any(|w| w.len() != dof) {
            return Err(PlanError::InvalidParameter {
                name: "waypoints",
                value: waypoints.len() as f64,
                expected: "at least one waypoint, all of the same length",
            });
        }
        let mut points: Vec<Vec<f64>> = vec![waypoints[0].clone()];
        let mut knots = vec![0.0];
        for w in &waypoints[1..] {
            let d = distance(points.last().unwrap_or(w), w);
            if d > 1e-12 {
                knots.push(knots.last().copied().unwrap_or(0.0) + d);
                points.push(w.clone());
            }
        }
        let second = natural_second_derivatives(&knots, &points, dof);
        Ok(Self {
            knots,
            points,
            second,
        })
    }

    /// Parameter length (chord length of the waypoint polyline).
    pub fn length(&self) -> f64 {
        self.knots.last().copied().unwrap_or(0.0)
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.points[0].len()
    }

    /// Evaluates position `q`, first derivative `dq = dq/ds` and second derivative
    /// `ddq = d²q/ds²` at parameter `s` (clamped to `[0, length]`).
    pub fn eval(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64]) {
        let n = self.points.len();
        if n == 1 {
            q.copy_from_slice(&self.points[0]);
            dq.fill(0.0);
            ddq.fill(0.0);
            return;
        }
        let s = s.clamp(0.0, self.length());
        // Segment k with knots[k] <= s <= knots[k+1].
        let k = match self.knots.binary_search_by(|x| x.total_cmp(&s)) {
            Ok(i) => i.min(n - 2),
            Err(i) => i.saturating_sub(1).min(n - 2),
        };
        let h = self.knots[k + 1] - self.knots[k];
        let a = (self.knots[k + 1] - s) / h;
        let b = (s - self.knots[k]) / h;
        for j in 0..self.dof() {
            let (y0, y1) = (self.points[k][j], self.points[k + 1][j]);
            let (m0, m1) = (self.second[k][j], self.second[k + 1][j]);
            q[j] = a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
            dq[j] = (y1 - y0) / h - (3.0 * a * a - 1.0) * h / 6.0 * m0
                + (3.0 * b * b - 1.0) * h / 6.0 * m1;
            ddq[j] = a * m0 + b * m1;
        }
    }

    /// Position at parameter `s`.
    pub fn position(&self, s: f64) -> Vec<f64> {
        let n = self.dof();
        let (mut q, mut dq, mut ddq) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        self.eval(s, &mut q, &mut dq, &mut ddq);
        q
    }
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Second derivatives of the natural cubic spline (zero at both ends), per joint, by the
/// tridiagonal (Thomas) algorithm.
fn natural_second_derivatives(knots: &[f64], points: &[Vec<f64>], dof: usize) -> Vec<Vec<f64>> {
    let n = knots.len();
    let mut second = vec![vec![0.0; dof]; n];
    if n < 3 {
        return second;
    }
    let h: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
    for j in 0..dof {
        // Unknowns m_1..m_{n-2}; system rows i = 1..n-2.
        let m = n - 2;
        let mut diag = vec![0.0; m];
        let mut upper = vec![0.0; m];
        let mut rhs = vec![0.0; m];
        for r in 0..m {
            let i = r + 1;
            diag[r] = (h[i - 1] + h[i]) / 3.0;
            upper[r] = h[i] / 6.0;
            rhs[r] = (points[i + 1][j] - points[i][j]) / h[i]
                - (points[i][j] - points[i - 1][j]) / h[i - 1];
        }
        // Forward elimination (lower diagonal entry of row r is h[r] / 6).
        for r in 1..m {
            let lower = h[r] / 6.0;
            let w = lower / diag[r - 1];
            diag[r] -= w * upper[r - 1];
            rhs[r] -= w * rhs[r - 1];
        }
        let mut sol = vec![0.0; m];
        sol[m - 1] = rhs[m - 1] / diag[m - 1];
        for r in (0..m - 1).rev() {
            sol[r] = (rhs[r] - upper[r] * sol[r + 1]) / diag[r];
        }
        for r in 0..m {
            second[r + 1][j] = sol[r];
        }
    }
    second
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn spline_interpolates_waypoints_and_derivatives_match_finite_differences() {
        let waypoints = vec![
            vec![0.0, 0.0],
            vec![1.0, 0.5],
            vec![1.5, 2.0],
            vec![3.0, 2.0],
        ];
        let spline = CubicSplinePath::new(&waypoints).unwrap();
        for (k, w) in waypoints.iter().enumerate() {
            let q = spline.position(spline.knots[k]);
            assert_relative_eq!(q[0], w[0], epsilon = 1e-12);
            assert_relative_eq!(q[1], w[1], epsilon = 1e-12);
        }
        let (mut q, mut dq, mut ddq) = (vec![0.0; 2], vec![0.0; 2], vec![0.0; 2]);
        let s = 0.37 * spline.length();
        spline.eval(s, &mut q, &mut dq, &mut ddq);
        let eps = 1e-6;
        let (qp, qm) = (spline.position(s + eps), spline.position(s - eps));
        for j in 0..2 {
            assert_relative_eq!(dq[j], (qp[j] - qm[j]) / (2.0 * eps), epsilon = 1e-6);
            assert_relative_eq!(
                ddq[j],
                (qp[j] - 2.0 * q[j] + qm[j]) / (eps * eps),
                epsilon = 1e-3
            );
        }
    }

    #[test]
    fn two_waypoints_give_a_straight_line() {
        let spline = CubicSplinePath::new(&[vec![0.0, 1.0], vec![2.0, 1.0]]).unwrap();
        assert_relative_eq!(spline.position(1.0)[0], 1.0, epsilon = 1e-12);
        assert_relative_eq!(spline.position(1.0)[1], 1.0, epsilon = 1e-12);
    }
}
