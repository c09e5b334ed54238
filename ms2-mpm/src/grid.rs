//! The background grid: its geometry, its boundary conditions, and the block-major node
//! storage the parallel transfers write into.
//!
//! Nodes sit at `origin + dx·(i, j, k)` for `0 <= i < resolution[0]` etc. Storage is padded by
//! one block of [`BLOCK`] nodes on every side and laid out block by block (`BLOCK³` nodes
//! contiguous), so that the transfers touch a few contiguous kilobytes per particle block.

use glam::Vec3;
use rayon::prelude::*;

use crate::error::MpmError;

/// Edge length (in nodes) of a storage block and of a particle bin.
pub const BLOCK: usize = 4;
const BLOCK_NODES: usize = BLOCK * BLOCK * BLOCK;

/// Geometry of the regular grid (SI units, world frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSpec {
    /// Position of node `(0, 0, 0)` (m).
    pub origin: Vec3,
    /// Node spacing `dx` (m); ManiSkill2 uses 0.005 to 0.015.
    pub cell_size: f32,
    /// Number of nodes along x, y, z.
    pub resolution: [usize; 3],
}

impl GridSpec {
    /// Grid of `resolution` nodes of spacing `cell_size` (m) starting at `origin` (m).
    pub fn new(origin: Vec3, cell_size: f32, resolution: [usize; 3]) -> Self {
        Self {
            origin,
            cell_size,
            resolution,
        }
    }

    /// Upper corner of the node lattice (m).
    pub fn max_corner(&self) -> Vec3 {
        self.origin
            + self.cell_size
                * Vec3::new(
                    self.resolution[0] as f32,
                    self.resolution[1] as f32,
                    self.resolution[2] as f32,
                )
    }

    pub(crate) fn validate(&self) -> Result<(), MpmError> {
        if !(self.cell_size.is_finite() && self.cell_size > 0.0) {
            return Err(MpmError::InvalidConfig {
                field: "grid.cell_size",
                value: self.cell_size.to_string(),
                expected: "a finite value > 0 m",
            });
        }
        if !self.origin.is_finite() {
            return Err(MpmError::InvalidConfig {
                field: "grid.origin",
                value: format!("{:?}", self.origin),
                expected: "finite coordinates (m)",
            });
        }
        if self.resolution.iter().any(|&n| !(8..=1024).contains(&n)) {
            return Err(MpmError::InvalidConfig {
                field: "grid.resolution",
                value: format!("{:?}", self.resolution),
                expected: "8 to 1024 nodes per axis",
            });
        }
        Ok(())
    }
}

/// How a domain wall treats grid velocities that point into it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WallKind {
    /// Material touching the wall stops (all velocity components zeroed).
    Sticky,
    /// Material may slide along and leave the wall; the velocity component into the wall is
    /// removed and the tangential one is reduced by Coulomb friction with this coefficient.
    Slip {
        /// Coulomb friction coefficient (0 = frictionless).
        friction: f32,
    },
    /// No wall: material flows freely until it reaches the domain's edge, where it is held
    /// (use only where material is not expected to arrive).
    Open,
}

/// Boundary conditions on the six faces of the domain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boundary {
    /// Walls `[axis][side]`, side 0 the low face (e.g. the floor for `z`) and 1 the high face.
    pub walls: [[WallKind; 2]; 3],
    /// Thickness of each wall in nodes (≥ 2); material is confined to the domain minus this
    /// band on every side.
    pub thickness: usize,
    /// Whether the walls' conditions also hold on the nodes of the usable domain's low faces
    /// (the floor's included), where particles are clamped (the high faces' nodes are wall
    /// nodes already). Without it those nodes are free: material resting on a low wall
    /// takes three quarters of its velocity from the free face node and keeps moving
    /// into the wall while its positions are clamped, so the grid sees no compression there.
    /// Clay's shear stiffness hides this; water (no shear) sinks into a thin sheet on the
    /// floor (a dam break kept 20 % of its depth), so fluids need it. Default `false`: the
    /// clay tasks were measured without it.
    pub constrain_face_nodes: bool,
}

impl Boundary {
    /// Every face the same kind of wall, 3 nodes thick.
    pub fn uniform(kind: WallKind) -> Self {
        Self {
            walls: [[kind; 2]; 3],
            thickness: 3,
            constrain_face_nodes: false,
        }
    }

    /// [`Self::uniform`] with [`Self::constrain_face_nodes`] set: the boundary for water.
    pub fn for_fluid(kind: WallKind) -> Self {
        Self {
            constrain_face_nodes: true,
            ..Self::uniform(kind)
        }
    }
}

impl Default for Boundary {
    /// Slip walls with friction 0.5 on every face (a floored box).
    fn default() -> Self {
        Self::uniform(WallKind::Slip { friction: 0.5 })
    }
}

/// The grid nodes that carry mass in the current substep, after the grid update (velocity,
/// gravity and the domain walls applied), as [`crate::ParticleForces::constrain_grid_nodes`]
/// sees them: it may overwrite their velocities before they are transferred back to the
/// particles.
pub struct GridNodes<'a> {
    storage: &'a mut GridStorage,
    spec: &'a GridSpec,
}

impl<'a> GridNodes<'a> {
    pub(crate) fn new(storage: &'a mut GridStorage, spec: &'a GridSpec) -> Self {
        Self { storage, spec }
    }

    /// The grid's layout.
    pub fn spec(&self) -> &GridSpec {
        self.spec
    }

    /// Calls `f(position, velocity, mass)` on every node with mass whose position (m, world)
    /// lies in the box `[lo, hi]`: `velocity` (m/s, world) may be changed in place, `mass`
    /// (kg) is what the particles transferred. Nodes are visited in storage order, on the
    /// calling thread.
    pub fn for_each_in_box(&mut self, lo: Vec3, hi: Vec3, mut f: impl FnMut(Vec3, &mut Vec3, f32)) {
        let spec = self.spec;
        let inv_dx = 1.0 / spec.cell_size;
        // Node index ranges of the box (real node indices, may be outside the resolution:
        // blocks only cover what particles touched).
        let first = ((lo - spec.origin) * inv_dx).ceil();
        let last = ((hi - spec.origin) * inv_dx).floor();
        if first.cmpgt(last).any() {
            return;
        }
        let [_, py, pz] = self.storage.padded_blocks;
        let b = BLOCK as i32;
        let storage = &mut *self.storage;
        for &block in &storage.active {
            let block = block as usize;
            let (bx, by, bz) = (block / (py * pz), (block / pz) % py, block % pz);
            // Real node index of the block's first node along each axis.
            let start = [bx, by, bz].map(|c| (c * BLOCK) as i32 - b);
            let outside =
                (0..3).any(|a| (start[a] + b - 1) < first[a] as i32 || start[a] > last[a] as i32);
            if outside {
                continue;
            }
            for l in 0..BLOCK_NODES {
                let ijk = [
                    start[0] + (l / (BLOCK * BLOCK)) as i32,
                    start[1] + ((l / BLOCK) % BLOCK) as i32,
                    start[2] + (l % BLOCK) as i32,
                ];
                if (0..3).any(|a| ijk[a] < first[a] as i32 || ijk[a] > last[a] as i32) {
                    continue;
                }
                let node = &mut storage.nodes[block * BLOCK_NODES + l];
                let m = node[3];
                if m <= 0.0 {
                    continue;
                }
                let x = spec.origin
                    + spec.cell_size * Vec3::new(ijk[0] as f32, ijk[1] as f32, ijk[2] as f32);
                let mut v = Vec3::new(node[0], node[1], node[2]);
                f(x, &mut v, m);
                node[0] = v.x;
                node[1] = v.y;
                node[2] = v.z;
            }
        }
    }
}

/// Grid nodes: momentum then velocity (m/s, xyz) and mass (kg, w).
pub(crate) struct GridStorage {
    pub nodes: Vec<[f32; 4]>,
    /// Storage blocks per axis including padding.
    pub padded_blocks: [usize; 3],
    /// Particle bins per axis (covering the real nodes).
    pub bins: [usize; 3],
    /// Indices of storage blocks that particles may touch (sorted ascending).
    pub active: Vec<u32>,
    /// Scratch of `set_active_from_bins`: one flag per storage block.
    mark: Vec<bool>,
}

impl GridStorage {
    pub fn new(spec: &GridSpec) -> Self {
        let bins = spec.resolution.map(|n| n.div_ceil(BLOCK));
        let padded_blocks = bins.map(|b| b + 2);
        let total = padded_blocks.iter().product::<usize>() * BLOCK_NODES;
        Self {
            nodes: vec![[0.0; 4]; total],
            padded_blocks,
            bins,
            active: Vec::new(),
            mark: Vec::new(),
        }
    }

    /// Storage index of real node `(i, j, k)` (each may be from −BLOCK to resolution+BLOCK−1).
    #[inline(always)]
    pub fn index(&self, i: i32, j: i32, k: i32) -> usize {
        let (pi, pj, pk) = (
            (i + BLOCK as i32) as usize,
            (j + BLOCK as i32) as usize,
            (k + BLOCK as i32) as usize,
        );
        let block = ((pi / BLOCK) * self.padded_blocks[1] + pj / BLOCK) * self.padded_blocks[2]
            + pk / BLOCK;
        block * BLOCK_NODES + ((pi % BLOCK) * BLOCK + pj % BLOCK) * BLOCK + pk % BLOCK
    }

    /// Marks the storage blocks touched by the given non-empty particle bins.
    /// `bins` holds `(bin index, first particle, end particle)` as in `Binning::bins`.
    pub fn set_active_from_bins(&mut self, bins: &[(u32, u32, u32)]) {
        let [_, by, bz] = self.bins;
        let [_, py, pz] = self.padded_blocks;
        let mark = &mut self.mark;
        mark.clear();
        mark.resize(self.padded_blocks.iter().product(), false);
        for &(b, _, _) in bins {
            let b = b as usize;
            let (x, y, z) = (b / (by * bz), (b / bz) % by, b % bz);
            // Bin b covers nodes [4b − 1, 4b + 6]: storage blocks b .. b + 2 (padded).
            for dx in 0..3 {
                for dy in 0..3 {
                    for dz in 0..3 {
                        mark[((x + dx) * py + y + dy) * pz + z + dz] = true;
                    }
                }
            }
        }
        self.active.clear();
        self.active.extend(
            mark.iter()
                .enumerate()
                .filter_map(|(i, &m)| m.then_some(i as u32)),
        );
    }

    /// Total mass (kg) on the active blocks (the only ones the last transfer wrote).
    pub fn active_mass(&self) -> f64 {
        self.active
            .iter()
            .flat_map(|&b| {
                let start = b as usize * BLOCK_NODES;
                &self.nodes[start..start + BLOCK_NODES]
            })
            .map(|n| n[3] as f64)
            .sum()
    }

    /// Zeroes every active block (on the calling thread: a memset, cheaper than waking
    /// threads at the sizes this solver runs).
    pub fn clear_active(&mut self) {
        for &b in &self.active {
            let start = b as usize * BLOCK_NODES;
            self.nodes[start..start + BLOCK_NODES].fill([0.0; 4]);
        }
    }

    /// Turns momentum into velocity, adds gravity and applies the boundary conditions, on
    /// every active node with mass.
    pub fn update_velocities(
        &mut self,
        spec: &GridSpec,
        boundary: &Boundary,
        dt: f32,
        gravity: Vec3,
    ) {
        let [_, py, pz] = self.padded_blocks;
        let res = spec.resolution.map(|n| n as i32);
        let t = boundary.thickness as i32;
        // Wall nodes: index below `low` or from `res − t` up. Particles are clamped to nodes
        // `t` and `res − t`: the high face node is a wall node, the low one only with
        // `constrain_face_nodes`.
        let low = t + i32::from(boundary.constrain_face_nodes);
        let nodes = crate::parallel::SyncPtr::new(self.nodes.as_mut_ptr());
        self.active.par_iter().for_each(|&b| {
            let b = b as usize;
            let (bx, by, bz) = (b / (py * pz), (b / pz) % py, b % pz);
            // SAFETY: distinct active blocks, disjoint ranges inside `nodes`.
            let block = unsafe { nodes.slice_mut(b * BLOCK_NODES, BLOCK_NODES) };
            for (l, node) in block.iter_mut().enumerate() {
                let m = node[3];
                if m <= 0.0 {
                    continue;
                }
                let mut v = Vec3::new(node[0], node[1], node[2]) / m + dt * gravity;
                let ijk = [
                    (bx * BLOCK + l / (BLOCK * BLOCK)) as i32 - BLOCK as i32,
                    (by * BLOCK + (l / BLOCK) % BLOCK) as i32 - BLOCK as i32,
                    (bz * BLOCK + l % BLOCK) as i32 - BLOCK as i32,
                ];
                for axis in 0..3 {
                    let side = if ijk[axis] < low {
                        0
                    } else if ijk[axis] >= res[axis] - t {
                        1
                    } else {
                        continue;
                    };
                    let outward = if side == 0 { -1.0 } else { 1.0 };
                    let vn = v[axis] * outward;
                    match boundary.walls[axis][side] {
                        WallKind::Sticky => v = Vec3::ZERO,
                        WallKind::Slip { friction } => {
                            if vn > 0.0 {
                                v[axis] = 0.0;
                                let vt = v.length();
                                if vt > 0.0 {
                                    v *= (1.0 - friction * vn / vt).max(0.0);
                                }
                            }
                        }
                        WallKind::Open => {}
                    }
                }
                *node = [v.x, v.y, v.z, m];
            }
        });
    }
}
