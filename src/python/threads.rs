//! The worker threads of the heavy calls (`spinal.set_num_threads`, `spinal.threads`): one
//! process-wide setting (a thread count, or the default) and one rayon pool per size, built
//! the first time that size is used and kept. The default is `RAYON_NUM_THREADS` when it
//! holds a positive integer (rayon's own convention), else the number of logical CPUs.
//! [`super::convert::detach_in_pool`] runs every heavy call inside the pool of the current
//! setting, so a process pool of Dask or joblib workers can give each worker one thread.

use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

/// Largest thread count accepted (a typo such as `10**6` must not spawn a million threads).
pub const MAX_THREADS: usize = 1024;

/// The setting: a thread count, or 0 for the default.
static SETTING: AtomicUsize = AtomicUsize::new(0);

/// The pools built so far, by size, and the process that built them: a child made by
/// `fork` (multiprocessing's default start method on Linux) inherits the map but not the
/// threads, so it builds its own pools.
static POOLS: Mutex<Option<(u32, Pools)>> = Mutex::new(None);

type Pools = HashMap<usize, Arc<rayon::ThreadPool>>;

/// The default thread count: `RAYON_NUM_THREADS` if it is a positive integer, else the
/// number of logical CPUs (at most [`MAX_THREADS`]).
fn default_threads() -> usize {
    let env = std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|s| s.trim().parse::<usize>().ok())
        .filter(|&n| n > 0);
    env.unwrap_or_else(cpus).min(MAX_THREADS)
}

/// The number of logical CPUs (read once: on Linux it reads the cgroup files).
fn cpus() -> usize {
    static CPUS: OnceLock<usize> = OnceLock::new();
    *CPUS.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// The thread count the next heavy call will use.
pub fn current_threads() -> usize {
    match SETTING.load(Ordering::Relaxed) {
        0 => default_threads(),
        n => n,
    }
}

/// The pool of `n` threads (built on first use).
fn pool_of(n: usize) -> PyResult<Arc<rayon::ThreadPool>> {
    let mut guard = POOLS.lock().unwrap_or_else(|e| e.into_inner());
    let pid = std::process::id();
    if guard.as_ref().is_some_and(|(owner, _)| *owner != pid) {
        // the parent's pools: their workers do not exist here, so never touch them again
        std::mem::forget(guard.take());
    }
    let (_, pools) = guard.get_or_insert_with(|| (pid, HashMap::new()));
    if let Some(p) = pools.get(&n) {
        return Ok(p.clone());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .thread_name(|i| format!("spinal-{i}"))
        .build()
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start {n} worker threads: {e}")))?;
    let pool = Arc::new(pool);
    pools.insert(n, pool.clone());
    Ok(pool)
}

/// The pool of the current setting.
pub fn current_pool() -> PyResult<Arc<rayon::ThreadPool>> {
    pool_of(current_threads())
}

/// Set the thread count (`None`: back to the default); the pool is built here, so a count
/// the system cannot start fails at once. The Python wrapper has checked the type.
#[pyfunction]
#[pyo3(signature = (n))]
pub fn set_num_threads(n: Option<usize>) -> PyResult<()> {
    match n {
        None => SETTING.store(0, Ordering::Relaxed),
        Some(n) if (1..=MAX_THREADS).contains(&n) => {
            pool_of(n)?;
            SETTING.store(n, Ordering::Relaxed);
        }
        Some(n) => {
            return Err(PyValueError::new_err(format!(
                "n: must be a positive int at most {MAX_THREADS}, got {n}"
            )));
        }
    }
    Ok(())
}

/// The setting: the thread count, or `None` for the default.
#[pyfunction]
pub fn num_threads_setting() -> Option<usize> {
    match SETTING.load(Ordering::Relaxed) {
        0 => None,
        n => Some(n),
    }
}

/// The thread count the next heavy call will use.
#[pyfunction]
pub fn get_num_threads() -> usize {
    current_threads()
}
