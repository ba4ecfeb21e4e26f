//! Wall and process CPU time for the plain-program benchmarks (shared by `#[path]`).

// Each benchmark includes this file and uses only some of it.
#![allow(dead_code)]

use std::time::Instant;

/// User and system CPU seconds of this process so far, all threads (Linux `/proc/self/stat`;
/// 0 elsewhere). On a loaded machine it is steadier than wall time.
pub fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the parenthesised command name: state is field 3, utime 14, stime 15.
    let Some(rest) = stat.rsplit_once(')').map(|(_, r)| r) else {
        return 0.0;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    // Clock ticks are 100 a second on Linux.
    (ticks(11) + ticks(12)) / 100.0
}

/// Best of `repeats` runs of `f` (at least one): wall seconds and CPU seconds of that run,
/// and the last run's result.
pub fn best<T>(repeats: usize, mut f: impl FnMut() -> T) -> ((f64, f64), T) {
    let mut best = (f64::INFINITY, 0.0);
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let (t, c) = (Instant::now(), cpu_seconds());
        let out = f();
        let wall = t.elapsed().as_secs_f64();
        if wall < best.0 {
            best = (wall, cpu_seconds() - c);
        }
        last = Some(out);
    }
    (best, last.expect("at least one run"))
}
