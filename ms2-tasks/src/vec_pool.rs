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
//! Soft-body envs keep rayon: their MPM step runs on rayon's pool itself, and a spinning worker
//! of another pool would take a core from it. Visual steps keep rayon too (the software
//! renderer's threads need the cores between physics phases).

use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
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
/// Items are handed out one at a time in `order` (indices into `items`, each exactly once):
/// every thread takes the next item of `order` whenever it is free, so an item that runs long
/// does not hold back items queued behind it on the same thread. Give the longest items first
/// ([`schedule`]) and the threads end close together.
///
/// A panic in `job` does not abort the process (as it would inside `micropool`): it is caught
/// per item and, once every item has run, resumed on the calling thread, as rayon does.
///
/// # Panics
///
/// If `order` is not a permutation of `0..items.len()` (before any item runs).
pub(crate) fn for_each<T: Send>(items: &mut [T], order: &[usize], job: &(impl Fn(&mut T) + Sync)) {
    assert!(
        is_permutation(order, items.len()),
        "order must list each of the {} items exactly once, got {order:?}",
        items.len()
    );
    let Some(pool) = pool() else {
        for &i in order {
            job(&mut items[i]);
        }
        return;
    };
    let first_panic = Mutex::new(None);
    // Each item behind its own (uncontended) lock: the shared counter below hands every index
    // of `order` to exactly one thread.
    let cells: Vec<Mutex<&mut T>> = items.iter_mut().map(Mutex::new).collect();
    let next = AtomicUsize::new(0);
    let take_items = || loop {
        let k = next.fetch_add(1, Ordering::Relaxed);
        let Some(&i) = order.get(k) else { break };
        let mut item = cells[i]
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Err(payload) = catch_unwind(AssertUnwindSafe(|| job(&mut **item))) {
            let mut slot = first_panic
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner());
            slot.get_or_insert(payload);
        }
    };
    let takers = (pool.num_threads() + 1).min(order.len());
    run_takers(pool, takers, &take_items);
    let panic = first_panic
        .into_inner()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some(payload) = panic {
        resume_unwind(payload);
    }
}

/// Runs `take` on `count` threads of `pool` at most, the calling thread one of them: each a job
/// of `pool.join`, so a worker that is busy or slow to wake leaves its share to the others (a
/// `take` that finds nothing left returns at once).
fn run_takers(pool: &micropool::ThreadPool, count: usize, take: &(impl Fn() + Sync)) {
    if count <= 1 {
        take();
    } else {
        pool.join(take, || run_takers(pool, count - 1, take));
    }
}

/// The order in which [`for_each`] hands out envs whose last steps took `costs` (any unit):
/// with no more envs than threads, each thread takes one, in index order (so each env stays on
/// the same thread from step to step); with more, the longest first ([`longest_first`]).
pub(crate) fn schedule(costs: &[u64]) -> Vec<usize> {
    let threads = pool().map_or(1, |pool| pool.num_threads() + 1);
    if costs.len() <= threads {
        (0..costs.len()).collect()
    } else {
        longest_first(costs)
    }
}

/// The indices `0..costs.len()` ordered by descending cost (ties in index order): handed out in
/// this order, the threads of a vector step run out of envs at about the same time when each
/// env's next step costs about what its last one did (the longest-processing-time-first rule).
fn longest_first(costs: &[u64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..costs.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(costs[i]));
    order
}

/// Whether `order` lists each of `0..len` exactly once.
fn is_permutation(order: &[usize], len: usize) -> bool {
    let mut seen = vec![false; len];
    order.len() == len
        && order
            .iter()
            .all(|&i| i < len && !std::mem::replace(&mut seen[i], true))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_item_runs_exactly_once_in_any_order() {
        for n in [0usize, 1, 2, 3, 7, 16] {
            let orders: [Vec<usize>; 2] = [(0..n).collect(), (0..n).rev().collect()];
            for order in orders {
                let mut items: Vec<(usize, u32)> = (0..n).map(|i| (i, 0)).collect();
                for_each(&mut items, &order, &|(i, runs)| {
                    *runs += 1;
                    *i *= 10;
                });
                for (k, (i, runs)) in items.iter().enumerate() {
                    assert_eq!((*i, *runs), (k * 10, 1), "item {k} of {n}, order {order:?}");
                }
            }
        }
    }

    #[test]
    #[should_panic(expected = "exactly once")]
    fn an_order_that_is_not_a_permutation_is_refused() {
        let mut items = [0u8; 3];
        for_each(&mut items, &[0, 1, 1], &|x| *x += 1);
    }

    #[test]
    fn longest_first_orders_by_descending_cost_ties_by_index() {
        assert_eq!(longest_first(&[5, 9, 5, 1, 9]), [1, 4, 0, 2, 3]);
        assert_eq!(longest_first(&[0, 0, 0]), [0, 1, 2]);
        assert_eq!(longest_first(&[]), Vec::<usize>::new());
    }

    #[test]
    fn schedule_keeps_index_order_up_to_one_env_per_thread() {
        let threads = pool().map_or(1, |pool| pool.num_threads() + 1);
        let few: Vec<u64> = (0..threads as u64).collect();
        assert_eq!(schedule(&few), (0..threads).collect::<Vec<_>>());
        let many: Vec<u64> = (0..=threads as u64).collect();
        assert_eq!(schedule(&many), (0..=threads).rev().collect::<Vec<_>>());
    }

    #[test]
    fn a_panicking_item_reaches_the_caller_after_the_others_ran() {
        let mut items: Vec<(usize, bool)> = (0..4).map(|i| (i, false)).collect();
        let order: Vec<usize> = (0..4).collect();
        let result = catch_unwind(AssertUnwindSafe(|| {
            for_each(&mut items, &order, &|(i, done)| {
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
