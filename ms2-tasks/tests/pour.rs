//! `Pour-v0`: the water stays in the upright bottle, episodes start with the open gripper
//! around the bottle and repeat by seed, the observation has its shapes, and a saved state
//! restores bit-exactly. The success terms on constructed particle sets are unit tests of
//! `families::soft::pour_scene`.

use ms2_tasks::families::soft::pour::Pour;
use ms2_tasks::families::soft::pour_policy::{PourPolicy, MIN_WRIST_RANGE};
use ms2_tasks::families::soft::pour_scene::{
    BOTTLE_BOTTOM, BOTTLE_HEIGHT, BOTTLE_INNER_RADIUS, WATER_HEIGHT,
};
use ms2_tasks::{make_env, EnvConfig, ScriptedPolicy};

fn pour_env(obs_mode: &str) -> ms2_tasks::Env {
    let mut cfg = EnvConfig::new("Pour-v0");
    cfg.obs_mode = obs_mode.to_owned();
    make_env(&cfg).unwrap()
}

/// Arm still, gripper open (normalized gripper action 1).
fn hold(env: &ms2_tasks::Env) -> Vec<f32> {
    let mut act = vec![0.0; env.action_space().size()];
    if let Some(g) = act.last_mut() {
        *g = 1.0;
    }
    act
}

/// Particles inside the bottle (in its frame: within its inner radius, above its bottom,
/// below its mouth) and the bottle's height (m) and axis cosine.
fn water_in_bottle(env: &ms2_tasks::Env) -> (usize, usize, f32, f32) {
    let pour = env.task().unwrap().downcast_ref::<Pour>().unwrap();
    let scene = env.task_scene().unwrap();
    let pose = scene.world.body_pose(pour.bottle().unwrap()).unwrap();
    let x = pour.arm().soft().unwrap().solver().positions();
    let inv = pose.inverse();
    let inside = x
        .iter()
        .filter(|p| {
            let l = inv * nalgebra::Point3::new(p.x, p.y, p.z);
            l.x.hypot(l.y) < BOTTLE_INNER_RADIUS + 0.001
                && l.z > BOTTLE_BOTTOM - 0.002
                && l.z < BOTTLE_HEIGHT
        })
        .count();
    let axis = pose.rotation * nalgebra::Vector3::z();
    (inside, x.len(), pose.translation.z, axis.z)
}

#[test]
fn water_stays_in_the_upright_bottle() {
    let mut env = pour_env("state");
    env.reset(Some(0), false).unwrap();
    let (inside, n, _, _) = water_in_bottle(&env);
    assert_eq!(inside, n, "at the start");
    let mean_height = |env: &ms2_tasks::Env| {
        let pour = env.task().unwrap().downcast_ref::<Pour>().unwrap();
        let x = pour.arm().soft().unwrap().solver().positions();
        x.iter().map(|p| p.z).sum::<f32>() / x.len() as f32
    };
    let z0 = mean_height(&env);
    // 0.75 s with the arm still and the gripper open: the water settles in the bottle.
    let act = hold(&env);
    for _ in 0..15 {
        env.step(&act).unwrap();
    }
    let (inside, n, z, cos) = water_in_bottle(&env);
    assert_eq!(inside, n, "water left the bottle");
    assert!(
        z.abs() < 0.003 && cos > 0.999,
        "the bottle moved: z {z}, cos {cos}"
    );
    // Weakly compressible: the water's mean height sinks by a few per cent of the column at
    // most, and does not rise. (Before water's pressure pushed off coupled surfaces, ms2-mpm
    // `tests/water.rs`, it fell from 4.7 to 3.2 cm here.) Since water's bulk modulus is capped
    // for the substep (1.68e4 Pa at this seed's 872 kg/m³, ms2-mpm
    // `Material::stable_water_bulk_modulus`) and slides on the walls without friction, the
    // undamped column sinks more: 4.70 -> 4.08 cm (8.3 % of its 7.4 cm), mean J 0.936.
    let column = env
        .task()
        .unwrap()
        .downcast_ref::<Pour>()
        .unwrap()
        .episode()
        .water_height;
    let z1 = mean_height(&env);
    assert!(
        z1 > z0 - 0.1 * column && z1 < z0 + 0.002,
        "mean height {z0} -> {z1} m"
    );
}

#[test]
fn episodes_start_around_the_bottle_and_repeat_by_seed() {
    let mut env = pour_env("particles");
    assert_eq!(env.max_episode_steps(), 350);
    let mut n = None;
    let mut lines = Vec::new();
    for seed in 0..4 {
        let (obs, info) = env.reset(Some(seed), false).unwrap();
        let x = obs.get("particles/x").unwrap().as_f32().unwrap();
        assert!(x.len() / 3 > 9000, "{} particles", x.len() / 3);
        assert_eq!(*n.get_or_insert(x.len()), x.len(), "seed {seed}");
        let tcp = obs.get("extra/tcp_pose").unwrap().as_f32().unwrap();
        let target = obs.get("extra/target").unwrap().as_f32().unwrap();
        assert_eq!((tcp.len(), target.len()), (7, 1));
        assert!((0.01..0.02).contains(&target[0]), "{target:?}");
        lines.push(target[0]);
        let pour = env.task().unwrap().downcast_ref::<Pour>().unwrap();
        let e = *pour.episode();
        // The TCP is on the bottle's axis at the drawn height (IK reached it).
        let d = glam::Vec2::new(tcp[0], tcp[1]).distance(e.bottle_xy);
        assert!(
            d < 0.002 && (tcp[2] - e.tcp_height).abs() < 0.002,
            "seed {seed}: {tcp:?} {e:?}"
        );
        let r = e.beaker_xy.length();
        assert!((0.2..0.25).contains(&r) && e.beaker_xy.y >= 0.0, "{e:?}");
        assert!((WATER_HEIGHT.0..WATER_HEIGHT.1).contains(&e.water_height));
        let success = ms2_tasks::info_get(&info, "success");
        assert_eq!(success, Some(ms2_tasks::InfoValue::Bool(false)));
    }
    lines.dedup();
    assert_eq!(lines.len(), 4, "{lines:?}");
    let (a, _) = env.reset(Some(2), false).unwrap();
    let (b, _) = env.reset(Some(2), false).unwrap();
    assert_eq!(a, b, "seed 2 twice");
}

/// The scripted pour tilts the bottle the way the Panda's last joint has range for. The start
/// leaves that joint about 1 rad from its lower limit: tilted that way (towards the beaker
/// from where the bottle stands, on about half the seeds) the bottle stalled near 100°, the
/// water trickled out at ~20 particles per step and seeds 3, 6 and 7 ended short of the line.
#[test]
fn scripted_pour_tilts_the_way_the_wrist_has_range() {
    let mut env = pour_env("state");
    let mut short_the_other_way = 0;
    for seed in 0..12 {
        env.reset(Some(seed), false).unwrap();
        let mut policy = PourPolicy::new(&env).unwrap();
        policy.reset(&env);
        let sign = policy.tilt_sign();
        let range = PourPolicy::wrist_range(&env, sign).unwrap();
        assert!(
            range >= MIN_WRIST_RANGE,
            "seed {seed}: tilt {sign}, {range} rad of range"
        );
        let other = PourPolicy::wrist_range(&env, -sign).unwrap();
        short_the_other_way += usize::from(other < MIN_WRIST_RANGE);
    }
    // The choice matters: the other way lacks the range on these starts.
    assert!(short_the_other_way > 0);
}

#[test]
fn state_round_trip_is_bit_exact() {
    let mut a = pour_env("state");
    let (obs, _) = a.reset(Some(1), false).unwrap();
    // state: qpos 9, qvel 9, base_pose 7, tcp_pose 7, target 1.
    assert_eq!(obs.as_f32().unwrap().len(), 33);
    let act = hold(&a);
    a.step(&act).unwrap();
    let saved = a.get_state();
    // Envs of the same seed, moved elsewhere first, restore it bit-exactly and then step
    // identically (the coupling's pending reaction wrench on the bottle, from the step before
    // the save, is not part of the state, as in the other soft tasks: a restored run is not
    // the saved run's continuation to the bit).
    let restore = || {
        let mut c = pour_env("state");
        c.reset(Some(1), false).unwrap();
        for _ in 0..2 {
            c.step(&vec![0.3; c.action_space().size()]).unwrap();
        }
        assert_ne!(c.get_state(), saved);
        c.set_state(&saved).unwrap();
        assert_eq!(c.get_state(), saved, "read back");
        c
    };
    let (mut c, mut d) = (restore(), restore());
    c.step(&act).unwrap();
    d.step(&act).unwrap();
    assert_eq!(c.get_state(), d.get_state(), "two restored runs diverged");
}

#[test]
fn random_actions_spill_the_water_without_diverging() {
    use rand::{Rng, SeedableRng};
    // Uniform random actions (as the Python sweeps send) shake the bottle and splash drops
    // out of it. Before water's bulk modulus was capped for the substep and its volume ratio
    // bounded (ms2-mpm `Material::stable_water_bulk_modulus`), this run failed with
    // `Diverged` at step 24.
    let seed: u64 = std::env::var("POUR_RANDOM_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let mut env = pour_env("state");
    env.reset(Some(seed), false).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let space = env.action_space().clone();
    let mut most_out = 0;
    for step in 0..50 {
        let act: Vec<f32> = space
            .low
            .iter()
            .zip(&space.high)
            .map(|(&lo, &hi)| rng.random_range(lo..=hi))
            .collect();
        env.step(&act)
            .unwrap_or_else(|e| panic!("step {step}: {e}"));
        let (inside, n, _, _) = water_in_bottle(&env);
        most_out = most_out.max(n - inside);
        let pour = env.task().unwrap().downcast_ref::<Pour>().unwrap();
        let v = pour.arm().soft().unwrap().solver().velocities();
        let vmax = v.iter().map(|v| v.length()).fold(0.0, f32::max);
        println!(
            "step {step}: {} out of the bottle, max speed {vmax:.2} m/s",
            n - inside
        );
        assert!(vmax < 10.0, "step {step}: max speed {vmax} m/s");
    }
    assert!(most_out > 0, "no water left the bottle");
}

#[test]
fn drops_falling_into_the_beaker_stay_finite() {
    // Sixteen particles of the column moved out as lone drops 1.6 cm apart (no two share a
    // grid node) 8-10 cm above the beaker, then 0.25 s: they fall into it. Before water's bulk
    // modulus was capped for the substep (ms2-mpm `Material::stable_water_bulk_modulus`),
    // a lone drop of this seed's 872 kg/m³ water oscillated ever harder between its pressure
    // and its APIC matrix and the step failed with `Diverged`.
    let mut env = pour_env("state");
    env.reset(Some(0), false).unwrap();
    let (beaker, n) = {
        let pour = env.task().unwrap().downcast_ref::<Pour>().unwrap();
        (pour.episode().beaker_xy, pour.arm().particle_count())
    };
    let mut state = env.get_state();
    let first = state.len() - 24 * n;
    for k in 0..16 {
        let c = &mut state[first + 24 * k..first + 24 * (k + 1)];
        let (i, j) = ((k % 4) as f32, (k / 4) as f32);
        c[0] = beaker.x + 0.016 * (i - 1.5);
        c[1] = beaker.y + 0.016 * (j - 1.5);
        c[2] = 0.08 + 0.01 * ((k % 3) as f32);
        c[3..6].copy_from_slice(&[0.0, 0.0, -0.2]);
    }
    env.set_state(&state).unwrap();
    let act = hold(&env);
    for step in 0..5 {
        env.step(&act)
            .unwrap_or_else(|e| panic!("step {step}: {e}"));
    }
    let pour = env.task().unwrap().downcast_ref::<Pour>().unwrap();
    let solver = pour.arm().soft().unwrap().solver();
    let vmax = solver
        .velocities()
        .iter()
        .map(|v| v.length())
        .fold(0.0, f32::max);
    // Free fall from 10 cm: 1.4 m/s.
    assert!(vmax < 2.0, "max speed {vmax} m/s");
    let e = pour.pour_eval(env.task_scene().unwrap()).unwrap();
    assert!(
        e.terms.counts.in_beaker == 16,
        "{} drops in the beaker",
        e.terms.counts.in_beaker
    );
}
