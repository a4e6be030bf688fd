//! The platforms an FMU carries a binary for (FMI 2.0 §2.1:
//! `binaries/<platform>/<modelIdentifier>.<extension>`), and the platform of an engine library
//! read from its header, so that a library is never packaged under the wrong folder.

mod stand_in;

use std::fmt;

/// The FMI version of the FMUs the packager writes (`--fmi-version`): 2.0 by default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FmiVersion {
    /// FMI 2.0 co-simulation: `binaries/linux64`, `binaries/win64`.
    #[default]
    V2,
    /// FMI 3.0 co-simulation: `binaries/x86_64-linux`, `binaries/x86_64-windows` (issue 47).
    V3,
}

impl std::str::FromStr for FmiVersion {
    type Err = String;

    /// `2` or `2.0`, `3` or `3.0`.
    fn from_str(text: &str) -> Result<FmiVersion, String> {
        match text {
            "2" | "2.0" => Ok(FmiVersion::V2),
            "3" | "3.0" => Ok(FmiVersion::V3),
            other => Err(format!(
                "unknown FMI version '{other}' (the packager writes 2 or 3)"
            )),
        }
    }
}

/// A platform that the packager fills, FMI 2.0's folder names by default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Platform {
    /// x86_64 Linux: an ELF shared object, `.so`.
    Linux64,
    /// x86_64 Windows: a PE32+ DLL, `.dll`.
    Win64,
}

impl Platform {
    /// Every platform, in the order of the FMU's entries and of the GUID's input.
    pub const ALL: [Platform; 2] = [Platform::Linux64, Platform::Win64];

    /// The platform of the machine this program runs on: the binaries the master loads.
    pub const HOST: Platform = if cfg!(windows) {
        Platform::Win64
    } else {
        Platform::Linux64
    };

    /// The folder under `binaries/` (FMI 2.0's name).
    pub const fn folder(self) -> &'static str {
        match self {
            Platform::Linux64 => "linux64",
            Platform::Win64 => "win64",
        }
    }

    /// The folder under `binaries/` in an FMU of `version` (FMI 3.0's platform tuples).
    pub fn folder_in(self, version: FmiVersion) -> &'static str {
        match (version, self) {
            (FmiVersion::V2, p) => p.folder(),
            (FmiVersion::V3, Platform::Linux64) => "x86_64-linux",
            (FmiVersion::V3, Platform::Win64) => "x86_64-windows",
        }
    }

    /// The shared library's file extension.
    pub fn extension(self) -> &'static str {
        match self {
            Platform::Linux64 => "so",
            Platform::Win64 => "dll",
        }
    }

    /// The platform of a folder name of either version (`linux64`, `x86_64-linux`, ...).
    pub fn from_folder(name: &str) -> Option<Platform> {
        Platform::ALL
            .into_iter()
            .find(|p| p.folder() == name || p.folder_in(FmiVersion::V3) == name)
    }

    /// What a library of this platform is, for messages.
    pub fn library_kind(self) -> &'static str {
        match self {
            Platform::Linux64 => "an ELF x86-64 shared object",
            Platform::Win64 => "a PE32+ x86-64 DLL",
        }
    }

    /// The platform of a shared library, from its header: ELF 64-bit little-endian, type
    /// ET_DYN, machine x86-64 (62); or PE with machine AMD64 (0x8664), the DLL flag (0x2000)
    /// and the PE32+ optional header (0x20b). None for anything else.
    pub fn of_library(bytes: &[u8]) -> Option<Platform> {
        let u16_at = |i: usize| {
            bytes
                .get(i..i + 2)
                .map(|b| u16::from_le_bytes([b[0], b[1]]))
        };
        let u32_at = |i: usize| {
            bytes
                .get(i..i + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        };
        if bytes.starts_with(b"\x7fELF") {
            let class_and_order = bytes.get(4..6) == Some(&[2, 1][..]);
            let shared = u16_at(16) == Some(3) && u16_at(18) == Some(62);
            return (class_and_order && shared).then_some(Platform::Linux64);
        }
        if bytes.starts_with(b"MZ") {
            let pe = u32_at(0x3c)? as usize;
            let signature = bytes.get(pe..pe + 4) == Some(&b"PE\0\0"[..]);
            let amd64 = u16_at(pe + 4) == Some(0x8664);
            let dll = u16_at(pe + 22).is_some_and(|c| c & 0x2000 != 0);
            let pe32_plus = u16_at(pe + 24) == Some(0x20b);
            return (signature && amd64 && dll && pe32_plus).then_some(Platform::Win64);
        }
        None
    }
}

impl fmt::Display for Platform {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.folder())
    }
}

/// A stand-in library of `platform`: a header [`Platform::of_library`] recognizes and a symbol
/// table that exports every FMI 2.0 co-simulation function (the packager checks both), padded
/// to `len` bytes (it has at least 0x200): for tests that package stand-in engines.
pub fn library_header(platform: Platform, len: usize) -> Vec<u8> {
    let names = &crate::engine_library::FMI2_COSIMULATION_FUNCTIONS;
    let mut b = match platform {
        Platform::Linux64 => stand_in::elf(names),
        Platform::Win64 => stand_in::pe(names),
    };
    if b.len() < len {
        b.resize(len, 0);
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_are_recognized_and_nothing_else() {
        for p in Platform::ALL {
            assert_eq!(Platform::of_library(&library_header(p, 0)), Some(p));
            assert_eq!(Platform::from_folder(p.folder()), Some(p));
        }
        assert_eq!(Platform::of_library(b""), None);
        assert_eq!(Platform::of_library(b"engine bytes"), None);
        // a 32-bit ELF, an ELF executable, an AArch64 ELF
        let mut elf = library_header(Platform::Linux64, 0);
        elf[4] = 1;
        assert_eq!(Platform::of_library(&elf), None);
        let mut exe = library_header(Platform::Linux64, 0);
        exe[16] = 2;
        assert_eq!(Platform::of_library(&exe), None);
        let mut arm = library_header(Platform::Linux64, 0);
        arm[18] = 183;
        assert_eq!(Platform::of_library(&arm), None);
        // a Windows executable (no DLL flag), a 32-bit DLL, a truncated PE
        let mut exe = library_header(Platform::Win64, 0);
        exe[0x80 + 22] = 0x22;
        exe[0x80 + 23] = 0;
        assert_eq!(Platform::of_library(&exe), None);
        let mut dll32 = library_header(Platform::Win64, 0);
        dll32[0x80 + 4..0x80 + 6].copy_from_slice(&0x14cu16.to_le_bytes());
        assert_eq!(Platform::of_library(&dll32), None);
        assert_eq!(
            Platform::of_library(&library_header(Platform::Win64, 0)[..0x90]),
            None
        );
        assert_eq!(Platform::from_folder("darwin64"), None);
    }

    #[test]
    fn missing_exports_are_named_for_either_platform() {
        use crate::engine_library::missing_functions;
        let few = ["fmi2Instantiate", "fmi2DoStep"];
        for (p, bytes) in [
            (Platform::Linux64, stand_in::elf(&few)),
            (Platform::Win64, stand_in::pe(&few)),
        ] {
            assert_eq!(Platform::of_library(&bytes), Some(p));
            let missing = missing_functions(&bytes, p).unwrap();
            assert_eq!(missing.len(), 32);
            assert!(missing.contains(&"fmi2GetReal") && !missing.contains(&"fmi2DoStep"));
        }
    }
}
