//! A panic caught by a plugin guard is captured into the error (message
//! and location) instead of being printed by the panic hook; a panic
//! outside a guard still reaches the hook that was there before.
//!
//! Its own test binary: it sets the process's panic hook.

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use hil_core::HilError;

static SEEN_BY_PREVIOUS_HOOK: AtomicUsize = AtomicUsize::new(0);

#[test]
fn a_guarded_panic_is_captured_not_printed() {
    std::panic::set_hook(Box::new(|_| {
        SEEN_BY_PREVIOUS_HOOK.fetch_add(1, Ordering::SeqCst);
    }));
    for _ in 0..12 {
        let boom = || -> hil_core::Result<()> { panic!("boom") };
        let e = hil_plugin::call_guarded(Path::new("lib.so"), "p", "decide", boom).unwrap_err();
        assert_eq!(hil_plugin::panicked_in(&e).as_deref(), Some("decide"));
        let HilError::Plugin { why, .. } = &e else {
            panic!("{e:?}")
        };
        // The location is in the error.
        assert!(why.contains(file!()), "{why}");
    }
    assert_eq!(SEEN_BY_PREVIOUS_HOOK.load(Ordering::SeqCst), 0);
    // Outside a guard, the previous hook still sees the panic.
    let _ = std::panic::catch_unwind(|| panic!("outside"));
    assert_eq!(SEEN_BY_PREVIOUS_HOOK.load(Ordering::SeqCst), 1);
}
