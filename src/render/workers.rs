//! An ordered worker pool: jobs run on worker threads, results are handed
//! over on the calling thread in job order, as soon as each and all before
//! it are done.
//!
//! Workers take jobs in order and run at most `ahead` jobs ahead of the
//! hand-over, so memory stays bounded; there is no barrier between groups
//! of jobs, so no worker waits for another's slow job. The first error of
//! the hand-over stops the workers and is returned; a worker's panic is
//! resumed on the calling thread. The projected-cell driver runs its chunks
//! of pieces through it ([`super::driver`]): workers project later chunks
//! while the calling thread uploads and draws finished ones.

use std::sync::{Condvar, Mutex};

/// Shared state of [`run_ordered`].
struct Handover<T> {
    /// Next job a worker takes.
    next: usize,
    /// Results handed over so far.
    handed: usize,
    /// Finished results waiting for the hand-over (`slots[i % len]`).
    slots: Vec<Option<T>>,
    /// Set when the hand-over failed or a worker panicked: everyone stops.
    stop: bool,
    panic: Option<Box<dyn std::any::Any + Send>>,
}

/// Runs `work(0..jobs)` on `workers` threads, at most `ahead` jobs ahead of
/// the hand-over, and calls `hand_over` with each result in job order on
/// this thread; see the module docs.
pub fn run_ordered<T: Send, E>(
    jobs: usize,
    workers: usize,
    ahead: usize,
    work: impl Fn(usize) -> T + Sync,
    mut hand_over: impl FnMut(T) -> Result<(), E>,
) -> Result<(), E> {
    if jobs == 0 {
        return Ok(());
    }
    let ahead = ahead.max(1);
    let state = Mutex::new(Handover {
        next: 0,
        handed: 0,
        slots: (0..ahead).map(|_| None).collect(),
        stop: false,
        panic: None,
    });
    let changed = Condvar::new();
    let lock = || state.lock().unwrap_or_else(|e| e.into_inner());
    let result = std::thread::scope(|s| {
        for _ in 0..workers.max(1).min(jobs) {
            s.spawn(|| loop {
                let i = {
                    let mut f = lock();
                    while !f.stop && f.next < jobs && f.next >= f.handed + ahead {
                        f = changed.wait(f).unwrap_or_else(|e| e.into_inner());
                    }
                    if f.stop || f.next >= jobs {
                        return;
                    }
                    f.next += 1;
                    f.next - 1
                };
                let done = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(i)));
                let mut f = lock();
                match done {
                    Ok(out) => f.slots[i % ahead] = Some(out),
                    Err(p) => {
                        f.stop = true;
                        f.panic.get_or_insert(p);
                    }
                }
                drop(f);
                changed.notify_all();
            });
        }
        for i in 0..jobs {
            let out = {
                let mut f = lock();
                loop {
                    if f.stop {
                        return Ok(());
                    }
                    if let Some(out) = f.slots[i % ahead].take() {
                        break out;
                    }
                    f = changed.wait(f).unwrap_or_else(|e| e.into_inner());
                }
            };
            let r = hand_over(out);
            let mut f = lock();
            f.handed += 1;
            if r.is_err() {
                f.stop = true;
            }
            drop(f);
            changed.notify_all();
            r?;
        }
        Ok(())
    });
    let panic = lock().panic.take();
    if let Some(p) = panic {
        std::panic::resume_unwind(p);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Results come in job order whatever the number of workers and however
    /// long each job takes; an error of the hand-over stops everything.
    #[test]
    fn hands_over_in_order_and_stops_on_error() {
        let work = |i: usize| {
            // Uneven job lengths.
            let spin = (i * 7919) % 13;
            let mut x = i as u64;
            for _ in 0..spin * 1000 {
                x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
            }
            (i, x)
        };
        for workers in [1, 2, 3, 5] {
            let mut got = Vec::new();
            run_ordered(200, workers, 4, work, |(i, _)| {
                got.push(i);
                Ok::<(), ()>(())
            })
            .unwrap();
            assert_eq!(got, (0..200).collect::<Vec<_>>(), "{workers} workers");
            let mut calls = 0;
            let r = run_ordered(200, workers, 4, work, |_| {
                calls += 1;
                if calls == 3 {
                    Err("stop")
                } else {
                    Ok(())
                }
            });
            assert_eq!(r, Err("stop"));
            assert_eq!(calls, 3);
        }
    }

    #[test]
    #[should_panic(expected = "job 5")]
    fn a_worker_panic_reaches_the_caller() {
        let _ = run_ordered(
            20,
            2,
            3,
            |i| {
                if i == 5 {
                    panic!("job 5");
                }
                i
            },
            |_| Ok::<(), ()>(()),
        );
    }
}
