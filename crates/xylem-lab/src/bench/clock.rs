//! The lab's CPU clocks, one of each kind, for every benchmark and study: the calling thread's
//! CPU time ([`CpuTimer::thread`], the tracing and wood benchmarks), this process's
//! ([`process_cpu_seconds`], `tradeoff` and `validate aliasing`) and its waited-for children's
//! ([`children_cpu_seconds`], a render by another binary). On a shared machine CPU time leaves
//! out the time other jobs hold the cores (cache and SMT contention still show). POSIX clocks
//! (`clock_gettime`, `getrusage`); elsewhere `None`, and the callers fall back to wall time.

use std::time::{Duration, Instant};

/// Seconds of a `clock_gettime` clock, `None` where it fails.
#[cfg(unix)]
fn clock_seconds(clock: libc::clockid_t) -> Option<f64> {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid timespec for clock_gettime to write.
    let ok = unsafe { libc::clock_gettime(clock, &mut ts) } == 0;
    ok.then_some(ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9)
}

/// CPU seconds of the calling thread so far (`CLOCK_THREAD_CPUTIME_ID`).
pub fn thread_cpu_seconds() -> Option<f64> {
    #[cfg(unix)]
    return clock_seconds(libc::CLOCK_THREAD_CPUTIME_ID);
    #[cfg(not(unix))]
    None
}

/// CPU seconds of this process so far, user + system over all its threads
/// (`CLOCK_PROCESS_CPUTIME_ID`).
pub fn process_cpu_seconds() -> Option<f64> {
    #[cfg(unix)]
    return clock_seconds(libc::CLOCK_PROCESS_CPUTIME_ID);
    #[cfg(not(unix))]
    None
}

/// CPU seconds (user + system) of this process's children that have been waited for
/// (`getrusage(RUSAGE_CHILDREN)`).
pub fn children_cpu_seconds() -> Option<f64> {
    #[cfg(unix)]
    {
        // SAFETY: getrusage writes the struct it is given and nothing else.
        let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
        if unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut ru) } != 0 {
            return None;
        }
        let s = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
        Some(s(ru.ru_utime) + s(ru.ru_stime))
    }
    #[cfg(not(unix))]
    None
}

/// A stopwatch over a CPU clock — the calling thread's ([`CpuTimer::thread`]) or the process's
/// ([`CpuTimer::process`]) — reading wall time where the clock is unavailable: the time spent
/// descheduled is not counted, for xylem and a peer alike.
#[derive(Clone, Copy)]
pub struct CpuTimer {
    clock: fn() -> Option<f64>,
    cpu: Option<f64>,
    wall: Instant,
}

impl CpuTimer {
    /// Starts a stopwatch over the calling thread's CPU time.
    pub fn thread() -> Self {
        Self::over(thread_cpu_seconds)
    }

    /// Starts a stopwatch over the process's CPU time (all threads).
    pub fn process() -> Self {
        Self::over(process_cpu_seconds)
    }

    fn over(clock: fn() -> Option<f64>) -> Self {
        CpuTimer {
            clock,
            cpu: clock(),
            wall: Instant::now(),
        }
    }

    /// CPU seconds since the start (wall seconds where the clock is unavailable).
    pub fn seconds(&self) -> f64 {
        match (self.cpu, (self.clock)()) {
            (Some(a), Some(b)) => (b - a).max(0.0),
            _ => self.wall.elapsed().as_secs_f64(),
        }
    }

    /// [`CpuTimer::seconds`] as a duration.
    pub fn elapsed(&self) -> Duration {
        Duration::from_secs_f64(self.seconds())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each clock runs forward while the thread works, and a sleeping thread's CPU clock barely
    /// moves while the wall clock does (the control: wall time would count the sleep).
    #[test]
    fn cpu_clocks_count_work_not_sleep() {
        let (t, p) = (CpuTimer::thread(), CpuTimer::process());
        let mut x = 0u64;
        while t.elapsed() < Duration::from_millis(50) {
            x = x.wrapping_add(std::hint::black_box(1));
        }
        assert!(x > 0 && p.seconds() >= 0.05);
        let (t, wall) = (CpuTimer::thread(), Instant::now());
        std::thread::sleep(Duration::from_millis(100));
        assert!(wall.elapsed() >= Duration::from_millis(100));
        assert!(t.elapsed() < Duration::from_millis(20), "{:?}", t.elapsed());
        // A child's CPU time arrives when it is waited for.
        let c = children_cpu_seconds().unwrap();
        assert!(c >= 0.0);
    }
}
