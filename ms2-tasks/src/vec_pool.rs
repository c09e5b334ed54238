//! The thread pool that steps a [`VecEnv`](crate::VecEnv)'s rigid envs in state modes.
//!
//! A rigid env step takes about a millisecond, and a vector step returns when its slowest env
//! is done, so what rayon's pool costs per vector step shows: the calling thread sleeps while
//! workers are woken, and the caller is woken again at the end (110-230 µs of a 1.5 ms vector
//! step with two envs on two cores, docs/benchmarks.md). `micropool`'s pool avoids both: the
//! calling thread steps envs itself, and a worker that has just run a job spins for
//! [`IDLE_SPIN_ITERATIONS`] (about half a millisecond) before it sleeps, so the next vector
//! step finds it awake when the caller comes back quickly (a benchmark loop, a cheap policy) and
//! costs at most that spin when it does not (a policy on PyTorch between steps).
//!
//! Measured (docs/benchmarks.md, `examples/vec_scaling.rs`): PickCube-v0 on two otherwise idle
//! cores, 10-14 % more env steps/s than rayon's pool in the same process with two envs (medians
//! per control mode, five runs each; 3-10 % with a spin a tenth as long) and 4-6 % with four; but on a
//! core-starved machine (load 5 on 2 cores) 13-34 % fewer, because a spinning thread holds a core
//! that another runnable thread needs. `MS2_VEC_POOL=rayon` ([`POOL_VARIABLE`]) selects rayon's
//! pool for every vector env of the process.
//!
//! The envs are split in contiguous halves (each half a job of `join`, down to single envs), so
//! with more envs than threads each thread steps the same envs from one vector step to the next
//! and an env moves to another thread only when one thread runs out of its own. Handing the envs
//! out one at a time instead, the longest last step first (which balances the threads better on
//! paper: 1.94 against 1.93x for four envs, 1.96 against 1.95x for eight, from traced step costs),
//! was slower on 2026-11-29: by 3-4 % with four and eight envs in `pd_ee_delta_pose`, 1-2 % in
//! `pd_joint_delta_pos` (PickCube-v0, medians of seven interleaved runs; docs/benchmarks.md), as
//! an env stepped on another core than its last step finds its state in the other core's cache.
//! The other way round, one contiguous chunk of envs per thread with no env ever moving was up to
//! 3.4 % slower than these halves with four and eight envs, 7 of 8 rows slower or equal
//! (PickCube-v0, both control modes, the two pools' vector envs alternating in blocks of 100
//! steps in one process, 2 × 20 blocks each; session 25): a thread that takes the other's next
//! env gains more than that env's cold cache costs.
//!
//! Soft-body envs keep rayon: their MPM step runs on rayon's pool itself, and a spinning worker
//! of another pool would take a core from it. Visual steps keep rayon too (the software
//! renderer's threads need the cores between physics phases).

use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::{Mutex, OnceLock};

/// Spin-loop iterations an idle worker waits for the next job before it sleeps: about 0.5 ms
/// on the 2-core development VM (an AMD EPYC, ~26 ns per iteration; 35-40 ns on recent Intel
/// cores).
pub(crate) const IDLE_SPIN_ITERATIONS: usize = 20_000;

/// The environment variable that chooses the pool of rigid state steps: `spinning` (the
/// default) or `rayon`.
pub(crate) const POOL_VARIABLE: &str = "MS2_VEC_POOL";

/// Whether [`POOL_VARIABLE`] asks for the spinning pool (unset or `spinning`) or for rayon's
/// (`rayon`); any other value is an error naming it.
pub(crate) fn spinning_by_default() -> Result<bool, crate::EnvError> {
    match std::env::var(POOL_VARIABLE) {
        Err(std::env::VarError::NotPresent) => Ok(true),
        Ok(value) if value == "spinning" => Ok(true),
        Ok(value) if value == "rayon" => Ok(false),
        Ok(value) => Err(crate::EnvError::InvalidConfig(format!(
            "{POOL_VARIABLE} must be 'spinning' or 'rayon', got '{value}'"
        ))),
        Err(std::env::VarError::NotUnicode(value)) => Err(crate::EnvError::InvalidConfig(format!(
            "{POOL_VARIABLE} must be 'spinning' or 'rayon', got {value:?}"
        ))),
    }
}

/// The pool: as many workers as rayon's pool has threads, minus the calling thread that helps
/// (so `RAYON_NUM_THREADS` bounds both); `None` with one thread.
fn pool() -> Option<&'static micropool::ThreadPool> {
    static POOL: OnceLock<Option<micropool::ThreadPool>> = OnceLock::new();
    POOL.get_or_init(|| {
        let workers = rayon::current_num_threads().saturating_sub(1);
        (workers > 0).then(|| {
            micropool::ThreadPoolBuilder::default()
                .num_threads(workers)
                .idle_spin_cycles(IDLE_SPIN_ITERATIONS)
                .build()
        })
    })
    .as_ref()
}

/// Calls `job` on every item, in parallel on the spinning pool, the calling thread taking part.
///
/// A panic in `job` does not abort the process (as it would inside `micropool`): it is caught
/// per item and, once every item has run, resumed on the calling thread, as rayon does.
pub(crate) fn for_each<T: Send>(items: &mut [T], job: &(impl Fn(&mut T) + Sync)) {
    let Some(pool) = pool() else {
        items.iter_mut().for_each(job);
        return;
    };
    let first_panic = Mutex::new(None);
    let guarded = |item: &mut T| {
        if let Err(payload) = catch_unwind(AssertUnwindSafe(|| job(item))) {
            let mut slot = first_panic
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner());
            slot.get_or_insert(payload);
        }
    };
    split(pool, items, &guarded);
    let panic = first_panic
        .into_inner()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some(payload) = panic {
        resume_unwind(payload);
    }
}

/// Halves `items` until single items are left, each half a job of `pool.join`.
fn split<T: Send>(pool: &micropool::ThreadPool, items: &mut [T], job: &(impl Fn(&mut T) + Sync)) {
    match items {
        [] => {}
        [item] => job(item),
        _ => {
            let (first, second) = items.split_at_mut(items.len() / 2);
            pool.join(|| split(pool, first, job), || split(pool, second, job));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_item_runs_exactly_once() {
        for n in [0usize, 1, 2, 3, 7, 16] {
            let mut items: Vec<(usize, u32)> = (0..n).map(|i| (i, 0)).collect();
            for_each(&mut items, &|(i, runs)| {
                *runs += 1;
                *i *= 10;
            });
            for (k, (i, runs)) in items.iter().enumerate() {
                assert_eq!((*i, *runs), (k * 10, 1), "item {k} of {n}");
            }
        }
    }

    #[test]
    fn a_panicking_item_reaches_the_caller_after_the_others_ran() {
        let mut items: Vec<(usize, bool)> = (0..4).map(|i| (i, false)).collect();
        let result = catch_unwind(AssertUnwindSafe(|| {
            for_each(&mut items, &|(i, done)| {
                if *i == 2 {
                    panic!("env 2 failed");
                }
                *done = true;
            })
        }));
        let payload = result.expect_err("the panic is resumed on the caller");
        assert_eq!(payload.downcast_ref::<&str>(), Some(&"env 2 failed"));
        let done: Vec<bool> = items.iter().map(|(_, done)| *done).collect();
        assert_eq!(done, [true, true, false, true]);
    }
}
