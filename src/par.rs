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
//! between the step's regions; [`ThreadChoice`]: a loop's choice between one thread and all,
//! made by timing both; [`concat_into`]: vectors concatenated on all threads
//! ([`split_lengths_mut`]: a slice cut into consecutive pieces, one per task).
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

/// `s` cut into consecutive pieces of the given lengths (their sum at most `s.len()`), for a
/// parallel loop that gives each thread its own piece.
pub fn split_lengths_mut<T>(s: &mut [T], lengths: impl IntoIterator<Item = usize>) -> Vec<&mut [T]> {
    let mut pieces = Vec::new();
    let mut rest = s;
    for len in lengths {
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
        pieces.push(head);
        rest = tail;
    }
    pieces
}

/// The vectors `field(part)` of `parts` concatenated in order into `out` (cleared first), each
/// part's copied by whichever thread takes that part in a parallel loop over `parts` (rayon
/// splits the list alike each time: on two threads the caller takes the first half and the
/// other thread the second, so that a part is mostly copied by the thread that filled it in an
/// earlier loop over the same list, from its own cache). The parts' vectors are left empty, with
/// their capacity. On one thread, or below `CONCAT_PAR_MIN` entries, one thread appends them.
pub fn concat_into<S: Send, T: Copy + Send + Sync>(out: &mut Vec<T>, parts: &mut [S], field: impl Fn(&mut S) -> &mut Vec<T> + Sync) {
    use rayon::prelude::*;
    out.clear();
    let total: usize = parts.iter_mut().map(|p| field(p).len()).sum();
    if rayon::current_num_threads() == 1 || total < CONCAT_PAR_MIN {
        for p in parts.iter_mut() {
            out.append(field(p));
        }
        return;
    }
    out.reserve(total);
    let lengths: Vec<usize> = parts.iter_mut().map(|p| field(p).len()).collect();
    let pieces = split_lengths_mut(&mut out.spare_capacity_mut()[..total], lengths);
    region();
    pieces.into_par_iter().zip(parts.par_iter_mut()).for_each(|(dst, p)| {
        let src = field(p);
        for (d, s) in dst.iter_mut().zip(src.iter()) {
            d.write(*s);
        }
        src.clear();
    });
    // SAFETY: the pieces cover out's first `total` entries (their lengths sum to it), and each
    // was written from its part's vector of the same length
    unsafe { out.set_len(total) };
}

/// Entries below which [`concat_into`] appends on one thread: 4096 (a few hundred kB of the
/// contact's pairs; below, a fork-join costs about what the copy does).
pub const CONCAT_PAR_MIN: usize = 4096;

/// A loop's choice between one thread and all the pool's threads, made by timing both: every
/// [`Self::PERIOD`] calls a trial of [`Self::TRIAL`] calls on one thread then as many on all
/// threads, and the rest of the period on whichever cost less per unit of work over the trial;
/// a new pool (another thread count) first runs [`Self::WARMUP`] calls on all threads untimed.
/// Only for a loop whose result is the same either way (bit-identical on any number of
/// threads): the choice depends on timings, so it must never change a value.
///
/// Why: the two vCPUs of a cloud VM may share a last-level cache or not, and the host moves them
/// between the two placements during a run; a cache line going from one vCPU to the other then
/// takes 3–5× as long (a ping-pong's round trip of 70–125 ns against 320–380 ns on the EPYC VM
/// of docs/performance.md §7, "Two kinds of core pair"; `cargo bench --bench forkjoin` prints it). A loop of many short regions whose
/// data moves between the threads (the contact's Gauss–Seidel sweeps: about 50 colours a step of
/// 10–30 µs each) gains on two threads in the first placement and loses in the second, so one
/// choice made before the run is wrong in one of them.
#[derive(Clone, Debug, Default)]
pub struct ThreadChoice {
    /// the pool's thread count at the last call (another count starts a new period)
    threads: usize,
    /// calls since the period count started
    calls: u64,
    /// seconds and work of the current trial, [one thread, all threads]
    trial: [(f64, f64); 2],
    /// the mode of the period's calls after its trial
    parallel_after_trial: bool,
    /// calls made on all threads, in all
    parallel_calls: u64,
}

impl ThreadChoice {
    /// Calls from one trial to the next: 512 (about 3 s of the fine dam's step, shorter than the
    /// placements were seen to last; the trial's 16 calls in the slower mode cost at most 3 % of
    /// the difference between the modes).
    pub const PERIOD: u64 = 512;
    /// Calls per mode in a trial: 16 (a dam step's sweeps vary by about ±30 % from step to
    /// step; 16 steps average that to a few per cent). In blocks, not alternating: on the dam a
    /// parallel call right after a one-thread call cost half what it costs among parallel calls
    /// (measured, fine mesh; the data is still where one thread left it).
    pub const TRIAL: u64 = 16;
    /// Calls of a new pool before its first trial: 64 (the first one-thread calls on a new
    /// pool cost 1.5× the later ones on the dam bench, which switches pools mid-run, and made
    /// the first trial pick the wrong mode).
    pub const WARMUP: u64 = 64;

    /// Whether the next call runs on all threads: never on one thread; with more, as the
    /// period's schedule says. A pool of another thread count than the last call's starts a new
    /// period (with its trial).
    pub fn parallel(&mut self) -> bool {
        let threads = rayon::current_num_threads();
        if threads != self.threads {
            // the warm-up: the end of a period whose choice is all threads
            *self = ThreadChoice { threads, calls: Self::PERIOD - Self::WARMUP, parallel_after_trial: true, parallel_calls: self.parallel_calls, ..ThreadChoice::default() };
        }
        threads > 1 && self.mode()
    }

    /// The schedule's mode for the next call (the trial: one thread, then all threads; then the
    /// choice).
    fn mode(&self) -> bool {
        match self.calls % Self::PERIOD {
            i if i < 2 * Self::TRIAL => i >= Self::TRIAL,
            _ => self.parallel_after_trial,
        }
    }

    /// Record the call just made (in the mode [`Self::parallel`] gave): its wall time [s] and its
    /// work (any measure proportional to the loop's cost on one thread, e.g. pairs × sweeps).
    pub fn record(&mut self, seconds: f64, work: f64) {
        let parallel = self.threads > 1 && self.mode();
        let i = self.calls % Self::PERIOD;
        if i < 2 * Self::TRIAL {
            let t = &mut self.trial[parallel as usize];
            t.0 += seconds;
            t.1 += work;
            if i == 2 * Self::TRIAL - 1 {
                let cost = |(s, w): (f64, f64)| if w > 0.0 { s / w } else { f64::INFINITY };
                // a tie, or no work to compare: all threads, as without the choice
                self.parallel_after_trial = cost(self.trial[1]) <= cost(self.trial[0]) || self.trial[0].1 == 0.0;
                self.trial = [(0.0, 0.0); 2];
            }
        }
        self.parallel_calls += parallel as u64;
        self.calls += 1;
    }

    /// The calls made on all threads, in all.
    pub fn parallel_calls(&self) -> u64 {
        self.parallel_calls
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concat_into_gives_the_parts_in_order_on_any_thread_count_and_empties_them() {
        // Reference: the serial concatenation; parts of unequal length (some empty), enough
        // entries for the parallel copy, on 1 and 2 threads.
        let make = || (0..37u64).map(|p| (0..(p * 613 % 401)).map(|i| p * 1000 + i).collect::<Vec<u64>>()).collect::<Vec<_>>();
        let expected: Vec<u64> = make().concat();
        assert!(expected.len() > CONCAT_PAR_MIN);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut parts = make();
            let mut out = vec![7u64; 3];
            pool.install(|| concat_into(&mut out, &mut parts, |p| p));
            assert_eq!(out, expected, "{threads} threads");
            assert!(parts.iter().all(|p| p.is_empty()));
        }
    }

    #[test]
    fn thread_choice_takes_the_mode_that_cost_less_in_its_trial_and_tries_both_again_each_period() {
        // Reference: the schedule of the doc (WARMUP calls on all threads on a new pool, then
        // periods of TRIAL calls on one thread, TRIAL on all, and the cheaper per unit of work
        // to the end of the period), with synthetic timings: one thread 1 s per unit of work,
        // all threads `p` s per unit.
        let run = |choice: &mut ThreadChoice, p: f64, calls: u64| {
            let mut modes = Vec::new();
            for _ in 0..calls {
                let par = choice.parallel();
                modes.push(par);
                choice.record(if par { 2.0 * p } else { 2.0 }, 2.0);
            }
            modes
        };
        let (t, per, w) = (ThreadChoice::TRIAL as usize, ThreadChoice::PERIOD, ThreadChoice::WARMUP);
        let trial = |m: &[bool]| m.iter().enumerate().all(|(i, &x)| x == (i >= t));
        let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        two.install(|| {
            let mut c = ThreadChoice::default();
            let m = run(&mut c, 2.0, w);
            assert!(m.iter().all(|&x| x), "the warm-up runs on all threads");
            // all threads twice as slow: the trial, then one thread for the rest of the period
            let m = run(&mut c, 2.0, per);
            assert!(trial(&m[..2 * t]), "the trial: one thread, then all");
            assert!(m[2 * t..].iter().all(|&x| !x), "one thread cost less: kept after the trial");
            // the machine changes: all threads now cost half; the next period's trial finds it
            let m = run(&mut c, 0.5, per);
            assert!(trial(&m[..2 * t]), "the trial: one thread, then all");
            assert!(m[2 * t..].iter().all(|&x| x), "all threads cost less: kept after the trial");
            assert_eq!(c.parallel_calls(), w + per);
            // another thread count mid-period: one thread never runs in parallel, and back on
            // two the trial starts again
            let m = one.install(|| run(&mut c, 0.5, 40));
            assert!(m.iter().all(|&x| !x));
            let m = run(&mut c, 0.5, w + 2 * ThreadChoice::TRIAL + 1);
            let w = w as usize;
            assert!(m[..w].iter().all(|&x| x) && trial(&m[w..w + 2 * t]) && m[w + 2 * t], "a new warm-up and trial, then all threads");
            // a trial with no work at all keeps all threads (nothing to choose on)
            let mut c = ThreadChoice::default();
            for _ in 0..w + 2 * t {
                c.parallel();
                c.record(0.0, 0.0);
            }
            assert!(c.parallel());
        });
    }
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
