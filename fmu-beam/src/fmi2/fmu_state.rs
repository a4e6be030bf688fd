//! FMU states for rollback and restart from file: the engine's [`Snapshot`] plus the phase of
//! the call sequence it was taken in.
//!
//! The call-sequence state itself stays outside the FMU state (as in modelica/Reference-FMUs);
//! only the phase travels with it, so that fmi2SetFMUstate leaves the instance in a state that
//! agrees with its engine: a state taken after initialization (in StepComplete, StepFailed or
//! Terminated) puts the instance into StepComplete, ready to step again from that point; one
//! taken before puts it back into Instantiated or InitializationMode.
//!
//! Serialized layout: `b"FMI2"`, the phase (1 byte), the length of the engine's bytes (u64
//! little-endian), the engine's bytes. Bytes after those are ignored, so a master's buffer may
//! be larger than fmi2SerializedFMUstateSize said.

use super::guard::Fault;
use super::state_machine::ModelState;
use super::types::fmi2FMUstate;
use crate::unit::engine::{Engine, Snapshot};

/// Marks memory that holds a live [`FmuState`] (cleared when it is freed).
const TAG: u64 = u64::from_le_bytes(*b"fmustate");
const HEADER: &[u8; 4] = b"FMI2";

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Instantiated = 0,
    InitializationMode = 1,
    Initialized = 2,
}

impl Phase {
    fn of(state: ModelState) -> Phase {
        match state {
            ModelState::Instantiated => Phase::Instantiated,
            ModelState::InitializationMode => Phase::InitializationMode,
            _ => Phase::Initialized,
        }
    }

    fn from_byte(b: u8) -> Option<Phase> {
        [
            Phase::Instantiated,
            Phase::InitializationMode,
            Phase::Initialized,
        ]
        .into_iter()
        .find(|p| *p as u8 == b)
    }
}

/// What an `fmi2FMUstate` points to.
#[derive(Debug, Clone)]
pub struct FmuState {
    tag: u64,
    phase: Phase,
    snapshot: Snapshot,
}

impl FmuState {
    pub fn new(state: ModelState, snapshot: Snapshot) -> FmuState {
        FmuState {
            tag: TAG,
            phase: Phase::of(state),
            snapshot,
        }
    }

    pub fn snapshot(&self) -> &Snapshot {
        &self.snapshot
    }

    /// The call-sequence state of an instance that this FMU state was set into.
    pub fn model_state(&self) -> ModelState {
        match self.phase {
            Phase::Instantiated => ModelState::Instantiated,
            Phase::InitializationMode => ModelState::InitializationMode,
            Phase::Initialized => ModelState::StepComplete,
        }
    }

    pub fn serialize(&self, engine: &Engine) -> Vec<u8> {
        let body = engine.serialize(&self.snapshot);
        let mut bytes = Vec::with_capacity(HEADER.len() + 9 + body.len());
        bytes.extend_from_slice(HEADER);
        bytes.push(self.phase as u8);
        bytes.extend_from_slice(&(body.len() as u64).to_le_bytes());
        bytes.extend_from_slice(&body);
        bytes
    }

    /// Refuses bytes that are not a state of this FMU's scene, with the reason.
    pub fn deserialize(engine: &Engine, bytes: &[u8]) -> Result<FmuState, Fault> {
        let refuse = |why: &str| Err(Fault::refused(format!("FMU state: {why}")));
        let Some((header, rest)) = bytes.split_first_chunk::<13>() else {
            return refuse(&format!(
                "{} bytes are too few for a serialized state",
                bytes.len()
            ));
        };
        if &header[..4] != HEADER {
            return refuse("not a serialized state of this FMU (wrong header)");
        }
        let Some(phase) = Phase::from_byte(header[4]) else {
            return refuse(&format!("corrupt phase byte {}", header[4]));
        };
        let len = u64::from_le_bytes(header[5..13].try_into().unwrap_or_default());
        let Some(body) = usize::try_from(len).ok().and_then(|n| rest.get(..n)) else {
            return refuse(&format!(
                "truncated: {} bytes of state announced, {} present",
                len,
                rest.len()
            ));
        };
        Ok(FmuState {
            tag: TAG,
            phase,
            snapshot: engine.deserialize(body)?,
        })
    }
}

/// Puts `state` where `*slot` says: into the FMU state it points to, or into a new one.
///
/// # Safety
/// `slot` is NULL or valid for reading and writing; a non-NULL `*slot` was made by this FMU
/// and not freed (the standard's rule for fmi2GetFMUstate).
pub unsafe fn store(slot: *mut fmi2FMUstate, state: FmuState) -> Result<(), Fault> {
    if slot.is_null() {
        return Err(Fault::refused("argument FMUstate is NULL"));
    }
    // SAFETY: see the contract above.
    let current = unsafe { *slot };
    if current.is_null() {
        // SAFETY: see the contract above.
        unsafe { *slot = Box::into_raw(Box::new(state)).cast() };
    } else {
        // SAFETY: see the contract above; the tag check catches some misuse.
        *unsafe { borrow_mut(current)? } = state;
    }
    Ok(())
}

/// The FMU state behind `ptr`.
///
/// # Safety
/// `ptr` is NULL or was made by [`store`] and not freed.
pub unsafe fn borrow<'a>(ptr: fmi2FMUstate) -> Result<&'a FmuState, Fault> {
    // SAFETY: see the contract above.
    unsafe { borrow_mut(ptr).map(|s| &*s) }
}

unsafe fn borrow_mut<'a>(ptr: fmi2FMUstate) -> Result<&'a mut FmuState, Fault> {
    if ptr.is_null() {
        return Err(Fault::refused("argument FMUstate is NULL"));
    }
    // SAFETY: see the contract of `borrow`.
    let state = unsafe { &mut *ptr.cast::<FmuState>() };
    if state.tag != TAG {
        return Err(Fault::refused(
            "argument FMUstate is not a live FMU state of this FMU (freed already?)",
        ));
    }
    Ok(state)
}

/// fmi2FreeFMUstate: frees `*slot` and sets it to NULL; NULL (either) is no error.
///
/// # Safety
/// As for [`store`].
pub unsafe fn free(slot: *mut fmi2FMUstate) -> Result<(), Fault> {
    if slot.is_null() {
        return Ok(());
    }
    // SAFETY: see the contract above.
    let ptr = unsafe { *slot };
    if ptr.is_null() {
        return Ok(());
    }
    // SAFETY: see the contract above.
    unsafe { borrow_mut(ptr)? }.tag = 0;
    // SAFETY: `ptr` came from `Box::into_raw` in `store`.
    drop(unsafe { Box::from_raw(ptr.cast::<FmuState>()) });
    // SAFETY: see the contract above.
    unsafe { *slot = std::ptr::null_mut() };
    Ok(())
}

/// fmi2SerializeFMUstate: copies the bytes into the master's buffer (the rest of it zeroed).
pub fn copy_out(bytes: &[u8], buffer: &mut [u8]) -> Result<(), Fault> {
    if buffer.len() < bytes.len() {
        return Err(Fault::refused(format!(
            "serializedState has {} bytes, the state needs {} (see fmi2SerializedFMUstateSize)",
            buffer.len(),
            bytes.len()
        )));
    }
    let (head, tail) = buffer.split_at_mut(bytes.len());
    head.copy_from_slice(bytes);
    tail.fill(0);
    Ok(())
}
