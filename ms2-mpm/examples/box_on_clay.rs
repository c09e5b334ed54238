//! Two-way coupling with the in-crate rigid backend: a wooden box dropped on a clay bed.
//! Prints, every 50 ms, the box height, its velocity and the soft material's push on it,
//! which settles at the box's weight.
//!
//! Run: `cargo run --release -p ms2-mpm --example box_on_clay`

use glam::Vec3;
use ms2_mpm::rigid::{Motion, SimpleRigidWorld};
use ms2_mpm::{sampling, Coupling, CouplingParams, GridSpec, Material, MpmSolver, SolverConfig};

fn main() -> Result<(), ms2_mpm::MpmError> {
    // 32³ grid of 1 cm cells; MPM at 2000 Hz, rigid bodies at 500 Hz (ManiSkill2's rates).
    let mut solver = MpmSolver::new(SolverConfig::new(GridSpec::new(Vec3::ZERO, 0.01, [32; 3])))?;
    let clay = solver.add_material(Material::clay(1000.0, 1e4, 0.3, 2e3))?;
    let spacing = 0.005;
    let (lo, _) = solver.usable_domain();
    let bed = sampling::sample_box(
        Vec3::new(0.08, 0.08, lo.z),
        Vec3::new(0.24, 0.24, 0.06),
        spacing,
    );
    solver.add_particles(&bed, clay, spacing.powi(3), Vec3::ZERO)?;

    let mut world = SimpleRigidWorld::new(solver.config().gravity);
    let half = Vec3::new(0.025, 0.025, 0.015);
    let body = world.add_box(half, 600.0, Vec3::new(0.16, 0.16, 0.12), Motion::Dynamic);
    let weight = world.bodies[body].mass * 9.81;
    let mut coupling = Coupling::new(
        &world,
        CouplingParams::for_substep(solver.config().substep_dt),
    )?;

    let substeps = 4;
    let rigid_dt = substeps as f32 * solver.config().substep_dt;
    println!(
        "{} clay particles; box weight {weight:.3} N",
        solver.particle_count()
    );
    println!(
        "{:>6} {:>10} {:>10} {:>12}",
        "t (s)", "box z (m)", "vz (m/s)", "push z (N)"
    );
    for step in 1..=300 {
        world.step(rigid_dt);
        coupling.advance(&mut solver, &mut world, substeps)?;
        if step % 25 == 0 {
            let b = &world.bodies[body];
            println!(
                "{:>6.3} {:>10.4} {:>10.4} {:>12.4}",
                step as f32 * rigid_dt,
                b.position.z,
                b.linear_velocity.z,
                coupling.last_wrenches()[body].force.z
            );
        }
    }
    Ok(())
}
