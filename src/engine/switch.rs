//! Test switches: a test runs code with one switched on, on its own thread,
//! to take a slower, simpler path (the per-contact pass, a full pair list,
//! one pass per hook) and compare its bits with the fast path's.

use std::cell::Cell;
use std::thread::LocalKey;

/// A switch, off unless [`Switch::on_during`] runs.
pub struct Switch(&'static LocalKey<Cell<bool>>);

/// Puts the switch back as it was, also when the code under it panics.
struct Restore(&'static LocalKey<Cell<bool>>, bool);

impl Drop for Restore {
    fn drop(&mut self) {
        self.0.with(|c| c.set(self.1));
    }
}

impl Switch {
    /// A switch kept in `key`.
    pub const fn new(key: &'static LocalKey<Cell<bool>>) -> Switch {
        Switch(key)
    }
    /// Run `f` with the switch on, on this thread.
    pub fn on_during<T>(&self, f: impl FnOnce() -> T) -> T {
        let _restore = Restore(self.0, self.0.with(|c| c.replace(true)));
        f()
    }
    /// Whether the switch is on on this thread.
    #[inline]
    pub fn is_on(&self) -> bool {
        self.0.with(|c| c.get())
    }
}

/// Declare a [`Switch`] named `$name`, off by default.
macro_rules! switch {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        static $name: $crate::engine::switch::Switch = {
            thread_local! {
                static KEY: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
            }
            $crate::engine::switch::Switch::new(&KEY)
        };
    };
}
pub(crate) use switch;
