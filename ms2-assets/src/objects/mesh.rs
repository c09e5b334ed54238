//! Closed triangle meshes for the procedural object families: solids of revolution, boxes,
//! ellipsoids, swept tubes and convex hulls, with rigid transforms, bounding boxes and volume.
//! Units: metres; triangles wind counter-clockwise seen from outside.

use std::f64::consts::TAU;

/// A triangle mesh (m). Generators return closed, outward-facing meshes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertices (m).
    pub vertices: Vec<[f64; 3]>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// Solid of revolution about z of a profile of `(r, z)` points (m) that starts and ends on
    /// the axis (`r = 0`), with `segments` around. The profile may fold back (hollow mugs,
    /// bowls): the result is closed whenever both ends are on the axis.
    pub fn lathe(profile: &[[f64; 2]], segments: usize) -> Mesh {
        let segments = segments.max(3);
        let mut m = Mesh::default();
        // Vertex index of each profile point at each angle (axis points are shared).
        let mut ring: Vec<Vec<u32>> = Vec::with_capacity(profile.len());
        for p in profile {
            if p[0] <= 1e-12 {
                m.vertices.push([0.0, 0.0, p[1]]);
                ring.push(vec![(m.vertices.len() - 1) as u32; segments]);
            } else {
                let mut r = Vec::with_capacity(segments);
                for k in 0..segments {
                    let a = TAU * k as f64 / segments as f64;
                    m.vertices.push([p[0] * a.cos(), p[0] * a.sin(), p[1]]);
                    r.push((m.vertices.len() - 1) as u32);
                }
                ring.push(r);
            }
        }
        for i in 0..profile.len().saturating_sub(1) {
            for k in 0..segments {
                let k1 = (k + 1) % segments;
                let (a, b) = (ring[i][k], ring[i][k1]);
                let (c, d) = (ring[i + 1][k], ring[i + 1][k1]);
                if a != b {
                    m.triangles.push([a, b, d]);
                }
                if c != d {
                    m.triangles.push([a, d, c]);
                }
            }
        }
        m.drop_degenerate();
        m.orient_outward();
        m
    }

    /// Box with half extents `half` (m), centred at the origin.
    pub fn cuboid(half: [f64; 3]) -> Mesh {
        let [x, y, z] = half;
        let vertices = vec![
            [-x, -y, -z],
            [x, -y, -z],
            [x, y, -z],
            [-x, y, -z],
            [-x, -y, z],
            [x, -y, z],
            [x, y, z],
            [-x, y, z],
        ];
        let triangles = vec![
            [0, 2, 1],
            [0, 3, 2],
            [4, 5, 6],
            [4, 6, 7],
            [0, 1, 5],
            [0, 5, 4],
            [1, 2, 6],
            [1, 6, 5],
            [2, 3, 7],
            [2, 7, 6],
            [3, 0, 4],
            [3, 4, 7],
        ];
        Mesh {
            vertices,
            triangles,
        }
    }

    /// Ellipsoid with semi-axes `radii` (m), centred at the origin.
    pub fn ellipsoid(radii: [f64; 3], stacks: usize, segments: usize) -> Mesh {
        let stacks = stacks.max(2);
        let profile: Vec<[f64; 2]> = (0..=stacks)
            .map(|i| {
                let t = std::f64::consts::PI * i as f64 / stacks as f64;
                [t.sin(), -t.cos()]
            })
            .collect();
        let mut m = Mesh::lathe(&profile, segments);
        m.scale(radii);
        m
    }

    /// A closed tube swept along `path` (m) with a circular section of `radius[i]` at point `i`
    /// and `sides` sides; the ends are capped flat.
    pub fn tube(path: &[[f64; 3]], radius: &[f64], sides: usize) -> Mesh {
        let sides = sides.max(3);
        let n = path.len();
        let mut m = Mesh::default();
        if n < 2 {
            return m;
        }
        let mut prev_normal: Option<[f64; 3]> = None;
        for i in 0..n {
            let t = normalize(sub(path[(i + 1).min(n - 1)], path[i.saturating_sub(1)]));
            // A normal carried along the path (parallel transport) so the rings do not twist.
            let seed = prev_normal.unwrap_or(if t[2].abs() < 0.9 {
                [0.0, 0.0, 1.0]
            } else {
                [1.0, 0.0, 0.0]
            });
            let nrm = normalize(sub(seed, scale3(t, dot(seed, t))));
            prev_normal = Some(nrm);
            let bin = cross(t, nrm);
            for k in 0..sides {
                let a = TAU * k as f64 / sides as f64;
                let off = add(scale3(nrm, a.cos()), scale3(bin, a.sin()));
                m.vertices.push(add(path[i], scale3(off, radius[i])));
            }
        }
        for i in 0..n - 1 {
            for k in 0..sides {
                let k1 = (k + 1) % sides;
                let a = (i * sides + k) as u32;
                let b = (i * sides + k1) as u32;
                let c = ((i + 1) * sides + k) as u32;
                let d = ((i + 1) * sides + k1) as u32;
                m.triangles.push([a, b, d]);
                m.triangles.push([a, d, c]);
            }
        }
        for (end, ring0) in [(path[0], 0usize), (path[n - 1], (n - 1) * sides)] {
            m.vertices.push(end);
            let c = (m.vertices.len() - 1) as u32;
            for k in 0..sides {
                let a = (ring0 + k) as u32;
                let b = (ring0 + (k + 1) % sides) as u32;
                if ring0 == 0 {
                    m.triangles.push([c, b, a]);
                } else {
                    m.triangles.push([c, a, b]);
                }
            }
        }
        m.orient_outward();
        m
    }

    /// Convex hull of points (m), through parry3d. `None` when the points are degenerate.
    pub fn convex_hull(points: &[[f64; 3]]) -> Option<Mesh> {
        if points.len() < 4 {
            return None;
        }
        let pts: Vec<parry3d::math::Vector> = points
            .iter()
            .map(|p| parry3d::math::Vector::new(p[0] as f32, p[1] as f32, p[2] as f32))
            .collect();
        let (v, t) = parry3d::transformation::try_convex_hull(&pts).ok()?;
        if t.is_empty() {
            return None;
        }
        let mut m = Mesh {
            vertices: v
                .iter()
                .map(|p| [p.x as f64, p.y as f64, p.z as f64])
                .collect(),
            triangles: t,
        };
        m.orient_outward();
        Some(m)
    }

    /// Scales each axis.
    pub fn scale(&mut self, s: [f64; 3]) {
        for v in &mut self.vertices {
            for i in 0..3 {
                v[i] *= s[i];
            }
        }
        if s[0] * s[1] * s[2] < 0.0 {
            self.flip();
        }
    }

    /// Moves by `t` (m).
    pub fn translate(&mut self, t: [f64; 3]) {
        for v in &mut self.vertices {
            *v = add(*v, t);
        }
    }

    /// Rotates by `angle` (rad) about the unit `axis` through the origin.
    pub fn rotate(&mut self, axis: [f64; 3], angle: f64) {
        let k = normalize(axis);
        let (s, c) = angle.sin_cos();
        for v in &mut self.vertices {
            // Rodrigues' rotation formula.
            let kv = cross(k, *v);
            let kd = dot(k, *v);
            *v = add(add(scale3(*v, c), scale3(kv, s)), scale3(k, kd * (1.0 - c)));
        }
    }

    /// Adds another mesh's triangles (the union is not merged: overlapping closed parts).
    pub fn append(&mut self, other: &Mesh) {
        let base = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }

    /// Axis-aligned bounding box `(min, max)` (m). Zeros for an empty mesh.
    pub fn bbox(&self) -> ([f64; 3], [f64; 3]) {
        if self.vertices.is_empty() {
            return ([0.0; 3], [0.0; 3]);
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for v in &self.vertices {
            for i in 0..3 {
                lo[i] = lo[i].min(v[i]);
                hi[i] = hi[i].max(v[i]);
            }
        }
        (lo, hi)
    }

    /// Signed enclosed volume (m³), positive for an outward-facing closed mesh.
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    /// Reverses every triangle's winding.
    pub fn flip(&mut self) {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
    }

    fn orient_outward(&mut self) {
        if self.volume() < 0.0 {
            self.flip();
        }
    }

    fn drop_degenerate(&mut self) {
        self.triangles
            .retain(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    }

    /// Vertices and triangles in f32 for OBJ writing.
    pub fn to_f32(&self) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        (
            self.vertices
                .iter()
                .map(|v| [v[0] as f32, v[1] as f32, v[2] as f32])
                .collect(),
            self.triangles.clone(),
        )
    }
}

pub(crate) fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(crate) fn scale3(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub(crate) fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    if n > 0.0 {
        scale3(a, 1.0 / n)
    } else {
        [0.0, 0.0, 1.0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_generators_have_their_analytic_volume() {
        let c = Mesh::cuboid([0.01, 0.02, 0.03]);
        assert!((c.volume() - 0.02 * 0.04 * 0.06).abs() < 1e-12);
        // A cylinder of radius 3 cm, height 10 cm (polygon area with 64 sides).
        let cyl = Mesh::lathe(
            &[[0.0, 0.0], [0.03, 0.0], [0.03, 0.1], [0.0, 0.1]],
            64,
        );
        let poly_area = 0.5 * 64.0 * 0.03f64.powi(2) * (TAU / 64.0).sin();
        assert!((cyl.volume() - poly_area * 0.1).abs() < 1e-9, "{}", cyl.volume());
        let e = Mesh::ellipsoid([0.02, 0.03, 0.04], 24, 48);
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 0.02 * 0.03 * 0.04;
        assert!((e.volume() - exact).abs() / exact < 0.02);
        // A hollow mug profile: outer cylinder minus the inner one.
        let mug = Mesh::lathe(
            &[
                [0.0, 0.0],
                [0.04, 0.0],
                [0.04, 0.1],
                [0.035, 0.1],
                [0.035, 0.005],
                [0.0, 0.005],
            ],
            128,
        );
        let exact = std::f64::consts::PI * (0.04f64.powi(2) * 0.1 - 0.035f64.powi(2) * 0.095);
        assert!((mug.volume() - exact).abs() / exact < 0.01);
        let t = Mesh::tube(&[[0.0, 0.0, 0.0], [0.0, 0.0, 0.1]], &[0.01, 0.01], 64);
        let exact = std::f64::consts::PI * 1e-4 * 0.1;
        assert!((t.volume() - exact).abs() / exact < 0.01);
    }

    #[test]
    fn rotation_keeps_volume_and_moves_the_box() {
        let mut c = Mesh::cuboid([0.01, 0.02, 0.03]);
        c.rotate([0.0, 0.0, 1.0], std::f64::consts::FRAC_PI_2);
        let (lo, hi) = c.bbox();
        assert!((hi[0] - 0.02).abs() < 1e-12 && (lo[1] + 0.01).abs() < 1e-12);
        assert!((c.volume() - 4.8e-5).abs() < 1e-12);
    }
}
