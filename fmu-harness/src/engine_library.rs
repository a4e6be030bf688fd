//! An engine library given to `fmu-harness package` (`--binary [PLATFORM=]PATH`), read with
//! care (issue 35): it must be a regular file of at most [`MAX_LIBRARY_BYTES`]
//! ([`crate::input_file::read`]: the type checked before opening and on the open file, the cap
//! kept while reading), and it must export every FMI 2.0 co-simulation function
//! ([`FMI2_COSIMULATION_FUNCTIONS`]), read from its symbol table (ELF `.dynsym`, PE export
//! table) with the `object` crate: nothing of the library is loaded or run to package it.

use crate::error::HarnessError;
use crate::platform::{FmiVersion, Platform};
use object::{Object, ObjectSymbol};
use std::path::Path;

/// Bytes of one engine library: 256 MiB (the engine is a few MB).
pub const MAX_LIBRARY_BYTES: u64 = 256 * 1024 * 1024;

/// The functions an FMI 2.0 co-simulation binary exports (all of them, also those whose
/// capability flag is false: FMI 2.0 §2.1.1, and the unit's own rule).
pub const FMI2_COSIMULATION_FUNCTIONS: [&str; 34] = [
    "fmi2GetTypesPlatform",
    "fmi2GetVersion",
    "fmi2SetDebugLogging",
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2Terminate",
    "fmi2Reset",
    "fmi2GetReal",
    "fmi2GetInteger",
    "fmi2GetBoolean",
    "fmi2GetString",
    "fmi2SetReal",
    "fmi2SetInteger",
    "fmi2SetBoolean",
    "fmi2SetString",
    "fmi2GetFMUstate",
    "fmi2SetFMUstate",
    "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize",
    "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative",
    "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives",
    "fmi2DoStep",
    "fmi2CancelStep",
    "fmi2GetStatus",
    "fmi2GetRealStatus",
    "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus",
    "fmi2GetStringStatus",
];

/// The functions of the FMI 3.0 standard, every one of which the engine exports (issue 47),
/// also those of interfaces it does not provide (they return fmi3Error with a message).
pub const FMI3_FUNCTIONS: [&str; 75] = [
    "fmi3GetVersion",
    "fmi3SetDebugLogging",
    "fmi3InstantiateModelExchange",
    "fmi3InstantiateCoSimulation",
    "fmi3InstantiateScheduledExecution",
    "fmi3FreeInstance",
    "fmi3EnterInitializationMode",
    "fmi3ExitInitializationMode",
    "fmi3EnterEventMode",
    "fmi3Terminate",
    "fmi3Reset",
    "fmi3GetFloat32",
    "fmi3GetFloat64",
    "fmi3GetInt8",
    "fmi3GetUInt8",
    "fmi3GetInt16",
    "fmi3GetUInt16",
    "fmi3GetInt32",
    "fmi3GetUInt32",
    "fmi3GetInt64",
    "fmi3GetUInt64",
    "fmi3GetBoolean",
    "fmi3GetString",
    "fmi3GetBinary",
    "fmi3GetClock",
    "fmi3SetFloat32",
    "fmi3SetFloat64",
    "fmi3SetInt8",
    "fmi3SetUInt8",
    "fmi3SetInt16",
    "fmi3SetUInt16",
    "fmi3SetInt32",
    "fmi3SetUInt32",
    "fmi3SetInt64",
    "fmi3SetUInt64",
    "fmi3SetBoolean",
    "fmi3SetString",
    "fmi3SetBinary",
    "fmi3SetClock",
    "fmi3GetNumberOfVariableDependencies",
    "fmi3GetVariableDependencies",
    "fmi3GetFMUState",
    "fmi3SetFMUState",
    "fmi3FreeFMUState",
    "fmi3SerializedFMUStateSize",
    "fmi3SerializeFMUState",
    "fmi3DeserializeFMUState",
    "fmi3GetDirectionalDerivative",
    "fmi3GetAdjointDerivative",
    "fmi3EnterConfigurationMode",
    "fmi3ExitConfigurationMode",
    "fmi3GetIntervalDecimal",
    "fmi3GetIntervalFraction",
    "fmi3GetShiftDecimal",
    "fmi3GetShiftFraction",
    "fmi3SetIntervalDecimal",
    "fmi3SetIntervalFraction",
    "fmi3SetShiftDecimal",
    "fmi3SetShiftFraction",
    "fmi3EvaluateDiscreteStates",
    "fmi3UpdateDiscreteStates",
    "fmi3EnterContinuousTimeMode",
    "fmi3CompletedIntegratorStep",
    "fmi3SetTime",
    "fmi3SetContinuousStates",
    "fmi3GetContinuousStateDerivatives",
    "fmi3GetEventIndicators",
    "fmi3GetContinuousStates",
    "fmi3GetNominalsOfContinuousStates",
    "fmi3GetNumberOfEventIndicators",
    "fmi3GetNumberOfContinuousStates",
    "fmi3EnterStepMode",
    "fmi3GetOutputDerivatives",
    "fmi3DoStep",
    "fmi3ActivateModelPartition",
];

/// The functions a library must export to be packaged in an FMU of `version`.
pub fn required_functions(version: FmiVersion) -> &'static [&'static str] {
    match version {
        FmiVersion::V2 => &FMI2_COSIMULATION_FUNCTIONS,
        FmiVersion::V3 => &FMI3_FUNCTIONS,
    }
}

/// The bytes of the library at `path`, or why it is refused (not a regular file, too large).
pub fn read(path: &Path) -> Result<Vec<u8>, HarnessError> {
    Ok(crate::input_file::read(
        path,
        "an engine library",
        MAX_LIBRARY_BYTES,
    )?)
}

/// The FMI 2.0 co-simulation functions `bytes` (a library of `platform`) does not export, in
/// [`FMI2_COSIMULATION_FUNCTIONS`] order; Err with the parser's reason when its symbol table
/// cannot be read.
pub fn missing_functions(
    bytes: &[u8],
    platform: Platform,
) -> Result<Vec<&'static str>, object::Error> {
    missing_functions_of(bytes, platform, FmiVersion::V2)
}

/// The functions of [`required_functions`] of `version` that `bytes` does not export.
pub fn missing_functions_of(
    bytes: &[u8],
    platform: Platform,
    version: FmiVersion,
) -> Result<Vec<&'static str>, object::Error> {
    let names: Vec<Vec<u8>> = match platform {
        Platform::Linux64 => {
            let elf = object::read::elf::ElfFile64::<object::Endianness>::parse(bytes)?;
            elf.dynamic_symbols()
                .filter(|s| s.is_definition() && s.is_global())
                .filter_map(|s| s.name_bytes().ok().map(<[u8]>::to_vec))
                .collect()
        }
        Platform::Win64 => {
            let pe = object::read::pe::PeFile64::parse(bytes)?;
            pe.exports()?
                .into_iter()
                .map(|e| e.name().to_vec())
                .collect()
        }
    };
    Ok(required_functions(version)
        .iter()
        .copied()
        .filter(|f| !names.iter().any(|n| n == f.as_bytes()))
        .collect())
}

/// Refuses a library of `platform` that misses any FMI 2.0 co-simulation function.
pub fn check_exports(path: &Path, bytes: &[u8], platform: Platform) -> Result<(), HarnessError> {
    check_exports_of(path, bytes, platform, FmiVersion::V2)
}

/// Refuses a library of `platform` that misses any function an FMU of `version` needs.
pub fn check_exports_of(
    path: &Path,
    bytes: &[u8],
    platform: Platform,
    version: FmiVersion,
) -> Result<(), HarnessError> {
    let missing = missing_functions_of(bytes, platform, version).map_err(|e| {
        HarnessError::LibrarySymbols {
            path: path.to_path_buf(),
            reason: e.to_string(),
        }
    })?;
    if missing.is_empty() {
        Ok(())
    } else {
        Err(HarnessError::MissingFunctions {
            path: path.to_path_buf(),
            count: missing.len(),
            of: required_functions(version).len(),
            missing,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::platform::library_header;

    #[test]
    fn the_stand_in_libraries_export_every_function_and_a_bare_header_none() {
        for p in Platform::ALL {
            assert_eq!(
                missing_functions(&library_header(p, 0), p).unwrap(),
                [""; 0]
            );
        }
        let mut elf = library_header(Platform::Linux64, 0);
        elf.truncate(64);
        assert!(missing_functions(&elf, Platform::Linux64).is_err());
    }
}
