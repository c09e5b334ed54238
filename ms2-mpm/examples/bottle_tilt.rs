//! Water in a kinematic bottle (Pour-v0's: 12 box staves around a 2.55 cm interior, 1 cm
//! bottom, flat shoulder at 12 cm, 8-stave neck of 1.3 cm inner radius up to 15 cm) tipped
//! over about a horizontal axis: prints, per 5° of tilt, the particles out of the bottle, the
//! mean volume ratio and the largest speed. The tilt to measure Pour-v0's outflow against
//! (the bottle's static outflow angle is about 75-80° for 7-9 cm of water).
//!
//! ```text
//! cargo run --release -p ms2-mpm --example bottle_tilt -- [density=1000] [height=0.08] [rate=0.4 rad/s]
//! ```
//! `FRICTION`, `OFFSET` override the coupling's friction and contact offset (m).

use glam::{Quat, Vec3};
use ms2_mpm::rigid::{Motion, SimpleBody, SimpleRigidWorld};
use ms2_mpm::{
    sampling, Boundary, CollisionShape, Coupling, CouplingParams, GridSpec, Material, MpmSolver,
    ShapeGeometry, SolverConfig, WallKind,
};

const DX: f32 = 0.005;
const SPACING: f32 = 0.0025;
const K: f32 = 3e5 * 0.1 / (1.1 * 0.8);
/// Bottle frame origin (on its axis at the table) relative to the body's origin, which is
/// the pivot (the grasp, 5 cm up).
const PIVOT_UP: f32 = 0.05;

fn stave_ring(n: usize, inner: f32, half_t: f32, z0: f32, z1: f32, out: &mut Vec<CollisionShape>) {
    let r = inner + half_t;
    let hw = (r + half_t) * (std::f32::consts::PI / n as f32).tan();
    for k in 0..n {
        let a = std::f32::consts::TAU * k as f32 / n as f32;
        out.push(CollisionShape {
            geometry: ShapeGeometry::Box {
                half_extents: Vec3::new(half_t, hw, 0.5 * (z1 - z0)),
            },
            position_in_body: Vec3::new(r * a.cos(), r * a.sin(), 0.5 * (z0 + z1) - PIVOT_UP),
            rotation_in_body: Quat::from_rotation_z(a),
        });
    }
}

fn bottle_shapes() -> Vec<CollisionShape> {
    let (wall, inner, outer) = (0.001, 0.0255, 0.0275);
    let mut s = vec![CollisionShape {
        geometry: ShapeGeometry::Cylinder {
            half_height: 0.005,
            radius: outer,
        },
        position_in_body: Vec3::new(0.0, 0.0, 0.005 - PIVOT_UP),
        rotation_in_body: Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
    }];
    stave_ring(12, inner, wall, 0.01, 0.122, &mut s);
    let (r0, r1) = (0.013, outer);
    let hw = r1 * (std::f32::consts::PI / 12.0).tan();
    for k in 0..12 {
        let a = std::f32::consts::TAU * (k as f32 + 0.5) / 12.0;
        let mid = 0.5 * (r0 + r1);
        s.push(CollisionShape {
            geometry: ShapeGeometry::Box {
                half_extents: Vec3::new(0.5 * (r1 - r0), hw, wall),
            },
            position_in_body: Vec3::new(mid * a.cos(), mid * a.sin(), 0.121 - PIVOT_UP),
            rotation_in_body: Quat::from_rotation_z(a),
        });
    }
    stave_ring(8, 0.013, wall, 0.12, 0.15, &mut s);
    s
}

fn main() {
    let args: Vec<f32> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let density = args.first().copied().unwrap_or(1000.0);
    let height = args.get(1).copied().unwrap_or(0.08);
    let rate = args.get(2).copied().unwrap_or(0.4);
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f32>().ok());
    let origin = Vec3::new(-0.13, -0.2, -3.0 * DX);
    let mut config = SolverConfig::new(GridSpec::new(origin, DX, [58, 60, 66]));
    config.boundary = Boundary::for_fluid(WallKind::Slip { friction: 0.5 });
    let mut solver = MpmSolver::new(config).unwrap();
    let water = solver.add_material(Material::water(density, K)).unwrap();
    // Bottle standing at the world origin, pivot 5 cm up; water from 1 cm up.
    let layers = 36.0;
    let pts: Vec<Vec3> =
        sampling::sample_cylinder(Vec3::new(0.0, 0.0, 0.01), 0.024, layers * SPACING, SPACING)
            .into_iter()
            .map(|p| {
                let k = ((p.z - 0.01) / SPACING - 0.5).round();
                p.truncate().extend(0.01 + (k + 0.5) * height / layers)
            })
            .collect();
    let volume = SPACING * SPACING * height / layers;
    solver
        .add_particles(&pts, water, volume, Vec3::ZERO)
        .unwrap();
    let mut world = SimpleRigidWorld::new(solver.config().gravity);
    world.bodies.push(SimpleBody {
        mass: 0.1,
        inertia: Vec3::splat(1e-4),
        position: Vec3::new(0.0, 0.0, PIVOT_UP),
        rotation: Quat::IDENTITY,
        linear_velocity: Vec3::ZERO,
        angular_velocity: Vec3::ZERO,
        shapes: bottle_shapes(),
        motion: Motion::Kinematic,
        coupling_force: Vec3::ZERO,
        coupling_torque: Vec3::ZERO,
    });
    let mut params = CouplingParams::for_substep(1e-3);
    if let Some(f) = env("FRICTION") {
        params.friction = f;
    }
    if let Some(o) = env("OFFSET") {
        params.contact_offset = o;
    }
    let mut coupling = Coupling::new(&world, params).unwrap();
    let rigid_dt = 2e-3;
    // Settle 0.3 s, tip to 50° at 1 rad/s, then `rate` up to 110°, about world x (the mouth
    // goes towards −y).
    let mut tilt = 0.0f32;
    let mut t = 0.0f32;
    let mut next_report = 50.0f32;
    let start = std::time::Instant::now();
    while tilt < 110f32.to_radians() {
        let w = if t < 0.3 {
            0.0
        } else if tilt < 50f32.to_radians() {
            1.0
        } else {
            rate
        };
        world.bodies[0].angular_velocity = Vec3::new(w, 0.0, 0.0);
        world.step(rigid_dt);
        tilt += w * rigid_dt;
        t += rigid_dt;
        coupling
            .advance(&mut solver, &mut world, 4)
            .unwrap_or_else(|e| panic!("t {t}: {e}"));
        if tilt.to_degrees() >= next_report {
            next_report += 5.0;
            let b = &world.bodies[0];
            let inv = b.rotation.inverse();
            let x = solver.positions();
            let out = x
                .iter()
                .filter(|p| {
                    let l = inv * (**p - b.position) + Vec3::Z * PIVOT_UP;
                    l.truncate().length() > 0.0275 || l.z > 0.15 || l.z < 0.0
                })
                .count();
            let in_neck = x
                .iter()
                .filter(|p| {
                    let l = inv * (**p - b.position) + Vec3::Z * PIVOT_UP;
                    l.truncate().length() < 0.0275 && l.z > 0.12 && l.z <= 0.15
                })
                .count();
            let j = solver
                .deformation_gradients()
                .iter()
                .map(|f| f.determinant())
                .sum::<f32>()
                / x.len() as f32;
            let vmax = solver
                .velocities()
                .iter()
                .map(|v| v.length())
                .fold(0.0, f32::max);
            println!(
                "tilt {:5.1}° t {t:.2} s: out {out:5} in neck {in_neck:4} mean J {j:.4} vmax {vmax:.2} ({:.0} s)",
                tilt.to_degrees(),
                start.elapsed().as_secs_f32()
            );
        }
    }
}
