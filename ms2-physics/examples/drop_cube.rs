//! Drops a 4 cm cube from 0.5 m and prints its height and the ground's contact force.
//!
//! `cargo run --release -p ms2-physics --example drop_cube`

use ms2_physics::{ActorDesc, ActorKind, Pose3, ShapeDesc, ShapeSpec, World, WorldConfig};

fn main() -> ms2_physics::Result<()> {
    let mut world = World::new(WorldConfig::default())?;
    let cube = world.add_actor(
        ActorDesc::new("cube", ActorKind::Dynamic)
            .with_pose(Pose3::translation(0.0, 0.0, 0.5))
            .with_shape(ShapeSpec::new(ShapeDesc::cuboid(0.04, 0.04, 0.04))),
    )?;
    let ground = world.ground().expect("default world has a ground");
    for step in 0..=1000 {
        if step % 100 == 0 {
            let z = world.body_pose(cube)?.translation.z;
            let f = world.contact_impulse_between(cube, ground) / world.timestep();
            println!(
                "t = {:.2} s  z = {z:.4} m  ground force on cube = ({:.3}, {:.3}, {:.3}) N",
                step as f32 * world.timestep(),
                f.x,
                f.y,
                f.z
            );
        }
        world.step();
    }
    println!("cube mass {:.4} kg", world.body_mass(cube)?);
    Ok(())
}
