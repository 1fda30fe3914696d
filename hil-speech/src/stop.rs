//! Ctrl-C for every speech channel of the process: each channel registers
//! its stop flag here, and a program's interrupt handler (`hil run`'s)
//! raises them all with [`stop_all`]. A channel checks its flag between
//! utterances, so an answer being heard is finished and recorded, and the
//! next turn ends the session with an error instead of listening again.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, Weak};

/// The flags of the channels alive now (dropped channels' entries are
/// pruned on the next registration).
static LIVE: Mutex<Vec<Weak<AtomicBool>>> = Mutex::new(Vec::new());

/// Registers `flag` so that [`stop_all`] raises it while it lives.
pub(crate) fn register(flag: &Arc<AtomicBool>) {
    let mut live = LIVE.lock().unwrap_or_else(|e| e.into_inner());
    live.retain(|w| w.strong_count() > 0);
    live.push(Arc::downgrade(flag));
}

/// Raises the stop flag of every speech channel alive; returns how many
/// there were (0: no speech channel to stop cleanly, end as usual).
pub fn stop_all() -> usize {
    let live = LIVE.lock().unwrap_or_else(|e| e.into_inner());
    let mut n = 0;
    for flag in live.iter().filter_map(Weak::upgrade) {
        flag.store(true, Ordering::SeqCst);
        n += 1;
    }
    n
}
