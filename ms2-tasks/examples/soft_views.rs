//! Writes what the cameras see of the soft-body tasks' clay: for `Excavate-v0` and `Fill-v0`,
//! the `rgbd` images of both observation cameras and the 512×512 human render
//! (`render_mode="rgb_array"`), at reset and during the scripted solution, as PNGs.
//!
//! `cargo run --release -p ms2-tasks --example soft_views -- [OUT_DIR] [SEED]`
//! (default `$TMPDIR/ms2-soft-views`, seed 1).

use ms2_tasks::{make_env, make_scripted_policy, ArrayData, EnvConfig, ObsValue};

fn save(array_shape: &[usize], rgb: &[u8], path: &std::path::Path) {
    let img = image::RgbImage::from_raw(array_shape[1] as u32, array_shape[0] as u32, rgb.to_vec())
        .expect("an [H, W, 3] image");
    img.save(path).expect("the PNG is written");
}

fn save_obs(obs: &ObsValue, cam: &str, path: &std::path::Path) {
    if let Some(ObsValue::Array(a)) = obs.get(&format!("image/{cam}/rgb")) {
        if let ArrayData::U8(rgb) = &a.data {
            save(&a.shape, rgb, path);
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = args
        .next()
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("ms2-soft-views"));
    let seed: u64 = args.next().map_or(Ok(1), |s| s.parse())?;
    std::fs::create_dir_all(&out)?;
    for (env_id, snapshots) in [("Excavate-v0", [0, 30, 72]), ("Fill-v0", [0, 20, 60])] {
        let mut env = make_env(&EnvConfig {
            obs_mode: "rgbd".to_owned(),
            render_mode: Some("rgb_array".to_owned()),
            ..EnvConfig::new(env_id)
        })?;
        let mut policy = make_scripted_policy(&env)?;
        let (mut obs, _) = env.reset(Some(seed), false)?;
        policy.reset(&env);
        for step in 0..=snapshots[2] {
            if snapshots.contains(&step) {
                let stem = format!("{env_id}_step{step:03}");
                for cam in ["base_camera", "hand_camera"] {
                    save_obs(&obs, cam, &out.join(format!("{stem}_{cam}.png")));
                }
                let human = env.render()?;
                if let ArrayData::U8(rgb) = &human.data {
                    save(&human.shape, rgb, &out.join(format!("{stem}_render.png")));
                }
            }
            obs = env.step(&policy.act(&env))?.obs;
        }
    }
    println!("wrote {}", out.display());
    Ok(())
}
