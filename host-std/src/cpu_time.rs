//! The process's CPU time: what a render costs per core, whatever else shares the machine.
//! Wall-clock time measures throughput only on an idle machine; the CPU time the process's
//! threads spent running does not grow while they wait for a core.

use std::time::Duration;

/// User plus system CPU time of every thread of this process so far, where the platform says
/// (`getrusage`); `None` elsewhere.
#[must_use]
pub fn process_cpu_time() -> Option<Duration> {
    #[cfg(unix)]
    {
        let mut usage = std::mem::MaybeUninit::<libc::rusage>::zeroed();
        // SAFETY: `getrusage` fills the struct it is handed and reads nothing else.
        let ok = unsafe { libc::getrusage(libc::RUSAGE_SELF, usage.as_mut_ptr()) } == 0;
        // SAFETY: zeroed is a valid `rusage`, and a successful call filled it.
        let usage = unsafe { usage.assume_init() };
        let time = |t: libc::timeval| Duration::new(t.tv_sec.max(0) as u64, (t.tv_usec.max(0) as u32) * 1000);
        ok.then(|| time(usage.ru_utime) + time(usage.ru_stime))
    }
    #[cfg(not(unix))]
    {
        None
    }
}

/// CPU seconds of every thread since `start` (a [`process_cpu_time`]), where the platform says.
#[must_use]
pub fn cpu_seconds_since(start: Option<Duration>) -> Option<f64> {
    start.zip(process_cpu_time()).map(|(a, b)| b.saturating_sub(a).as_secs_f64())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[cfg(unix)]
    fn cpu_time_grows_with_work() {
        let before = process_cpu_time().expect("unix has getrusage");
        let mut x = 1u64;
        let start = std::time::Instant::now();
        while start.elapsed() < Duration::from_millis(30) {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
        }
        std::hint::black_box(x);
        assert!(process_cpu_time().unwrap() > before);
    }
}
