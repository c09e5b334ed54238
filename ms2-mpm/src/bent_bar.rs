//! A straight bar of square cross-section (a rope, a noodle) bent along a planar centreline:
//! particle positions together with the deformation gradients that map the straight rest bar
//! onto the bent one, so an elastic bar starts bent but remembers that it is straight.
//!
//! The centreline lies in the vertical plane spanned by a horizontal unit vector `along` and
//! world +z. Its heading `θ` (rad) is measured in that plane from `along` towards +z: the
//! tangent is `t = cos θ·along + sin θ·z`, the in-plane normal `n = −sin θ·along + cos θ·z`,
//! and the out-of-plane side axis is `z × along`. The rest bar lies along `along` with its
//! cross-section spanned by the side axis and +z.
//!
//! A rest point at arc length `s`, side offset `w` and normal offset `v` goes to
//! `c(s) + k(s)·w·side + v·n(s)`, where `k(s)` ([`BentBar::width_scale`]) squeezes the side
//! axis locally (a pinch between two fingers). Its deformation gradient is
//! `(1 − κ·v)·t·alongᵀ + k·side·sideᵀ + n·zᵀ` with `κ = dθ/ds` the centreline's curvature.

use glam::{Mat3, Vec3};

/// One piece of a planar centreline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CurvePiece {
    /// A straight run of `length` (m).
    Straight {
        /// Length (m).
        length: f32,
    },
    /// A circular arc of `radius` (m) turning the heading by `angle` (rad; positive turns
    /// from `along` towards +z).
    Arc {
        /// Radius (m, > 0).
        radius: f32,
        /// Turn (rad).
        angle: f32,
    },
}

impl CurvePiece {
    /// Arc length (m).
    pub fn length(&self) -> f32 {
        match *self {
            CurvePiece::Straight { length } => length.max(0.0),
            CurvePiece::Arc { radius, angle } => radius * angle.abs(),
        }
    }

    /// Curvature `dθ/ds` (1/m).
    fn curvature(&self) -> f32 {
        match *self {
            CurvePiece::Straight { .. } => 0.0,
            CurvePiece::Arc { radius, angle } => angle.signum() / radius,
        }
    }
}

/// A bar bent along a planar centreline (see the [module docs](self)).
#[derive(Clone, Debug, PartialEq)]
pub struct BentBar {
    /// Start of the centreline (m, world).
    pub start: Vec3,
    /// Horizontal unit vector of the centreline's plane (and of the rest bar's axis).
    pub along: Vec3,
    /// Heading (rad) at the start.
    pub heading: f32,
    /// The centreline, from the start.
    pub pieces: Vec<CurvePiece>,
    /// Half the cross-section's edge (m).
    pub half_width: f32,
    /// Squeeze of the side axis at arc length `s` (1 = none), `(s_from, s_to, k)` with
    /// `0 < k <= 1` over `[s_from, s_to]` (m).
    pub width_scale: Option<(f32, f32, f32)>,
}

/// Particles of a [`BentBar`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BarParticles {
    /// Positions (m, world).
    pub positions: Vec<Vec3>,
    /// Deformation gradients from the straight rest bar.
    pub gradients: Vec<Mat3>,
    /// Rest arc length (m) of each particle along the bar.
    pub arc_length: Vec<f32>,
    /// Whether each particle lies on the bar's axis row nearest the centreline.
    pub on_axis: Vec<bool>,
}

impl BentBar {
    /// Total length (m).
    pub fn length(&self) -> f32 {
        self.pieces.iter().map(CurvePiece::length).sum()
    }

    /// The out-of-plane side axis `z × along`.
    pub fn side(&self) -> Vec3 {
        Vec3::Z.cross(self.along)
    }

    /// Centreline point (m, world), heading (rad) and curvature (1/m) at arc length `s`
    /// (clamped to the bar).
    pub fn centreline(&self, s: f32) -> (Vec3, f32, f32) {
        let (a, z) = (self.along, Vec3::Z);
        let dir = |h: f32| h.cos() * a + h.sin() * z;
        let (mut p, mut h, mut rest) = (self.start, self.heading, s.max(0.0));
        let mut kappa = 0.0;
        for piece in &self.pieces {
            let len = piece.length();
            let ds = rest.min(len);
            kappa = piece.curvature();
            match *piece {
                CurvePiece::Straight { .. } => p += dir(h) * ds,
                CurvePiece::Arc { radius, angle } => {
                    let turn = angle.signum() * ds / radius;
                    // Chord of the arc: along the mean heading, 2·r·sin(turn/2) long.
                    p += dir(h + 0.5 * turn) * (2.0 * radius * (0.5 * turn).sin().abs());
                    h += turn;
                }
            }
            rest -= ds;
            if rest <= 0.0 {
                break;
            }
        }
        (p, h, kappa)
    }

    /// Lattice particles of `spacing` (m) filling the bar: `⌊length / spacing⌋` rows along it
    /// and `⌊2·half_width / spacing⌋` across each axis, centred; rows run from the start, and
    /// within a row the side offset varies slowest.
    pub fn sample(&self, spacing: f32) -> BarParticles {
        let mut out = BarParticles::default();
        if !(spacing.is_finite() && spacing > 0.0) {
            return out;
        }
        // A few parts per million of slack: 0.02 / 0.004 is 4.9999995 in f32.
        let count = |extent: f32| (extent / spacing + 1e-4).floor() as usize;
        let rows = count(self.length());
        let across = count(2.0 * self.half_width).max(1);
        let offset = |i: usize| (i as f32 - 0.5 * (across as f32 - 1.0)) * spacing;
        let mid = across / 2;
        let side = self.side();
        let (a, z) = (self.along, Vec3::Z);
        for r in 0..rows {
            let s = (r as f32 + 0.5) * spacing;
            let (c, h, kappa) = self.centreline(s);
            let t = h.cos() * a + h.sin() * z;
            let n = -h.sin() * a + h.cos() * z;
            let k = match self.width_scale {
                Some((from, to, k)) if (from..=to).contains(&s) => k,
                _ => 1.0,
            };
            for i in 0..across {
                for j in 0..across {
                    let (w, v) = (offset(i), offset(j));
                    out.positions.push(c + side * (k * w) + n * v);
                    let f = outer(t * (1.0 - kappa * v), a) + outer(side * k, side) + outer(n, z);
                    out.gradients.push(f);
                    out.arc_length.push(s);
                    out.on_axis.push(i == mid && j == mid);
                }
            }
        }
        out
    }
}

/// `u·vᵀ`.
fn outer(u: Vec3, v: Vec3) -> Mat3 {
    Mat3::from_cols(u * v.x, u * v.y, u * v.z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::FRAC_PI_2;

    fn hook() -> BentBar {
        BentBar {
            start: Vec3::new(0.1, 0.2, 0.3),
            along: Vec3::X,
            heading: 0.0,
            pieces: vec![
                CurvePiece::Straight { length: 0.1 },
                CurvePiece::Arc {
                    radius: 0.05,
                    angle: -FRAC_PI_2,
                },
                CurvePiece::Straight { length: 0.1 },
            ],
            half_width: 0.01,
            width_scale: None,
        }
    }

    #[test]
    fn centreline_follows_the_pieces() {
        let bar = hook();
        let len = bar.length();
        assert!((len - (0.2 + 0.05 * FRAC_PI_2)).abs() < 1e-6);
        let (end, h, _) = bar.centreline(len);
        // 0.1 along x, a quarter turn down of radius 5 cm, then 0.1 straight down.
        let expected = Vec3::new(0.1 + 0.1 + 0.05, 0.2, 0.3 - 0.05 - 0.1);
        assert!(end.distance(expected) < 1e-5, "{end:?}");
        assert!((h + FRAC_PI_2).abs() < 1e-6);
    }

    #[test]
    fn gradients_are_the_derivative_of_the_bending_map() {
        let mut bar = hook();
        bar.width_scale = Some((0.02, 0.06, 0.5));
        let spacing = 0.004;
        let p = bar.sample(spacing);
        assert_eq!(p.positions.len(), (bar.length() / spacing) as usize * 25);
        // Neighbouring rest points (one spacing apart in every direction) map to points whose
        // difference is F times the rest difference, up to second-order terms.
        let across = 5;
        for (idx, f) in p.gradients.iter().enumerate() {
            let (row, rem) = (idx / (across * across), idx % (across * across));
            let (i, j) = (rem / across, rem % across);
            if row + 1 >= p.positions.len() / 25 || i + 1 >= across || j + 1 >= across {
                continue;
            }
            let s = p.arc_length[idx];
            // Pinch edges and piece joints: the map's derivative jumps there.
            let joints = [0.02, 0.06, 0.1, 0.1 + 0.05 * FRAC_PI_2];
            let pinch_edge = joints.iter().any(|e| (s - e).abs() < 2.0 * spacing);
            let next = |d: usize| p.positions[idx + d] - p.positions[idx];
            let checks = [(across * across, Vec3::X), (across, Vec3::Y), (1, Vec3::Z)];
            for (d, rest) in checks {
                if pinch_edge && d == across * across {
                    continue;
                }
                let mapped = *f * (rest * spacing);
                let err = (next(d) - mapped).length();
                assert!(err < 0.05 * spacing, "particle {idx}, step {rest:?}: {err}");
            }
        }
        // The pinch halves the side axis: J = 0.5 (times the bend's stretch) there.
        let squeezed = p.arc_length.iter().position(|&s| s > 0.03).unwrap();
        let j = p.gradients[squeezed].determinant();
        assert!((j - 0.5).abs() < 0.01, "J = {j}");
        assert_eq!(
            p.on_axis.iter().filter(|&&a| a).count(),
            p.positions.len() / 25
        );
    }
}
