//! The memory a scene's unit will hold, asked for before the unit builds anything (issue 35).
//!
//! Rust ends the process when an allocation fails (`handle_alloc_error` aborts), and an abort
//! inside an FMU takes the master's whole process with it. So before a system is assembled the
//! engine reserves, and gives back at once, an address range as large as the scene's estimate
//! ([`crate::scene::Scene::size`], an upper bound of the matrices the unit holds) with headroom:
//! where that reservation fails, the unit refuses with [`EngineError::OutOfMemory`] instead.
//!
//! What it catches: a limit on the address space (`ulimit -v`, RLIMIT_AS, common on batch
//! systems), strict commit accounting (Linux `vm.overcommit_memory = 2`, Windows' commit
//! limit) and an estimate above what the machine has at all (Linux's default heuristic refuses
//! a single mapping larger than RAM and swap). What it cannot catch: a memory cgroup, where
//! reserving succeeds and touching the pages later wakes the kernel's OOM killer; the scene's
//! limit ([`crate::scene::rules::MAX_UNIT_MEMORY`], 1 GiB) bounds that case.

use crate::error::EngineError;
use crate::scene::Scene;

/// Headroom over the scene's estimate: a quarter of it more, and 32 MiB for what the estimate
/// leaves out (vectors, histories, the allocator's own fragmentation).
fn with_headroom(bytes: u64) -> u64 {
    bytes.saturating_add(bytes / 4).saturating_add(32 << 20)
}

/// Reserves (without touching) and releases the memory the scene's unit will need; refuses
/// with the figures when the reservation fails.
pub(crate) fn ensure_available(scene: &Scene, what: &'static str) -> Result<(), EngineError> {
    let need = with_headroom(scene.size().memory);
    let mut probe: Vec<u8> = Vec::new();
    let fits = usize::try_from(need)
        .ok()
        .is_some_and(|bytes| probe.try_reserve_exact(bytes).is_ok());
    drop(probe);
    if fits {
        Ok(())
    } else {
        Err(EngineError::OutOfMemory {
            what,
            mebibytes: need >> 20,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::with_headroom;

    #[test]
    fn the_headroom_is_a_quarter_and_32_mib_and_saturates() {
        assert_eq!(with_headroom(0), 32 << 20);
        assert_eq!(with_headroom(400 << 20), 532 << 20);
        assert_eq!(with_headroom(u64::MAX), u64::MAX);
    }
}
