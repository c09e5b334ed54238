//! Triangle meshes: the data uploaded to the renderer, and procedural builders.
//!
//! All builders produce meshes in their own local frame, centred on the origin, with outward
//! per-vertex normals, counter-clockwise front faces and texture coordinates in `[0, 1]`.
//! Lengths are in metres.

use crate::RenderError;
use std::f32::consts::PI;

/// A triangle mesh in its local frame: positions in metres, unit normals, optional texture
/// coordinates, and triangles as triples of vertex indices (counter-clockwise seen from outside).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct MeshData {
    /// Vertex positions in the mesh's local frame, metres.
    pub positions: Vec<[f32; 3]>,
    /// Per-vertex unit normals in the mesh's local frame; same length as `positions`.
    pub normals: Vec<[f32; 3]>,
    /// Optional per-vertex texture coordinates (u right, v down, in `[0, 1]`); if present, same
    /// length as `positions`.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Triangle vertex indices, three per triangle.
    pub indices: Vec<u32>,
}

impl MeshData {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Checks that the arrays agree in length, indices are in range and values are finite.
    pub fn validate(&self) -> Result<(), RenderError> {
        let n = self.positions.len();
        if n == 0 || self.indices.is_empty() {
            return Err(RenderError::InvalidMesh(format!(
                "expected at least one vertex and one triangle, got {n} vertices and {} indices",
                self.indices.len()
            )));
        }
        if self.normals.len() != n {
            return Err(RenderError::InvalidMesh(format!(
                "expected {n} normals (one per vertex), got {}",
                self.normals.len()
            )));
        }
        if let Some(uvs) = &self.uvs {
            if uvs.len() != n {
                return Err(RenderError::InvalidMesh(format!(
                    "expected {n} uvs (one per vertex), got {}",
                    uvs.len()
                )));
            }
        }
        if !self.indices.len().is_multiple_of(3) {
            return Err(RenderError::InvalidMesh(format!(
                "index count {} is not a multiple of 3",
                self.indices.len()
            )));
        }
        if let Some(bad) = self.indices.iter().find(|&&i| i as usize >= n) {
            return Err(RenderError::InvalidMesh(format!(
                "index {bad} out of range for {n} vertices"
            )));
        }
        let finite = self
            .positions
            .iter()
            .chain(self.normals.iter())
            .all(|v| v.iter().all(|c| c.is_finite()));
        if !finite {
            return Err(RenderError::InvalidMesh(
                "positions and normals must be finite".into(),
            ));
        }
        Ok(())
    }

    /// Appends another mesh (used by the builders to join parts).
    fn append(&mut self, other: MeshData) {
        let base = self.positions.len() as u32;
        self.positions.extend(other.positions);
        self.normals.extend(other.normals);
        match (&mut self.uvs, other.uvs) {
            (Some(a), Some(b)) => a.extend(b),
            (None, Some(b)) if base == 0 => self.uvs = Some(b),
            _ => self.uvs = None,
        }
        self.indices
            .extend(other.indices.into_iter().map(|i| i + base));
    }

    /// An axis-aligned box centred on the origin with the given half extents (metres), flat
    /// shaded (4 vertices per face, 12 triangles).
    pub fn cuboid(half_extents: [f32; 3]) -> MeshData {
        let mut mesh = MeshData {
            uvs: Some(Vec::new()),
            ..Default::default()
        };
        // For each face: normal axis, sign; the two in-plane axes (u, v) chosen so u × v = n.
        for axis in 0..3 {
            for sign in [1.0f32, -1.0] {
                let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
                let (u_axis, v_axis) = if sign > 0.0 { (a, b) } else { (b, a) };
                let mut normal = [0.0; 3];
                normal[axis] = sign;
                let base = mesh.positions.len() as u32;
                for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    let mut p = [0.0; 3];
                    p[axis] = sign * half_extents[axis];
                    p[u_axis] = su * half_extents[u_axis];
                    p[v_axis] = sv * half_extents[v_axis];
                    mesh.positions.push(p);
                    mesh.normals.push(normal);
                    if let Some(uvs) = &mut mesh.uvs {
                        uvs.push([(su + 1.0) / 2.0, (1.0 - sv) / 2.0]);
                    }
                }
                mesh.indices
                    .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
            }
        }
        mesh
    }

    /// A rectangle in the local z = 0 plane facing +z, with half sizes along x and y (metres).
    pub fn plane(half_size_x: f32, half_size_y: f32) -> MeshData {
        MeshData {
            positions: vec![
                [-half_size_x, -half_size_y, 0.0],
                [half_size_x, -half_size_y, 0.0],
                [half_size_x, half_size_y, 0.0],
                [-half_size_x, half_size_y, 0.0],
            ],
            normals: vec![[0.0, 0.0, 1.0]; 4],
            uvs: Some(vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]),
            indices: vec![0, 1, 2, 0, 2, 3],
        }
    }

    /// A UV sphere of the given radius (metres) with `segments` (≥ 3) around the z axis and
    /// `rings` (≥ 2) from pole to pole; smaller values are raised to these minimums.
    pub fn sphere(radius: f32, segments: u32, rings: u32) -> MeshData {
        Self::lathe(segments, rings, |t| {
            // t in [0, 1] from the south pole (z = -r) to the north pole (z = +r).
            let polar = PI * (1.0 - t);
            let (s, c) = polar.sin_cos();
            let s = s.max(0.0); // sin(π) rounds to a tiny negative radius
            ([radius * s, radius * c], [s, c])
        })
    }

    /// A geodesic sphere of the given radius (metres): an icosahedron (20 triangles, 12
    /// vertices) whose triangles are split in four `subdivisions` times (at most 5), the new
    /// vertices pushed onto the sphere; smooth normals, no uvs. The cheapest round shape per
    /// triangle, for meshes drawn many times such as particles.
    pub fn icosphere(radius: f32, subdivisions: u32) -> MeshData {
        let t = (1.0 + 5f32.sqrt()) / 2.0;
        let mut dirs: Vec<[f32; 3]> = [
            [-1.0, t, 0.0],
            [1.0, t, 0.0],
            [-1.0, -t, 0.0],
            [1.0, -t, 0.0],
            [0.0, -1.0, t],
            [0.0, 1.0, t],
            [0.0, -1.0, -t],
            [0.0, 1.0, -t],
            [t, 0.0, -1.0],
            [t, 0.0, 1.0],
            [-t, 0.0, -1.0],
            [-t, 0.0, 1.0],
        ]
        .into_iter()
        .map(normalized)
        .collect();
        let mut faces: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..subdivisions.min(5) {
            let mut midpoints = std::collections::HashMap::new();
            let mut midpoint = |a: u32, b: u32, dirs: &mut Vec<[f32; 3]>| -> u32 {
                *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    let (p, q) = (dirs[a as usize], dirs[b as usize]);
                    dirs.push(normalized([p[0] + q[0], p[1] + q[1], p[2] + q[2]]));
                    dirs.len() as u32 - 1
                })
            };
            let mut split = Vec::with_capacity(faces.len() * 4);
            for [a, b, c] in faces {
                let ab = midpoint(a, b, &mut dirs);
                let bc = midpoint(b, c, &mut dirs);
                let ca = midpoint(c, a, &mut dirs);
                split.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            faces = split;
        }
        MeshData {
            positions: dirs.iter().map(|d| d.map(|v| v * radius)).collect(),
            normals: dirs,
            uvs: None,
            indices: faces.into_iter().flatten().collect(),
        }
    }

    /// A closed cylinder along the local z axis, radius and half length in metres, with
    /// `segments` (≥ 3) around the axis.
    pub fn cylinder(radius: f32, half_length: f32, segments: u32) -> MeshData {
        let mut mesh = Self::lathe(segments, 1, |t| {
            ([radius, half_length * (2.0 * t - 1.0)], [1.0, 0.0])
        });
        mesh.append(Self::disk(radius, half_length, segments, 1.0));
        mesh.append(Self::disk(radius, -half_length, segments, -1.0));
        mesh
    }

    /// A capsule along the local z axis: a cylinder of the given radius and half length
    /// (metres, not counting the caps) closed by two hemispheres.
    pub fn capsule(radius: f32, half_length: f32, segments: u32, rings_per_cap: u32) -> MeshData {
        let rings = rings_per_cap.max(1);
        // Profile: south cap (rings steps), straight side (1 step), north cap (rings steps).
        let total = 2 * rings + 1;
        Self::lathe(segments, total, |t| {
            let step = t * total as f32;
            if step <= rings as f32 {
                let polar = PI - 0.5 * PI * step / rings as f32; // from π (south) to π/2
                let (s, c) = polar.sin_cos();
                ([radius * s, -half_length + radius * c], [s, c])
            } else if step >= (rings + 1) as f32 {
                let polar = 0.5 * PI * (1.0 - (step - (rings + 1) as f32) / rings as f32);
                let (s, c) = polar.sin_cos();
                ([radius * s, half_length + radius * c], [s, c])
            } else {
                let f = step - rings as f32;
                ([radius, half_length * (2.0 * f - 1.0)], [1.0, 0.0])
            }
        })
    }

    /// A surface of revolution about z. `profile(t)` for t in `[0, 1]` gives `([radius, z],
    /// [normal_radial, normal_z])`; `rows` steps of t and `segments` around the axis.
    fn lathe(segments: u32, rows: u32, profile: impl Fn(f32) -> ([f32; 2], [f32; 2])) -> MeshData {
        let segments = segments.max(3);
        let rows = rows.max(1);
        let mut mesh = MeshData {
            uvs: Some(Vec::new()),
            ..Default::default()
        };
        for row in 0..=rows {
            let t = row as f32 / rows as f32;
            let ([r, z], [nr, nz]) = profile(t);
            for seg in 0..=segments {
                let phi = 2.0 * PI * seg as f32 / segments as f32;
                let (s, c) = phi.sin_cos();
                mesh.positions.push([r * c, r * s, z]);
                mesh.normals.push([nr * c, nr * s, nz]);
                if let Some(uvs) = &mut mesh.uvs {
                    uvs.push([seg as f32 / segments as f32, 1.0 - t]);
                }
            }
        }
        let stride = segments + 1;
        for row in 0..rows {
            for seg in 0..segments {
                let a = row * stride + seg;
                let b = a + 1;
                let c = a + stride;
                let d = c + 1;
                mesh.indices.extend([a, b, d, a, d, c]);
            }
        }
        mesh
    }

    /// A flat disk at height z facing `normal_sign` · z.
    fn disk(radius: f32, z: f32, segments: u32, normal_sign: f32) -> MeshData {
        let segments = segments.max(3);
        let mut mesh = MeshData {
            positions: vec![[0.0, 0.0, z]],
            normals: vec![[0.0, 0.0, normal_sign]],
            uvs: Some(vec![[0.5, 0.5]]),
            indices: Vec::new(),
        };
        for seg in 0..segments {
            let phi = 2.0 * PI * seg as f32 / segments as f32;
            let (s, c) = phi.sin_cos();
            mesh.positions.push([radius * c, radius * s, z]);
            mesh.normals.push([0.0, 0.0, normal_sign]);
            if let Some(uvs) = &mut mesh.uvs {
                uvs.push([0.5 + 0.5 * c, 0.5 - 0.5 * s]);
            }
        }
        for seg in 0..segments {
            let a = 1 + seg;
            let b = 1 + (seg + 1) % segments;
            if normal_sign > 0.0 {
                mesh.indices.extend([0, a, b]);
            } else {
                mesh.indices.extend([0, b, a]);
            }
        }
        mesh
    }
}

/// `v` scaled to unit length.
fn normalized(v: [f32; 3]) -> [f32; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / n)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sum over triangles of (v1 - v0) × (v2 - v0) · centroid must be positive for outward CCW
    /// winding of a convex mesh centred at the origin; normals must point away from the centre.
    fn assert_outward(mesh: &MeshData) {
        mesh.validate().unwrap();
        for tri in mesh.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[tri[k] as usize]);
            let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            let centroid = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0);
            let dot: f32 = (0..3).map(|k| n[k] * centroid[k]).sum();
            let area2: f32 = n.iter().map(|x| x * x).sum::<f32>().sqrt();
            if area2 > 1e-7 {
                assert!(dot > 0.0, "triangle {tri:?} winds inward");
            }
        }
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            let dot: f32 = (0..3).map(|k| p[k] * n[k]).sum();
            assert!(dot >= -1e-6, "normal {n:?} at {p:?} points inward");
            let len: f32 = n.iter().map(|x| x * x).sum::<f32>().sqrt();
            assert!((len - 1.0).abs() < 1e-4);
        }
    }

    #[test]
    fn builders_produce_valid_outward_meshes() {
        let cube = MeshData::cuboid([0.1, 0.2, 0.3]);
        assert_eq!(cube.triangle_count(), 12);
        assert_outward(&cube);
        let max = cube.positions.iter().map(|p| p[2]).fold(f32::MIN, f32::max);
        assert_eq!(max, 0.3);
        assert_outward(&MeshData::sphere(0.5, 16, 8));
        assert_outward(&MeshData::cylinder(0.2, 0.4, 12));
        assert_outward(&MeshData::capsule(0.1, 0.3, 12, 4));
        for (subdivisions, triangles, vertices) in [(0, 20, 12), (1, 80, 42), (2, 320, 162)] {
            let ico = MeshData::icosphere(0.5, subdivisions);
            assert_eq!(ico.triangle_count(), triangles);
            assert_eq!(
                ico.positions.len(),
                vertices,
                "vertices shared between faces"
            );
            assert_outward(&ico);
            for p in &ico.positions {
                let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                assert!((r - 0.5).abs() < 1e-5);
            }
        }
        let sphere = MeshData::sphere(0.5, 16, 8);
        for p in &sphere.positions {
            let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            assert!((r - 0.5).abs() < 1e-5);
        }
        let capsule = MeshData::capsule(0.1, 0.3, 12, 4);
        let top = capsule
            .positions
            .iter()
            .map(|p| p[2])
            .fold(f32::MIN, f32::max);
        assert!((top - 0.4).abs() < 1e-5, "capsule top at {top}");
    }

    #[test]
    fn validation_rejects_bad_meshes() {
        let mut mesh = MeshData::plane(1.0, 1.0);
        mesh.indices.push(7);
        assert!(matches!(mesh.validate(), Err(RenderError::InvalidMesh(_))));
        let mut mesh = MeshData::plane(1.0, 1.0);
        mesh.normals.pop();
        assert!(mesh.validate().is_err());
        let mut mesh = MeshData::plane(1.0, 1.0);
        mesh.positions[0][0] = f32::NAN;
        assert!(mesh.validate().is_err());
    }
}
