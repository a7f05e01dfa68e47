//! Assembling MJCF documents from the world files in `mjcf/`.
//!
//! The files in `mjcf/` are complete MJCF models so that MuJoCo's own viewer opens them unchanged;
//! `world.xml` combines them with `<include>`. MuJoCo's include inserts the children of the included
//! `<mujoco>` element; [`inner`] does the same textually, so scenes built here are the same model as
//! the files, with the object slot filled by a mesh and extra parts (sensor plugins) added.

use crate::sim::SimError;
use crate::units::push_round_trip;

/// `mjcf/arm.xml`: the arm of Sec. V-A1 with the sensor pad site.
pub const ARM_XML: &str = include_str!("../../mjcf/arm.xml");
/// `mjcf/table.xml`: the table, its top at z = 0.
pub const TABLE_XML: &str = include_str!("../../mjcf/table.xml");
/// Height of the table top in `mjcf/table.xml` (the object rests on it), metres.
pub const TABLE_TOP_Z_M: f64 = 0.0;
/// The geom group of collision-only geoms (MuJoCo's usual convention, hidden in its viewer by
/// default): they take part in contacts, and the tactile sensor does not see them.
pub const COLLISION_GROUP: i32 = 3;

/// The names of the two `<numeric>` fields that carry the exact surface of mesh asset `mesh` when
/// the asset itself is a coarse copy (a large scan: `mesh::cluster_vertices`): its vertices
/// (x, y, z, in the coordinates the asset was given in) and its faces (three vertex indices each).
/// The covering sensor reads such a mesh through these instead of MuJoCo's copy.
pub fn sensed_surface_names(mesh: &str) -> (String, String) {
    (format!("{mesh}:sensed_vertex"), format!("{mesh}:sensed_face"))
}

/// The children of the root `<mujoco>` element of `xml` (what `<include>` would insert).
pub fn inner(xml: &str, origin: &str) -> Result<String, SimError> {
    let missing = |what: &str| SimError::Mjcf {
        origin: origin.to_string(),
        message: what.to_string(),
    };
    let open = xml
        .find("<mujoco")
        .ok_or_else(|| missing("no <mujoco> root element"))?;
    let body_start = xml[open..]
        .find('>')
        .map(|i| open + i + 1)
        .ok_or_else(|| missing("unterminated <mujoco>"))?;
    let close = xml
        .rfind("</mujoco>")
        .ok_or_else(|| missing("no closing </mujoco>"))?;
    if close < body_start {
        return Err(missing("</mujoco> before the root element's content"));
    }
    Ok(xml[body_start..close].to_string())
}

/// Where a piece of XML goes in the assembled document.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Section {
    Asset,
    Worldbody,
    Extension,
    Sensor,
    Contact,
    Keyframe,
    Custom,
}

impl Section {
    fn tag(self) -> &'static str {
        match self {
            Self::Asset => "asset",
            Self::Worldbody => "worldbody",
            Self::Extension => "extension",
            Self::Sensor => "sensor",
            Self::Contact => "contact",
            Self::Keyframe => "keyframe",
            Self::Custom => "custom",
        }
    }
}

/// An MJCF document under construction: whole included models plus extra section content.
#[derive(Debug, Clone, Default)]
pub struct Document {
    includes: Vec<String>,
    sections: Vec<(Section, String)>,
}

impl Document {
    /// Inserts the children of a complete `<mujoco>` model, as `<include>` would.
    pub fn include(&mut self, xml: &str, origin: &str) -> Result<&mut Self, SimError> {
        self.includes.push(inner(xml, origin)?);
        Ok(self)
    }

    /// Adds raw elements to a section.
    pub fn add(&mut self, section: Section, xml: impl Into<String>) -> &mut Self {
        self.sections.push((section, xml.into()));
        self
    }

    /// The assembled document. MJCF merges repeated top-level sections, so each part keeps its own.
    pub fn to_xml(&self, model_name: &str) -> String {
        let mut xml = format!("<mujoco model=\"{}\">\n", escape_attr(model_name));
        for part in &self.includes {
            xml.push_str(part);
            xml.push('\n');
        }
        for (section, content) in &self.sections {
            let tag = section.tag();
            xml.push_str(&format!("<{tag}>\n{content}\n</{tag}>\n"));
        }
        xml.push_str("</mujoco>\n");
        xml
    }
}

/// Escapes a string for use inside a double-quoted XML attribute. Characters XML 1.0 does not
/// allow in a document at all (control characters other than tab and line breaks) become U+FFFD.
pub fn escape_attr(value: &str) -> String {
    xml_chars(value)
        .replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// `text` as an XML comment, `<!--` and `-->` on lines of their own.
///
/// A well-formed comment holds no `--` and does not end in `-` (strict parsers such as Python's
/// `xml.etree` and dm_control's `mjcf` refuse the file otherwise, although MuJoCo reads it): a
/// hyphen that follows another gets a space before it (`a--b` becomes `a- -b`).
pub fn comment(text: &str) -> String {
    let mut body = String::with_capacity(text.len() + 16);
    for c in xml_chars(text).chars() {
        if c == '-' && body.ends_with('-') {
            body.push(' ');
        }
        body.push(c);
    }
    format!("<!--\n{body}\n-->")
}

/// `text` with the characters XML 1.0 forbids replaced by U+FFFD.
fn xml_chars(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_control() && !matches!(c, '\t' | '\n' | '\r') {
                char::REPLACEMENT_CHARACTER
            } else {
                c
            }
        })
        .collect()
}

/// Space-separated numbers in shortest round-trip form
/// ([`round_trip`](crate::units::round_trip)), so the compiled model holds exactly these values.
pub fn numbers<I: IntoIterator<Item = f64>>(values: I) -> String {
    space_separated(values, push_round_trip)
}

/// The single-precision value MuJoCo reads from `x` written by [`numbers`] (its parser, `strtof`,
/// rounds the decimal text to the nearest `f32`), without the text: so a mesh handed to MuJoCo as
/// numbers compiles to the model its MJCF text does, bit for bit.
///
/// The text is the shortest decimal that reads back as `x`, so it lies within half an `f64` step
/// of `x`, closer than any `f32` rounding boundary other than `x` itself: rounding it and rounding
/// `x` agree unless `x` is exactly halfway between two `f32`s, where `x` rounds to even and the
/// text to its own side. Only there is the text written and read.
pub fn as_read_f32(x: f64) -> f32 {
    let nearest = x as f32;
    let (below, above) = if f64::from(nearest) <= x {
        (nearest, nearest.next_up())
    } else {
        (nearest.next_down(), nearest)
    };
    let halfway = (f64::from(below) + f64::from(above)) * 0.5;
    if halfway != x || !x.is_finite() {
        return nearest;
    }
    let mut text = String::new();
    push_round_trip(&mut text, x);
    text.parse().unwrap_or(nearest)
}

/// `values` written by `write` into one string, separated by spaces: MJCF's list attributes, built
/// without a string per value (a scanned mesh has millions).
pub fn space_separated<T>(values: impl IntoIterator<Item = T>, write: impl Fn(&mut String, T)) -> String {
    let mut s = String::new();
    for (i, v) in values.into_iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        write(&mut s, v);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inner_strips_the_root_and_keeps_content() {
        let xml = "<!-- c --><mujoco model=\"m\">\n<worldbody/>\n</mujoco>\n";
        assert_eq!(inner(xml, "t").unwrap().trim(), "<worldbody/>");
        assert!(
            inner("<x/>", "t")
                .unwrap_err()
                .to_string()
                .contains("no <mujoco>")
        );
    }

    #[test]
    fn comments_and_attributes_stay_well_formed_whatever_the_text() {
        let text = "a--b --- c-\u{1}";
        let wrapped = comment(text);
        let body = &wrapped["<!--".len()..wrapped.len() - "-->".len()];
        assert!(!body.contains("--") && !body.ends_with('-'), "{wrapped}");
        assert_eq!(body.trim(), "a- -b - - - c-\u{fffd}");
        let document = format!("{wrapped}<m a=\"{}\"/>", escape_attr(text));
        let parsed = roxmltree::Document::parse(&document).expect("well-formed");
        assert_eq!(parsed.root_element().attribute("a"), Some("a--b --- c-\u{fffd}"));
    }

    #[test]
    fn numbers_handed_over_are_the_numbers_the_text_reads_as() {
        let halfway = |f: f32| (f64::from(f) + f64::from(f.next_up())) * 0.5;
        let ties: Vec<f64> = [1.0f32, 0.04, -0.037_5, 3.0e-5, 0.123_456_7]
            .into_iter()
            .flat_map(|f| [halfway(f), -halfway(f)])
            .collect();
        let plain = [0.0, -0.0, 0.04, 1.0 / 3.0, -2.5e-6, 123.456_789, 1e-30];
        let mut cast_differs = 0;
        for &x in ties.iter().chain(&plain) {
            let text = numbers([x]);
            let read: f32 = text.parse().unwrap();
            assert_eq!(as_read_f32(x).to_bits(), read.to_bits(), "{x} written as {text}");
            cast_differs += usize::from((x as f32).to_bits() != read.to_bits());
        }
        // The tie above 1: its text (1.0000000596046448) lies above it and rounds up, where the
        // cast rounds to even (1.0).
        assert_eq!(as_read_f32(halfway(1.0)), 1.0f32.next_up());
        assert!(cast_differs > 0);
    }

    #[test]
    fn world_files_are_complete_models() {
        for (xml, name) in [(ARM_XML, "arm.xml"), (TABLE_XML, "table.xml")] {
            assert!(inner(xml, name).is_ok(), "{name}");
        }
    }
}
