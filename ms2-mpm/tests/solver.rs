//! Behaviour of the solver, checked by simulating it.

mod common;

use common::*;
use glam::{Mat3, Vec3};
use ms2_mpm::{sampling, Boundary, Material, WallKind};

#[test]
fn mass_is_conserved_exactly() {
    let mut s = solver(Boundary::default());
    let clay = s
        .add_material(Material::clay(1200.0, 1e4, 0.3, 2e3))
        .unwrap();
    let pts = sampling::sample_box(
        Vec3::new(0.1, 0.1, 0.06),
        Vec3::new(0.18, 0.18, 0.12),
        SPACING,
    );
    s.add_particles(&pts, clay, SPACING.powi(3), Vec3::new(0.2, 0.0, -0.5))
        .unwrap();
    let expected = pts.len() as f64 * (1200.0f32 * SPACING.powi(3)) as f64;
    let before = s.total_mass();
    run(&mut s, 200);
    assert_eq!(s.particle_count(), pts.len());
    assert_eq!(s.total_mass(), before, "particle masses never change");
    assert!((before - expected).abs() / expected < 1e-6);
    // Particle-to-grid distributes every particle's whole mass (B-spline weights sum to 1).
    assert!(
        (s.grid_mass() - before).abs() / before < 1e-5,
        "grid {} vs particles {before}",
        s.grid_mass()
    );
}

#[test]
fn momentum_is_conserved_in_free_flight() {
    let mut s = solver(Boundary::uniform(WallKind::Open));
    let rubber = s.add_material(Material::elastic(1000.0, 5e4, 0.3)).unwrap();
    let mut pts = sampling::sample_box(Vec3::splat(0.12), Vec3::splat(0.2), SPACING);
    sampling::jitter(&mut pts, 0.001, 11);
    s.add_particles(&pts, rubber, SPACING.powi(3), Vec3::new(0.3, -0.2, 0.1))
        .unwrap();
    // Give the body internal stress and spin: squash it and rotate it about z.
    let mut state = s.state();
    let centre = Vec3::splat(0.16);
    for (i, p) in state.positions.iter().enumerate() {
        state.deformation_gradients[i] = Mat3::from_diagonal(Vec3::new(1.05, 0.97, 1.0));
        state.velocities[i] += Vec3::Z.cross(*p - centre) * 2.0;
    }
    s.set_state(&state).unwrap();
    let mut config = *s.config();
    config.gravity = Vec3::ZERO;
    let mut s2 = ms2_mpm::MpmSolver::new(config).unwrap();
    s2.add_material(Material::elastic(1000.0, 5e4, 0.3))
        .unwrap();
    s2.set_state(&state).unwrap();
    let p0 = s2.total_momentum();
    let norm0 = p0.iter().map(|x| x * x).sum::<f64>().sqrt();
    run(&mut s2, 200);
    let p1 = s2.total_momentum();
    let diff = (0..3).map(|a| (p1[a] - p0[a]).powi(2)).sum::<f64>().sqrt();
    assert!(diff / norm0 < 1e-4, "momentum {p0:?} -> {p1:?}");
    // And the body did deform (the stress was active): velocities are no longer rigid.
    assert!(max_speed(&s2) > 0.0);
}

#[test]
fn clay_cube_dropped_on_the_floor_settles_above_it() {
    let mut s = solver(Boundary::default());
    let clay = s
        .add_material(Material::clay(1000.0, 1e4, 0.3, 2e3))
        .unwrap();
    let lo = Vec3::new(0.12, 0.12, 0.08);
    let pts = sampling::sample_box(lo, lo + Vec3::splat(0.06), SPACING);
    s.add_particles(&pts, clay, SPACING.powi(3), Vec3::ZERO)
        .unwrap();
    let (domain_lo, _) = s.usable_domain();
    let floor = domain_lo.z;
    run(&mut s, 1200);
    // At rest: no particle faster than 5 cm/s.
    assert!(
        max_speed(&s) < 0.05,
        "still moving at {} m/s",
        max_speed(&s)
    );
    // Held by the floor's boundary condition, not by the domain clamp: no particle sits at
    // (or below) the clamp plane, and the lowest ones are within a cell of the floor.
    let min_z = s.positions().iter().map(|p| p.z).fold(f32::MAX, f32::min);
    assert!(
        min_z > floor + 1e-4,
        "lowest particle {min_z} m at the clamp plane {floor} m"
    );
    assert!(
        min_z < floor + 0.012,
        "cube did not reach the floor: lowest particle {min_z} m"
    );
    // Plastic: the impact at ~1.3 m/s flattened it for good (height lost, footprint grown).
    let top = s.positions().iter().map(|p| p.z).fold(f32::MIN, f32::max);
    assert!(
        top - min_z < 0.055,
        "height {} m: the cube did not flatten",
        top - min_z
    );
}

#[test]
fn water_spreads_over_the_floor() {
    let mut s = solver(Boundary::default());
    let water = s.add_material(Material::water(1000.0, 2e4)).unwrap();
    let lo = Vec3::new(0.13, 0.13, 0.035);
    let pts = sampling::sample_box(lo, lo + Vec3::new(0.06, 0.06, 0.08), SPACING);
    s.add_particles(&pts, water, SPACING.powi(3), Vec3::ZERO)
        .unwrap();
    let extent = |s: &ms2_mpm::MpmSolver| {
        let xs = s.positions().iter().map(|p| p.x);
        xs.clone().fold(f32::MIN, f32::max) - xs.fold(f32::MAX, f32::min)
    };
    let (w0, h0) = (extent(&s), center_of_mass(&s).z);
    run(&mut s, 800);
    let (w1, h1) = (extent(&s), center_of_mass(&s).z);
    assert!(w1 > 2.0 * w0, "width {w0} -> {w1} m: water did not spread");
    assert!(
        h1 < h0 - 0.015,
        "centre of mass {h0} -> {h1} m: water did not fall"
    );
}

#[test]
fn elastic_cube_bounces() {
    let mut s = solver(Boundary::uniform(WallKind::Slip { friction: 0.0 }));
    let rubber = s.add_material(Material::elastic(1000.0, 5e4, 0.3)).unwrap();
    let lo = Vec3::new(0.13, 0.13, 0.09);
    let pts = sampling::sample_box(lo, lo + Vec3::splat(0.05), SPACING);
    s.add_particles(&pts, rubber, SPACING.powi(3), Vec3::new(0.0, 0.0, -1.0))
        .unwrap();
    let mut max_up = f32::MIN;
    let mut min_v = 0.0f32;
    for _ in 0..500 {
        s.substep().unwrap();
        let v = mean_velocity(&s).z;
        min_v = min_v.min(v);
        // Only count upward motion after the impact (once falling has stopped).
        if min_v < -1.0 {
            max_up = max_up.max(v);
        }
    }
    assert!(min_v < -1.1, "never fell fast: {min_v}");
    assert!(
        max_up > 0.3 * -min_v,
        "rebound {max_up} m/s after impact at {min_v} m/s"
    );
}

#[test]
fn runs_are_deterministic_for_any_thread_count() {
    let make = || {
        let mut s = solver(Boundary::default());
        let clay = s
            .add_material(Material::clay(1000.0, 1e4, 0.3, 2e3))
            .unwrap();
        let mut pts = sampling::sample_box(
            Vec3::new(0.1, 0.1, 0.05),
            Vec3::new(0.2, 0.16, 0.1),
            SPACING,
        );
        sampling::jitter(&mut pts, 0.001, 42);
        s.add_particles(&pts, clay, SPACING.powi(3), Vec3::new(0.5, 0.2, -1.0))
            .unwrap();
        s
    };
    let sim = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut s = make();
        pool.install(|| run(&mut s, 150));
        s.state()
    };
    let a = sim(1);
    let b = sim(2);
    let c = sim(2);
    assert!(a == b, "1 thread and 2 threads differ");
    assert!(b == c, "two runs with 2 threads differ");
    // The run did something.
    assert!(
        a.positions != make().state().positions,
        "the run did not move anything"
    );
}

#[test]
fn state_round_trip_and_particle_removal() {
    let mut s = solver(Boundary::default());
    let clay = s
        .add_material(Material::clay(1000.0, 1e4, 0.3, 2e3))
        .unwrap();
    let pts = sampling::sample_cylinder(Vec3::new(0.16, 0.16, 0.04), 0.04, 0.04, SPACING);
    let ids = s
        .add_particles(&pts, clay, SPACING.powi(3), Vec3::ZERO)
        .unwrap();
    run(&mut s, 20);
    let saved = s.state();
    run(&mut s, 40);
    let after_a = s.state();
    s.set_state(&saved).unwrap();
    run(&mut s, 40);
    assert!(
        s.state() == after_a,
        "replaying from a saved state gives a different result"
    );
    // Remove the first ten particles by id, then everything above 6 cm.
    assert_eq!(s.remove_particles(&ids[..10]), 10);
    assert!(s.particle_ids().iter().all(|id| !ids[..10].contains(id)));
    let removed = s.retain_particles(|_, p, _, _| p.z < 0.06);
    assert!(removed > 0 && s.positions().iter().all(|p| p.z < 0.06));
    run(&mut s, 10);
    // Bad input is refused with a typed error.
    let mut bad = s.state();
    bad.velocities.pop();
    assert!(matches!(
        s.set_state(&bad),
        Err(ms2_mpm::MpmError::LengthMismatch { .. })
    ));
    let outside = [Vec3::new(0.16, 0.16, 5.0)];
    assert!(matches!(
        s.add_particles(&outside, clay, 1e-7, Vec3::ZERO),
        Err(ms2_mpm::MpmError::OutsideDomain { .. })
    ));
}

/// Clay block of 6 × 6 × 2 cm sliding along +x at `speed` (m/s) on a floor of friction
/// coefficient `mu`; returns how far its centre of mass travels in `seconds` (m).
fn slide_distance(mu: f32, speed: f32, seconds: f32) -> f32 {
    let mut s = solver(Boundary::uniform(WallKind::Slip { friction: mu }));
    let clay = s
        .add_material(Material::clay(1000.0, 1e4, 0.3, 2e3))
        .unwrap();
    let floor = s.usable_domain().0.z;
    let lo = Vec3::new(0.04, 0.13, floor);
    let pts = sampling::sample_box(lo, lo + Vec3::new(0.06, 0.06, 0.02), SPACING);
    s.add_particles(&pts, clay, SPACING.powi(3), Vec3::ZERO)
        .unwrap();
    // Let it settle onto the floor at rest, then launch it.
    run(&mut s, 400);
    let start = center_of_mass(&s).x;
    let mut state = s.state();
    for v in state.velocities.iter_mut() {
        *v = Vec3::new(speed, 0.0, 0.0);
    }
    for c in state.affine_velocities.iter_mut() {
        *c = Mat3::ZERO;
    }
    s.set_state(&state).unwrap();
    let substeps = (seconds / s.config().substep_dt).round() as usize;
    run(&mut s, substeps);
    center_of_mass(&s).x - start
}

#[test]
fn floor_friction_stops_a_sliding_block_as_coulomb_predicts() {
    // Coulomb: a block launched at v on a floor of friction μ stops after v²/(2μg).
    let (mu, v) = (0.5, 0.5);
    let expected = v * v / (2.0 * mu * 9.81);
    let with_friction = slide_distance(mu, v, 0.2);
    eprintln!("slid {with_friction} expected {expected}");
    assert!(
        (0.6 * expected..1.4 * expected).contains(&with_friction),
        "slid {with_friction} m on μ = {mu}; Coulomb predicts {expected} m"
    );
    // Without friction it keeps going (the clay's own plasticity aside).
    let frictionless = slide_distance(0.0, v, 0.2);
    assert!(
        frictionless > 0.8 * v * 0.2,
        "slid only {frictionless} m on a frictionless floor"
    );
}
