//! The C types of `fmi3PlatformTypes.h` and `fmi3FunctionTypes.h` (FMI 3.0), as this layer
//! uses them.
//!
//! `fmi3Boolean` is C's `bool`: read here as a byte (any value but 0 is true), since a Rust
//! `bool` must never hold anything but 0 or 1 and a master may pass any byte; written as 0 or 1.
//! Enumerations a master passes in are plain `c_int`s.
//!
//! Each name is the FMI 3.0 standard's and means what the standard documents for it (its §2.2
//! and the two headers): `missing_docs` is allowed here rather than repeating the standard.

#![allow(non_camel_case_types, non_snake_case, non_upper_case_globals)]
#![allow(missing_docs)]

use std::os::raw::{c_char, c_int, c_void};

pub type fmi3Instance = *mut c_void;
pub type fmi3InstanceEnvironment = *mut c_void;
pub type fmi3FMUState = *mut c_void;
pub type fmi3ValueReference = u32;
pub type fmi3Float32 = f32;
pub type fmi3Float64 = f64;
pub type fmi3Int8 = i8;
pub type fmi3UInt8 = u8;
pub type fmi3Int16 = i16;
pub type fmi3UInt16 = u16;
pub type fmi3Int32 = i32;
pub type fmi3UInt32 = u32;
pub type fmi3Int64 = i64;
pub type fmi3UInt64 = u64;
pub type fmi3Boolean = u8;
pub type fmi3Char = c_char;
pub type fmi3String = *const fmi3Char;
pub type fmi3Byte = u8;
pub type fmi3Binary = *const fmi3Byte;
pub type fmi3Clock = u8;

pub const fmi3True: fmi3Boolean = 1;
pub const fmi3False: fmi3Boolean = 0;

/// Status returned by every function; only ever passed *out* of the FMU.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum fmi3Status {
    fmi3OK = 0,
    fmi3Warning = 1,
    fmi3Discard = 2,
    fmi3Error = 3,
    fmi3Fatal = 4,
}

pub type fmi3DependencyKind = c_int;
pub type fmi3IntervalQualifier = c_int;

/// `void logMessage(instanceEnvironment, status, category, message)`: the message is plain
/// text (not a printf format, unlike FMI 2.0's logger).
pub type fmi3LogMessageCallback =
    unsafe extern "C" fn(fmi3InstanceEnvironment, c_int, fmi3String, fmi3String);

/// The callbacks this unit never calls (intermediate update, clocks, preemption): kept as
/// opaque pointers.
pub type fmi3OpaqueCallback = *const c_void;
