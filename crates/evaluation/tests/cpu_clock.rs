//! The clock of CPU-second budgets ([`process_cpu_seconds`]) counts the time the process's
//! threads spend on a CPU, not the time that passes: sleeping adds (almost) nothing, work in
//! another thread adds what it ran. A wall clock fails the first check; a clock of the calling
//! thread only fails the second. One test in its own file: the clock is process-wide, and
//! other tests running beside it would add their time.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use restir_evaluation::process_cpu_seconds;

#[test]
fn cpu_seconds_count_work_not_waiting() {
    let before = process_cpu_seconds();
    assert!(before.is_finite() && before >= 0.0, "{before}");
    std::thread::sleep(Duration::from_millis(400));
    let slept = process_cpu_seconds() - before;
    assert!(slept < 0.1, "0.4 s of sleep counted {slept} CPU seconds");

    // A worker spins until the clock has seen 0.25 CPU seconds more (however loaded the
    // machine, it gets there), while this thread only sleeps between looks.
    let stop = AtomicBool::new(false);
    let start = process_cpu_seconds();
    let deadline = Instant::now() + Duration::from_secs(60);
    let counted = std::thread::scope(|scope| {
        scope.spawn(|| {
            let mut x = 1u64;
            while !stop.load(Ordering::Relaxed) {
                x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
            }
        });
        let counted = loop {
            std::thread::sleep(Duration::from_millis(20));
            let d = process_cpu_seconds() - start;
            if d >= 0.25 || Instant::now() > deadline {
                break d;
            }
        };
        stop.store(true, Ordering::Relaxed);
        counted
    });
    assert!(
        counted >= 0.25,
        "a spinning thread counted {counted} CPU seconds in 60 s"
    );
}
