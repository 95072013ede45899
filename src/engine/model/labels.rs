//! What a model labels an event with: a few named values that the engine
//! hands to its observers as they are, without knowing what they mean (a
//! chain's unit and closing speed, a place along a continuum). The log
//! writes them after the state, in the order the model gave them.

/// One labelled value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Label {
    /// A whole number (a part's index).
    Count(u64),
    /// A real number (a speed, a position).
    Number(f64),
}

impl Label {
    /// The value as a real number, whichever kind it is.
    pub fn as_f64(self) -> f64 {
        match self {
            Label::Count(n) => n as f64,
            Label::Number(x) => x,
        }
    }
}

/// Up to [`Labels::CAPACITY`] labels of one event, in order; copied, never
/// allocated (a chain labels a million impacts a second).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Labels {
    len: usize,
    items: [(&'static str, Label); Labels::CAPACITY],
}

impl Default for Labels {
    fn default() -> Self {
        Labels::NONE
    }
}

impl Labels {
    /// The most labels an event carries.
    pub const CAPACITY: usize = 3;

    /// No labels.
    pub const NONE: Labels = Labels {
        len: 0,
        items: [("", Label::Count(0)); Labels::CAPACITY],
    };

    /// These labels and `key: value` after them. A label past the capacity
    /// is a model's mistake: it is dropped (and caught by debug builds).
    pub fn with(mut self, key: &'static str, value: Label) -> Self {
        debug_assert!(
            self.len < Self::CAPACITY,
            "more than {} labels",
            Self::CAPACITY
        );
        if self.len < Self::CAPACITY {
            self.items[self.len] = (key, value);
            self.len += 1;
        }
        self
    }

    /// These labels and `key: value` if there is a value.
    pub fn with_some(self, key: &'static str, value: Option<Label>) -> Self {
        match value {
            Some(value) => self.with(key, value),
            None => self,
        }
    }

    /// The labels, in order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, Label)> + '_ {
        self.items[..self.len].iter().copied()
    }

    /// The value labelled `key`, if any.
    pub fn get(&self, key: &str) -> Option<Label> {
        self.iter().find(|(k, _)| *k == key).map(|(_, v)| v)
    }

    /// The whole number labelled `key`, if there is one.
    pub fn count(&self, key: &str) -> Option<u64> {
        match self.get(key) {
            Some(Label::Count(n)) => Some(n),
            _ => None,
        }
    }

    /// The value labelled `key` as a real number, if there is one.
    pub fn number(&self, key: &str) -> Option<f64> {
        self.get(key).map(Label::as_f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_keep_their_order_and_kinds() {
        let labels = Labels::NONE
            .with("unit", Label::Count(7))
            .with_some("rel_velocity", None)
            .with("x", Label::Number(-0.25));
        let keys: Vec<&str> = labels.iter().map(|(k, _)| k).collect();
        assert_eq!(keys, ["unit", "x"]);
        assert_eq!(labels.count("unit"), Some(7));
        assert_eq!(labels.number("x"), Some(-0.25));
        assert_eq!(labels.count("x"), None);
        assert_eq!(labels.get("rel_velocity"), None);
    }
}
