//! Two-way coupling with the in-crate rigid backend, checked by simulating it.

mod common;

use common::*;
use glam::{Mat3, Quat, Vec3};
use ms2_mpm::rigid::{Motion, SimpleRigidWorld};
use ms2_mpm::{
    sampling, Boundary, Coupling, CouplingParams, GridSpec, Material, MpmSolver, ParticleId,
    SolverConfig, WallKind,
};

/// ManiSkill2's rates: rigid 500 Hz, MPM 2000 Hz.
const SUBSTEPS: usize = 4;

fn clay_bed(s: &mut MpmSolver, top: f32) {
    let clay = s
        .add_material(Material::clay(1000.0, 1e4, 0.3, 2e3))
        .unwrap();
    let (lo, hi) = s.usable_domain();
    let pts = sampling::sample_box(
        Vec3::new(0.08, 0.08, lo.z),
        Vec3::new(hi.x.min(0.24), 0.24, top),
        SPACING,
    );
    s.add_particles(&pts, clay, SPACING.powi(3), Vec3::ZERO)
        .unwrap();
}

#[test]
fn box_resting_on_clay_feels_its_weight() {
    let mut s = solver(Boundary::default());
    clay_bed(&mut s, 0.06);
    // Let the bed settle under gravity first.
    run(&mut s, 200);
    let mut world = SimpleRigidWorld::new(s.config().gravity);
    let half = Vec3::new(0.025, 0.025, 0.015);
    let body = world.add_box(
        half,
        600.0,
        Vec3::new(0.16, 0.16, 0.06 + half.z + 0.004),
        Motion::Dynamic,
    );
    let weight = world.bodies[body].mass * 9.81;
    let mut coupling =
        Coupling::new(&world, CouplingParams::for_substep(s.config().substep_dt)).unwrap();
    let rigid_dt = SUBSTEPS as f32 * s.config().substep_dt;
    let mut support = Vec::new();
    for step in 0..300 {
        world.step(rigid_dt);
        coupling.advance(&mut s, &mut world, SUBSTEPS).unwrap();
        if step >= 200 {
            support.push(coupling.last_wrenches()[body].force.z);
        }
    }
    let mean = support.iter().sum::<f32>() / support.len() as f32;
    assert!(
        (mean - weight).abs() < 0.05 * weight,
        "coupling force {mean} N vs weight {weight} N"
    );
    // At rest, resting on (not sunk into or bounced off) the bed.
    let b = &world.bodies[body];
    assert!(
        b.linear_velocity.length() < 0.02,
        "box still moving: {:?}",
        b.linear_velocity
    );
    let bottom = b.position.z - half.z;
    assert!((0.045..0.07).contains(&bottom), "box bottom at {bottom} m");
    // No clay particle inside the box (beyond the contact offset).
    let inside = s
        .positions()
        .iter()
        .filter(|p| ((**p - b.position).abs() - half).max_element() < -0.003)
        .count();
    assert_eq!(inside, 0, "{inside} particles inside the box");
}

#[test]
fn plate_pushed_into_clay_deforms_it_and_feels_the_reaction() {
    let mut s = solver(Boundary::default());
    clay_bed(&mut s, 0.07);
    run(&mut s, 100);
    let mut world = SimpleRigidWorld::new(s.config().gravity);
    let half = Vec3::new(0.03, 0.03, 0.005);
    let start_z = 0.07 + half.z + 0.002;
    let plate = world.add_box(
        half,
        1000.0,
        Vec3::new(0.16, 0.16, start_z),
        Motion::Kinematic,
    );
    world.bodies[plate].linear_velocity = Vec3::new(0.0, 0.0, -0.2);
    let mut coupling =
        Coupling::new(&world, CouplingParams::for_substep(s.config().substep_dt)).unwrap();
    let rigid_dt = SUBSTEPS as f32 * s.config().substep_dt;
    let under_plate = |s: &MpmSolver, centre: Vec3| {
        s.positions()
            .iter()
            .filter(|p| {
                (p.x - centre.x).abs() < half.x - 0.005 && (p.y - centre.y).abs() < half.y - 0.005
            })
            .map(|p| p.z)
            .fold(f32::MIN, f32::max)
    };
    let top_before = under_plate(&s, world.bodies[plate].position);
    let mut early = 0.0;
    for step in 0..75 {
        world.step(rigid_dt);
        coupling.advance(&mut s, &mut world, SUBSTEPS).unwrap();
        if step == 25 {
            early = coupling.last_wrenches()[plate].force.z;
        }
    }
    // 75 steps × 2 ms × 0.2 m/s = 3 cm down, i.e. ~2.3 cm into the clay.
    let p = world.bodies[plate].position;
    let reaction = coupling.last_wrenches()[plate].force.z;
    let top_after = under_plate(&s, p);
    assert!(
        top_after < top_before - 0.015,
        "clay top under the plate {top_before} -> {top_after} m"
    );
    assert!(
        top_after < p.z - half.z + 0.004,
        "clay above the plate's bottom face"
    );
    assert!(reaction > 1.0, "plate feels only {reaction} N");
    assert!(
        reaction > early,
        "reaction should grow with depth: {early} -> {reaction} N"
    );
    // The clay pushed sideways rises around the plate (plastic flow), conserving volume.
    let rim = s
        .positions()
        .iter()
        .filter(|q| (q.x - p.x).abs() > half.x + 0.005 || (q.y - p.y).abs() > half.y + 0.005)
        .map(|q| q.z)
        .fold(f32::MIN, f32::max);
    assert!(
        rim > top_before + 0.002,
        "no bulge around the plate: rim {rim} m"
    );
}

#[test]
fn mesh_collider_pushes_like_the_equivalent_box() {
    let half = Vec3::new(0.03, 0.03, 0.01);
    let mut forces = Vec::new();
    for use_mesh in [false, true] {
        let mut s = solver(Boundary::default());
        clay_bed(&mut s, 0.06);
        let mut world = SimpleRigidWorld::new(s.config().gravity);
        let plate = world.add_box(
            half,
            1000.0,
            Vec3::new(0.16, 0.16, 0.06 + half.z),
            Motion::Kinematic,
        );
        if use_mesh {
            world.bodies[plate].shapes = vec![ms2_mpm::CollisionShape::at_body_origin(
                ms2_mpm::ShapeGeometry::TriMesh(ms2_mpm::TriMesh::cuboid(half)),
            )];
        }
        world.bodies[plate].linear_velocity = Vec3::new(0.0, 0.0, -0.2);
        let mut coupling =
            Coupling::new(&world, CouplingParams::for_substep(s.config().substep_dt)).unwrap();
        for _ in 0..40 {
            world.step(0.002);
            coupling.advance(&mut s, &mut world, SUBSTEPS).unwrap();
        }
        forces.push(coupling.last_wrenches()[plate].force.z);
    }
    assert!(forces[0] > 0.5, "box reaction {} N", forces[0]);
    assert!(
        (forces[1] - forces[0]).abs() < 0.2 * forces[0],
        "box {} N vs mesh {} N",
        forces[0],
        forces[1]
    );
}

#[test]
fn coupled_runs_are_deterministic_for_any_thread_count() {
    let sim = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut s = solver(Boundary::default());
            clay_bed(&mut s, 0.05);
            let mut world = SimpleRigidWorld::new(s.config().gravity);
            let body = world.add_box(
                Vec3::new(0.02, 0.03, 0.01),
                800.0,
                Vec3::new(0.15, 0.17, 0.07),
                Motion::Dynamic,
            );
            // Off-centre and spinning, so that torques matter too.
            world.bodies[body].angular_velocity = Vec3::new(1.0, -2.0, 3.0);
            let mut coupling =
                Coupling::new(&world, CouplingParams::for_substep(s.config().substep_dt)).unwrap();
            for _ in 0..60 {
                world.step(0.002);
                coupling.advance(&mut s, &mut world, SUBSTEPS).unwrap();
            }
            (world.bodies[body].clone(), s.state())
        })
    };
    let (body_a, soft_a) = sim(1);
    let (body_b, soft_b) = sim(2);
    assert!(
        body_a == body_b,
        "rigid body differs: {body_a:?} vs {body_b:?}"
    );
    assert!(
        soft_a == soft_b,
        "soft state differs between 1 and 2 threads"
    );
    assert!(
        body_a.coupling_force.length() > 0.0,
        "the box never touched the clay"
    );
}

#[test]
fn bad_coupling_input_is_refused() {
    let mut world = SimpleRigidWorld::new(Vec3::new(0.0, 0.0, -9.81));
    world.add_box(
        Vec3::splat(0.02),
        500.0,
        Vec3::new(0.1, 0.1, 0.1),
        Motion::Dynamic,
    );
    let mut params = CouplingParams::for_substep(5e-4);
    params.friction = f32::NAN;
    let err = Coupling::new(&world, params)
        .err()
        .expect("NaN friction must be refused");
    assert!(err.to_string().contains("friction"), "{err}");
    let mut coupling = Coupling::new(&world, CouplingParams::for_substep(5e-4)).unwrap();
    world.add_box(
        Vec3::splat(0.02),
        500.0,
        Vec3::new(0.2, 0.1, 0.1),
        Motion::Dynamic,
    );
    assert!(matches!(
        coupling.sync_bodies(&world),
        Err(ms2_mpm::MpmError::BodyCountChanged {
            expected: 1,
            got: 2
        })
    ));
    world.bodies[0].position.x = f32::INFINITY;
    world.bodies.pop();
    assert!(matches!(
        coupling.sync_bodies(&world),
        Err(ms2_mpm::MpmError::NonFiniteInput { .. })
    ));
}

#[test]
fn distance_to_body_follows_the_synced_pose() {
    let mut world = SimpleRigidWorld::new(Vec3::ZERO);
    let b = world.add_box(
        Vec3::new(0.02, 0.03, 0.04),
        500.0,
        Vec3::new(0.1, 0.1, 0.1),
        Motion::Kinematic,
    );
    let mut coupling = Coupling::new(&world, CouplingParams::for_substep(5e-4)).unwrap();
    let d = coupling
        .distance_to_body(b, Vec3::new(0.1, 0.1, 0.2))
        .unwrap();
    assert!((d - 0.06).abs() < 1e-6, "{d}");
    // Turn the box 90° about x: its z half extent becomes 3 cm.
    world.bodies[b].rotation = glam::Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    coupling.sync_bodies(&world).unwrap();
    let d = coupling
        .distance_to_body(b, Vec3::new(0.1, 0.1, 0.2))
        .unwrap();
    assert!((d - 0.07).abs() < 1e-5, "{d}");
    assert!(
        coupling
            .distance_to_body(b, Vec3::new(0.1, 0.1, 0.1))
            .unwrap()
            < 0.0
    );
    assert!(coupling.distance_to_body(7, Vec3::ZERO).is_err());
}

#[test]
fn thin_plate_lifts_the_clay_above_it_out_of_a_bed() {
    // A 6 mm thick plate (less than a grid cell) buried in a clay bed and lifted: the clay on
    // top rises with it, the clay below stays. Material on both sides of a wall this thin
    // shares grid nodes; without the compatibility masks (`ParticleForces::blocked_nodes`)
    // the two sides move together through the wall.
    let mut s = solver(Boundary::uniform(WallKind::Sticky));
    clay_bed(&mut s, 0.075);
    let mut world = SimpleRigidWorld::new(s.config().gravity);
    let half = Vec3::new(0.03, 0.03, 0.003);
    let centre = Vec3::new(0.16, 0.16, 0.05);
    s.retain_particles(|_, p, _, _| ((p - centre).abs() - half).max_element() > 0.003);
    run(&mut s, 100);
    let plate = world.add_box(half, 1000.0, centre, Motion::Kinematic);
    let mut coupling =
        Coupling::new(&world, CouplingParams::for_substep(s.config().substep_dt)).unwrap();
    let footprint = |s: &MpmSolver, above: bool| -> Vec<ParticleId> {
        s.particle_ids()
            .iter()
            .zip(s.positions())
            .filter(|(_, p)| {
                (p.x - centre.x).abs() < half.x - 0.005
                    && (p.y - centre.y).abs() < half.y - 0.005
                    && (p.z > centre.z) == above
            })
            .map(|(id, _)| *id)
            .collect()
    };
    let (on_plate, under_plate) = (footprint(&s, true), footprint(&s, false));
    let mean_z = |s: &MpmSolver, ids: &[ParticleId]| {
        let (sum, n) = s
            .particle_ids()
            .iter()
            .zip(s.positions())
            .filter(|(id, _)| ids.contains(id))
            .fold((0.0, 0), |(sum, n), (_, p)| (sum + p.z, n + 1));
        sum / n as f32
    };
    let (before_on, before_under) = (mean_z(&s, &on_plate), mean_z(&s, &under_plate));
    let rigid_dt = SUBSTEPS as f32 * s.config().substep_dt;
    world.bodies[plate].linear_velocity = Vec3::new(0.0, 0.0, 0.1);
    // 150 rigid steps of 2 ms at 0.1 m/s: the plate rises 3 cm.
    for _ in 0..150 {
        world.step(rigid_dt);
        coupling.advance(&mut s, &mut world, SUBSTEPS).unwrap();
    }
    let rise = world.bodies[plate].position.z - centre.z;
    let carried = mean_z(&s, &on_plate) - before_on;
    let dragged = mean_z(&s, &under_plate) - before_under;
    assert!(
        carried > 0.6 * rise,
        "clay above the plate rose {carried} m while the plate rose {rise} m"
    );
    // The clay below stays on the (sticky) floor instead of being pulled up through the
    // plate along the grid nodes it shares with the clay above (2.5 cm without the masks).
    assert!(
        dragged.abs() < 0.2 * rise,
        "clay under the plate moved {dragged} m while the plate rose {rise} m"
    );
    // The clay it tore free pulled back on it (downwards).
    assert!(coupling.last_wrenches()[plate].force.z < 0.0);
}

#[test]
fn clay_near_a_thin_plate_keeps_its_momentum_when_nothing_touches_it() {
    // No gravity, no contact (zero contact offset, and the clay 5 mm clear of a tilted 6 mm
    // plate): only the clay's own stress and affine motion act, and those are internal, so
    // the clay's momentum must stay zero. Its lowest layer reaches stencil nodes across the
    // plate, which the compatibility masks block; taken about the particles instead of the
    // nodes they reach, the stress of a compressed slab pushed it off the plate (the
    // contact-free cushion the scripted scoop's clay slid out of the bucket on) and its
    // shear added momentum every substep.
    let grid = GridSpec::new(Vec3::ZERO, 0.01, [32; 3]);
    let mut config = SolverConfig::new(grid);
    config.gravity = Vec3::ZERO;
    config.boundary = Boundary::uniform(WallKind::Sticky);
    let mut s = MpmSolver::new(config).unwrap();
    let clay = s
        .add_material(Material::clay(1000.0, 1e4, 0.3, 2e3))
        .unwrap();
    let mut world = SimpleRigidWorld::new(Vec3::ZERO);
    let half = Vec3::new(0.05, 0.05, 0.003);
    let centre = Vec3::new(0.16, 0.16, 0.1);
    let plate = world.add_box(half, 1000.0, centre, Motion::Kinematic);
    let tilt = Quat::from_rotation_y(-15f32.to_radians());
    world.bodies[plate].rotation = tilt;
    // A 4 × 4 × 2 cm slab on the plate, in the plate's frame, 5 mm above its top.
    let local = sampling::sample_box(
        Vec3::new(-0.02, -0.02, half.z + 0.005),
        Vec3::new(0.02, 0.02, half.z + 0.025),
        SPACING,
    );
    let pts: Vec<Vec3> = local.iter().map(|p| centre + tilt * *p).collect();
    s.add_particles(&pts, clay, SPACING.powi(3), Vec3::ZERO)
        .unwrap();
    // Compressed by 10 % and sheared at 2 /s about its centre of mass: zero momentum.
    let mut state = s.state();
    let com = state.positions.iter().sum::<Vec3>() / state.positions.len() as f32;
    let shear = Mat3::from_cols(Vec3::ZERO, Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0));
    for i in 0..state.positions.len() {
        state.deformation_gradients[i] = Mat3::from_diagonal(Vec3::splat(0.9));
        state.affine_velocities[i] = shear;
        state.velocities[i] = shear * (state.positions[i] - com);
    }
    s.set_state(&state).unwrap();
    let params = CouplingParams {
        contact_offset: 0.0,
        ..CouplingParams::for_substep(s.config().substep_dt)
    };
    let mut coupling = Coupling::new(&world, params).unwrap();
    let speed_sum = |s: &MpmSolver| -> f64 {
        s.velocities()
            .iter()
            .zip(s.masses())
            .map(|(v, m)| (v.length() * m) as f64)
            .sum()
    };
    for _ in 0..4 {
        s.substep_with_forces(&mut coupling).unwrap();
        let p = s.total_momentum();
        let p_len = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        assert!(
            p_len < 1e-3 * speed_sum(&s),
            "momentum {p:?} kg·m/s against Σ m|v| = {} kg·m/s",
            speed_sum(&s)
        );
    }
    assert_eq!(coupling.last_wrenches()[plate].force, Vec3::ZERO);
}

/// A 4 × 4 × 3 cm clay block (1000 kg/m³) settled on the floor of the common 32³ grid; its
/// bounds (m).
fn settled_block(s: &mut MpmSolver) -> (Vec3, Vec3) {
    let clay = s
        .add_material(Material::clay(1000.0, 1e4, 0.3, 2e3))
        .unwrap();
    let (lo, _) = s.usable_domain();
    let pts = sampling::sample_box(
        Vec3::new(0.14, 0.14, lo.z),
        Vec3::new(0.18, 0.18, lo.z + 0.03),
        SPACING,
    );
    s.add_particles(&pts, clay, SPACING.powi(3), Vec3::ZERO)
        .unwrap();
    run(s, 100);
    let lo = s.positions().iter().fold(Vec3::MAX, |a, p| a.min(*p));
    let hi = s.positions().iter().fold(Vec3::MIN, |a, p| a.max(*p));
    (lo, hi)
}

/// Two frictionless kinematic pads squeeze the block from ±x (1 mm each in 0.05 s), lift it
/// at 0.1 m/s for 0.3 s, then open at 0.1 m/s for 0.1 s and stay 0.2 s. Returns the block's
/// rise (m) at the top of the lift and at the end, and the pads' mean vertical coupling force
/// (N) over the last 50 rigid steps of the lift. Timeline in 2 ms rigid steps: squeeze 25,
/// lift 150, open 50 (1 cm each), stay 100.
fn pinch_and_lift(sticky_reach: Option<f32>) -> (f32, f32, f32) {
    let mut s = solver(Boundary::uniform(WallKind::Slip { friction: 0.5 }));
    let (lo, hi) = settled_block(&mut s);
    let half = Vec3::new(0.003, 0.03, 0.012);
    let params = CouplingParams {
        friction: 0.0,
        ..CouplingParams::for_substep(s.config().substep_dt)
    };
    let z = lo.z + half.z;
    let gap = params.contact_offset + half.x;
    let mut world = SimpleRigidWorld::new(Vec3::ZERO);
    let pads = [
        world.add_box(
            half,
            1000.0,
            Vec3::new(lo.x - gap, 0.16, z),
            Motion::Kinematic,
        ),
        world.add_box(
            half,
            1000.0,
            Vec3::new(hi.x + gap, 0.16, z),
            Motion::Kinematic,
        ),
    ];
    let mut coupling = Coupling::new(&world, params).unwrap();
    for pad in pads {
        coupling.set_sticky_nodes(pad, sticky_reach).unwrap();
    }
    let before = center_of_mass(&s).z;
    let rigid_dt = SUBSTEPS as f32 * s.config().substep_dt;
    let mut lift_force = Vec::new();
    let mut lifted = 0.0;
    for step in 0..325 {
        let (inward, up) = match step {
            0..25 => (0.02, 0.0),
            25..175 => (0.0, 0.1),
            175..225 => (-0.1, 0.0),
            _ => (0.0, 0.0),
        };
        world.bodies[pads[0]].linear_velocity = Vec3::new(inward, 0.0, up);
        world.bodies[pads[1]].linear_velocity = Vec3::new(-inward, 0.0, up);
        world.step(rigid_dt);
        coupling.advance(&mut s, &mut world, SUBSTEPS).unwrap();
        if (125..175).contains(&step) {
            let w = coupling.last_wrenches();
            lift_force.push(w[pads[0]].force.z + w[pads[1]].force.z);
        }
        if step == 174 {
            lifted = center_of_mass(&s).z - before;
        }
    }
    let mean_force = lift_force.iter().sum::<f32>() / lift_force.len() as f32;
    (lifted, center_of_mass(&s).z - before, mean_force)
}

#[test]
fn sticky_pads_lift_a_pinched_block_and_let_it_go_when_they_open() {
    // Frictionless pads: the penalty contact alone cannot lift the block.
    let (lifted, _, _) = pinch_and_lift(None);
    assert!(
        lifted.abs() < 0.005,
        "block rose {lifted} m between frictionless pads"
    );
    // Sticky nodes within a cell of the pads hold it: it rises with them (3 cm) and
    // weighs on them, and falls back when they open.
    let (lifted, end, force) = pinch_and_lift(Some(0.01));
    assert!(
        lifted > 0.02,
        "block rose {lifted} m while the sticky pads rose 0.03 m"
    );
    let weight = 1000.0 * 0.04 * 0.04 * 0.03 * 9.81;
    assert!(
        force < -0.5 * weight && force > -2.0 * weight,
        "pads' force {force} N against the block's weight {weight} N"
    );
    assert!(
        end < 0.3 * lifted,
        "block still {end} m up after the pads opened"
    );
}

#[test]
fn a_sticky_surface_does_not_pull_material_by_adhesion() {
    // A sticky plate touching the block's top and rising moves away from it along its own
    // normal: the block stays on the floor.
    let mut s = solver(Boundary::uniform(WallKind::Slip { friction: 0.5 }));
    let (_, hi) = settled_block(&mut s);
    let mut world = SimpleRigidWorld::new(Vec3::ZERO);
    let half = Vec3::new(0.03, 0.03, 0.003);
    let plate = world.add_box(
        half,
        1000.0,
        Vec3::new(0.16, 0.16, hi.z + 0.0025 + half.z),
        Motion::Kinematic,
    );
    let mut coupling =
        Coupling::new(&world, CouplingParams::for_substep(s.config().substep_dt)).unwrap();
    coupling.set_sticky_nodes(plate, Some(0.01)).unwrap();
    let before = center_of_mass(&s).z;
    world.bodies[plate].linear_velocity = Vec3::new(0.0, 0.0, 0.1);
    let rigid_dt = SUBSTEPS as f32 * s.config().substep_dt;
    for _ in 0..150 {
        world.step(rigid_dt);
        coupling.advance(&mut s, &mut world, SUBSTEPS).unwrap();
    }
    let rise = center_of_mass(&s).z - before;
    assert!(
        rise.abs() < 0.003,
        "block rose {rise} m under a rising sticky plate"
    );
}

#[test]
fn sticky_nodes_refuse_bad_input() {
    let world = {
        let mut w = SimpleRigidWorld::new(Vec3::ZERO);
        w.add_box(
            Vec3::splat(0.01),
            1000.0,
            Vec3::splat(0.1),
            Motion::Kinematic,
        );
        w
    };
    let mut coupling = Coupling::new(&world, CouplingParams::for_substep(5e-4)).unwrap();
    assert!(coupling.set_sticky_nodes(1, Some(0.01)).is_err());
    for bad in [0.0, -0.01, f32::NAN, f32::INFINITY] {
        let err = coupling.set_sticky_nodes(0, Some(bad)).unwrap_err();
        assert!(err.to_string().contains("sticky reach"), "{err}");
    }
    coupling.set_sticky_nodes(0, Some(0.01)).unwrap();
    coupling.set_sticky_nodes(0, None).unwrap();
}
