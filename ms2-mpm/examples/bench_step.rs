//! Times the clay benchmark scene (`ms2_mpm::scenes::clay_block`) and prints one line of
//! `key=value` pairs, the format `bench/compare_taichi.sh` reads. `state_hash` fingerprints the
//! final state (FNV-1a over the bits of every particle's position, velocity, deformation
//! gradient and affine matrix, in canonical order): equal hashes from two builds mean
//! bit-identical simulations. `build` names the transfer kernels' build that ran
//! (`ms2_mpm::transfer_build`: `avx512` or `baseline`).
//!
//! Usage: `cargo run --release -p ms2-mpm --example bench_step -- [particles] [threads] [substeps]`
//! (defaults 32768, all cores, 400).

use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, default: usize| -> Result<usize, Box<dyn std::error::Error>> {
        match args.get(i) {
            Some(s) => Ok(s
                .parse()
                .map_err(|e| format!("argument {} = {s:?}: {e}", i + 1))?),
            None => Ok(default),
        }
    };
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let particles = arg(0, 32_768)?;
    let threads = arg(1, all)?;
    let substeps = arg(2, 400)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let mut solver = ms2_mpm::scenes::clay_block(particles)?;
    // Rates are per particle the scene really holds.
    let particles = solver.particle_count();
    pool.install(|| -> Result<(), ms2_mpm::MpmError> {
        for _ in 0..50 {
            solver.substep()?;
        }
        let start = Instant::now();
        for _ in 0..substeps {
            solver.substep()?;
        }
        let secs = start.elapsed().as_secs_f64();
        let top = solver
            .positions()
            .iter()
            .map(|p| p.z)
            .fold(f32::MIN, f32::max);
        let hash = state_hash(&solver.state());
        println!(
            "engine=ms2-mpm particles={particles} threads={threads} substeps={substeps} \
             seconds={secs:.3} particle_substeps_per_s={:.4e} top_z={top:.4} \
             state_hash={hash:016x} build={}",
            (particles * substeps) as f64 / secs,
            ms2_mpm::transfer_build()
        );
        Ok(())
    })?;
    Ok(())
}

/// FNV-1a over the bits of the state's per-particle kinematics (see the module docs).
fn state_hash(state: &ms2_mpm::MpmState) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: f32| {
        for b in x.to_bits().to_le_bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    };
    for i in 0..state.positions.len() {
        state.positions[i].to_array().into_iter().for_each(&mut eat);
        state.velocities[i]
            .to_array()
            .into_iter()
            .for_each(&mut eat);
        state.deformation_gradients[i]
            .to_cols_array()
            .into_iter()
            .for_each(&mut eat);
        state.affine_velocities[i]
            .to_cols_array()
            .into_iter()
            .for_each(&mut eat);
    }
    h
}
