//! A stored mesh on the CPU: its triangles under a bounding-volume hierarchy (parry's SAH
//! [`Bvh`]) for closest-hit ray queries in the mesh's local frame.

use crate::MeshData;
use parry3d::bounding_volume::Aabb;
use parry3d::math::Vec3;
use parry3d::partitioning::{Bvh, BvhBuildStrategy};
use parry3d::query::Ray;
use std::cell::Cell;

/// A mesh's CPU copy for ray casting (local frame, metres).
pub(crate) struct CpuMesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Option<Vec<[f32; 2]>>,
    triangles: Vec<[u32; 3]>,
    /// For a merged mesh: which member mesh each triangle came from.
    parts: Option<Vec<u32>>,
    bvh: Bvh,
    /// Bounds of all vertices, local frame.
    pub(crate) aabb: Aabb,
}

/// The closest triangle a ray hits: its index, the ray parameter and barycentrics (of the
/// second and third vertex).
#[derive(Clone, Copy, Debug)]
pub(crate) struct TriangleHit {
    pub(crate) triangle: u32,
    pub(crate) t: f32,
    pub(crate) u: f32,
    pub(crate) v: f32,
}

/// Surface attributes at a hit, mesh frame.
pub(crate) struct SurfacePoint {
    /// Interpolated vertex normal (not normalised).
    pub(crate) normal: Vec3,
    /// Geometric normal of the triangle (counter-clockwise winding = front).
    pub(crate) face_normal: Vec3,
    pub(crate) uv: Option<[f32; 2]>,
    /// For a merged mesh, the member the triangle belongs to (0 otherwise).
    pub(crate) part: u32,
}

impl CpuMesh {
    /// Builds the hierarchy of a validated mesh.
    pub(crate) fn new(mesh: &MeshData) -> CpuMesh {
        let positions: Vec<Vec3> = mesh.positions.iter().map(|p| Vec3::from(*p)).collect();
        let normals = mesh.normals.iter().map(|n| Vec3::from(*n)).collect();
        let triangles: Vec<[u32; 3]> = mesh
            .indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        Self::build(positions, normals, mesh.uvs.clone(), triangles, None)
    }

    /// One mesh of several placed in the same frame (e.g. the parts of one robot link, one
    /// per material): one hierarchy over all their triangles, each remembering its member.
    pub(crate) fn merged(members: &[&CpuMesh]) -> CpuMesh {
        let any_uvs = members.iter().any(|m| m.uvs.is_some());
        let (mut positions, mut normals, mut triangles) = (Vec::new(), Vec::new(), Vec::new());
        let mut uvs = Vec::new();
        let mut parts = Vec::new();
        for (k, m) in members.iter().enumerate() {
            let offset = positions.len() as u32;
            positions.extend_from_slice(&m.positions);
            normals.extend_from_slice(&m.normals);
            if any_uvs {
                match &m.uvs {
                    Some(u) => uvs.extend_from_slice(u),
                    None => uvs.extend(std::iter::repeat_n([0.0, 0.0], m.positions.len())),
                }
            }
            triangles.extend(m.triangles.iter().map(|t| t.map(|i| i + offset)));
            parts.extend(std::iter::repeat_n(k as u32, m.triangles.len()));
        }
        let uvs = any_uvs.then_some(uvs);
        Self::build(positions, normals, uvs, triangles, Some(parts))
    }

    fn build(
        positions: Vec<Vec3>,
        normals: Vec<Vec3>,
        uvs: Option<Vec<[f32; 2]>>,
        triangles: Vec<[u32; 3]>,
        parts: Option<Vec<u32>>,
    ) -> CpuMesh {
        let leaves: Vec<Aabb> = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                Aabb::new(a.min(b).min(c), a.max(b).max(c))
            })
            .collect();
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves);
        let aabb = positions.iter().fold(Aabb::new_invalid(), |mut acc, p| {
            acc.take_point(*p);
            acc
        });
        CpuMesh {
            positions,
            normals,
            uvs,
            triangles,
            parts,
            bvh,
            aabb,
        }
    }

    /// The closest triangle hit by `ray` (local frame; `dir` need not be unit) with
    /// `t_min < t < t_max`; both faces count.
    pub(crate) fn cast(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<TriangleHit> {
        let best: Cell<Option<TriangleHit>> = Cell::new(None);
        self.bvh.cast_ray(ray, t_max, |tri, best_t| {
            let hit = self.intersect(tri, ray, t_min, best_t)?;
            best.set(Some(hit));
            Some(hit.t)
        })?;
        best.get()
    }

    /// Möller–Trumbore intersection with triangle `tri`, both faces.
    fn intersect(&self, tri: u32, ray: &Ray, t_min: f32, t_max: f32) -> Option<TriangleHit> {
        let [a, b, c] = self.triangles[tri as usize].map(|i| self.positions[i as usize]);
        let e1 = b - a;
        let e2 = c - a;
        let p = ray.dir.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            return None;
        }
        let inv = 1.0 / det;
        let s = ray.origin - a;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(e1);
        let v = ray.dir.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = e2.dot(q) * inv;
        (t > t_min && t < t_max).then_some(TriangleHit {
            triangle: tri,
            t,
            u,
            v,
        })
    }

    /// Normals and texture coordinates at a hit.
    pub(crate) fn surface(&self, hit: &TriangleHit) -> SurfacePoint {
        let idx = self.triangles[hit.triangle as usize];
        let w = [1.0 - hit.u - hit.v, hit.u, hit.v];
        let [a, b, c] = idx.map(|i| self.positions[i as usize]);
        let normal = idx.iter().zip(w).fold(Vec3::ZERO, |acc, (&i, wk)| {
            acc + self.normals[i as usize] * wk
        });
        let uv = self.uvs.as_ref().map(|uvs| {
            idx.iter().zip(w).fold([0.0, 0.0], |acc, (&i, wk)| {
                let t = uvs[i as usize];
                [acc[0] + t[0] * wk, acc[1] + t[1] * wk]
            })
        });
        SurfacePoint {
            normal,
            face_normal: (b - a).cross(c - a),
            uv,
            part: self.parts.as_ref().map_or(0, |p| p[hit.triangle as usize]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_hit_of_a_sphere_mesh() {
        let mesh = CpuMesh::new(&MeshData::icosphere(0.5, 3));
        let ray = Ray::new(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 0.0, -1.0));
        let hit = mesh.cast(&ray, 0.0, 10.0).expect("the ray hits the sphere");
        // The icosphere's vertices lie on the sphere, its faces slightly inside it.
        assert!((hit.t - 1.5).abs() < 0.01, "t = {}", hit.t);
        let s = mesh.surface(&hit);
        assert!(s.normal.normalize().z > 0.99);
        assert!(
            s.face_normal.dot(ray.dir) < 0.0,
            "front face towards the ray"
        );
        // A t_min past the front face finds the back face; past both, nothing.
        let back = mesh.cast(&ray, hit.t + 0.01, 10.0).expect("back face");
        assert!((back.t - 2.5).abs() < 0.01, "t = {}", back.t);
        assert!(mesh.cast(&ray, 2.6, 10.0).is_none());
        assert!(mesh.cast(&ray, 0.0, 1.4).is_none());
        let miss = Ray::new(Vec3::new(0.6, 0.0, 2.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(mesh.cast(&miss, 0.0, 10.0).is_none());
    }
}
