//! The soft-body tasks' clay in visual observations: seen where its particles are, at their
//! depth, with its own segmentation id (not the robot's), moving with the scoop and the pour,
//! and batched renders equal to single-env renders. Writes PNGs to `$TMPDIR/ms2-soft-render/`.

use glam::Vec3;
use ms2_tasks::adapters::{RenderContext, WorldRenderScene};
use ms2_tasks::families::soft::bucket_arm::CLAY_SEGMENTATION_NAME;
use ms2_tasks::families::soft::excavate::Excavate;
use ms2_tasks::families::soft::fill::{BEAKER_HEIGHT, BEAKER_INNER_HALF};
use ms2_tasks::{
    make_env, make_scripted_policy, ArrayData, Env, EnvConfig, ObsValue, SoftComponent, VecEnv,
};

fn env(id: &str, obs_mode: &str) -> Env {
    make_env(&EnvConfig {
        obs_mode: obs_mode.to_owned(),
        ..EnvConfig::new(id)
    })
    .unwrap()
}

fn leaf<'a>(obs: &'a ObsValue, path: &str) -> (&'a [usize], &'a ArrayData) {
    match obs.get(path) {
        Some(ObsValue::Array(a)) => (&a.shape, &a.data),
        other => panic!("{path}: expected an array, got {other:?}"),
    }
}

fn f32s<'a>(obs: &'a ObsValue, path: &str) -> &'a [f32] {
    match leaf(obs, path).1 {
        ArrayData::F32(v) => v,
        other => panic!("{path}: not f32: {other:?}"),
    }
}

/// The soft component of a soft env (Excavate-v0 or Fill-v0).
fn task(env: &Env) -> &dyn SoftComponent {
    env.task().unwrap().soft().unwrap()
}

/// The clay's segmentation ids (visual id, actor/link id), as the env's sensors assign them:
/// the world's objects, then the task's particle sets.
fn clay_ids(env: &Env) -> (u32, u32) {
    let ctx = RenderContext::shared().unwrap();
    let mut scene =
        WorldRenderScene::build(&ctx, env.task_scene().unwrap().world.as_ref()).unwrap();
    let visuals = task(env).particle_visuals();
    assert_eq!(visuals.len(), 1, "one particle set: the clay");
    scene.add_particle_set(&visuals[0]);
    let clay = scene
        .objects()
        .iter()
        .find(|o| o.name == CLAY_SEGMENTATION_NAME)
        .unwrap();
    (scene.visual_count(), clay.id)
}

fn particles(env: &Env) -> Vec<Vec3> {
    task(env).particle_positions(0).to_vec()
}

fn clay_radius(env: &Env) -> f32 {
    task(env).particle_visuals()[0].radius_m
}

/// Distance (m) from `p` to the nearest particle centre, on a hash grid of `cell` m.
struct NearestParticle {
    cell: f32,
    grid: std::collections::HashMap<[i32; 3], Vec<Vec3>>,
}

impl NearestParticle {
    fn new(points: &[Vec3], cell: f32) -> Self {
        let mut grid: std::collections::HashMap<[i32; 3], Vec<Vec3>> = Default::default();
        for &p in points {
            grid.entry(Self::key(p, cell)).or_default().push(p);
        }
        Self { cell, grid }
    }

    fn key(p: Vec3, cell: f32) -> [i32; 3] {
        (p / cell).floor().as_ivec3().to_array()
    }

    /// Distance to the nearest particle within one cell, else `f32::INFINITY`.
    fn distance(&self, p: Vec3) -> f32 {
        let [x, y, z] = Self::key(p, self.cell);
        let mut best = f32::INFINITY;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(ps) = self.grid.get(&[x + dx, y + dy, z + dz]) {
                        for q in ps {
                            best = best.min(q.distance(p));
                        }
                    }
                }
            }
        }
        best
    }
}

/// Points of a `pointcloud*` observation: (position, [visual id, link id], robot flag).
fn cloud(obs: &ObsValue) -> Vec<(Vec3, [u32; 2], bool)> {
    let xyzw = f32s(obs, "pointcloud/xyzw");
    let ArrayData::U32(seg) = leaf(obs, "pointcloud/Segmentation").1 else {
        panic!("Segmentation is not u32")
    };
    let robot = match obs.get("pointcloud/robot_seg") {
        Some(ObsValue::Array(a)) => match &a.data {
            ArrayData::Bool(m) => m.clone(),
            other => panic!("robot_seg: {other:?}"),
        },
        _ => vec![false; xyzw.len() / 4],
    };
    xyzw.chunks_exact(4)
        .enumerate()
        .filter(|(_, p)| p[3] == 1.0)
        .map(|(i, p)| {
            (
                Vec3::new(p[0], p[1], p[2]),
                [seg[4 * i], seg[4 * i + 1]],
                robot[i],
            )
        })
        .collect()
}

/// Checks that every clay point lies on a particle's sphere and has the clay's visual id and
/// no robot flag; returns the clay points.
fn clay_points(env: &Env, obs: &ObsValue) -> Vec<Vec3> {
    let (visual_id, link_id) = clay_ids(env);
    let r = clay_radius(env);
    let near = NearestParticle::new(&particles(env), 0.01);
    let mut out = Vec::new();
    for (p, [visual, link], robot) in cloud(obs) {
        if link != link_id {
            assert_ne!(
                visual, visual_id,
                "a non-clay point {p} has the clay's visual id"
            );
            continue;
        }
        assert_eq!(visual, visual_id, "clay point {p}: visual id");
        assert!(!robot, "clay point {p} is flagged as robot");
        let d = near.distance(p);
        assert!(
            (r - 1e-3..=r + 1e-3).contains(&d),
            "clay point {p} is {d} m from the nearest particle centre (radius {r} m)"
        );
        out.push(p);
    }
    out
}

fn out_dir() -> std::path::PathBuf {
    let dir = std::env::temp_dir().join("ms2-soft-render");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes an `[H, W, 3]` u8 image of `obs` at `path` to `name`.png.
fn save_rgb(obs: &ObsValue, path: &str, name: &str) {
    let (shape, ArrayData::U8(rgb)) = leaf(obs, path) else {
        panic!("{path} is not u8")
    };
    let img = image::RgbImage::from_raw(shape[1] as u32, shape[0] as u32, rgb.clone()).unwrap();
    img.save(out_dir().join(format!("{name}.png"))).unwrap();
}

/// The clay's depth image as the camera of `obs` should see it, ray-cast on the CPU: per pixel
/// (OpenCV convention, pixel (0, 0) centred at (0, 0)), the depth along the optical axis of the
/// nearest particle sphere hit, or infinity.
fn ray_cast_clay(obs: &ObsValue, cam: &str, points: &[Vec3], r: f32) -> Vec<f32> {
    let (shape, _) = leaf(obs, &format!("image/{cam}/depth"));
    let (h, w) = (shape[0] as i64, shape[1] as i64);
    let k = f32s(obs, &format!("camera_param/{cam}/intrinsic_cv"));
    let ext = f32s(obs, &format!("camera_param/{cam}/extrinsic_cv"));
    let (fx, fy, cx, cy) = (k[0], k[4], k[2], k[5]);
    let mut depth = vec![f32::INFINITY; (h * w) as usize];
    for p in points {
        let c = Vec3::from_array(std::array::from_fn(|i| {
            ext[4 * i] * p.x + ext[4 * i + 1] * p.y + ext[4 * i + 2] * p.z + ext[4 * i + 3]
        }));
        if c.z <= r {
            continue;
        }
        let (u, v) = (fx * c.x / c.z + cx, fy * c.y / c.z + cy);
        let reach = (fx.max(fy) * r / (c.z - r)).ceil() as i64 + 1;
        for row in (v as i64 - reach).max(0)..=(v as i64 + reach).min(h - 1) {
            for col in (u as i64 - reach).max(0)..=(u as i64 + reach).min(w - 1) {
                // Ray t · d, d = ((u − cx) / fx, (v − cy) / fy, 1): depth along the axis is t.
                let d = Vec3::new((col as f32 - cx) / fx, (row as f32 - cy) / fy, 1.0);
                let (a, b) = (d.length_squared(), d.dot(c));
                let disc = b * b - a * (c.length_squared() - r * r);
                if disc >= 0.0 {
                    let t = (b - disc.sqrt()) / a;
                    let i = (row * w + col) as usize;
                    depth[i] = depth[i].min(t);
                }
            }
        }
    }
    depth
}

/// Checks `obs` (`rgbd_robot_seg`) against a CPU ray cast of all of `env`'s particles: where a
/// camera's ray hits a particle sphere and the robot does not hide it, the depth is the ray
/// cast's within 1 mm, for at least 98 % of those pixels (a pixel centre grazing a rim may round
/// either way). Returns the pixels checked per camera.
fn assert_depth_matches_ray_cast(env: &Env, obs: &ObsValue, when: &str) -> Vec<usize> {
    let (points, r) = (particles(env), clay_radius(env));
    let mut counts = Vec::new();
    for cam in ["base_camera", "hand_camera"] {
        let expected = ray_cast_clay(obs, cam, &points, r);
        let depth = f32s(obs, &format!("image/{cam}/depth"));
        let ArrayData::Bool(robot) = leaf(obs, &format!("image/{cam}/robot_seg")).1 else {
            panic!("robot_seg is not bool")
        };
        let (mut checked, mut off) = (0, 0);
        for i in 0..depth.len() {
            if expected[i].is_finite() && !robot[i] {
                checked += 1;
                if (depth[i] - expected[i]).abs() > 1e-3 {
                    off += 1;
                }
            }
        }
        assert!(
            off * 50 <= checked,
            "{when}, {cam}: {off} of {checked} clay pixels off the ray-cast depth by > 1 mm"
        );
        counts.push(checked);
    }
    counts
}

/// In `rgbd_robot_seg`, both cameras see the clay exactly where a CPU ray cast of all its
/// particle spheres says (away from the robot, which may hide it), at reset and with the bed
/// cut open by the scripted scoop: so hidden-particle culling leaves no holes. Without the
/// clay these pixels see the table, centimetres further away.
#[test]
fn excavate_rgbd_depth_matches_ray_cast_particles() {
    let mut e = env("Excavate-v0", "rgbd_robot_seg");
    let mut policy = make_scripted_policy(&e).unwrap();
    let (mut obs, _) = e.reset(Some(2), false).unwrap();
    policy.reset(&e);
    save_rgb(&obs, "image/base_camera/rgb", "excavate_base_reset");
    save_rgb(&obs, "image/hand_camera/rgb", "excavate_hand_reset");
    let at_reset = assert_depth_matches_ray_cast(&e, &obs, "reset");
    assert!(at_reset.iter().all(|&n| n > 50), "clay pixels {at_reset:?}");
    for _ in 0..34 {
        obs = e.step(&policy.act(&e)).unwrap().obs;
    }
    save_rgb(&obs, "image/hand_camera/rgb", "excavate_hand_scoop");
    let scooping = assert_depth_matches_ray_cast(&e, &obs, "scooping");
    assert!(
        scooping.iter().sum::<usize>() > 50,
        "clay pixels {scooping:?}"
    );
}

/// In `pointcloud_robot_seg`, the clay's points lie on its particles with the clay's ids and no
/// robot flag, and cover the bed; after the scripted scoop, clay is seen above the bed.
#[test]
fn excavate_point_cloud_shows_the_clay_bed_then_the_scooped_clay() {
    let mut e = env("Excavate-v0", "pointcloud_robot_seg");
    let mut policy = make_scripted_policy(&e).unwrap();
    let (obs, _) = e.reset(Some(1), false).unwrap();
    policy.reset(&e);
    let bed = e
        .task()
        .unwrap()
        .downcast_ref::<Excavate>()
        .unwrap()
        .bed()
        .unwrap()
        .clone();
    let clay = clay_points(&e, &obs);
    assert!(clay.len() > 300, "{} clay points at reset", clay.len());
    let top = clay.iter().map(|p| p.z).fold(f32::MIN, f32::max);
    assert!(
        (bed.bed_top_z - 0.005..bed.bed_top_z + 0.01).contains(&top),
        "clay seen up to {top} m, bed top {} m",
        bed.bed_top_z
    );
    let mut obs = obs;
    for _ in 0..72 {
        obs = e.step(&policy.act(&e)).unwrap().obs;
    }
    let clay = clay_points(&e, &obs);
    let lifted = clay.iter().filter(|p| p.z > bed.bed_top_z + 0.03).count();
    assert!(
        lifted > 30,
        "{lifted} clay points above the bed after the scoop"
    );
}

/// Fill-v0: the clay is seen in the bucket at reset and in the beaker after the scripted pour.
#[test]
fn fill_point_cloud_shows_the_clay_in_the_bucket_then_in_the_beaker() {
    let mut e = env("Fill-v0", "pointcloud");
    let mut policy = make_scripted_policy(&e).unwrap();
    let (obs, _) = e.reset(Some(3), false).unwrap();
    policy.reset(&e);
    let clay = clay_points(&e, &obs);
    assert!(clay.len() > 50, "{} clay points at reset", clay.len());
    let bucket = e.privileged_obs();
    let bucket = f32s(&bucket, "extra/bucket_pose");
    let centre = Vec3::new(bucket[0], bucket[1], bucket[2]);
    for p in &clay {
        assert!(
            p.distance(centre) < 0.1,
            "clay point {p} far from the bucket at {centre}"
        );
    }
    // Pour until the episode ends in success (about 60 control steps); the arm then moves
    // on and may hide the beaker from the camera.
    let mut obs = obs;
    for _ in 0..90 {
        let out = e.step(&policy.act(&e)).unwrap();
        obs = out.obs;
        if out.terminated {
            break;
        }
    }
    let beaker = e.privileged_obs();
    let beaker = f32s(&beaker, "extra/beaker_pos");
    let clay = clay_points(&e, &obs);
    let in_beaker = clay
        .iter()
        .filter(|p| {
            (p.x - beaker[0]).abs() < BEAKER_INNER_HALF
                && (p.y - beaker[1]).abs() < BEAKER_INNER_HALF
                && p.z < BEAKER_HEIGHT
        })
        .count();
    // The beaker is small in the 128 × 128 base camera and the hand camera looks away: a few
    // dozen clay pixels at most.
    assert!(
        in_beaker * 2 > clay.len() && in_beaker >= 8,
        "{in_beaker} of {} clay points in the beaker after the pour",
        clay.len()
    );
    let mut r = env("Fill-v0", "rgbd");
    let (obs, _) = r.reset(Some(3), false).unwrap();
    save_rgb(&obs, "image/base_camera/rgb", "fill_base_reset");
}

/// A vector env's batched images equal single-env images of the same episodes.
#[test]
fn batched_soft_env_images_equal_single_env_images() {
    let cfg = EnvConfig {
        obs_mode: "rgbd".to_owned(),
        ..EnvConfig::new("Excavate-v0")
    };
    let seeds = [4u64, 5];
    let mut venv = VecEnv::new(&cfg, seeds.len()).unwrap();
    venv.reset(&seeds.map(Some)).unwrap();
    let dim = venv.envs()[0].action_space().size();
    let action: Vec<f32> = (0..dim).map(|k| 0.3 * ((k % 3) as f32 - 1.0)).collect();
    let actions: Vec<f32> = seeds.iter().flat_map(|_| action.clone()).collect();
    let mut batched = Vec::new();
    for _ in 0..3 {
        batched = venv.step(&actions).unwrap();
    }
    for (k, seed) in seeds.iter().enumerate() {
        let mut single = make_env(&cfg).unwrap();
        single.reset(Some(*seed), false).unwrap();
        let mut out = None;
        for _ in 0..3 {
            out = Some(single.step(&action).unwrap());
        }
        let out = out.unwrap();
        for cam in ["base_camera", "hand_camera"] {
            for key in ["rgb", "depth"] {
                let path = format!("image/{cam}/{key}");
                assert!(
                    leaf(&batched[k].obs, &path) == leaf(&out.obs, &path),
                    "env {k}: batched {path} differs from the single env's"
                );
            }
        }
        assert!(
            particles(&venv.envs()[k]) == particles(&single),
            "env {k}: same episode, same particles"
        );
    }
}
