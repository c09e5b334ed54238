//! Triangle meshes: validation, unsigned distance and inside/outside by winding number.
//! Used to build SDF volumes for mesh colliders and to fill meshes with particles.

use glam::Vec3;

use crate::error::MpmError;

/// A closed, consistently oriented triangle mesh (m, in its own frame).
#[derive(Clone, Debug, PartialEq)]
pub struct TriMesh {
    /// Vertex positions (m).
    pub vertices: Vec<Vec3>,
    /// Triangles as vertex index triples, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Builds a mesh after checking that it has triangles, finite vertices and valid indices.
    pub fn new(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, MpmError> {
        if triangles.is_empty() {
            return Err(MpmError::InvalidMesh {
                reason: "no triangles".into(),
            });
        }
        if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(MpmError::InvalidMesh {
                reason: format!("vertex {i} is not finite: {:?}", vertices[i]),
            });
        }
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&i| i as usize >= vertices.len()) {
                return Err(MpmError::InvalidMesh {
                    reason: format!(
                        "triangle {t} uses vertex {bad}, but there are {} vertices",
                        vertices.len()
                    ),
                });
            }
        }
        Ok(Self {
            vertices,
            triangles,
        })
    }

    /// Axis-aligned bounds `(min, max)` (m).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.vertices.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), &v| (lo.min(v), hi.max(v)),
        )
    }

    fn corners(&self, t: &[u32; 3]) -> (Vec3, Vec3, Vec3) {
        (
            self.vertices[t[0] as usize],
            self.vertices[t[1] as usize],
            self.vertices[t[2] as usize],
        )
    }

    /// Distance (m) from `p` to the surface.
    pub fn unsigned_distance(&self, p: Vec3) -> f32 {
        self.triangles
            .iter()
            .map(|t| {
                let (a, b, c) = self.corners(t);
                (closest_point_on_triangle(p, a, b, c) - p).length_squared()
            })
            .fold(f32::MAX, f32::min)
            .sqrt()
    }

    /// Generalised winding number of `p`: about 1 inside a closed outward-oriented mesh, about
    /// 0 outside. Robust to small holes.
    pub fn winding_number(&self, p: Vec3) -> f32 {
        let mut total = 0.0f64;
        for t in &self.triangles {
            let (a, b, c) = self.corners(t);
            let (a, b, c) = (a - p, b - p, c - p);
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let num = a.dot(b.cross(c));
            let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            total += 2.0 * (num as f64).atan2(den as f64);
        }
        (total / (4.0 * std::f64::consts::PI)) as f32
    }

    /// Whether `p` is inside (winding number above one half).
    pub fn contains(&self, p: Vec3) -> bool {
        self.winding_number(p) > 0.5
    }

    /// Signed distance (m): negative inside.
    pub fn signed_distance(&self, p: Vec3) -> f32 {
        let d = self.unsigned_distance(p);
        if self.contains(p) {
            -d
        } else {
            d
        }
    }

    /// The 12-triangle box of half extents `half` (m) centred at the origin.
    pub fn cuboid(half: Vec3) -> Self {
        let v: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    if i & 1 == 0 { -half.x } else { half.x },
                    if i & 2 == 0 { -half.y } else { half.y },
                    if i & 4 == 0 { -half.z } else { half.z },
                )
            })
            .collect();
        let triangles = vec![
            [0, 2, 1],
            [1, 2, 3], // -z
            [4, 5, 6],
            [5, 7, 6], // +z
            [0, 1, 4],
            [1, 5, 4], // -y
            [2, 6, 3],
            [3, 6, 7], // +y
            [0, 4, 2],
            [2, 4, 6], // -x
            [1, 3, 5],
            [3, 7, 5], // +x
        ];
        Self {
            vertices: v,
            triangles,
        }
    }
}

/// Closest point to `p` on triangle `abc` (region-based, after Ericson's formulation).
pub(crate) fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuboid_inside_outside_and_distance() {
        let m = TriMesh::cuboid(Vec3::new(0.1, 0.2, 0.3));
        assert!(m.contains(Vec3::new(0.05, -0.1, 0.2)));
        assert!(!m.contains(Vec3::new(0.15, 0.0, 0.0)));
        assert!((m.winding_number(Vec3::ZERO) - 1.0).abs() < 1e-4);
        assert!((m.signed_distance(Vec3::new(0.0, 0.0, 0.25)) + 0.05).abs() < 1e-6);
        assert!((m.signed_distance(Vec3::new(0.3, 0.0, 0.0)) - 0.2).abs() < 1e-6);
    }

    #[test]
    fn bad_index_is_reported() {
        let err = TriMesh::new(vec![Vec3::ZERO; 3], vec![[0, 1, 5]]).unwrap_err();
        assert!(err.to_string().contains("vertex 5"), "{err}");
    }
}
