//! The gallery picture of one task from Rust (what `ms2 gallery` renders through the Python
//! package): `reset(seed)`, `steps` steps of the scripted policy, then the 512×512 `render()`
//! view, written as a PNG.
//!
//! `cargo run --release -p ms2-tasks --example task_picture -- ENV_ID OUT.png [STEPS=30] [SEED=0]`
//!
//! `CAMERA="x y z pitch yaw"` moves the render camera to world (x, y, z) (m), looking along
//! its yaw (degrees about z, 0 = +x) pitched down by `pitch` (degrees), e.g. to see Write-v0's
//! slab past the arm: `CAMERA="0.22 0 0.32 50 180"`.

use ms2_tasks::sensors::{CameraCfgUpdates, CameraUpdate};
use ms2_tasks::{make_env, make_scripted_policy, ArrayData, EnvConfig};

/// The render camera update of `CAMERA="x y z pitch yaw"` (m, degrees).
fn camera_update(text: &str) -> Result<CameraCfgUpdates, Box<dyn std::error::Error>> {
    let v: Vec<f32> = text
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let [x, y, z, pitch, yaw] = v[..] else {
        return Err(format!("CAMERA={text:?}: expected \"x y z pitch yaw\"").into());
    };
    let q = nalgebra::UnitQuaternion::from_euler_angles(0.0, pitch.to_radians(), yaw.to_radians());
    Ok(CameraCfgUpdates {
        all: CameraUpdate {
            p: Some([x, y, z]),
            q: Some([q.w, q.i, q.j, q.k]),
            ..Default::default()
        },
        per_camera: Vec::new(),
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(env_id), Some(out)) = (args.first(), args.get(1)) else {
        return Err("usage: task_picture ENV_ID OUT.png [STEPS=30] [SEED=0]".into());
    };
    let steps: u32 = args.get(2).map_or(Ok(30), |s| s.parse())?;
    let seed: u64 = args.get(3).map_or(Ok(0), |s| s.parse())?;
    let mut env = make_env(&EnvConfig {
        obs_mode: "none".to_owned(),
        render_mode: Some("rgb_array".to_owned()),
        render_camera_updates: std::env::var("CAMERA")
            .ok()
            .map(|t| camera_update(&t))
            .transpose()?,
        ..EnvConfig::new(env_id)
    })?;
    let mut policy = make_scripted_policy(&env)?;
    env.reset(Some(seed), false)?;
    policy.reset(&env);
    for _ in 0..steps {
        let out = env.step(&policy.act(&env))?;
        if out.terminated || out.truncated {
            break;
        }
    }
    let frame = env.render()?;
    let ArrayData::U8(rgb) = &frame.data else {
        return Err("render() returned no RGB bytes".into());
    };
    let (h, w) = (frame.shape[0] as u32, frame.shape[1] as u32);
    image::RgbImage::from_raw(w, h, rgb.clone())
        .ok_or("render() returned a frame of the wrong size")?
        .save(out)?;
    println!("{env_id}: {out}");
    Ok(())
}
