//! Names of states, modes, guards and events, as the engine's models give
//! them and its logs print them.
//!
//! A model written in Rust names things with literals, which cost nothing;
//! a model read from a file (or a name made from others, such as a
//! sensitivity's `dstrain/deta`) has its names only at run time. A
//! [`Name`] is either, shared without copying its text, and freed with the
//! last model or outcome that holds it.

use std::borrow::Borrow;
use std::cmp::Ordering;
use std::fmt;
use std::hash::{Hash, Hasher};
use std::ops::Deref;
use std::sync::Arc;

/// A name: a literal (`Name::new("impact")`, usable in constants) or text
/// made at run time (`Name::from(text)`). It compares, orders and hashes
/// as its text, and reads as a `&str`.
#[derive(Clone)]
pub struct Name(Text);

#[derive(Clone)]
enum Text {
    Literal(&'static str),
    Shared(Arc<str>),
}

impl Name {
    /// A name from a literal.
    pub const fn new(text: &'static str) -> Self {
        Name(Text::Literal(text))
    }

    /// Its text.
    pub fn as_str(&self) -> &str {
        match &self.0 {
            Text::Literal(text) => text,
            Text::Shared(text) => text,
        }
    }
}

/// A constant slice of names from literals, for a model's
/// [`state_names`](crate::engine::HybridModel::state_names):
/// `names!["x", "v"]`.
#[macro_export]
macro_rules! names {
    ($($name:literal),* $(,)?) => {{
        const NAMES: &[$crate::engine::Name] = &[$($crate::engine::Name::new($name)),*];
        NAMES
    }};
}

impl From<&str> for Name {
    fn from(text: &str) -> Self {
        Name(Text::Shared(text.into()))
    }
}

impl From<String> for Name {
    fn from(text: String) -> Self {
        Name(Text::Shared(text.into()))
    }
}

impl Deref for Name {
    type Target = str;

    fn deref(&self) -> &str {
        self.as_str()
    }
}

impl AsRef<str> for Name {
    fn as_ref(&self) -> &str {
        self.as_str()
    }
}

impl Borrow<str> for Name {
    fn borrow(&self) -> &str {
        self.as_str()
    }
}

impl PartialEq for Name {
    fn eq(&self, other: &Name) -> bool {
        self.as_str() == other.as_str()
    }
}

impl Eq for Name {}

impl PartialEq<str> for Name {
    fn eq(&self, other: &str) -> bool {
        self.as_str() == other
    }
}

impl PartialEq<&str> for Name {
    fn eq(&self, other: &&str) -> bool {
        self.as_str() == *other
    }
}

impl PartialOrd for Name {
    fn partial_cmp(&self, other: &Name) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Name {
    fn cmp(&self, other: &Name) -> Ordering {
        self.as_str().cmp(other.as_str())
    }
}

impl Hash for Name {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.as_str().hash(state)
    }
}

impl fmt::Display for Name {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl fmt::Debug for Name {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.as_str(), f)
    }
}

impl serde::Serialize for Name {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A literal and run-time text of the same name are one name: equal,
    /// ordered and hashed alike, so a map keyed by either finds the other.
    #[test]
    fn literal_and_shared_names_are_the_same_name() {
        let literal = Name::new("impact");
        let shared = Name::from(String::from("impact"));
        assert_eq!(literal, shared);
        assert_eq!(literal.cmp(&Name::from("zeno")), Ordering::Less);
        let mut counts = std::collections::HashMap::new();
        counts.insert(literal, 1);
        assert_eq!(counts.get("impact"), Some(&1));
        assert_eq!(counts.get(&shared), Some(&1));
        assert_eq!(format!("{shared} {shared:?}"), "impact \"impact\"");
    }

    /// Shared text lives as long as its last holder, and no longer.
    #[test]
    fn shared_text_is_freed_with_its_last_holder() {
        let text: Arc<str> = "dx/deta".into();
        let name = Name(Text::Shared(text.clone()));
        let copy = name.clone();
        assert_eq!(Arc::strong_count(&text), 3);
        drop((name, copy));
        assert_eq!(Arc::strong_count(&text), 1);
    }
}
