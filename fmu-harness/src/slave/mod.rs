//! A safe FMI 2.0 co-simulation slave over [`crate::fmi2_binding`]: extracts an `.fmu` into a
//! directory of its own, reads its `modelDescription.xml`, loads the binary, and turns every
//! status other than fmi2OK/fmi2Warning into a [`SlaveError`] that carries the function, the
//! status and what the FMU logged. Reading `modelDescription.xml` is `description.rs`'s.

mod description;
mod extract;

pub use description::{
    Causality, DefaultExperiment, ModelDescription, VarType, Variable, MAX_MODEL_IDENTIFIER_BYTES,
};
pub use extract::{declared_bytes, MAX_ENTRIES, MAX_EXTRACTED_BYTES, MAX_NAME_BYTES};

use crate::fmi2_binding::{self, Api, FmuState, Instance, LogMessage, Refusal, Status};
use crate::scratch::Scratch;
use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use thiserror::Error;

/// The FMI platform folder of the binary this master loads: the one of the machine it runs on
/// (the win64 build of the master, in the win64 wheel, loads `binaries/win64/<id>.dll`).
pub const PLATFORM: &str = if cfg!(windows) { "win64" } else { "linux64" };

/// The file extension of that binary.
const LIBRARY_EXTENSION: &str = if cfg!(windows) { "dll" } else { "so" };

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
    Load(#[from] fmi2_binding::LoadError),
    #[error("{function} returned {status}{}", messages_suffix(.messages))]
    Call {
        function: &'static str,
        status: Status,
        messages: Vec<LogMessage>,
    },
    #[error("fmi2Instantiate returned NULL{}", messages_suffix(.messages))]
    Instantiate { messages: Vec<LogMessage> },
    #[error("{function}: the FMU does not export it")]
    NotExported { function: &'static str },
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
        "{}: valueReference {vr} of {kind} variable `{second}` is also `{first}`'s; aliases \
         may share one only if at most one of them is an input or a parameter, and an input \
         has none",
        .path.display()
    )]
    DuplicateValueReference {
        path: PathBuf,
        vr: u32,
        kind: &'static str,
        first: String,
        second: String,
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

/// One FMU: its extracted directory, model description, loaded binary and (after
/// [`Slave::instantiate`]) one instance.
pub struct Slave {
    pub model_description: ModelDescription,
    instance: Option<Instance>,
    api: Arc<Api>,
    dir: Scratch,
    /// Bytes its extraction wrote.
    extracted: u64,
}

impl Slave {
    /// Extracts the FMU, reads its model description and loads `binaries/linux64/<id>.so`.
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
    ) -> Result<(ModelDescription, Arc<Api>, u64), SlaveError> {
        let extracted = extract::extract(fmu, dir, budget)?;
        let md_path = dir.join("modelDescription.xml");
        let xml = std::fs::read_to_string(&md_path).map_err(|source| SlaveError::Io {
            path: fmu.join("modelDescription.xml"),
            action: "reading",
            source,
        })?;
        let md = ModelDescription::parse(&xml, &fmu.join("modelDescription.xml"))?;
        let so = dir
            .join("binaries")
            .join(PLATFORM)
            .join(format!("{}.{LIBRARY_EXTENSION}", md.model_identifier));
        extract::binary_inside(dir, &so)?;
        extract::binary_loadable(&so, PLATFORM)?;
        let api = Api::load(&so)?;
        Ok((md, api, extracted))
    }

    /// The directory the FMU was extracted to (removed on drop).
    pub fn directory(&self) -> &Path {
        self.dir.path()
    }

    /// `fmi2Instantiate` as co-simulation, resources at the extracted `resources/`; replaces
    /// (frees) a previous instance.
    pub fn instantiate(&mut self, name: &str, logging_on: bool) -> Result<(), SlaveError> {
        self.instance = None;
        let name = CString::new(name).map_err(|_| SlaveError::Nul {
            what: "the instance name",
        })?;
        let guid = CString::new(self.model_description.guid.as_str())
            .map_err(|_| SlaveError::Nul { what: "the GUID" })?;
        let uri = CString::new(file_uri(&self.dir.path().join("resources"))).map_err(|_| {
            SlaveError::Nul {
                what: "the resource URI",
            }
        })?;
        let instance = Instance::instantiate(&self.api, &name, &guid, &uri, false, logging_on)
            .map_err(|messages| SlaveError::Instantiate { messages })?;
        self.instance = Some(instance);
        Ok(())
    }

    fn live(&mut self, function: &'static str) -> Result<&mut Instance, SlaveError> {
        self.instance
            .as_mut()
            .ok_or(SlaveError::NotInstantiated { function })
    }

    /// Ok for fmi2OK and fmi2Warning; anything else an error with the logged messages.
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
        self.instance
            .as_ref()
            .map(Instance::take_messages)
            .unwrap_or_default()
    }

    pub fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> Result<Status, SlaveError> {
        const F: &str = "fmi2SetupExperiment";
        let s = self
            .live(F)?
            .setup_experiment(tolerance, start_time, stop_time);
        self.check(F, s)
    }

    pub fn enter_initialization_mode(&mut self) -> Result<Status, SlaveError> {
        const F: &str = "fmi2EnterInitializationMode";
        let s = self.live(F)?.enter_initialization_mode();
        self.check(F, s)
    }

    pub fn exit_initialization_mode(&mut self) -> Result<Status, SlaveError> {
        const F: &str = "fmi2ExitInitializationMode";
        let s = self.live(F)?.exit_initialization_mode();
        self.check(F, s)
    }

    pub fn do_step(&mut self, t: f64, h: f64, no_set_prior: bool) -> Result<Status, SlaveError> {
        const F: &str = "fmi2DoStep";
        let s = self.live(F)?.do_step(t, h, no_set_prior);
        self.check(F, s)
    }

    /// fmi2GetBooleanStatus(fmi2Terminated): whether the FMU asks to end the simulation (after
    /// a Discard). False when the FMU does not export the function or does not answer it
    /// (fmi2Error, as an FMU that never ends a simulation may); what it logged then is dropped.
    pub fn terminated(&mut self) -> Result<bool, SlaveError> {
        const F: &str = "fmi2GetBooleanStatus";
        match self
            .live(F)?
            .get_boolean_status(fmi2_binding::fmi2Terminated)
        {
            Ok((s, value)) if s.is_success() => Ok(value),
            Ok(_) | Err(Refusal::NotExported(_)) => {
                let _ = self.take_messages();
                Ok(false)
            }
            Err(r) => Err(Self::refused(F, r)),
        }
    }

    /// fmi2GetRealStatus(fmi2LastSuccessfulTime): the time of the FMU's last good state.
    pub fn last_successful_time(&mut self) -> Result<f64, SlaveError> {
        const F: &str = "fmi2GetRealStatus";
        match self
            .live(F)?
            .get_real_status(fmi2_binding::fmi2LastSuccessfulTime)
        {
            Ok((s, value)) => self.check(F, s).map(|_| value),
            Err(r) => Err(Self::refused(F, r)),
        }
    }

    pub fn terminate(&mut self) -> Result<Status, SlaveError> {
        const F: &str = "fmi2Terminate";
        let s = self.live(F)?.terminate();
        self.check(F, s)
    }

    pub fn reset(&mut self) -> Result<Status, SlaveError> {
        const F: &str = "fmi2Reset";
        let s = self.live(F)?.reset();
        self.check(F, s)
    }

    pub fn get_real(&mut self, vr: &[u32]) -> Result<Vec<f64>, SlaveError> {
        const F: &str = "fmi2GetReal";
        let mut values = vec![0.0; vr.len()];
        let s = self.live(F)?.get_real(vr, &mut values);
        self.check(F, s).map(|_| values)
    }

    pub fn set_real(&mut self, vr: &[u32], values: &[f64]) -> Result<Status, SlaveError> {
        const F: &str = "fmi2SetReal";
        let s = self.live(F)?.set_real(vr, values);
        self.check(F, s)
    }

    pub fn get_integer(&mut self, vr: &[u32]) -> Result<Vec<i32>, SlaveError> {
        const F: &str = "fmi2GetInteger";
        let mut values = vec![0; vr.len()];
        let s = self.live(F)?.get_integer(vr, &mut values);
        self.check(F, s).map(|_| values)
    }

    pub fn set_integer(&mut self, vr: &[u32], values: &[i32]) -> Result<Status, SlaveError> {
        const F: &str = "fmi2SetInteger";
        let s = self.live(F)?.set_integer(vr, values);
        self.check(F, s)
    }

    pub fn get_boolean(&mut self, vr: &[u32]) -> Result<Vec<bool>, SlaveError> {
        const F: &str = "fmi2GetBoolean";
        let mut values = vec![0; vr.len()];
        let s = self.live(F)?.get_boolean(vr, &mut values);
        self.check(F, s)
            .map(|_| values.iter().map(|&b| b != 0).collect())
    }

    pub fn set_boolean(&mut self, vr: &[u32], values: &[bool]) -> Result<Status, SlaveError> {
        const F: &str = "fmi2SetBoolean";
        let ints: Vec<i32> = values.iter().map(|&b| b as i32).collect();
        let s = self.live(F)?.set_boolean(vr, &ints);
        self.check(F, s)
    }

    pub fn set_real_input_derivatives(
        &mut self,
        vr: &[u32],
        order: &[i32],
        values: &[f64],
    ) -> Result<Status, SlaveError> {
        const F: &str = "fmi2SetRealInputDerivatives";
        let s = self
            .live(F)?
            .set_real_input_derivatives(vr, order, values)
            .map_err(|r| Self::refused(F, r))?;
        self.check(F, s)
    }

    /// `fmi2GetDirectionalDerivative`: Σ_j ∂unknown_i/∂known_j dv_j for each unknown.
    pub fn get_directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
    ) -> Result<Vec<f64>, SlaveError> {
        const F: &str = "fmi2GetDirectionalDerivative";
        let mut out = vec![0.0; unknowns.len()];
        let s = self
            .live(F)?
            .get_directional_derivative(unknowns, knowns, dv_known, &mut out)
            .map_err(|r| Self::refused(F, r))?;
        self.check(F, s).map(|_| out)
    }

    /// `fmi2GetFMUstate` into an empty state or one this instance made before.
    pub fn get_fmu_state(&mut self, state: &mut FmuState) -> Result<Status, SlaveError> {
        const F: &str = "fmi2GetFMUstate";
        let s = self
            .live(F)?
            .get_fmu_state(state)
            .map_err(|r| Self::refused(F, r))?;
        self.check(F, s)
    }

    pub fn set_fmu_state(&mut self, state: &FmuState) -> Result<Status, SlaveError> {
        const F: &str = "fmi2SetFMUstate";
        let s = self
            .live(F)?
            .set_fmu_state(state)
            .map_err(|r| Self::refused(F, r))?;
        self.check(F, s)
    }

    pub fn free_fmu_state(&mut self, state: &mut FmuState) -> Result<Status, SlaveError> {
        const F: &str = "fmi2FreeFMUstate";
        let s = self
            .live(F)?
            .free_fmu_state(state)
            .map_err(|r| Self::refused(F, r))?;
        self.check(F, s)
    }
}

impl Drop for Slave {
    fn drop(&mut self) {
        // fmi2FreeInstance first, while the library is loaded; the files go last.
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
