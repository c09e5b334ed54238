//! Convex pieces (boxes, prisms) and their Wavefront OBJ text: one `o` object per piece, so a
//! loader can take one convex hull per object.

use std::fmt::Write;

/// A convex piece: vertices (m) and outward counter-clockwise triangles.
#[derive(Clone, Debug)]
pub(crate) struct Piece {
    pub(crate) vertices: Vec<[f64; 3]>,
    pub(crate) faces: Vec<[usize; 3]>,
}

impl Piece {
    /// A box of half extents `half` centred at `center`, rotated by `yaw` (rad) about z.
    pub(crate) fn cuboid(center: [f64; 3], half: [f64; 3], yaw: f64) -> Piece {
        let (s, c) = yaw.sin_cos();
        Piece::hexahedron(std::array::from_fn(|i| {
            let x = if i & 1 == 0 { -half[0] } else { half[0] };
            let y = if i & 2 == 0 { -half[1] } else { half[1] };
            let z = if i & 4 == 0 { -half[2] } else { half[2] };
            [
                center[0] + c * x - s * y,
                center[1] + s * x + c * y,
                center[2] + z,
            ]
        }))
    }

    /// A convex hexahedron from its 8 corners, indexed by bits (x = 1, y = 2, z = 4) of a
    /// right-handed frame: corner `i` lies on the `+x` side when `i & 1`, `+y` when `i & 2`,
    /// `+z` when `i & 4` (a box deformed without folding, e.g. a tapered stave).
    pub(crate) fn hexahedron(vertices: [[f64; 3]; 8]) -> Piece {
        let quads = [
            [0, 2, 3, 1], // -z
            [4, 5, 7, 6], // +z
            [0, 1, 5, 4], // -y
            [2, 6, 7, 3], // +y
            [0, 4, 6, 2], // -x
            [1, 3, 7, 5], // +x
        ];
        let faces = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        Piece {
            vertices: vertices.to_vec(),
            faces,
        }
    }

    /// A regular `n`-gon prism (a cylinder approximation) of `radius` along z, from `z0` to
    /// `z1`, centred on (x, y).
    pub(crate) fn cylinder_z(x: f64, y: f64, radius: f64, z0: f64, z1: f64, n: usize) -> Piece {
        let mut vertices = Vec::with_capacity(2 * n);
        for z in [z0, z1] {
            for k in 0..n {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                vertices.push([x + radius * a.cos(), y + radius * a.sin(), z]);
            }
        }
        let mut faces = Vec::with_capacity(4 * n);
        for k in 0..n {
            let k1 = (k + 1) % n;
            faces.push([k, k1, n + k1]);
            faces.push([k, n + k1, n + k]);
        }
        for k in 1..n - 1 {
            faces.push([0, k + 1, k]); // bottom, facing -z
            faces.push([n, n + k, n + k + 1]); // top, facing +z
        }
        Piece { vertices, faces }
    }

    /// A regular `n`-gon prism of `radius` from `a` to `b` along one coordinate axis
    /// (`axis` 0 = x, 1 = y, 2 = z) through `center` (the other two coordinates).
    pub(crate) fn cylinder_axis(
        axis: usize,
        center: [f64; 3],
        radius: f64,
        a: f64,
        b: f64,
        n: usize,
    ) -> Piece {
        let along_z = Piece::cylinder_z(0.0, 0.0, radius, a, b, n);
        // Proper rotations taking z to the axis (so faces keep their outward winding).
        let rotated = match axis {
            0 => along_z.rotated([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]),
            1 => along_z.rotated([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]),
            _ => along_z,
        };
        let mut d = center;
        d[axis.min(2)] = 0.0;
        rotated.translated(d)
    }

    /// The piece rotated about the origin by the rotation matrix `r` (rows), which must be
    /// proper (determinant +1) so the triangles stay outward.
    pub(crate) fn rotated(mut self, r: [[f64; 3]; 3]) -> Piece {
        for v in &mut self.vertices {
            let p = *v;
            for (i, row) in r.iter().enumerate() {
                v[i] = row[0] * p[0] + row[1] * p[1] + row[2] * p[2];
            }
        }
        self
    }

    /// The piece moved by `d` (m).
    pub(crate) fn translated(mut self, d: [f64; 3]) -> Piece {
        for v in &mut self.vertices {
            for i in 0..3 {
                v[i] += d[i];
            }
        }
        self
    }
}

/// OBJ text of the pieces, one object each.
pub(crate) fn to_obj(pieces: &[Piece], header: &str) -> String {
    let mut out = format!("# {header}\n");
    let mut base = 1;
    for (i, p) in pieces.iter().enumerate() {
        let _ = writeln!(out, "o part_{i}");
        for v in &p.vertices {
            let _ = writeln!(out, "v {:.6} {:.6} {:.6}", v[0], v[1], v[2]);
        }
        for f in &p.faces {
            let _ = writeln!(out, "f {} {} {}", f[0] + base, f[1] + base, f[2] + base);
        }
        base += p.vertices.len();
    }
    out
}

/// Axis-aligned bounds of the pieces.
pub(crate) fn bounds(pieces: &[Piece]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in pieces.iter().flat_map(|p| &p.vertices) {
        for i in 0..3 {
            lo[i] = lo[i].min(v[i]);
            hi[i] = hi[i].max(v[i]);
        }
    }
    (lo, hi)
}
