//! Names that live as long as the program: the engine's events and logs
//! take `&'static str`, and a model read from a file (or a name made from
//! others, such as a sensitivity's `dstrain/deta`) has its names only at
//! run time.

use std::collections::HashSet;
use std::sync::{Mutex, OnceLock};

/// `name` as a `&'static str`. Each distinct name is stored once, however
/// many scenes and runs use it.
pub fn intern(name: &str) -> &'static str {
    static NAMES: OnceLock<Mutex<HashSet<&'static str>>> = OnceLock::new();
    let mut names = NAMES
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    match names.get(name) {
        Some(known) => known,
        None => {
            let leaked: &'static str = Box::leak(name.to_string().into_boxed_str());
            names.insert(leaked);
            leaked
        }
    }
}
