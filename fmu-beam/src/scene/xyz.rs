//! Serde forms of the scene's vectors, shared by planar and 3D scenes: a point or direction is
//! written with 2 numbers (planar: z = 0) or 3; a torque or an inertia with one number (about
//! z, the planar form) or 3. Stored as `[f64; 3]`; written back with 3 numbers.

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
        d.deserialize_seq(Xyz { scalar: false })
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
        d.deserialize_any(Xyz { scalar: true })
    }
}

/// An optional `[x, y, z]` (a 3D direction).
pub mod direction {
    use super::*;

    /// Writes the 3 numbers (the fields that use it skip `None`).
    pub fn serialize<S: Serializer>(v: &Option<[f64; 3]>, s: S) -> Result<S::Ok, S::Error> {
        serde::Serialize::serialize(v, s)
    }

    /// Reads 3 numbers (2 are taken as z = 0, as for a point).
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 3]>, D::Error> {
        d.deserialize_seq(Xyz { scalar: false }).map(Some)
    }
}

struct Xyz {
    scalar: bool,
}

impl<'de> Visitor<'de> for Xyz {
    type Value = [f64; 3];

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        if self.scalar {
            f.write_str("a number (about z) or an array of 3 numbers [x, y, z]")
        } else {
            f.write_str("an array of 2 numbers [x, y] or 3 numbers [x, y, z]")
        }
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<[f64; 3], E> {
        if self.scalar {
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
        let mut n = 0;
        while let Some(x) = seq.next_element::<f64>()? {
            if n == 3 {
                return Err(de::Error::invalid_length(4, &self));
            }
            v[n] = x;
            n += 1;
        }
        let allowed = if self.scalar {
            n == 3
        } else {
            n == 2 || n == 3
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
