//! Jobs of unequal length run in a chosen order by every thread of a pool: each thread starts the
//! next job as soon as it is free, so a pool given its longest jobs first ends on short ones
//! instead of idling while its slowest job finishes. The objects of a batch of datasets
//! (`explore::collect_datasets`) and the active-touch explorations of the `active` experiment
//! (`paper::active`) run this way.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};

/// Runs `job(0)`, `job(1)`, ..., `job(count - 1)` on every thread of the current rayon pool (in
/// [`rayon::ThreadPool::install`], that pool), each free thread starting the lowest index not yet
/// started, and returns their outputs in index order.
///
/// The first error stops the queue: no job starts after it (those already running finish), and it
/// is returned. The outputs depend on the jobs alone, never on the threads or on which thread ran
/// which job.
pub fn run_in_order<T, E>(count: usize, job: impl Fn(usize) -> Result<T, E> + Sync) -> Result<Vec<T>, E>
where
    T: Send,
    E: Send,
{
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let failure: Mutex<Option<E>> = Mutex::new(None);
    let outputs: Vec<Mutex<Option<T>>> = (0..count).map(|_| Mutex::new(None)).collect();
    rayon::scope(|scope| {
        for _ in 0..rayon::current_num_threads() {
            scope.spawn(|_| {
                while !stop.load(Ordering::Relaxed) {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= count {
                        break;
                    }
                    match job(i) {
                        Ok(output) => {
                            *outputs[i].lock().unwrap_or_else(PoisonError::into_inner) = Some(output)
                        }
                        Err(e) => {
                            stop.store(true, Ordering::Relaxed);
                            failure
                                .lock()
                                .unwrap_or_else(PoisonError::into_inner)
                                .get_or_insert(e);
                        }
                    }
                }
            });
        }
    });
    if let Some(e) = failure.into_inner().unwrap_or_else(PoisonError::into_inner) {
        return Err(e);
    }
    // Without a failure every index below `count` was taken by a thread and ran to its output.
    Ok(outputs
        .into_iter()
        .filter_map(|slot| slot.into_inner().unwrap_or_else(PoisonError::into_inner))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
    }

    #[test]
    fn outputs_come_in_index_order_whatever_the_threads() {
        // Jobs of very unequal length, so that threads finish them out of order.
        let job = |i: usize| -> Result<u64, String> {
            let spins = if i.is_multiple_of(3) { 200_000 } else { 10 };
            Ok((0..spins).fold(i as u64, |a, k| a.wrapping_mul(31).wrapping_add(k)))
        };
        let want: Vec<u64> = (0..40).map(|i| job(i).expect("no error")).collect();
        for threads in [1, 2, 4] {
            assert_eq!(
                pool(threads).install(|| run_in_order(40, job)),
                Ok(want.clone()),
                "{threads} threads"
            );
        }
        assert_eq!(pool(2).install(|| run_in_order(0, job)), Ok(Vec::new()));
    }

    #[test]
    fn jobs_start_in_index_order() {
        let started = Mutex::new(Vec::new());
        let out = pool(1).install(|| {
            run_in_order(6, |i| -> Result<usize, ()> {
                started.lock().expect("not poisoned").push(i);
                Ok(i)
            })
        });
        assert_eq!(out, Ok((0..6).collect()));
        assert_eq!(
            started.into_inner().expect("not poisoned"),
            (0..6).collect::<Vec<_>>()
        );
    }

    #[test]
    fn the_first_error_stops_the_queue_and_is_returned() {
        let ran = AtomicUsize::new(0);
        let out = pool(1).install(|| {
            run_in_order(10, |i| {
                ran.fetch_add(1, Ordering::Relaxed);
                if i == 3 {
                    Err(format!("job {i} failed"))
                } else {
                    Ok(i)
                }
            })
        });
        assert_eq!(out, Err("job 3 failed".to_string()));
        assert_eq!(ran.load(Ordering::Relaxed), 4, "no job starts after the failure");
        // On two threads the error comes back too, and the queue stops short of its end.
        let ran = AtomicUsize::new(0);
        let out = pool(2).install(|| {
            run_in_order(1000, |i| {
                ran.fetch_add(1, Ordering::Relaxed);
                if i == 3 { Err("job 3 failed") } else { Ok(i) }
            })
        });
        assert_eq!(out, Err("job 3 failed"));
        assert!(ran.load(Ordering::Relaxed) < 1000);
    }
}
