//! Soft-body tasks: the ms2-physics ↔ ms2-mpm adapter, checked by simulating it.

use glam::Vec3;
use ms2_mpm::{sampling, Coupling, CouplingParams, GridSpec, Material, MpmSolver, SolverConfig};
use ms2_physics::{ActorDesc, ActorKind, Pose3, ShapeDesc, ShapeSpec, World, WorldConfig};
use ms2_tasks::adapters::mpm_rigid::{CoupledBodies, MpmAdapterError, MpmRigidWorld};
use nalgebra::Vector3;

/// Particle spacing (m): two per 1 cm cell and axis.
const SPACING: f32 = 0.005;
/// Soft substeps per 500 Hz rigid step (MPM at 2000 Hz, as ManiSkill2).
const SUBSTEPS: usize = 4;

fn clay_bed(top: f32) -> MpmSolver {
    let grid = GridSpec::new(Vec3::ZERO, 0.01, [32; 3]);
    let mut s = MpmSolver::new(SolverConfig::new(grid)).unwrap();
    let clay = s
        .add_material(Material::clay(1000.0, 1e4, 0.3, 2e3))
        .unwrap();
    let (lo, _) = s.usable_domain();
    let pts = sampling::sample_box(
        Vec3::new(0.08, 0.08, lo.z),
        Vec3::new(0.24, 0.24, top),
        SPACING,
    );
    s.add_particles(&pts, clay, SPACING.powi(3), Vec3::ZERO)
        .unwrap();
    s
}

#[test]
fn rigid_box_resting_on_clay_is_held_up_by_it() {
    let bed_top = 0.06;
    let mut solver = clay_bed(bed_top);
    for _ in 0..200 {
        solver.substep().unwrap();
    }
    let mut world = World::new(WorldConfig::default()).unwrap();
    let half = Vector3::new(0.025, 0.025, 0.015);
    let start_z = bed_top + half.z + 0.004;
    let block = world
        .add_actor(
            ActorDesc::new("block", ActorKind::Dynamic)
                .with_pose(Pose3::translation(0.16, 0.16, start_z))
                .with_shape(ShapeSpec::new(ShapeDesc::Box { half_extents: half })),
        )
        .unwrap();
    let bodies = CoupledBodies::new(&world, vec![block]).unwrap();
    let weight = world.body_mass(block).unwrap() * 9.81;
    let mut coupling = Coupling::new(
        &MpmRigidWorld::new(&mut world, &bodies),
        CouplingParams::for_substep(solver.config().substep_dt),
    )
    .unwrap();
    let mut support = Vec::new();
    for step in 0..300 {
        world.step();
        coupling
            .advance(
                &mut solver,
                &mut MpmRigidWorld::new(&mut world, &bodies),
                SUBSTEPS,
            )
            .unwrap();
        if step >= 200 {
            support.push(coupling.last_wrenches()[0].force.z);
        }
    }
    // Without the clay the block would fall to the ground (z = half.z); it rests on the bed.
    let z = world.body_pose(block).unwrap().translation.vector.z;
    let bottom = z - half.z;
    assert!(
        (0.045..0.07).contains(&bottom),
        "block bottom at {bottom} m (bed top {bed_top} m)"
    );
    let v = world.body_linear_velocity(block).unwrap().norm();
    assert!(v < 0.02, "block still moving at {v} m/s");
    let mean = support.iter().sum::<f32>() / support.len() as f32;
    assert!(
        (mean - weight).abs() < 0.1 * weight,
        "clay pushes with {mean} N, block weighs {weight} N"
    );
}

#[test]
fn unsupported_shapes_are_refused_by_name() {
    let mut world = World::new(WorldConfig::default()).unwrap();
    let hull = world
        .add_actor(
            ActorDesc::new("hull", ActorKind::Dynamic).with_shape(ShapeSpec::new(
                ShapeDesc::ConvexHull {
                    points: vec![
                        [0.0, 0.0, 0.0].into(),
                        [0.1, 0.0, 0.0].into(),
                        [0.0, 0.1, 0.0].into(),
                        [0.0, 0.0, 0.1].into(),
                    ],
                },
            )),
        )
        .unwrap();
    let err = CoupledBodies::new(&world, vec![hull]).unwrap_err();
    assert!(matches!(
        err,
        MpmAdapterError::UnsupportedShape {
            kind: "convex hull",
            ..
        }
    ));
}

use ms2_tasks::families::soft::excavate_scene::{ExcavateScene, ScriptedScoop};

/// Runs the scripted scoop for `steps` control steps.
fn run_scoop(scene: &mut ExcavateScene, plan: &ScriptedScoop, from: u32, steps: u32) {
    for step in from..from + steps {
        scene.step(plan.command(step)).unwrap();
    }
}

#[test]
fn scripted_sweep_collects_clay_in_the_bucket() {
    let mut scene = ExcavateScene::new(7).unwrap();
    let plan = ScriptedScoop::plan(&scene);
    assert_eq!(scene.evaluate().particles_in_bucket, 0);
    // Lower the bucket onto the floor and slide it into the bed (the first 20 control steps).
    run_scoop(&mut scene, &plan, 0, 20);
    let eval = scene.evaluate();
    assert!(
        eval.particles_in_bucket > 50,
        "only {} particles in the bucket after the sweep",
        eval.particles_in_bucket
    );
    assert!(!eval.success, "clay on the floor cannot be a success");
}

#[test]
fn scripted_scoop_lifts_clay_above_the_target_height() {
    assert_scripted_scoop_lifts_clay(ExcavateScene::new(11).unwrap());
}

#[test]
fn scripted_scoop_lifts_clay_at_maniskill2s_2_khz_too() {
    // At 2 kHz the clay used to slide out over the lip during the lift (0 particles left):
    // on the stencil nodes the plate blocks, the clay's stress pushed it off the plate
    // without contact (no friction), and the APIC term added momentum every substep.
    assert_scripted_scoop_lifts_clay(ExcavateScene::with_substep(11, 5e-4).unwrap());
}

/// Runs the whole scripted scoop on `scene` and checks that clay ends in the lifted bucket.
fn assert_scripted_scoop_lifts_clay(mut scene: ExcavateScene) {
    let plan = ScriptedScoop::plan(&scene);
    // Sweep, curl and lift (48 control steps), then 4 steps at rest.
    run_scoop(&mut scene, &plan, 0, 52);
    let eval = scene.evaluate();
    assert!(
        eval.particles_in_bucket >= 150,
        "only {} particles lifted in the bucket",
        eval.particles_in_bucket
    );
    assert!(
        eval.lowest_in_bucket > scene.target_height(),
        "lowest clay in the bucket at {} m, target height {} m",
        eval.lowest_in_bucket,
        scene.target_height()
    );
}

#[test]
fn excavate_is_deterministic_and_state_round_trips() {
    let run = |seed: u64| {
        let mut scene = ExcavateScene::new(seed).unwrap();
        let plan = ScriptedScoop::plan(&scene);
        run_scoop(&mut scene, &plan, 0, 6);
        scene
    };
    let mut a = run(3);
    let mut b = run(3);
    let state_a = a.get_state();
    assert_eq!(state_a, b.get_state(), "same seed, different states");
    let c = run(4);
    assert_ne!(a.target_particles(), 0);
    assert_ne!(
        a.particle_positions(),
        c.particle_positions(),
        "different seeds, same clay"
    );
    // Continue a; restore b from a's saved state and continue the same way.
    let plan = ScriptedScoop::plan(&ExcavateScene::new(3).unwrap());
    run_scoop(&mut a, &plan, 6, 3);
    let mut fresh = ExcavateScene::new(9).unwrap();
    fresh.set_state(&state_a).unwrap();
    run_scoop(&mut fresh, &plan, 6, 3);
    assert_eq!(a.get_state(), fresh.get_state(), "restored run diverged");
}

#[test]
fn kinematic_plate_lifts_a_clay_block() {
    use ms2_tasks::soft::{SoftConfig, SoftWorld};
    let (mut solver, clay) = SoftWorld::solver_for(&SoftConfig::default()).unwrap();
    let plate_top = solver.usable_domain().0.z + 0.03;
    let pts = sampling::sample_box(
        Vec3::new(0.13, 0.13, plate_top),
        Vec3::new(0.19, 0.19, plate_top + 0.03),
        SPACING,
    );
    solver
        .add_particles(&pts, clay, SPACING.powi(3), Vec3::ZERO)
        .unwrap();
    let mut world = World::new(WorldConfig::default()).unwrap();
    let mut z = plate_top - 0.005;
    let plate = world
        .add_actor(
            ActorDesc::new("plate", ActorKind::Kinematic)
                .with_pose(Pose3::translation(0.16, 0.16, z))
                .with_shape(ShapeSpec::new(ShapeDesc::Box {
                    half_extents: Vector3::new(0.05, 0.05, 0.005),
                })),
        )
        .unwrap();
    let mut soft = SoftWorld::new(solver, &world, vec![plate]).unwrap();
    // Settle for 0.2 s, then lift at 0.1 m/s for 0.5 s (5 cm).
    for step in 0..350 {
        if step >= 100 {
            z += 0.0002;
        }
        world
            .set_kinematic_target(plate, &Pose3::translation(0.16, 0.16, z))
            .unwrap();
        soft.step(&mut world).unwrap();
    }
    let plate_top_now = z + 0.005;
    let lowest = soft
        .solver()
        .positions()
        .iter()
        .map(|p| p.z)
        .fold(f32::INFINITY, f32::min);
    assert!(
        plate_top_now > plate_top + 0.045,
        "plate did not move: top at {plate_top_now} m"
    );
    assert!(
        (plate_top_now..plate_top_now + 0.01).contains(&lowest),
        "clay bottom at {lowest} m, plate top at {plate_top_now} m"
    );
}

#[test]
fn every_excavate_bed_has_the_same_particle_count_and_its_own_surface() {
    use ms2_tasks::families::soft::excavate_scene::{
        excavate_soft_config, ExcavateBed, BED_PARTICLES,
    };
    let config = excavate_soft_config(Vec3::new(-0.18, -0.16, -0.03));
    let mut left_counts = Vec::new();
    for seed in 0..12 {
        let (solver, bed) = ExcavateBed::sample(&config, seed).unwrap();
        assert_eq!(solver.particle_count(), BED_PARTICLES, "seed {seed}");
        let x = solver.positions();
        let highest = x.iter().map(|p| p.z).fold(f32::MIN, f32::max);
        let lowest = x.iter().map(|p| p.z).fold(f32::MAX, f32::min);
        assert!(
            lowest > bed.floor_z && lowest < bed.floor_z + 0.005,
            "seed {seed}: {lowest}"
        );
        assert!(
            highest <= bed.bed_top_z + 0.005,
            "seed {seed}: {highest} > {}",
            bed.bed_top_z
        );
        assert!(
            (x.iter().map(|p| p.z).sum::<f32>() / x.len() as f32 - bed.floor_z - 0.0175).abs()
                < 0.003,
            "seed {seed}: the bed's mean height is off"
        );
        let centre_x = 0.5 * (bed.footprint[0].x + bed.footprint[1].x);
        left_counts.push(x.iter().filter(|p| p.x < centre_x).count());
    }
    // The height maps differ between seeds: so does the clay on each side of the bed.
    let spread = left_counts.iter().max().unwrap() - left_counts.iter().min().unwrap();
    assert!(spread > 40, "particles left of the centre: {left_counts:?}");
}

mod soft_envs {
    use ms2_tasks::{info_get, make_env, make_scripted_policy, EnvConfig, EnvError, InfoValue};

    fn env(obs_mode: &str) -> ms2_tasks::Env {
        let mut cfg = EnvConfig::new("Excavate-v0");
        cfg.obs_mode = obs_mode.to_owned();
        make_env(&cfg).unwrap()
    }

    fn mean_particle(obs: &ms2_tasks::ObsValue) -> [f64; 3] {
        let x = obs.get("particles/x").unwrap().as_f32().unwrap();
        let n = (x.len() / 3) as f64;
        let mut m = [0.0; 3];
        for p in x.chunks_exact(3) {
            for a in 0..3 {
                m[a] += f64::from(p[a]) / n;
            }
        }
        m
    }

    #[test]
    fn particles_obs_mode_state_round_trip_and_determinism() {
        round_trip("Excavate-v0", 2000);
        round_trip("Fill-v0", 500);
    }

    fn round_trip(env_id: &str, min_particles: usize) {
        assert!(ms2_tasks::env_ids().contains(&env_id));
        let env = |obs_mode: &str| {
            let mut cfg = EnvConfig::new(env_id);
            cfg.obs_mode = obs_mode.to_owned();
            make_env(&cfg).unwrap()
        };
        let mut a = env("particles");
        assert!(a.obs_modes().contains(&"particles".to_owned()));
        assert_eq!(a.max_episode_steps(), 250);
        let (obs, _) = a.reset(Some(5), false).unwrap();
        let x = obs.get("particles/x").unwrap();
        let ms2_tasks::ObsValue::Array(arr) = x else {
            panic!("particles/x is not an array");
        };
        assert_eq!(arr.shape[1], 3);
        assert!(arr.shape[0] > min_particles, "{} particles", arr.shape[0]);
        assert!(obs.get("extra/bucket_pose").is_some());
        let zero = vec![0.0; a.action_space().size()];
        for _ in 0..2 {
            a.step(&zero).unwrap();
        }
        let saved = a.get_state();
        assert_eq!(saved.len(), a.get_state().len());
        let mut later = Vec::new();
        for _ in 0..2 {
            later.push(mean_particle(&a.step(&zero).unwrap().obs));
        }
        // Same seed and actions in a second env: the same state.
        let mut b = env("particles");
        b.reset(Some(5), false).unwrap();
        for _ in 0..2 {
            b.step(&zero).unwrap();
        }
        assert_eq!(b.get_state(), saved, "same seed, different states");
        // Restoring the saved state in `a` repeats the continuation.
        a.set_state(&saved).unwrap();
        for expected in later {
            let got = mean_particle(&a.step(&zero).unwrap().obs);
            for k in 0..3 {
                assert!(
                    (got[k] - expected[k]).abs() < 1e-5,
                    "{got:?} vs {expected:?}"
                );
            }
        }
    }

    #[test]
    fn scripted_fill_episode_pours_the_clay_into_the_beaker() {
        let mut env = env_of("Fill-v0");
        let mut policy = make_scripted_policy(&env).unwrap();
        env.reset(Some(3), false).unwrap();
        policy.reset(&env);
        let mut info = Vec::new();
        for _ in 0..80 {
            let out = env.step(&policy.act(&env)).unwrap();
            info = out.info;
            if out.terminated {
                break;
            }
        }
        let Some(InfoValue::F64(inside)) = info_get(&info, "fraction_inside") else {
            panic!("no fraction_inside in {info:?}");
        };
        assert!(inside > 0.9, "{info:?}");
        assert_eq!(
            info_get(&info, "success"),
            Some(InfoValue::Bool(true)),
            "{info:?}"
        );
    }

    /// The scripted pour in `pd_ee_delta_pose` (whose rotation is clipped at 0.1 rad per step):
    /// seeds 0-4 succeed. Before the pour turned the bucket sideways, the forward tilt put the
    /// hand out of the Panda's reach, IK failed, and the bucket drifted back from the beaker.
    #[test]
    fn scripted_fill_pours_in_pd_ee_delta_pose() {
        let mut cfg = EnvConfig::new("Fill-v0");
        cfg.control_mode = Some("pd_ee_delta_pose".to_owned());
        let mut env = make_env(&cfg).unwrap();
        let mut policy = make_scripted_policy(&env).unwrap();
        let mut outcomes = Vec::new();
        for seed in 0..5 {
            env.reset(Some(seed), false).unwrap();
            policy.reset(&env);
            let mut info = Vec::new();
            for _ in 0..120 {
                let out = env.step(&policy.act(&env)).unwrap();
                info = out.info;
                if out.terminated {
                    break;
                }
            }
            outcomes.push((
                seed,
                info_get(&info, "success"),
                info_get(&info, "fraction_inside"),
            ));
        }
        assert!(
            outcomes
                .iter()
                .all(|(_, success, _)| *success == Some(InfoValue::Bool(true))),
            "{outcomes:?}"
        );
    }

    fn env_of(env_id: &str) -> ms2_tasks::Env {
        make_env(&EnvConfig::new(env_id)).unwrap()
    }

    #[test]
    fn particles_obs_mode_is_refused_without_particles() {
        let mut cfg = EnvConfig::new("PickCube-v0");
        cfg.obs_mode = "particles".to_owned();
        assert!(matches!(
            make_env(&cfg),
            Err(EnvError::UnknownObsMode { .. })
        ));
    }

    #[test]
    fn scripted_excavate_episode_lifts_clay_with_the_arm() {
        let mut env = env("state");
        let mut policy = make_scripted_policy(&env).unwrap();
        env.reset(Some(1), false).unwrap();
        policy.reset(&env);
        let mut info = Vec::new();
        for _ in 0..72 {
            let out = env.step(&policy.act(&env)).unwrap();
            info = out.info;
            if out.terminated {
                break;
            }
        }
        let Some(InfoValue::I64(inside)) = info_get(&info, "particles_in_bucket") else {
            panic!("no particles_in_bucket in {info:?}");
        };
        let Some(InfoValue::F64(lowest)) = info_get(&info, "lowest_in_bucket") else {
            panic!("no lowest_in_bucket in {info:?}");
        };
        let target_height = env
            .privileged_obs()
            .get("extra/target_height")
            .unwrap()
            .as_f32()
            .unwrap()[0];
        assert!(inside >= 100, "only {inside} particles lifted: {info:?}");
        assert!(lowest > f64::from(target_height), "{info:?}");
    }

    /// MPM substeps the clay of `env` has taken so far.
    fn mpm_substeps_taken(env: &ms2_tasks::Env) -> u64 {
        use ms2_tasks::families::soft::{excavate::Excavate, fill::Fill};
        let task = env.task().unwrap();
        let arm = match task.downcast_ref::<Excavate>() {
            Some(e) => e.arm(),
            None => task.downcast_ref::<Fill>().unwrap().arm(),
        };
        arm.soft().unwrap().solver().substeps_taken()
    }

    #[test]
    fn mpm_freq_sets_the_soft_substeps_and_bad_values_are_refused() {
        for (env_id, mpm_freq, per_step) in [
            // ManiSkill2's 2 kHz by default.
            ("Excavate-v0", None, 100),
            ("Excavate-v0", Some(1000.0), 50),
            ("Fill-v0", Some(1500.0), 75),
        ] {
            let mut cfg = EnvConfig::new(env_id);
            cfg.mpm_freq = mpm_freq;
            let mut env = make_env(&cfg).unwrap();
            assert_eq!(env.config().mpm_freq, Some(mpm_freq.unwrap_or(2000.0)));
            env.reset(Some(0), false).unwrap();
            let before = mpm_substeps_taken(&env);
            env.step(&vec![0.0; env.action_space().size()]).unwrap();
            assert_eq!(
                mpm_substeps_taken(&env) - before,
                per_step,
                "{env_id} {mpm_freq:?}"
            );
        }
        for (env_id, bad, named) in [
            ("Excavate-v0", 1234.0, "1234"),
            ("Excavate-v0", f64::NAN, "NaN"),
            ("Fill-v0", -2000.0, "-2000"),
            ("PickCube-v0", 2000.0, "PickCube-v0"),
        ] {
            let mut cfg = EnvConfig::new(env_id);
            cfg.mpm_freq = Some(bad);
            let err = make_env(&cfg).expect_err("accepted a bad mpm_freq");
            let msg = err.to_string();
            assert!(
                matches!(err, EnvError::InvalidConfig(_))
                    && msg.contains("mpm_freq")
                    && msg.contains(named),
                "{env_id} {bad}: {msg}"
            );
        }
        assert_eq!(
            make_env(&EnvConfig::new("PickCube-v0"))
                .unwrap()
                .config()
                .mpm_freq,
            None
        );
    }
}
