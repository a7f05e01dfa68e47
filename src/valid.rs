//! Configurations checked once, where they enter the program, and trusted from there on.
//!
//! A configuration struct (`ControlConfig`, `PlannerConfig`, `SamplerConfig`, ...) is plain data:
//! serde reads it, flags fill it, struct-update syntax tweaks it. It implements [`Check`], whose
//! `check` destructures every field, so a field added later cannot be left unchecked (it is a
//! compile error until it is listed). The code that runs on a configuration takes a [`Valid`]
//! wrapper, which only [`Valid::new`] (or serde, through the same check) can build: the controllers
//! and the planner never re-validate, and cannot be handed an unchecked value. This is the
//! `Params -> check() -> ValidParams` pattern of linfa.

use std::fmt;
use std::ops::Deref;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A configuration that can say whether each of its fields is in range.
pub trait Check {
    /// What is wrong, naming the field.
    type Error: fmt::Display;

    /// `Ok` when every field is in its allowed range (and finite, for real numbers).
    fn check(&self) -> Result<(), Self::Error>;
}

/// A `T` whose [`Check`] passed. Reads like a `T` (it dereferences to one); to change a field, take
/// the value out with [`into_inner`](Self::into_inner), change it and check it again.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Valid<T>(T);

impl<T: Check> Valid<T> {
    /// Checks `value`.
    pub fn new(value: T) -> Result<Self, T::Error> {
        value.check()?;
        Ok(Self(value))
    }
}

impl<T> Valid<T> {
    /// The checked value, to be changed and checked again.
    pub fn into_inner(self) -> T {
        self.0
    }
}

impl<T> Deref for Valid<T> {
    type Target = T;

    fn deref(&self) -> &T {
        &self.0
    }
}

impl<T: Check + Default> Default for Valid<T> {
    /// The default configuration, which every `Check` type keeps in range (each one's unit tests
    /// assert it).
    fn default() -> Self {
        let value = T::default();
        debug_assert!(
            value.check().is_ok(),
            "a default configuration fails its own check"
        );
        Self(value)
    }
}

impl<T: Serialize> Serialize for Valid<T> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.0.serialize(serializer)
    }
}

impl<'de, T: Deserialize<'de> + Check> Deserialize<'de> for Valid<T> {
    /// Reads a `T` and checks it: a file cannot smuggle an out-of-range value past [`Valid::new`].
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let value = T::deserialize(deserializer)?;
        Self::new(value).map_err(serde::de::Error::custom)
    }
}

/// Declares a checked number: a newtype over a finite `f64` that only its checks can build.
///
/// Why one macro: a number with a range of its own (a probability, a pseudo-count, `--scale`)
/// enters the program through a constructor, `TryFrom<f64>`, a flag's `FromStr` and serde. Four
/// hand-written copies of those doors had drifted apart: two checked finiteness and two left it to
/// their bounds, two parsed text and two could not. Each door here is the same check, so a value
/// refused by one is refused by all, with the same message.
///
/// What it generates for `$name`:
///
/// - the struct, `Debug, Clone, Copy, PartialEq, PartialOrd`, serialized as its bare number and
///   deserialized through `TryFrom<f64>` (a file cannot smuggle a value past the check);
/// - `new(value) -> Result<$name, $error>`: `Ok` when `value` is finite and the predicate holds,
///   else the out-of-range error of `value` (NaN and the infinities are always refused, whatever
///   the predicate says, since a comparison with NaN is false and a negated one true);
/// - `get(self) -> f64`, `From<$name> for f64`, `TryFrom<f64>` (`new`), `Display` (the number);
/// - `FromStr`: the text trimmed and parsed, the untrimmed text in the not-a-number error, the
///   number then through `new`.
///
/// The refusal is either an error enum the macro declares beside the number (`OutOfRange(f64)` and
/// `NotANumber(String)`, each with its message), or an existing error type built by two functions,
/// of the refused value and of the text that is no number:
///
/// ```ignore
/// checked_f64! {
///     /// A probability in (0, 1].
///     pub struct Probability(p) where p > 0.0 && p <= 1.0;
///     /// A value that is not a [`Probability`].
///     pub enum ProbabilityError {
///         OutOfRange = "{0} is not a probability in (0, 1]",
///         NotANumber = "'{0}' is not a number",
///     }
/// }
///
/// checked_f64! {
///     /// A count above zero.
///     pub struct PseudoCount(alpha) where alpha > 0.0;
///     refused as RecognizeError: out_of_range, not_a_number;
/// }
/// ```
///
/// Constants and a `Default` are written beside the invocation, in the same module (the field is
/// private to it).
macro_rules! checked_f64 {
    (
        $(#[$doc:meta])*
        pub struct $name:ident($value:ident) where $accepts:expr;
        $(#[$error_doc:meta])*
        pub enum $error:ident {
            OutOfRange = $out_of_range:tt,
            NotANumber = $not_a_number:tt $(,)?
        }
    ) => {
        $(#[$error_doc])*
        #[derive(Debug, Clone, PartialEq, thiserror::Error)]
        pub enum $error {
            #[error($out_of_range)]
            OutOfRange(f64),
            #[error($not_a_number)]
            NotANumber(String),
        }

        $crate::valid::checked_f64! {
            $(#[$doc])*
            pub struct $name($value) where $accepts;
            refused as $error: $error::OutOfRange, |text: &str| $error::NotANumber(text.to_string());
        }
    };
    (
        $(#[$doc:meta])*
        pub struct $name:ident($value:ident) where $accepts:expr;
        refused as $error:ty: $out_of_range:expr, $not_a_number:expr;
    ) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, PartialOrd, ::serde::Serialize, ::serde::Deserialize)]
        #[serde(try_from = "f64", into = "f64")]
        pub struct $name(f64);

        impl $name {
            #[doc = concat!(
                "Checks `", stringify!($value), "`: it must be finite and `", stringify!($accepts), "`."
            )]
            pub fn new($value: f64) -> Result<Self, $error> {
                if $value.is_finite() && $accepts {
                    Ok(Self($value))
                } else {
                    Err(($out_of_range)($value))
                }
            }

            /// The number, checked.
            pub fn get(self) -> f64 {
                self.0
            }
        }

        impl TryFrom<f64> for $name {
            type Error = $error;
            fn try_from(value: f64) -> Result<Self, $error> {
                Self::new(value)
            }
        }

        impl From<$name> for f64 {
            fn from(value: $name) -> f64 {
                value.0
            }
        }

        impl std::str::FromStr for $name {
            type Err = $error;
            fn from_str(text: &str) -> Result<Self, $error> {
                let value: f64 = text.trim().parse().map_err(|_| ($not_a_number)(text))?;
                Self::new(value)
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}", self.0)
            }
        }
    };
}
pub(crate) use checked_f64;

/// A field outside its allowed range: the error type of most [`Check`] impls.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{config}: {field} = {value} is outside {allowed}")]
pub struct RangeError {
    /// Which configuration (`control config`, `planner config`, ...).
    pub config: &'static str,
    pub field: &'static str,
    /// The offending value, formatted.
    pub value: String,
    /// The allowed range, as a reader would write it (`(0, 1]`).
    pub allowed: &'static str,
}

/// Collects the first failing field of a [`Check`]: each `real`/`count`/`that` call tests one field,
/// and `finish` returns the first failure.
pub(crate) struct FieldChecks {
    config: &'static str,
    first_error: Option<RangeError>,
}

impl FieldChecks {
    pub(crate) fn of(config: &'static str) -> Self {
        Self {
            config,
            first_error: None,
        }
    }

    fn fail(&mut self, field: &'static str, value: String, allowed: &'static str) {
        if self.first_error.is_none() {
            self.first_error = Some(RangeError {
                config: self.config,
                field,
                value,
                allowed,
            });
        }
    }

    /// A real number that must be finite and satisfy `ok`.
    pub(crate) fn real(
        &mut self,
        field: &'static str,
        value: f64,
        ok: bool,
        allowed: &'static str,
    ) -> &mut Self {
        if !(ok && value.is_finite()) {
            self.fail(field, value.to_string(), allowed);
        }
        self
    }

    /// A count that must satisfy `ok`.
    pub(crate) fn count(
        &mut self,
        field: &'static str,
        value: usize,
        ok: bool,
        allowed: &'static str,
    ) -> &mut Self {
        if !ok {
            self.fail(field, value.to_string(), allowed);
        }
        self
    }

    /// Any other value (a vector, a relation between fields), shown with `Debug`.
    pub(crate) fn that(
        &mut self,
        field: &'static str,
        value: impl fmt::Debug,
        ok: bool,
        allowed: &'static str,
    ) -> &mut Self {
        if !ok {
            self.fail(field, format!("{value:?}"), allowed);
        }
        self
    }

    pub(crate) fn finish(&mut self) -> Result<(), RangeError> {
        match self.first_error.take() {
            Some(error) => Err(error),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Default, Clone, Copy, PartialEq, Serialize, Deserialize)]
    struct Gain {
        kp: f64,
    }

    impl Check for Gain {
        type Error = RangeError;
        fn check(&self) -> Result<(), RangeError> {
            let Self { kp } = *self;
            FieldChecks::of("gain")
                .real("kp", kp, kp >= 0.0, "[0, inf)")
                .finish()
        }
    }

    #[test]
    fn only_a_value_that_passes_its_check_is_wrapped() {
        assert_eq!(Valid::new(Gain { kp: 0.5 }).map(|v| v.kp), Ok(0.5));
        let error = Valid::new(Gain { kp: -1.0 }).unwrap_err();
        assert_eq!(error.to_string(), "gain: kp = -1 is outside [0, inf)");
        assert_eq!(Valid::new(Gain { kp: f64::NAN }).unwrap_err().field, "kp");
    }

    #[test]
    fn deserializing_checks_and_serializing_is_transparent() {
        let valid: Valid<Gain> = serde_json::from_str(r#"{"kp": 2.0}"#).unwrap();
        assert_eq!(serde_json::to_string(&valid).unwrap(), r#"{"kp":2.0}"#);
        let error = serde_json::from_str::<Valid<Gain>>(r#"{"kp": -2.0}"#).unwrap_err();
        assert!(
            error.to_string().contains("gain: kp = -2 is outside [0, inf)"),
            "{error}"
        );
    }

    #[test]
    fn the_first_failing_field_is_reported() {
        let error = FieldChecks::of("c")
            .real("a", 1.0, true, "x")
            .count("b", 0, false, "1 or more")
            .real("c", -1.0, false, "y")
            .finish()
            .unwrap_err();
        assert_eq!((error.field, error.value.as_str()), ("b", "0"));
    }
}
