//! `Hang-v0`: the noodle on the rod (simulated), the env's start, states and observations.

use glam::Vec3;
use ms2_mpm::bent_bar::{BentBar, CurvePiece};
use ms2_physics::{ActorDesc, ActorKind, Pose3, ShapeDesc, ShapeSpec, World, WorldConfig};
use ms2_tasks::families::soft::hang::{Hang, ROD_HALF, ROD_STICKY_REACH, START_FINGER_QPOS};
use ms2_tasks::families::soft::hang_scene::{
    hang_terms, rope_solver, HangTerms, RodPose, RopeStart, HANG_MPM_FREQ_HZ, ROPE_HALF_WIDTH,
    ROPE_LENGTH,
};
use ms2_tasks::soft::SoftWorld;
use ms2_tasks::{make_env, EnvConfig};
use nalgebra::{Translation3, UnitQuaternion, Vector3};

/// Simulates `bar` (the rope, at rest) next to a kinematic rod at `rod` for `seconds` with
/// the task's solver (grid, material, rate, contact constants of that substep), the fingers
/// open; returns the success terms at the end.
fn simulate_rope(bar: BentBar, rod: RodPose, seconds: f32) -> HangTerms {
    simulate_rope_on(bar, rod, seconds, Some(ROD_STICKY_REACH))
}

/// As [`simulate_rope`], the rod's grid contact sticky within `sticky_reach` (m) or not.
fn simulate_rope_on(
    bar: BentBar,
    rod: RodPose,
    seconds: f32,
    sticky_reach: Option<f32>,
) -> HangTerms {
    let mut world = World::new(WorldConfig::default()).unwrap();
    let p = rod.position;
    let rod_body = world
        .add_actor(
            ActorDesc::new("rod", ActorKind::Kinematic)
                .with_pose(Pose3::from_parts(
                    Translation3::new(p.x, p.y, p.z),
                    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), rod.yaw),
                ))
                .with_shape(ShapeSpec::new(ShapeDesc::Box {
                    half_extents: Vector3::from(ROD_HALF),
                })),
        )
        .unwrap();
    let dt = (1.0 / HANG_MPM_FREQ_HZ) as f32;
    let (mut solver, rope) = rope_solver(dt).unwrap();
    let start = RopeStart {
        bar,
        grasp_arc: 0.0,
        fingers: Vec::new(),
    };
    let tracked_ids = start.add_to(&mut solver, rope, 7).unwrap();
    let params = ms2_mpm::CouplingParams::for_substep(dt);
    let mut soft = SoftWorld::with_params(solver, &world, vec![rod_body], params).unwrap();
    soft.set_sticky(0, sticky_reach).unwrap();
    let steps = (seconds / world.timestep()).round() as usize;
    for _ in 0..steps {
        soft.step(&mut world).unwrap();
    }
    let s = soft.solver();
    let tracked = tracked_ids.map(|id| {
        let i = s.particle_ids().iter().position(|&p| p == id).unwrap();
        s.positions()[i]
    });
    hang_terms(s.positions(), s.velocities(), &tracked, &rod, 0.08)
}

/// A rope draped over `rod`: straight up on the robot's side, half a turn over the rod,
/// straight down on the far side, in the vertical plane of the rod's normal.
fn draped(rod: RodPose) -> BentBar {
    draped_off_centre(rod, 0.0)
}

/// As [`draped`], the far leg `shift` (m) longer and the near one as much shorter.
fn draped_off_centre(rod: RodPose, shift: f32) -> BentBar {
    // An arch wider than the rod (the rope is too stiff to wrap a 2 cm rod), its top on it.
    let radius = 0.05;
    let arc = std::f32::consts::PI * radius;
    let leg = 0.5 * (ROPE_LENGTH - arc);
    let n = rod.normal();
    let arch_centre = rod.position - Vec3::Z * (radius - ROD_HALF[2] - ROPE_HALF_WIDTH - 0.002);
    BentBar {
        start: arch_centre - n * radius - Vec3::Z * (leg - shift),
        along: n,
        heading: std::f32::consts::FRAC_PI_2,
        pieces: vec![
            CurvePiece::Straight {
                length: leg - shift,
            },
            CurvePiece::Arc {
                radius,
                angle: -std::f32::consts::PI,
            },
            CurvePiece::Straight {
                length: leg + shift,
            },
        ],
        half_width: ROPE_HALF_WIDTH,
        width_scale: None,
    }
}

#[test]
fn a_rope_draped_over_a_high_rod_hangs_there_at_rest_and_succeeds() {
    let rod = RodPose::from_unit(0.5, 0.3, 0.9);
    let t = simulate_rope(draped(rod), rod, 3.0);
    assert!(t.sides && t.over_rod && t.ends_down, "{t:?}");
    assert!(t.off_ground, "{t:?}");
    assert!(t.rest_fraction > 0.99, "{t:?}");
    assert!(t.success, "{t:?}");
}

#[test]
fn a_rope_hung_off_centre_stays_on_the_sticky_rod_and_slides_off_a_slippery_one() {
    // The far leg 8 cm longer than the near one (the rod 40 % along the rope). With the penalty contact's friction alone the rope slid off
    // towards its heavier side; the rod's sticky grid contact (ManiSkill2's) holds it.
    let rod = RodPose::from_unit(0.5, 0.3, 0.9);
    let held = simulate_rope_on(
        draped_off_centre(rod, 0.04),
        rod,
        1.5,
        Some(ROD_STICKY_REACH),
    );
    assert!(
        held.sides && held.over_rod && held.ends_down && held.off_ground,
        "{held:?}"
    );
    let slid = simulate_rope_on(draped_off_centre(rod, 0.04), rod, 1.5, None);
    assert!(!(slid.over_rod && slid.off_ground), "{slid:?}");
}

#[test]
fn a_rope_beside_the_rod_falls_to_the_ground_and_fails() {
    let rod = RodPose::from_unit(0.5, 0.3, 0.9);
    // The same rope, 10 cm further out along the normal: it misses the rod.
    let mut bar = draped(rod);
    bar.start += rod.normal() * 0.1;
    let t = simulate_rope(bar, rod, 1.5);
    assert!(!t.off_ground && !t.over_rod && !t.success, "{t:?}");
}

#[test]
fn the_tracked_particles_lie_where_maniskill2_selects_them() {
    // ManiSkill2's `selected_indices`: the first particle past the start of the bands 5-15 %,
    // 25-35 %, 48-52 %, 65-75 % and 85-95 % along its straight rope, counted from the short
    // end. On a straight rope along +x from the origin, each tracked particle's x is its arc
    // length; it lies on the rope's axis.
    let bar = BentBar {
        start: Vec3::new(0.0, 0.0, 0.1),
        along: Vec3::X,
        heading: 0.0,
        pieces: vec![CurvePiece::Straight {
            length: ROPE_LENGTH,
        }],
        half_width: ROPE_HALF_WIDTH,
        width_scale: None,
    };
    let start = RopeStart {
        bar,
        grasp_arc: 0.0,
        fingers: Vec::new(),
    };
    let (mut solver, rope) = rope_solver((1.0 / HANG_MPM_FREQ_HZ) as f32).unwrap();
    let ids = start.add_to(&mut solver, rope, 3).unwrap();
    for (k, fraction) in [0.05f32, 0.25, 0.48, 0.65, 0.85].into_iter().enumerate() {
        let i = solver
            .particle_ids()
            .iter()
            .position(|&p| p == ids[k])
            .unwrap();
        let p = solver.positions()[i];
        assert!(
            (p.x - fraction * ROPE_LENGTH).abs() < 0.003,
            "tracked particle {k} at x {} m, not {fraction} of the rope",
            p.x
        );
        assert!(p.y.abs() < 0.002 && (p.z - 0.1).abs() < 0.002, "{p:?}");
    }
}

fn hang_env(obs_mode: &str) -> ms2_tasks::Env {
    let mut cfg = EnvConfig::new("Hang-v0");
    cfg.obs_mode = obs_mode.to_owned();
    make_env(&cfg).unwrap()
}

/// Number of elements of the box at `path` ("a/b") in `space`.
fn space_size(space: &ms2_tasks::Space, path: &str) -> usize {
    let mut node = space;
    for key in path.split('/') {
        let ms2_tasks::Space::Dict(entries) = node else {
            panic!("{path}: not a dict at {key}")
        };
        node = &entries.iter().find(|(k, _)| k == key).unwrap().1;
    }
    match node {
        ms2_tasks::Space::Box(b) => b.size(),
        ms2_tasks::Space::Dict(_) => panic!("{path} is a dict"),
    }
}

#[test]
fn episodes_start_with_the_rope_pinched_between_the_fingertips_and_a_seeded_rod() {
    let mut env = hang_env("particles");
    assert_eq!(env.max_episode_steps(), 350);
    let mut heights = Vec::new();
    for seed in 0..4 {
        let (obs, _) = env.reset(Some(seed), false).unwrap();
        let x = obs.get("particles/x").unwrap().as_f32().unwrap();
        // The whole rope: 160 rows of 8 × 8 particles, none cut away by the fingers.
        assert_eq!(x.len() / 3, 10_240, "seed {seed}");
        // The observation space fixes the count: every seed has the same particles.
        assert_eq!(
            x.len(),
            space_size(env.observation_space(), "particles/x"),
            "seed {seed}"
        );
        let target = obs.get("extra/target").unwrap().as_f32().unwrap();
        let (r, z) = (target[0].hypot(target[1]), target[2]);
        assert!(
            (0.2..0.23).contains(&r) && (0.2..0.3).contains(&z),
            "{target:?}"
        );
        assert!(
            target[0] > 0.13,
            "the rod is in front of the robot: {target:?}"
        );
        heights.push(z);
        let hang = env.task().unwrap().downcast_ref::<Hang>().unwrap();
        let soft = hang.arm().soft().unwrap();
        // The rope is pinched: a face of it lies along each fingertip pad (coupled bodies 0
        // and 1), no particle inside a finger; the rod is away from it.
        for body in 0..3 {
            let d: Vec<f32> = soft
                .solver()
                .positions()
                .iter()
                .map(|p| soft.distance_to_body(body, *p).unwrap())
                .collect();
            let nearest = d.iter().copied().fold(f32::MAX, f32::min);
            if body < 2 {
                assert!(
                    nearest > 0.0,
                    "seed {seed}: a particle inside finger {body}"
                );
                // A face of the rope on a 20 × 20 mm pad: about 8 × 8 particles.
                let on_pad = d.iter().filter(|&&d| d < 0.002).count();
                assert!(
                    on_pad >= 40,
                    "seed {seed}: {on_pad} particles on pad {body}"
                );
            } else {
                assert!(nearest > 0.05, "seed {seed}: rod at {nearest} m");
            }
        }
        let e = hang
            .hang_eval(env.task_scene().unwrap().world.as_ref())
            .unwrap();
        assert!(!e.terms.success && e.terms.finger_distance < 0.07, "{e:?}");
    }
    heights.dedup();
    assert_eq!(heights.len(), 4, "the rod height repeats: {heights:?}");
    // Every grasp point the seeds draw keeps the observation space's particle count.
    let expected = space_size(env.observation_space(), "particles/x");
    for seed in 4..40 {
        let (obs, _) = env.reset(Some(seed), false).unwrap();
        let x = obs.get("particles/x").unwrap().as_f32().unwrap();
        assert_eq!(x.len(), expected, "seed {seed}");
    }
}

#[test]
fn state_round_trip_is_bit_exact_and_seeds_repeat() {
    let mut a = hang_env("state");
    a.reset(Some(2), false).unwrap();
    let hold = {
        // Arm still, fingers at their start opening (0.01 m each: the gripper's −0.01..0.04 m
        // target range mapped to −1..1).
        let mut act = vec![0.0; a.action_space().size()];
        if let Some(g) = act.last_mut() {
            *g = -0.2;
        }
        act
    };
    for _ in 0..2 {
        a.step(&hold).unwrap();
    }
    let saved = a.get_state();
    let mut b = hang_env("state");
    b.reset(Some(2), false).unwrap();
    for _ in 0..2 {
        b.step(&hold).unwrap();
    }
    assert_eq!(b.get_state(), saved, "same seed, different states");
    // A state restores into an episode of the same particle count (the same seed's), here
    // moved on by other actions first; two restores then step identically.
    let restore = || {
        let mut c = hang_env("state");
        c.reset(Some(2), false).unwrap();
        for _ in 0..3 {
            c.step(&vec![0.3; c.action_space().size()]).unwrap();
        }
        assert_ne!(c.get_state(), saved);
        c.set_state(&saved).unwrap();
        c
    };
    let (mut c, mut d) = (restore(), restore());
    // The read-back equals the saved state except the kinematic rod's velocity, which the
    // rigid world derives from its kinematic target (float noise of 1e-5 m/s after a reset
    // teleport, 0 after a restore); it does not act on anything.
    let (back, n) = (c.get_state(), saved.len());
    assert_eq!(back.len(), n);
    let differing: Vec<usize> = (0..n).filter(|&i| back[i] != saved[i]).collect();
    assert!(
        differing.len() <= 3 && differing.iter().all(|&i| i < 13),
        "{differing:?}"
    );
    for _ in 0..2 {
        c.step(&hold).unwrap();
        d.step(&hold).unwrap();
    }
    assert_eq!(c.get_state(), d.get_state(), "two restored runs diverged");
}

/// Heights (m) of the tracked particles (5 %, 25 %, 48 %, 65 %, 85 % along the rope).
fn tracked_z(env: &ms2_tasks::Env) -> [f32; 5] {
    let (scene, task) = (env.task_scene().unwrap(), env.task().unwrap());
    let hang = task.downcast_ref::<Hang>().unwrap();
    hang.hang_eval(scene.world.as_ref())
        .unwrap()
        .tracked
        .map(|p| p.z)
}

#[test]
fn the_fingers_lift_the_rope_they_hold() {
    // The closed hand rises 23 cm over 20 control steps from the start's pinch. The fingers'
    // sticky grid contact carries the rope: its grasped part rises with the hand and the
    // rest hangs below it (with the penalty contact alone it tore at the fingertips and fell
    // as the lift began).
    let mut env = hang_env("state");
    let oracle = ms2_tasks::scripted::tcp_oracle(&env).unwrap();
    env.reset(Some(0), false).unwrap();
    let start = {
        let scene = env.task_scene().unwrap();
        scene.agent.tcp_pose(scene.world.as_ref())
    };
    let before = tracked_z(&env);
    for step in 1..=20 {
        let mut target = start;
        target.translation.vector.z += 0.0115 * step as f32;
        let action = oracle.action(&env, &target, f64::from(START_FINGER_QPOS));
        env.step(&action).unwrap();
    }
    let after = tracked_z(&env);
    // The fingers hold the rope 20-24 % along (the tracked particles 5 % and 25 % along).
    for k in 0..2 {
        assert!(
            after[k] - before[k] > 0.15,
            "particle {k} near the grasp rose {} m (z {} → {})",
            after[k] - before[k],
            before[k],
            after[k]
        );
    }
    assert!(
        after[2] > before[2] + 0.1,
        "the rope's middle stayed at z {}",
        after[2]
    );
}

#[test]
fn the_scripted_policy_first_lays_the_rope_down_and_lets_go_of_it() {
    // The plan's first step: open at the start and rise, the rope falls to the ground whole
    // and the fingers leave it (the re-grasp needs the rope lying free).
    let mut env = hang_env("state");
    let mut policy = ms2_tasks::make_scripted_policy(&env).unwrap();
    env.reset(Some(1), false).unwrap();
    policy.reset(&env);
    for _ in 0..ms2_tasks::families::soft::hang_policy::PLAN_STEP {
        let action = policy.act(&env);
        env.step(&action).unwrap();
    }
    let (scene, task) = (env.task_scene().unwrap(), env.task().unwrap());
    let hang = task.downcast_ref::<Hang>().unwrap();
    let soft = hang.arm().soft().unwrap();
    let x = soft.solver().positions();
    let top = x.iter().map(|p| p.z).fold(f32::MIN, f32::max);
    assert!(top < 0.03, "the rope's top is {top} m up");
    for finger in 0..2 {
        let d = x
            .iter()
            .map(|p| soft.distance_to_body(finger, *p).unwrap_or(9.0))
            .fold(f32::MAX, f32::min);
        assert!(d > 0.02, "finger {finger} is {d} m from the rope");
    }
    let e = hang.hang_eval(scene.world.as_ref()).unwrap();
    assert!(
        e.finger_opening > 0.07,
        "fingers {} m open",
        e.finger_opening
    );
}

#[test]
fn low_rods_get_their_own_release_point_within_the_arms_reach() {
    use ms2_control::{DlsIk, IkOptions, RobotConfig};
    use ms2_tasks::families::soft::hang::{ARM_START, BASE_X};
    use ms2_tasks::families::soft::hang_policy::{
        opens_away_from_rod, release_point, FAR_OFFSET, HIGH_ROD_Z, LOW_ROD_FAR_OFFSET,
        LOW_ROD_RELEASE_HEIGHT, LOW_ROD_Z, OPEN_SHIFT, RELEASE_HEIGHT,
    };
    // The committed release on high rods; on low rods the one measured to leave the rope's
    // middle on the rod (the high rods' let the long leg reach the ground, seeds 7, 8, 10);
    // continuous in between.
    assert_eq!(release_point(0.3), (FAR_OFFSET, RELEASE_HEIGHT));
    assert_eq!(release_point(HIGH_ROD_Z), (FAR_OFFSET, RELEASE_HEIGHT));
    assert_eq!(
        release_point(0.2),
        (LOW_ROD_FAR_OFFSET, LOW_ROD_RELEASE_HEIGHT)
    );
    assert_ne!(release_point(0.2), release_point(0.3));
    let (mut last, n) = (release_point(LOW_ROD_Z), 20);
    for k in 1..=n {
        let z = LOW_ROD_Z + (HIGH_ROD_Z - LOW_ROD_Z) * k as f32 / n as f32;
        let p = release_point(z);
        assert!(
            (p.0 - last.0).abs() < 0.005 && (p.1 - last.1).abs() < 0.005,
            "{last:?} -> {p:?} at {z} m"
        );
        last = p;
    }
    // The Panda reaches every release point with the start's hand orientation, turned about
    // the vertical in quarter turns (the carry's yaw depends on the rope), for the farthest
    // rods (0.23 m from the origin) in the extreme directions and heights; on the rods where
    // the hand opens away from the rod, also where the opening ends.
    let robot = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
    let chain = robot.tcp_chain().unwrap();
    let mut seed: Vec<f64> = ARM_START.iter().map(|&q| f64::from(q)).collect();
    seed.resize(chain.dof(), 0.0);
    let start = chain.forward_kinematics(&seed).unwrap();
    let ik = DlsIk::new(IkOptions {
        max_iterations: 200,
        position_tolerance_m: 1e-3,
        rotation_tolerance_rad: 1e-2,
        ..IkOptions::default()
    });
    // The check can fail: a point 0.5 m beyond the farthest rod is out of reach.
    let far = nalgebra::Isometry3::from_parts(
        nalgebra::Translation3::new(0.73 - f64::from(BASE_X), 0.0, 0.25),
        start.rotation,
    );
    assert!(ik.solve(&chain, &far, &seed, None).is_err());
    for u_angle in [0.0, 0.5, 0.999] {
        for u_height in [0.0, 0.5, 0.999] {
            let rod = RodPose::from_unit(0.999, u_angle, u_height);
            let (far, up) = release_point(rod.position.z);
            let mut offsets = vec![far];
            if opens_away_from_rod(&rod) {
                offsets.push(far + OPEN_SHIFT);
            }
            for (far, quarter) in offsets
                .into_iter()
                .flat_map(|f| [-1.0f64, 0.0, 1.0].map(|q| (f, q)))
            {
                let p = rod.position + rod.normal() * far + Vec3::Z * up;
                let turn = nalgebra::UnitQuaternion::from_axis_angle(
                    &Vector3::z_axis(),
                    quarter * std::f64::consts::FRAC_PI_2,
                );
                let target = nalgebra::Isometry3::from_parts(
                    nalgebra::Translation3::new(
                        f64::from(p.x - BASE_X),
                        f64::from(p.y),
                        f64::from(p.z),
                    ),
                    turn * start.rotation,
                );
                let r = ik.solve(&chain, &target, &seed, None);
                assert!(
                    r.is_ok(),
                    "release {p:?} (rod {rod:?}, turn {quarter}) out of reach: {r:?}"
                );
            }
        }
    }
}

#[test]
fn the_hand_opens_away_from_the_rod_only_on_the_rods_turned_furthest_aside() {
    use ms2_tasks::families::soft::hang_policy::{
        opens_away_from_rod, HangPolicy, Waypoint, GRIP_FINGER_TARGET, OPEN_SHIFT, OPEN_STEPS,
    };
    use ms2_tasks::scripted::oracle::GRIPPER_OPEN;
    // The rod's direction is 45° + 90° × u_angle from +y: only the rods more than 30° from
    // straight ahead (below 60° or above 120°: u_angle below 1/6 or above 5/6) open away from
    // the rod.
    let gated: Vec<bool> = (0..=100)
        .map(|k| opens_away_from_rod(&RodPose::from_unit(0.5, k as f32 / 100.0, 0.5)))
        .collect();
    assert!(gated[..=16].iter().all(|g| *g), "{gated:?}");
    assert!(gated[17..=83].iter().all(|g| !g), "{gated:?}");
    assert!(gated[84..].iter().all(|g| *g), "{gated:?}");
    for (u_angle, u_height, away) in [
        (0.0, 0.2, true),
        (0.2, 0.9, false),
        (0.5, 0.2, false),
        (0.8, 0.9, false),
        (0.9, 0.9, true),
        (0.999, 0.2, true),
    ] {
        let rod = RodPose::from_unit(0.5, u_angle, u_height);
        let (s0, tcp, grasp) = (20, Vec3::new(0.0, 0.0, 0.12), Vec3::new(-0.03, 0.0, 0.01));
        let plan = HangPolicy::hang_plan(s0, tcp, grasp, glam::Vec2::X, &rod);
        // The opening at the release: the last waypoint holding the rope, then the first one
        // open after the grasp (44 steps after the plan starts).
        let i = plan
            .iter()
            .position(|w| w.0 > s0 + 44 && w.3 == GRIPPER_OPEN)
            .unwrap();
        let (closed, opened) = (plan[i - 1], plan[i]);
        assert_eq!(opened.0 - closed.0, OPEN_STEPS);
        assert_eq!(closed.3, GRIP_FINGER_TARGET);
        // The finger on the rod's side: the TCP less one finger's opening along the normal.
        let n = rod.normal();
        let rod_side_finger = |w: &Waypoint| w.1 - n * w.3 as f32;
        let moved = rod_side_finger(&opened).distance(rod_side_finger(&closed));
        if away {
            assert!(moved < 1e-5, "the rod-side finger moved {moved} m");
            let shift = opened.1 - closed.1;
            assert!((shift.dot(n) - OPEN_SHIFT).abs() < 1e-5, "{shift:?}");
            assert!(shift.z.abs() < 1e-6, "{shift:?}");
        } else {
            // The committed plan: the hand opens in place, the finger sweeps towards the rod.
            assert_eq!(closed.1, opened.1, "u_angle {u_angle}");
            assert!((moved - OPEN_SHIFT).abs() < 1e-5, "{moved}");
        }
        // Then the hand rises 5 cm from where the opening ended.
        let rise = plan[i + 1].1 - opened.1;
        assert!(rise.truncate().length() < 1e-6 && (rise.z - 0.05).abs() < 1e-6);
    }
}
