//! Keeping the pool's other threads awake for the length of a run.
//!
//! A step runs about eight short parallel loops (integrate, the rebuild
//! check, forces, walls, fixes, integrate) with serial work between them. On
//! bed (a) a loop holds 10-100 µs of work; rayon lets an idle worker fall
//! asleep after a few rounds of looking for work, and waking it again is a
//! futex wake-up (on a VM an inter-processor interrupt, a VM exit) that
//! arrives when the loop is half done. Profiled on 2 threads: the second
//! thread ran ~72% of the wall time, the first ~91%.
//!
//! [`Awake::start`] parks one task on every other thread of the current pool
//! for the run: it takes rayon work whenever there is some (so the loops'
//! halves are stolen at once) and otherwise polls, yielding the core to the
//! OS between polls so that other processes on the machine still run. Which
//! thread executes a loop's chunk never changes what is computed (chunks are
//! fixed and combined in order), so results keep their bits on any thread
//! count.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Polls that spin on the CPU before the keeper starts yielding to the OS.
const SPINS: u32 = 64;

/// While alive, the pool's other threads stay awake; dropping it lets them go.
pub struct Awake {
    stop: Arc<AtomicBool>,
}

impl Awake {
    /// Keep the other threads of the current rayon pool awake; `None` on a
    /// single thread or outside a pool (nothing to keep awake).
    pub fn start() -> Option<Awake> {
        let owner = rayon::current_thread_index()?;
        if rayon::current_num_threads() < 2 {
            return None;
        }
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        rayon::spawn_broadcast(move |ctx| {
            // The owner runs the step loop itself: its copy returns at once
            // (it must not block the loop's own thread).
            if ctx.index() != owner {
                keep(&flag);
            }
        });
        Some(Awake { stop })
    }
}

impl Drop for Awake {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
    }
}

/// Take rayon work until `stop`; between jobs spin a little, then yield.
fn keep(stop: &AtomicBool) {
    let mut idle = 0u32;
    while !stop.load(Ordering::Acquire) {
        match rayon::yield_now() {
            Some(rayon::Yield::Executed) => idle = 0,
            Some(rayon::Yield::Idle) => {
                idle = idle.saturating_add(1);
                if idle < SPINS {
                    std::hint::spin_loop();
                } else {
                    std::thread::yield_now();
                }
            }
            None => return,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// The keeper takes its share of the loops and stops when dropped: the
    /// pool's threads are free again (a broadcast reaches every thread).
    #[test]
    fn keeper_works_and_lets_go() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        pool.install(|| {
            let awake = Awake::start();
            assert!(awake.is_some());
            let owner = rayon::current_thread_index().unwrap();
            let mut other = 0;
            for _ in 0..200 {
                let threads: Vec<usize> = (0..64)
                    .into_par_iter()
                    .map(|_| {
                        let t0 = std::time::Instant::now();
                        while t0.elapsed().as_micros() < 20 {
                            std::hint::spin_loop();
                        }
                        rayon::current_thread_index().unwrap()
                    })
                    .collect();
                other += threads.iter().filter(|&&t| t != owner).count();
            }
            assert!(other > 0, "the other thread took no chunk");
            drop(awake);
            let seen = rayon::broadcast(|ctx| ctx.index());
            assert_eq!(seen.len(), 2);
        });
        let single = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        assert!(single.install(Awake::start).is_none());
        assert!(Awake::start().is_none(), "outside a pool");
    }
}
