//! A safe FMI 2.0 or 3.0 co-simulation slave over [`crate::fmi2_binding`] or
//! [`crate::fmi3_binding`], chosen by the model description's `fmiVersion`: extracts an `.fmu`
//! into a directory of its own, reads its `modelDescription.xml`, loads the binary of its
//! version's platform folder (`binaries/linux64/`, `binaries/x86_64-linux/`, ...), and turns
//! every status other than OK/Warning into a [`SlaveError`] that carries the function, the
//! status and what the FMU logged. Reading `modelDescription.xml` is `description.rs`'s; the
//! calls, each in both versions, are `calls.rs`'s.

mod calls;
mod description;
mod extract;

pub use description::{
    Causality, DefaultExperiment, ModelDescription, VarType, Variable, MAX_ARRAY_ELEMENTS,
    MAX_MODEL_IDENTIFIER_BYTES,
};
pub use extract::{declared_bytes, MAX_ENTRIES, MAX_EXTRACTED_BYTES, MAX_NAME_BYTES};

use crate::binding::{LoadError, LogMessage, Refusal, Status};
use crate::fmi3_binding::StepOutcome;
use crate::platform::{FmiVersion, Platform};
use crate::scratch::Scratch;
use crate::{fmi2_binding, fmi3_binding};
use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use thiserror::Error;

/// The FMI 2.0 platform folder of the binary this master loads: the one of the machine it runs
/// on (the win64 build of the master, in the win64 wheel, loads `binaries/win64/<id>.dll`); an
/// FMI 3.0 unit's is its platform tuple ([`Platform::folder_in`]: `x86_64-linux`).
pub const PLATFORM: &str = Platform::HOST.folder();

#[derive(Debug, Error)]
pub enum SlaveError {
    #[error("{}: {action}: {source}", .path.display())]
    Io {
        path: PathBuf,
        action: &'static str,
        source: std::io::Error,
    },
    #[error("{}: not a readable FMU archive: {source}", .path.display())]
    Zip {
        path: PathBuf,
        source: zip::result::ZipError,
    },
    #[error("{}: modelDescription.xml: {message}", .path.display())]
    ModelDescription { path: PathBuf, message: String },
    /// The FMU was refused as unsafe or absurd (boxed: [`FmuRefused`] carries the figures).
    #[error(transparent)]
    Refused(Box<FmuRefused>),
    #[error(transparent)]
    Load(#[from] LoadError),
    #[error("{function} returned {}{}", .status.named_for(function), messages_suffix(.messages))]
    Call {
        function: &'static str,
        status: Status,
        messages: Vec<LogMessage>,
    },
    #[error("{function} returned NULL{}", messages_suffix(.messages))]
    Instantiate {
        function: &'static str,
        messages: Vec<LogMessage>,
    },
    #[error("{function}: the FMU does not export it")]
    NotExported { function: &'static str },
    /// A call of FMI 2.0 that FMI 3.0 has no function for (input derivatives).
    #[error("{function}: FMI 3.0 has no such function (its inputs are held over a step)")]
    NotInFmi3 { function: &'static str },
    /// fmi3DoStep returned early, which the master did not allow.
    #[error(
        "fmi3DoStep from t = {t} returned early at t = {at} (earlyReturn), which the master \
         did not allow (earlyReturnAllowed = false)"
    )]
    EarlyReturn { t: f64, at: f64 },
    #[error("{function}: no fmi3DoStep has returned its lastSuccessfulTime yet")]
    NoStepYet { function: &'static str },
    #[error("{function}: the FMU state belongs to another instance, or is empty")]
    ForeignState { function: &'static str },
    #[error("{function}: the instance was not instantiated (call Slave::instantiate)")]
    NotInstantiated { function: &'static str },
    #[error("no variable named `{name}` in the model description")]
    UnknownVariable { name: String },
    #[error("{what} contains a NUL byte")]
    Nul { what: &'static str },
    /// The FMU's path is not a regular file (a FIFO, a device, a directory): refused without
    /// being opened for reading, which would block on a FIFO (issue 45).
    #[error(transparent)]
    File(#[from] crate::input_file::InputFileError),
}

/// Why the master refuses an FMU it was given (issue 35): an archive entry, a limit, the model
/// description or the binary; each variant carries the names and figures its message gives.
#[derive(Debug, Error)]
pub enum FmuRefused {
    #[error(
        "{}: line {line}, column {column}: not well-formed XML: {expected}",
        .path.display()
    )]
    XmlSyntax {
        path: PathBuf,
        line: usize,
        column: usize,
        expected: String,
    },
    #[error(
        "{}: modelIdentifier \"{shown}\" ({bytes} bytes) {reason}; the master needs a plain \
         identifier ([A-Za-z_][A-Za-z0-9_]*, at most {limit} bytes) to name the binary",
        .path.display()
    )]
    ModelIdentifier {
        path: PathBuf,
        shown: String,
        bytes: usize,
        limit: usize,
        reason: &'static str,
    },
    #[error(
        "{}: valueReference {vr} of {kind} variable `{second}` is also `{first}`'s; {rule}",
        .path.display()
    )]
    DuplicateValueReference {
        path: PathBuf,
        vr: u32,
        kind: &'static str,
        first: String,
        second: String,
        /// What the FMU's version allows.
        rule: &'static str,
    },
    #[error("{}: entry `{entry}` {reason}: the master refuses the FMU", .path.display())]
    UnsafeEntry {
        path: PathBuf,
        entry: String,
        reason: &'static str,
    },
    #[error(
        "{}: {entries} entries; the master extracts at most {limit}",
        .path.display()
    )]
    TooManyEntries {
        path: PathBuf,
        entries: usize,
        limit: usize,
    },
    #[error(
        "{}: {} {bytes} bytes (up to entry `{entry}`); the master extracts at most {limit} \
         bytes",
        .path.display(),
        if *.declared { "declares" } else { "expands to at least" }
    )]
    TooLarge {
        path: PathBuf,
        entry: String,
        bytes: u64,
        declared: bool,
        limit: u64,
    },
    #[error("{}: entry `{entry}`: {source}", .path.display())]
    Entry {
        path: PathBuf,
        entry: String,
        source: std::io::Error,
    },
    #[error("{}: the model's binary {reason}; the master loads only a regular file of the FMU", .path.display())]
    Binary { path: PathBuf, reason: &'static str },
}

impl From<FmuRefused> for SlaveError {
    fn from(r: FmuRefused) -> Self {
        SlaveError::Refused(Box::new(r))
    }
}

fn messages_suffix(messages: &[LogMessage]) -> String {
    messages
        .iter()
        .map(|m| format!("\n  [{}] {}: {}", m.status, m.category, m.message))
        .collect()
}

/// `file://` URI of a directory (absolute path, unreserved characters and `/` kept). A Windows
/// path (`C:\a\b`, as the win64 build of the master sees its temporary folder) becomes
/// `file:///C:/a/b`, the form Windows masters send.
fn file_uri(dir: &Path) -> String {
    uri_of_path(dir.as_os_str().as_encoded_bytes(), cfg!(windows))
}

/// The URI of a path's bytes; `windows`: a Windows path (backslashes, a drive letter).
fn uri_of_path(path: &[u8], windows: bool) -> String {
    let mut uri = String::from("file://");
    let mut path = path.to_vec();
    if windows {
        let text = String::from_utf8_lossy(&path).into_owned();
        let text = text
            .strip_prefix(r"\\?\")
            .unwrap_or(&text)
            .replace('\\', "/");
        let mut rest = text.as_str();
        if rest.len() >= 2 && rest.as_bytes()[0].is_ascii_alphabetic() && rest.as_bytes()[1] == b':'
        {
            uri.push('/');
            uri.push_str(&rest[..2]);
            rest = &rest[2..];
        }
        path = rest.as_bytes().to_vec();
    }
    for b in path {
        match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'.' | b'_' | b'~' | b'/' => {
                uri.push(b as char)
            }
            _ => uri.push_str(&format!("%{b:02X}")),
        }
    }
    uri
}

/// The library of the FMU's version.
enum Api {
    V2(Arc<fmi2_binding::Api>),
    V3(Arc<fmi3_binding::Api>),
}

/// An instance of the FMU's version.
enum Live {
    V2(fmi2_binding::Instance),
    V3(fmi3_binding::Instance),
}

/// One FMU: its extracted directory, model description, loaded binary and (after
/// [`Slave::instantiate`]) one instance.
pub struct Slave {
    pub model_description: ModelDescription,
    instance: Option<Live>,
    api: Api,
    dir: Scratch,
    /// Bytes its extraction wrote.
    extracted: u64,
    /// FMI 3.0: the experiment that [`Slave::setup_experiment`] was given (tolerance, start,
    /// stop), passed on by fmi3EnterInitializationMode.
    experiment: (Option<f64>, f64, Option<f64>),
    /// FMI 3.0: what the last fmi3DoStep returned besides its status.
    last_step: Option<StepOutcome>,
}

impl Slave {
    /// Extracts the FMU, reads its model description and loads the binary of its version
    /// (`binaries/linux64/<id>.so`, `binaries/x86_64-linux/<id>.so`).
    pub fn load(fmu: &Path) -> Result<Slave, SlaveError> {
        Slave::load_within(fmu, MAX_EXTRACTED_BYTES)
    }

    /// [`Slave::load`], extracting at most `budget` bytes (what a co-simulation has left of
    /// its own budget; never more than [`MAX_EXTRACTED_BYTES`]).
    pub fn load_within(fmu: &Path, budget: u64) -> Result<Slave, SlaveError> {
        let stem = fmu
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let stem: String = stem
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        let stem: String = stem.chars().take(64).collect();
        let dir = Scratch::directory(&stem).map_err(|source| SlaveError::Io {
            path: std::env::temp_dir(),
            action: "creating the extraction directory",
            source,
        })?;
        // On an error `dir` is dropped here, which removes it.
        let (model_description, api, extracted) = Self::load_into(fmu, dir.path(), budget)?;
        Ok(Slave {
            model_description,
            instance: None,
            api,
            dir,
            extracted,
            experiment: (None, 0.0, None),
            last_step: None,
        })
    }

    /// The bytes its extraction wrote.
    pub fn extracted_bytes(&self) -> u64 {
        self.extracted
    }

    fn load_into(
        fmu: &Path,
        dir: &Path,
        budget: u64,
    ) -> Result<(ModelDescription, Api, u64), SlaveError> {
        let extracted = extract::extract(fmu, dir, budget)?;
        let md_path = dir.join("modelDescription.xml");
        let xml = std::fs::read_to_string(&md_path).map_err(|source| SlaveError::Io {
            path: fmu.join("modelDescription.xml"),
            action: "reading",
            source,
        })?;
        let md = ModelDescription::parse(&xml, &fmu.join("modelDescription.xml"))?;
        let version = md.fmi_version;
        let so = dir
            .join("binaries")
            .join(Platform::HOST.folder_in(version))
            .join(format!(
                "{}.{}",
                md.model_identifier,
                Platform::HOST.extension()
            ));
        extract::binary_inside(dir, &so)?;
        extract::binary_loadable(&so, version)?;
        let api = match version {
            FmiVersion::V2 => Api::V2(fmi2_binding::Api::load(&so)?),
            FmiVersion::V3 => Api::V3(fmi3_binding::Api::load(&so)?),
        };
        Ok((md, api, extracted))
    }

    /// The directory the FMU was extracted to (removed on drop).
    pub fn directory(&self) -> &Path {
        self.dir.path()
    }

    /// Instantiates as co-simulation, resources at the extracted `resources/` (FMI 2.0: as a
    /// `file://` URI; FMI 3.0: as a path with a trailing separator); replaces (frees) a previous
    /// instance.
    pub fn instantiate(&mut self, name: &str, logging_on: bool) -> Result<(), SlaveError> {
        self.instance = None;
        self.last_step = None;
        let name = CString::new(name).map_err(|_| SlaveError::Nul {
            what: "the instance name",
        })?;
        let guid =
            CString::new(self.model_description.guid.as_str()).map_err(|_| SlaveError::Nul {
                what: "the GUID or instantiationToken",
            })?;
        let resources = self.dir.path().join("resources");
        let nul = |_| SlaveError::Nul {
            what: "the resource location",
        };
        self.instance = Some(match &self.api {
            Api::V2(api) => {
                let uri = CString::new(file_uri(&resources)).map_err(nul)?;
                let i =
                    fmi2_binding::Instance::instantiate(api, &name, &guid, &uri, false, logging_on)
                        .map_err(|messages| SlaveError::Instantiate {
                            function: "fmi2Instantiate",
                            messages,
                        })?;
                Live::V2(i)
            }
            Api::V3(api) => {
                let mut path = resources.into_os_string();
                path.push(std::path::MAIN_SEPARATOR_STR);
                let path = CString::new(path.as_encoded_bytes().to_vec()).map_err(nul)?;
                let i = fmi3_binding::Instance::instantiate(
                    api, &name, &guid, &path, false, logging_on,
                )
                .map_err(|messages| SlaveError::Instantiate {
                    function: "fmi3InstantiateCoSimulation",
                    messages,
                })?;
                Live::V3(i)
            }
        });
        Ok(())
    }

    /// Ok for OK and Warning; anything else an error with the logged messages.
    fn check(&mut self, function: &'static str, status: Status) -> Result<Status, SlaveError> {
        if status.is_success() {
            Ok(status)
        } else {
            let messages = self.take_messages();
            Err(SlaveError::Call {
                function,
                status,
                messages,
            })
        }
    }

    fn refused(function: &'static str, r: Refusal) -> SlaveError {
        match r {
            Refusal::NotExported(_) => SlaveError::NotExported { function },
            Refusal::ForeignState => SlaveError::ForeignState { function },
        }
    }

    /// The messages the FMU logged since the last take (errors take them too).
    pub fn take_messages(&mut self) -> Vec<LogMessage> {
        match &self.instance {
            Some(Live::V2(i)) => i.take_messages(),
            Some(Live::V3(i)) => i.take_messages(),
            None => Vec::new(),
        }
    }
}

impl Drop for Slave {
    fn drop(&mut self) {
        // The instance is freed first, while the library is loaded; the files go last.
        self.instance = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_uri_escapes_reserved_bytes() {
        assert_eq!(file_uri(Path::new("/tmp/a b%/r")), "file:///tmp/a%20b%25/r");
        assert_eq!(
            uri_of_path(br"C:\users\a b\Temp\fmu-harness-1\resources", true),
            "file:///C:/users/a%20b/Temp/fmu-harness-1/resources"
        );
        assert_eq!(uri_of_path(br"\\?\D:\r", true), "file:///D:/r");
    }
}
