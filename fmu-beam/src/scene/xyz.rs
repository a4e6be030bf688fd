//! Serde forms of the scene's vectors, shared by planar and 3D scenes: a point or direction is
//! written with 2 numbers (planar: z = 0) or 3; a torque or an inertia with one number (about
//! z, the planar form) or 3; a 3D direction with 3. Stored as `[f64; 3]`; written back with 3
//! numbers. A refusal says how many numbers were given and how many are expected. A joint's
//! `frames` are exactly two names ([`pair`]).

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::ser::Serializer;
use std::fmt;

/// `[x, y]` or `[x, y, z]`.
pub mod point {
    use super::*;

    /// Writes the 3 numbers.
    pub fn serialize<S: Serializer>(v: &[f64; 3], s: S) -> Result<S::Ok, S::Error> {
        serde::Serialize::serialize(v, s)
    }

    /// Reads 2 numbers (z = 0) or 3.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
        d.deserialize_seq(Xyz(Form::Point))
    }
}

/// A number (about z: `[0, 0, number]`) or `[x, y, z]`.
pub mod about_z {
    use super::*;

    /// Writes the 3 numbers.
    pub fn serialize<S: Serializer>(v: &[f64; 3], s: S) -> Result<S::Ok, S::Error> {
        serde::Serialize::serialize(v, s)
    }

    /// Reads a number n as `[0, 0, n]`, or 3 numbers.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
        d.deserialize_any(Xyz(Form::AboutZ))
    }
}

/// An optional `[x, y, z]` (a 3D direction).
pub mod direction {
    use super::*;

    /// Writes the 3 numbers (the fields that use it skip `None`).
    pub fn serialize<S: Serializer>(v: &Option<[f64; 3]>, s: S) -> Result<S::Ok, S::Error> {
        serde::Serialize::serialize(v, s)
    }

    /// Reads 3 numbers.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 3]>, D::Error> {
        d.deserialize_seq(Xyz(Form::Direction)).map(Some)
    }
}

/// Exactly two strings (a joint's two frames): a third is refused, not dropped.
pub mod pair {
    use super::*;

    /// Writes the 2 strings.
    pub fn serialize<S: Serializer>(v: &[String; 2], s: S) -> Result<S::Ok, S::Error> {
        serde::Serialize::serialize(v, s)
    }

    /// Reads exactly 2 strings.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[String; 2], D::Error> {
        d.deserialize_seq(Pair)
    }

    struct Pair;

    impl<'de> Visitor<'de> for Pair {
        type Value = [String; 2];

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("exactly 2 frames")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[String; 2], A::Error> {
            let mut v: Vec<String> = Vec::with_capacity(2);
            let mut n = 0usize;
            while let Some(x) = seq.next_element::<String>()? {
                if v.len() < 2 {
                    v.push(x);
                }
                n += 1;
            }
            match <[String; 2]>::try_from(v) {
                Ok(pair) if n == 2 => Ok(pair),
                _ => Err(de::Error::invalid_length(n, &self)),
            }
        }
    }
}

/// Which vector a sequence of numbers is read as.
#[derive(Clone, Copy)]
enum Form {
    /// 2 or 3 numbers.
    Point,
    /// A number or 3.
    AboutZ,
    /// 3 numbers.
    Direction,
}

struct Xyz(Form);

impl<'de> Visitor<'de> for Xyz {
    type Value = [f64; 3];

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(match self.0 {
            Form::AboutZ => "a number (about z) or an array of 3 numbers [x, y, z]",
            Form::Point => "an array of 2 numbers [x, y] or 3 numbers [x, y, z]",
            Form::Direction => "an array of 3 numbers [x, y, z]",
        })
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<[f64; 3], E> {
        if matches!(self.0, Form::AboutZ) {
            Ok([0.0, 0.0, v])
        } else {
            Err(E::invalid_type(de::Unexpected::Float(v), &self))
        }
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<[f64; 3], E> {
        self.visit_f64(v as f64)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<[f64; 3], E> {
        self.visit_f64(v as f64)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[f64; 3], A::Error> {
        let mut v = [0.0; 3];
        let mut n = 0usize;
        // every number is counted, so that a refusal says how many were given
        while let Some(x) = seq.next_element::<f64>()? {
            if let Some(slot) = v.get_mut(n) {
                *slot = x;
            }
            n += 1;
        }
        let allowed = match self.0 {
            Form::Point => n == 2 || n == 3,
            Form::AboutZ | Form::Direction => n == 3,
        };
        if allowed {
            Ok(v)
        } else {
            Err(de::Error::invalid_length(n, &self))
        }
    }
}

/// The JSON-Schema forms of these vectors (`fmu-harness schema`).
#[cfg(feature = "schema")]
pub mod schema {
    use schemars::{json_schema, Schema, SchemaGenerator};

    /// `[x, y]` or `[x, y, z]`.
    pub fn point(_: &mut SchemaGenerator) -> Schema {
        json_schema!({
            "type": "array",
            "items": { "type": "number" },
            "minItems": 2,
            "maxItems": 3
        })
    }

    /// A number (about z) or `[x, y, z]`.
    pub fn about_z(_: &mut SchemaGenerator) -> Schema {
        json_schema!({
            "anyOf": [
                { "type": "number" },
                { "type": "array", "items": { "type": "number" }, "minItems": 3, "maxItems": 3 }
            ]
        })
    }

    /// Exactly two frame names.
    pub fn pair(_: &mut SchemaGenerator) -> Schema {
        json_schema!({
            "type": "array",
            "items": { "type": "string" },
            "minItems": 2,
            "maxItems": 2
        })
    }

    /// `[x, y, z]`.
    pub fn direction(_: &mut SchemaGenerator) -> Schema {
        json_schema!({
            "type": "array",
            "items": { "type": "number" },
            "minItems": 3,
            "maxItems": 3
        })
    }
}
