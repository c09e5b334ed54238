//! Hidden-particle culling for densely packed particle sets (MPM clay): a particle whose 26
//! neighbouring cells, on a grid of the packing's spacing, all hold particles is enclosed by
//! their spheres and is not drawn.
//!
//! Why it is safe for the drawn radius: spheres of radius `r > s/√2` on a lattice of spacing
//! `s` overlap across every face of every lattice cube, so their union is a solid whose only
//! voids are isolated pockets at the cube centres; a particle with all 26 neighbours present is
//! inside that solid and no ray from outside reaches it. Deformed clay is no longer a lattice,
//! but it keeps about one particle per cell (clay is nearly incompressible), so the test stays a
//! close, cheap stand-in: one pass over a dense occupancy grid, ~0.1 ms for 4,000 particles.
//! On lavapipe, where fragments behind a ray-traced sphere are still shaded, it removes most
//! of the bed's overdraw (a 3.5 cm bed is seven particles deep).

use glam::{IVec3, Vec3};

/// Largest occupancy grid (cells) worth building; beyond it (particles scattered far apart)
/// every particle is drawn.
const MAX_CELLS: usize = 1 << 22;

/// The particles of `positions` not enclosed by neighbours, for a packing of `spacing_m`
/// (> 0), appended to `out` (cleared first) in their original order.
pub fn visible_particles(positions: &[Vec3], spacing_m: f32, out: &mut Vec<Vec3>) {
    out.clear();
    let Some((lo, dims)) = grid_bounds(positions, spacing_m) else {
        out.extend_from_slice(positions);
        return;
    };
    let cell = |p: Vec3| ((p - lo) / spacing_m).floor().as_ivec3() + IVec3::ONE;
    let index = |c: IVec3| (c.x + dims.x * (c.y + dims.y * c.z)) as usize;
    let mut occupied = vec![false; (dims.x * dims.y * dims.z) as usize];
    for &p in positions {
        occupied[index(cell(p))] = true;
    }
    let enclosed = |c: IVec3| {
        (-1..=1).all(|dz| {
            (-1..=1).all(|dy| (-1..=1).all(|dx| occupied[index(c + IVec3::new(dx, dy, dz))]))
        })
    };
    out.extend(positions.iter().filter(|&&p| !enclosed(cell(p))));
}

/// The grid's lower corner and its size in cells, with a one-cell empty margin on every side
/// (so neighbour lookups never leave it); `None` for no particles, a bad spacing or a grid
/// over [`MAX_CELLS`].
fn grid_bounds(positions: &[Vec3], spacing_m: f32) -> Option<(Vec3, IVec3)> {
    if positions.is_empty() || !(spacing_m.is_finite() && spacing_m > 0.0) {
        return None;
    }
    let (lo, hi) = positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let extent = ((hi - lo) / spacing_m).floor();
    if !extent.is_finite() || extent.max_element() > 1e6 {
        return None;
    }
    let dims = extent.as_ivec3() + IVec3::splat(3);
    let cells = dims.x as usize * dims.y as usize * dims.z as usize;
    (cells <= MAX_CELLS).then_some((lo, dims))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(n: [i32; 3], s: f32) -> Vec<Vec3> {
        let mut out = Vec::new();
        for z in 0..n[2] {
            for y in 0..n[1] {
                for x in 0..n[0] {
                    out.push(Vec3::new(x as f32, y as f32, z as f32) * s + Vec3::splat(0.3 * s));
                }
            }
        }
        out
    }

    #[test]
    fn only_the_surface_of_a_block_is_drawn() {
        let s = 0.005;
        let block = lattice([6, 5, 4], s);
        let mut out = Vec::new();
        visible_particles(&block, s, &mut out);
        // The interior is 4 × 3 × 2 particles.
        assert_eq!(out.len(), block.len() - 4 * 3 * 2);
        let lo = block[0];
        for p in &out {
            let c = ((*p - lo) / s).round();
            let on_surface =
                c.x == 0.0 || c.y == 0.0 || c.z == 0.0 || c.x == 5.0 || c.y == 4.0 || c.z == 3.0;
            assert!(on_surface, "{p} is inside the block");
        }
    }

    #[test]
    fn a_hole_exposes_its_neighbours_and_scattered_sets_draw_everything() {
        let s = 0.005;
        let mut block = lattice([5, 5, 5], s);
        // Without the centre (2, 2, 2), the other 26 interior particles each border an empty
        // cell: everything is drawn.
        block.remove(62);
        let mut out = Vec::new();
        visible_particles(&block, s, &mut out);
        assert_eq!(out.len(), block.len());
        let far = vec![Vec3::ZERO, Vec3::splat(1e4)];
        visible_particles(&far, s, &mut out);
        assert_eq!(out, far);
        visible_particles(&[], s, &mut out);
        assert!(out.is_empty());
    }
}
