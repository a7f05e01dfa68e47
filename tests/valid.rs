//! Checked numbers (`valid::checked_f64!`): each enters through `new`, `TryFrom<f64>`, `FromStr`
//! (a flag) and serde (a file), and each door refuses what the others refuse, with the same message.

use std::fmt::{Debug, Display};
use std::str::FromStr;

use serde::de::value::{Error as ValueError, F64Deserializer};
use serde::de::{DeserializeOwned, IntoDeserializer};
use taction::explore::Probability;
use taction::paper::Scale;
use taction::recognize::{PseudoCount, VarianceFraction};

/// One checked number's doors, its edges and what it refuses.
struct Doors<T, E> {
    new: fn(f64) -> Result<T, E>,
    /// Values at the edges of the range, all accepted.
    edges: &'static [f64],
    /// Values just outside, NaN and the infinities among them, all refused.
    outside: &'static [f64],
    /// The message refusing a value (its `Display`).
    refusal: fn(&str) -> String,
    /// The message refusing a text that is no number.
    not_a_number: fn(&str) -> String,
}

fn every_door_agrees<T, E>(doors: Doors<T, E>)
where
    T: TryFrom<f64> + FromStr + DeserializeOwned + Into<f64> + Copy + Debug,
    E: Display,
    <T as TryFrom<f64>>::Error: Display,
    <T as FromStr>::Err: Display,
{
    for &value in doors.edges {
        let through_new = (doors.new)(value).unwrap_or_else(|e| panic!("{value}: {e}"));
        assert_eq!(Into::<f64>::into(through_new), value);
        let through_try = T::try_from(value).unwrap_or_else(|e| panic!("{value}: {e}"));
        assert_eq!(Into::<f64>::into(through_try), value);
        let through_text: T = value
            .to_string()
            .parse()
            .unwrap_or_else(|e| panic!("{value}: {e}"));
        assert_eq!(Into::<f64>::into(through_text), value);
        let file: F64Deserializer<ValueError> = value.into_deserializer();
        assert_eq!(T::deserialize(file).map(Into::<f64>::into).ok(), Some(value));
    }
    for &value in doors.outside {
        let want = (doors.refusal)(&value.to_string());
        let refused = |door: &str, e: Option<String>| {
            assert_eq!(e.as_deref(), Some(want.as_str()), "{value} through {door}");
        };
        refused("new", (doors.new)(value).err().map(|e| e.to_string()));
        refused("TryFrom", T::try_from(value).err().map(|e| e.to_string()));
        refused(
            "FromStr",
            value.to_string().parse::<T>().err().map(|e| e.to_string()),
        );
        let file: F64Deserializer<ValueError> = value.into_deserializer();
        refused("serde", T::deserialize(file).err().map(|e| e.to_string()));
    }
    for text in ["x", "", "0.5.5"] {
        let e = text.parse::<T>().err().map(|e| e.to_string());
        assert_eq!(e, Some((doors.not_a_number)(text)), "'{text}'");
    }
}

/// What every checked number refuses besides its own range.
const NOT_FINITE: [f64; 3] = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY];

#[test]
fn a_checked_number_is_refused_out_of_range_wherever_it_enters() {
    every_door_agrees(Doors {
        new: VarianceFraction::new,
        edges: &[f64::MIN_POSITIVE, 0.5, 1.0],
        outside: &[
            0.0,
            -0.1,
            1.0 + f64::EPSILON,
            NOT_FINITE[0],
            NOT_FINITE[1],
            NOT_FINITE[2],
        ],
        refusal: |v| format!("invalid parameter variance_kept: {v} is not a fraction in (0, 1]"),
        not_a_number: |t| format!("invalid parameter variance_kept: '{t}' is not a number"),
    });
    every_door_agrees(Doors {
        new: PseudoCount::new,
        edges: &[f64::MIN_POSITIVE, 1.0, f64::MAX],
        outside: &[0.0, -1.0, NOT_FINITE[0], NOT_FINITE[1], NOT_FINITE[2]],
        refusal: |v| format!("invalid parameter pseudo_count: {v} is not a positive finite count"),
        not_a_number: |t| format!("invalid parameter pseudo_count: '{t}' is not a number"),
    });
    every_door_agrees(Doors {
        new: Probability::new,
        edges: &[f64::MIN_POSITIVE, 0.95, 1.0],
        outside: &[
            0.0,
            -0.1,
            1.0 + f64::EPSILON,
            NOT_FINITE[0],
            NOT_FINITE[1],
            NOT_FINITE[2],
        ],
        refusal: |v| format!("{v} is not a probability in (0, 1]"),
        not_a_number: |t| format!("'{t}' is not a number"),
    });
    every_door_agrees(Doors {
        new: Scale::new,
        edges: &[f64::MIN_POSITIVE, 1.0, 10.0],
        outside: &[
            0.0,
            -1.0,
            10.000000000000002,
            NOT_FINITE[0],
            NOT_FINITE[1],
            NOT_FINITE[2],
        ],
        refusal: |v| format!("--scale {v}: must be a number in (0, 10] (1.0 is the paper's data sizes)"),
        not_a_number: |t| format!("--scale '{t}': not a number"),
    });
}

#[test]
fn a_checked_number_reads_its_text_trimmed_and_writes_its_bare_number() {
    assert_eq!(" 0.95 ".parse::<Probability>().map(Probability::get), Ok(0.95));
    assert_eq!(
        Scale::new(0.25).map(|s| (s.get(), s.fraction())),
        Ok((0.25, 0.25))
    );
    assert_eq!(serde_json::to_string(&VarianceFraction::PAPER).unwrap(), "0.9");
    assert_eq!(PseudoCount::LAPLACE.to_string(), "1");
    let e = serde_json::from_str::<Scale>("11").unwrap_err().to_string();
    assert!(e.starts_with("--scale 11: must be a number in (0, 10]"), "{e}");
}
