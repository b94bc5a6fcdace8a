//! `Memo`: a per-process cache that builds each value once, even when several threads ask at once
//! (the others wait for the first build instead of repeating it).

use std::{
    collections::HashMap,
    hash::Hash,
    sync::{Arc, Mutex, OnceLock},
};

type Slot<V> = Arc<OnceLock<Arc<V>>>;

/// A lazily built, shared value per key.
pub(crate) struct Memo<K, V> {
    slots: OnceLock<Mutex<HashMap<K, Slot<V>>>>,
}

impl<K: Eq + Hash, V> Memo<K, V> {
    /// An empty cache (usable in a `static`).
    pub(crate) const fn new() -> Self {
        Self {
            slots: OnceLock::new(),
        }
    }

    /// The value for `key`, built by `build` the first time.
    pub(crate) fn get_or_build(&self, key: K, build: impl FnOnce() -> V) -> Arc<V> {
        let slot = {
            // A poisoned lock only means another build panicked; the map itself is intact.
            let mut map = self
                .slots
                .get_or_init(Default::default)
                .lock()
                .unwrap_or_else(|e| e.into_inner());
            map.entry(key).or_default().clone()
        };
        slot.get_or_init(|| Arc::new(build())).clone()
    }
}
