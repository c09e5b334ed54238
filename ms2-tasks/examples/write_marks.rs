//! Compares `Write-v0`'s written marks with the goal's: writes a character with the scripted
//! plan either by the robot (a scripted episode) or by a kinematic stick (the task's capsule
//! moved exactly along the plan, no arm), then saves PNGs (8 px per height-image pixel, the
//! glyph upright: world +x up, world −y right) and prints the pixel classes.
//!
//! ```text
//! cargo run --release -p ms2-tasks --example write_marks -- robot <seed> [out_dir=/tmp/write_marks]
//! cargo run --release -p ms2-tasks --example write_marks -- kinematic <character id> [out_dir]
//! ```
//! Images: `<tag>_goal.png`, `<tag>_clay.png` (heights, 30 mm black to 60 mm white) and
//! `<tag>_classes.png`: green = counted (written in one, near in the other), red = goal written
//! but the clay not near, blue = clay written but the goal not near, dark grey = near only;
//! the stick tip's path below the slab's top in yellow (robot: the actual tip, white the plan).
//! The robot's episode goes on after its success (which ends it) to step 200, to measure the
//! whole character; `STOP=1` stops at the success. `MPM=<Hz>` sets the robot's MPM rate. The PNGs' data are saved too (`<tag>_images.json`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::{Vec2, Vec3};
use ms2_tasks::families::soft::write::Write;
use ms2_tasks::families::soft::write_ideal::{ideal_stick_path, write_ideally, IdealWriter};
use ms2_tasks::families::soft::write_policy::{tip_command, WritePolicy, TIP_IN_HAND_Z};
use ms2_tasks::families::soft::write_targets::{
    builtin_characters, goal_image, mark_iou, written_pixels, Character, TargetSplit, IMAGE_SIZE,
    IMAGE_WORLD_SIZE_M, NEAR_BELOW_MM, WRITTEN_BELOW_MM,
};
use ms2_tasks::{make_env, make_scripted_policy, EnvConfig};

/// Upscale of the PNGs.
const ZOOM: u32 = 8;

type Error = Box<dyn std::error::Error>;

/// PNG pixel (column, row) of a height-image pixel (x, y): the glyph upright.
fn to_png(x: usize, y: usize) -> (u32, u32) {
    ((IMAGE_SIZE - 1 - y) as u32, (IMAGE_SIZE - 1 - x) as u32)
}

fn world_to_image(p: Vec2) -> (f32, f32) {
    let s = IMAGE_SIZE as f32 / IMAGE_WORLD_SIZE_M;
    (
        (p.x + IMAGE_WORLD_SIZE_M / 2.0) * s,
        (p.y + IMAGE_WORLD_SIZE_M / 2.0) * s,
    )
}

fn save(out: &Path, name: &str, pixel: impl Fn(usize, usize) -> [u8; 3]) -> Result<(), Error> {
    let side = IMAGE_SIZE as u32 * ZOOM;
    let mut img = image::RgbImage::new(side, side);
    for y in 0..IMAGE_SIZE {
        for x in 0..IMAGE_SIZE {
            let (c, r) = to_png(x, y);
            let v = image::Rgb(pixel(x, y));
            for i in 0..ZOOM {
                for j in 0..ZOOM {
                    img.put_pixel(c * ZOOM + i, r * ZOOM + j, v);
                }
            }
        }
    }
    img.save(out.join(name))?;
    Ok(())
}

fn draw_path(out: &Path, name: &str, paths: &[(&[Vec3], [u8; 3])]) -> Result<(), Error> {
    let file = out.join(name);
    let mut img = image::open(&file)?.to_rgb8();
    for (path, colour) in paths {
        for p in path.iter().filter(|p| p.z < 0.05) {
            let (fx, fy) = world_to_image(p.truncate());
            // Pixel centres sit at integer image coordinates (the height image's convention).
            let col = (IMAGE_SIZE as f32 - 1.0 - fy + 0.5) * ZOOM as f32;
            let row = (IMAGE_SIZE as f32 - 1.0 - fx + 0.5) * ZOOM as f32;
            let inside = col >= 1.0 && row >= 1.0;
            if inside && col < img.width() as f32 - 1.0 && row < img.height() as f32 - 1.0 {
                for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    img.put_pixel(
                        col as u32 + di - 1,
                        row as u32 + dj - 1,
                        image::Rgb(*colour),
                    );
                }
            }
        }
    }
    img.save(file)?;
    Ok(())
}

fn grey(v: i32) -> [u8; 3] {
    let g = ((v - 30) as f32 / 30.0 * 255.0).clamp(0.0, 255.0) as u8;
    [g, g, g]
}

/// Saves the images and prints the classes; returns the IoU.
fn report(
    out: &Path,
    tag: &str,
    goal: &[i32],
    clay: &[i32],
    paths: &[(&[Vec3], [u8; 3])],
) -> Result<f32, Error> {
    std::fs::create_dir_all(out)?;
    std::fs::write(
        out.join(format!("{tag}_images.json")),
        serde_json::to_string(&serde_json::json!({"goal": goal, "clay": clay}))?,
    )?;
    save(out, &format!("{tag}_goal.png"), |x, y| {
        grey(goal[y * IMAGE_SIZE + x])
    })?;
    save(out, &format!("{tag}_clay.png"), |x, y| {
        grey(clay[y * IMAGE_SIZE + x])
    })?;
    let (mut both, mut goal_only, mut clay_only) = (0, 0, 0);
    save(out, &format!("{tag}_classes.png"), |x, y| {
        let (g, c) = (goal[y * IMAGE_SIZE + x], clay[y * IMAGE_SIZE + x]);
        let (gw, gn) = (g < WRITTEN_BELOW_MM, g < NEAR_BELOW_MM);
        let (cw, cn) = (c < WRITTEN_BELOW_MM, c < NEAR_BELOW_MM);
        if (gn && cw) || (gw && cn) {
            [40, 200, 40]
        } else if gw {
            [220, 40, 40]
        } else if cw {
            [60, 90, 240]
        } else if gn || cn {
            [70, 70, 70]
        } else {
            [0, 0, 0]
        }
    })?;
    for (g, c) in goal.iter().zip(clay) {
        let (gw, gn) = (*g < WRITTEN_BELOW_MM, *g < NEAR_BELOW_MM);
        let (cw, cn) = (*c < WRITTEN_BELOW_MM, *c < NEAR_BELOW_MM);
        if (gn && cw) || (gw && cn) {
            both += 1;
        } else if gw {
            goal_only += 1;
        } else if cw {
            clay_only += 1;
        }
    }
    draw_path(out, &format!("{tag}_classes.png"), paths)?;
    let iou = mark_iou(goal, clay);
    println!(
        "{tag}: iou {iou:.3}; counted {both}, goal-only {goal_only}, clay-only {clay_only}; written goal {} clay {}",
        written_pixels(goal),
        written_pixels(clay)
    );
    Ok(iou)
}

fn robot(seed: u64, out: &Path) -> Result<(), Error> {
    let mut env = make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        mpm_freq: std::env::var("MPM").ok().and_then(|v| v.parse().ok()),
        ..EnvConfig::new("Write-v0")
    })?;
    let mut policy = make_scripted_policy(&env)?;
    env.reset(Some(seed), false)?;
    policy.reset(&env);
    let tip = |env: &ms2_tasks::Env| {
        let w = env.task().unwrap().downcast_ref::<Write>().unwrap();
        let hand = w
            .arm()
            .hand_pose(env.task_scene().unwrap().world.as_ref())
            .unwrap();
        let p = hand * nalgebra::Point3::new(0.0, 0.0, TIP_IN_HAND_Z);
        Vec3::new(p.x, p.y, p.z)
    };
    let (character, goal) = {
        let w = env.task().unwrap().downcast_ref::<Write>().unwrap();
        (w.character().clone(), w.goal_image().to_vec())
    };
    let plan = WritePolicy::plan(tip(&env), &character.world_strokes());
    let start = Instant::now();
    let (mut actual, mut planned) = (vec![tip(&env)], Vec::new());
    let (mut err_sum, mut err_max, mut n) = (0.0f32, 0.0f32, 0);
    let mut first_success = None;
    for step in 0..200u32 {
        let r = env.step(&policy.act(&env))?;
        let p = tip(&env);
        let c = tip_command(&plan, step).unwrap_or(p);
        actual.push(p);
        planned.push(c);
        if c.z < 0.05 {
            let e = (p - c).length();
            err_sum += e;
            err_max = err_max.max(e);
            n += 1;
            if step % 5 == 0 {
                println!(
                    "step {step:3}: tip [{:.4} {:.4} {:.4}] plan [{:.4} {:.4} {:.4}] err xy {:.1} mm z {:.1} mm",
                    p.x, p.y, p.z, c.x, c.y, c.z,
                    (p.truncate() - c.truncate()).length() * 1e3,
                    (p.z - c.z) * 1e3
                );
            }
        }
        // The episode ends on success; the writer goes on (`STOP=1`: not) to measure its
        // whole character.
        if r.terminated && first_success.is_none() {
            first_success = Some(step + 1);
            if std::env::var("STOP").is_ok() {
                break;
            }
        }
        if r.truncated {
            break;
        }
    }
    println!("seed {seed}: first success after step {first_success:?}");
    println!(
        "seed {seed} [{}]: in-clay tracking error mean {:.1} mm max {:.1} mm over {n} steps; {:.0} s",
        character.id,
        err_sum / n.max(1) as f32 * 1e3,
        err_max * 1e3,
        start.elapsed().as_secs_f64()
    );
    let clay = env
        .task()
        .unwrap()
        .downcast_ref::<Write>()
        .unwrap()
        .current_image();
    report(
        out,
        &format!("robot_{seed}_{}", character.id),
        &goal,
        &clay,
        &[(&planned, [255, 255, 255]), (&actual, [255, 220, 0])],
    )?;
    Ok(())
}

/// Writes `character` with the ideal writer (`write_ideal`, a kinematic stick).
fn kinematic(character: &Character, out: &Path) -> Result<(), Error> {
    let start = Instant::now();
    let writer = IdealWriter::default();
    let clay = write_ideally(character, &writer)?;
    println!(
        "ideal writer {}: {:.0} s",
        character.id,
        start.elapsed().as_secs_f64()
    );
    let path: Vec<Vec3> = ideal_stick_path(character, &writer)
        .windows(2)
        .flat_map(|w| (0..=20).map(move |k| w[0].0.lerp(w[1].0, k as f32 / 20.0)))
        .collect();
    report(
        out,
        &format!("kinematic_{}", character.id),
        &goal_image(character),
        &clay,
        &[(&path, [255, 220, 0])],
    )?;
    Ok(())
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = PathBuf::from(args.get(2).map_or("/tmp/write_marks", |s| s.as_str()));
    match (args.first().map(String::as_str), args.get(1)) {
        (Some("robot"), Some(seed)) => robot(seed.parse()?, &out),
        (Some("kinematic"), Some(id)) => {
            let all: Vec<Character> = builtin_characters(TargetSplit::Train)
                .into_iter()
                .chain(builtin_characters(TargetSplit::Test))
                .collect();
            let c = all
                .iter()
                .find(|c| &c.id == id)
                .ok_or_else(|| format!("no character {id:?}"))?;
            kinematic(c, &out)
        }
        _ => Err("usage: write_marks robot <seed> | kinematic <id> [out_dir]".into()),
    }
}
