//! Loads the Panda, prints its joints and limits, holds the rest pose for 2 s and prints the
//! joint errors and the TCP pose.
//!
//! `cargo run --release -p ms2-physics --example panda_info`

use ms2_physics::{add_panda, PandaOptions, World, WorldConfig};

fn main() -> ms2_physics::Result<()> {
    let mut world = World::new(WorldConfig::default())?;
    let options = PandaOptions::default();
    let panda = add_panda(&mut world, &options)?;
    println!(
        "articulation \"{}\", {} dof",
        world.articulation_name(panda)?,
        world.dof(panda)?
    );
    for (info, lim) in world
        .joint_infos(panda)?
        .iter()
        .zip(world.joint_limits(panda)?)
    {
        println!(
            "  {:<22} {:?}  limits [{:+.4}, {:+.4}]  mimic {:?}",
            info.name, info.joint_type, lim[0], lim[1], info.mimic
        );
    }
    println!("links: {:?}", world.link_names(panda)?);
    let start = std::time::Instant::now();
    world.step_n(1000);
    let elapsed = start.elapsed();
    let q = world.qpos(panda)?;
    let err: Vec<f32> = q.iter().zip(options.qpos).map(|(a, b)| a - b).collect();
    println!("after 2 s: qpos error {err:?}");
    let tcp = world.link_index(panda, ms2_assets::PANDA_TCP_LINK)?;
    println!("tcp pose {}", world.link_pose(panda, tcp)?);
    println!(
        "1000 steps in {:.3} s ({:.1} µs/step)",
        elapsed.as_secs_f64(),
        elapsed.as_secs_f64() * 1e3
    );
    Ok(())
}
