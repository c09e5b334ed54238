//! The gallery picture of one task from Rust (what `ms2 gallery` renders through the Python
//! package): `reset(seed)`, `steps` steps of the scripted policy, then the 512×512 `render()`
//! view, written as a PNG.
//!
//! `cargo run --release -p ms2-tasks --example task_picture -- ENV_ID OUT.png [STEPS=30] [SEED=0]`

use ms2_tasks::{make_env, make_scripted_policy, ArrayData, EnvConfig};

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
