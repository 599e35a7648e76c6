//! Parallel regions of the explicit step: how many fork-joins a run opens.
//!
//! Owns: the process-wide count of the parallel regions (rayon fork-joins) that the step's loops
//! open ([`region`], [`fork_joins`]). Every loop of the step that hands work to rayon's threads
//! (the element loop's colours, the nodal loops, the condensed foundation's product, the contact
//! search and the sweeps' colours) calls [`region`] once per fork-join it opens, so that a
//! benchmark can read the fork-joins per step (`benches/dam.rs`) and weigh them against the
//! measured cost of one (`benches/forkjoin.rs`, docs/performance.md §7).
//!
//! Invariants: counting never changes a result (a relaxed atomic add, about 5 ns, a few dozen a
//! step); the count is of the whole process (all threads, all runs), so read it as a difference
//! around the steps timed.
//!
//! Also [`with_awake_workers`]: a run's time loop with the pool's other workers kept awake
//! between the step's regions.
//!
//! A leaf (std and rayon only).

use std::sync::atomic::{AtomicU64, Ordering};

static FORK_JOINS: AtomicU64 = AtomicU64::new(0);

/// Count one parallel region (a rayon fork-join) about to be opened.
#[inline]
pub fn region() {
    FORK_JOINS.fetch_add(1, Ordering::Relaxed);
}

/// Parallel regions opened so far by this process.
pub fn fork_joins() -> u64 {
    FORK_JOINS.load(Ordering::Relaxed)
}

/// Run `f` (the time loop of a run) with the pool's other workers kept awake: while `f` runs,
/// each of them spins in [`rayon::yield_now`], taking any work the step's parallel regions hand
/// out, instead of falling asleep between regions. With more than one thread only; on one
/// thread `f` just runs.
///
/// Why: a rayon worker with nothing to do yields a few dozen times and then sleeps, so each
/// region that follows a serial stretch of the step (the contact's set-up and record, the
/// recorder, the nodal loops' tails) first wakes it through the kernel. On the fine dam step
/// the kernel's sleeping and waking was 42 % of the extra CPU of two threads over one, and
/// keeping the worker awake took 4–6 % off the two-thread step (median 1.58× → 1.67× over eight pairs,
/// docs/performance.md §7, "Workers kept awake"). The price is CPU: the kept worker spins through
/// the serial stretches (about 7 % more CPU a step on the fine dam), so a run on `--threads 2`
/// takes its two cores whole, as the thread count says it may.
///
/// Results do not depend on it: it changes which thread runs a piece of work, never the order in
/// which any value is summed (the step's loops are bit-identical on any number of threads).
/// The keepers stop when `f` returns or panics (a guard sets the flag in both cases).
pub fn with_awake_workers<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    let others = rayon::current_num_threads().saturating_sub(1);
    if others == 0 || rayon::current_thread_index().is_none() {
        return f();
    }
    let done = std::sync::atomic::AtomicBool::new(false);
    struct Stop<'a>(&'a std::sync::atomic::AtomicBool);
    impl Drop for Stop<'_> {
        fn drop(&mut self) {
            self.0.store(true, Ordering::Release);
        }
    }
    rayon::scope(|s| {
        for _ in 0..others {
            s.spawn(|_| {
                while !done.load(Ordering::Acquire) {
                    if rayon::yield_now() != Some(rayon::Yield::Executed) {
                        std::hint::spin_loop();
                    }
                }
            });
        }
        let _stop = Stop(&done);
        f()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn awake_workers_run_the_loop_and_its_regions_and_stop_after_it_even_on_a_panic() {
        // Reference: the same sum on one thread (integers, exact); the keepers must take part in
        // the regions (a region that needs both threads completes: a join where each side waits
        // for the other's flag would hang without a second thread taking work) and stop when
        // the closure returns or panics (without the guard the scope would wait forever).
        let serial: u64 = (0..100_000u64).map(|i| i * i % 7).sum();
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let got = pool.install(|| with_awake_workers(|| (0..50).map(|_| (0..100_000u64).into_par_iter().map(|i| i * i % 7).sum::<u64>()).collect::<Vec<_>>()));
            assert!(got.iter().all(|&s| s == serial), "{threads} threads");
            if threads > 1 {
                // both halves of a join run at once: only possible when another thread takes one
                let flags = (std::sync::atomic::AtomicBool::new(false), std::sync::atomic::AtomicBool::new(false));
                pool.install(|| {
                    with_awake_workers(|| {
                        rayon::join(
                            || {
                                flags.0.store(true, Ordering::Release);
                                while !flags.1.load(Ordering::Acquire) {
                                    std::hint::spin_loop();
                                }
                            },
                            || {
                                flags.1.store(true, Ordering::Release);
                                while !flags.0.load(Ordering::Acquire) {
                                    std::hint::spin_loop();
                                }
                            },
                        )
                    })
                });
            }
            let r = pool.install(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| with_awake_workers(|| -> u32 { panic!("the loop failed") }))));
            assert!(r.is_err());
            // and outside any pool it just runs
            assert_eq!(with_awake_workers(|| 7), 7);
        }
    }
}
