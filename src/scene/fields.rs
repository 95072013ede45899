//! Reading the keys of a JSON object one by one, with the path of every key
//! kept for error messages and unknown keys reported at the end.

use serde_json::{Map, Value};

use crate::scene::SceneError;

/// The keys of one JSON object still to be read.
pub struct Fields<'a> {
    path: String,
    map: &'a Map<String, Value>,
    seen: Vec<&'static str>,
}

impl<'a> Fields<'a> {
    /// Open `value` as an object found at `path` (`""` for the top level).
    pub fn open(value: &'a Value, path: &str) -> Result<Self, SceneError> {
        match value {
            Value::Object(map) => Ok(Fields {
                path: path.to_string(),
                map,
                seen: Vec::new(),
            }),
            other => Err(SceneError::field(
                if path.is_empty() { "(top level)" } else { path },
                format!("must be a JSON object, found {}", kind(other)),
            )),
        }
    }

    /// The full path of `key` inside this object.
    pub fn path(&self, key: &str) -> String {
        if self.path.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.path)
        }
    }

    /// Whether `key` is present.
    pub fn has(&self, key: &str) -> bool {
        self.map.contains_key(key)
    }

    /// The value of `key`, if present; either way `key` counts as known.
    pub fn optional(&mut self, key: &'static str) -> Option<&'a Value> {
        self.seen.push(key);
        self.map.get(key)
    }

    /// The value of `key`, or an error saying it is missing.
    pub fn required(&mut self, key: &'static str) -> Result<&'a Value, SceneError> {
        self.optional(key)
            .ok_or_else(|| SceneError::field(&self.path(key), "is missing".into()))
    }

    /// A finite number.
    pub fn number(&mut self, key: &'static str) -> Result<f64, SceneError> {
        let value = self.required(key)?;
        self.as_number(key, value)
    }

    /// A finite number, if `key` is present.
    pub fn optional_number(&mut self, key: &'static str) -> Result<Option<f64>, SceneError> {
        self.optional(key)
            .map(|v| self.as_number(key, v))
            .transpose()
    }

    /// A finite number that satisfies `ok`, described by `rule` otherwise.
    pub fn number_where(
        &mut self,
        key: &'static str,
        rule: &str,
        ok: impl Fn(f64) -> bool,
    ) -> Result<f64, SceneError> {
        let x = self.number(key)?;
        self.check(key, x, rule, ok)
    }

    /// `x`, the value of `key`, if it satisfies `ok`; otherwise an error
    /// saying it must be `rule`.
    pub fn check(
        &self,
        key: &str,
        x: f64,
        rule: &str,
        ok: impl Fn(f64) -> bool,
    ) -> Result<f64, SceneError> {
        if ok(x) {
            Ok(x)
        } else {
            Err(SceneError::field(
                &self.path(key),
                format!("must be {rule} (got {x})"),
            ))
        }
    }

    /// A string.
    pub fn string(&mut self, key: &'static str) -> Result<&'a str, SceneError> {
        let value = self.required(key)?;
        self.as_string(key, value)
    }

    /// A string, if `key` is present.
    pub fn optional_string(&mut self, key: &'static str) -> Result<Option<&'a str>, SceneError> {
        self.optional(key)
            .map(|v| self.as_string(key, v))
            .transpose()
    }

    /// A positive whole number.
    pub fn optional_count(&mut self, key: &'static str) -> Result<Option<u64>, SceneError> {
        self.optional(key)
            .map(|v| {
                v.as_u64().filter(|n| *n > 0).ok_or_else(|| {
                    SceneError::field(
                        &self.path(key),
                        format!("must be a positive whole number, found {v}"),
                    )
                })
            })
            .transpose()
    }

    /// Fail on any key that was never asked for.
    pub fn finish(self) -> Result<(), SceneError> {
        match self.map.keys().find(|k| !self.seen.contains(&k.as_str())) {
            None => Ok(()),
            Some(key) => {
                let known = self.seen.join(", ");
                Err(SceneError::field(
                    &self.path(key),
                    format!("is not a known key here (known: {known})"),
                ))
            }
        }
    }

    fn as_number(&self, key: &str, value: &Value) -> Result<f64, SceneError> {
        match value.as_f64() {
            Some(x) if x.is_finite() => Ok(x),
            _ => Err(SceneError::field(
                &self.path(key),
                format!("must be a finite number, found {}", kind(value)),
            )),
        }
    }

    fn as_string(&self, key: &str, value: &'a Value) -> Result<&'a str, SceneError> {
        value.as_str().ok_or_else(|| {
            SceneError::field(
                &self.path(key),
                format!("must be a string, found {}", kind(value)),
            )
        })
    }
}

/// How a value reads in an error message.
pub fn kind(value: &Value) -> String {
    match value {
        Value::Null => "null".into(),
        Value::Bool(b) => format!("the boolean {b}"),
        Value::Number(n) => format!("the number {n}"),
        Value::String(s) => format!("the string {s:?}"),
        Value::Array(_) => "an array".into(),
        Value::Object(_) => "an object".into(),
    }
}
