//! Issue 45, item 7: a restored state is checked like a new one. A forger who rewrites a
//! serialized state and recomputes its checksum gets it refused unless its parameter values
//! keep the scene's rules and its integration state is one a run of that model can reach:
//! times from the start on, coordinates, rates and multipliers within their bounds, the
//! proposed step within the stepper's, the joints closed (`Stepper::implausible`). A refused
//! state changes nothing; every shipped scene's own states are accepted.

use crate::common;
use common::{scene, vr};
use fmu_beam::{Engine, EngineError};

/// FNV-1a (64 bit), as the state's checksum.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Where the numbers of a serialized state (`Engine::serialize`, format version 8) lie.
struct Layout {
    /// First byte of each parameter or input value, by value reference.
    values: usize,
    /// The model's absolute time of the communication point.
    time: usize,
    /// The state at the communication point: t, h, then q's values.
    state: GaAt,
    /// The integrator's state.
    front: GaAt,
}

#[derive(Clone, Copy)]
struct GaAt {
    t: usize,
    h: usize,
    /// First byte of q's values.
    q: usize,
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

/// The layout of `bytes`, read as `Engine::deserialize` reads them.
fn layout(bytes: &[u8]) -> Layout {
    let mut at = 8 + 4 + 8 + 1 + 8; // magic, version, fingerprint, initialized, start time
    let vec = |at: &mut usize| {
        let n = u64_at(bytes, *at) as usize;
        *at += 8;
        let first = *at;
        *at += 8 * n;
        first
    };
    let values = vec(&mut at);
    vec(&mut at); // input derivatives
    assert_eq!(bytes[at], 1, "a state with a model");
    at += 1;
    let time = at;
    at += 8;
    let ga = |at: &mut usize| {
        let (t, h) = (*at, *at + 8);
        *at += 24; // t, h, work
        let q = vec(at);
        for _ in 0..4 {
            vec(at);
        }
        GaAt { t, h, q }
    };
    let state = ga(&mut at);
    let front = ga(&mut at);
    Layout {
        values,
        time,
        state,
        front,
    }
}

/// The engine's bytes with the f64 at each `(offset, value)` replaced and the checksum
/// recomputed, as a forger would.
fn forged(bytes: &[u8], edits: &[(usize, f64)]) -> Vec<u8> {
    let mut b = bytes[..bytes.len() - 8].to_vec();
    for &(at, x) in edits {
        b[at..at + 8].copy_from_slice(&x.to_le_bytes());
    }
    let sum = fnv1a(&b);
    b.extend_from_slice(&sum.to_le_bytes());
    b
}

/// An initialized instance of `file` after `steps` communication steps of `h`.
fn run(file: &str, steps: usize, h: f64) -> Engine {
    let mut e = Engine::new(scene(file));
    e.exit_initialization().unwrap();
    for k in 0..steps {
        e.do_step(k as f64 * h, h).unwrap();
    }
    e
}

fn refused(e: &Engine, bytes: &[u8], why: &str) {
    match e.deserialize(bytes) {
        Err(EngineError::BadState { message }) => {
            assert!(message.contains(why), "'{why}' not in: {message}")
        }
        other => panic!("not refused with '{why}': {other:?}"),
    }
}

#[test]
fn forged_states_are_refused_and_change_nothing() {
    let h = 0.01;
    let mut e = run("flexible_pendulum.toml", 10, h);
    let bytes = e.serialize(&e.snapshot());
    let at = layout(&bytes);
    let value_of = |name: &str| at.values + 8 * vr(&e, name) as usize;
    let before = e.snapshot();
    // the bytes as written are a state, and the forger's tool is right
    e.deserialize(&bytes).expect("its own state");
    e.deserialize(&forged(&bytes, &[])).expect("the same bytes");

    // before: each of these was accepted, and the next steps returned fmi2OK
    refused(&e, &forged(&bytes, &[(at.front.q, 1e300)]), "coordinate 0");
    refused(
        &e,
        &forged(&bytes, &[(at.state.q + 8, 1e300)]),
        "coordinate 1",
    );
    refused(&e, &forged(&bytes, &[(at.front.h, 0.0)]), "proposed step 0");
    refused(&e, &forged(&bytes, &[(at.front.h, 1e300)]), "proposed step");
    refused(
        &e,
        &forged(&bytes, &[(value_of("beam.rho"), 1e-300)]),
        "at least 0.1 kg/m³",
    );
    // times: before the start, the system's time not the time less the start, the integrator
    // further ahead than a step
    refused(&e, &forged(&bytes, &[(at.time, -1.0)]), "its time -1 s");
    refused(&e, &forged(&bytes, &[(at.state.t, 0.5)]), "since the start");
    refused(
        &e,
        &forged(&bytes, &[(at.front.t, 1e6)]),
        "from the communication point",
    );

    // nothing changed, and the instance goes on as before
    assert_eq!(e.snapshot(), before);
    e.do_step(10.0 * h, h).unwrap();
    let mut twin = run("flexible_pendulum.toml", 11, h);
    let angle = |e: &mut Engine| e.get_real(vr(e, "hinge.angle")).unwrap();
    assert_eq!(angle(&mut e).to_bits(), angle(&mut twin).to_bits());
}

/// A beam made twice as long in a closed loop (the slider-crank's crank) breaks the scene's
/// rule that the joints' frames meet at the start: refused. A state whose coordinates open the
/// joints (the crank's frame moved by 5 cm) is no state of the system: refused. A pendulum's
/// beam twice as long is another valid pendulum, whose hinge the state's coordinates still
/// close: its parameters keep the scene's rules and its state is plausible, so it is taken, as
/// a new instance with that length would be.
#[test]
fn a_longer_beam_is_refused_where_it_opens_the_joints() {
    let e = run("slider_crank.toml", 10, 1e-3);
    let bytes = e.serialize(&e.snapshot());
    let at = layout(&bytes);
    let crank = at.values + 8 * vr(&e, "crank.length") as usize;
    let length = f64::from_le_bytes(bytes[crank..crank + 8].try_into().unwrap());
    refused(
        &e,
        &forged(&bytes, &[(crank, 2.0 * length)]),
        "must meet at t = 0",
    );
    let x = f64::from_le_bytes(bytes[at.front.q..at.front.q + 8].try_into().unwrap());
    refused(
        &e,
        &forged(&bytes, &[(at.front.q, x + 0.05)]),
        "the joints are open",
    );

    let mut e = run("flexible_pendulum.toml", 10, 0.01);
    let bytes = e.serialize(&e.snapshot());
    let at = layout(&bytes);
    let beam = at.values + 8 * vr(&e, "beam.length") as usize;
    let longer = forged(&bytes, &[(beam, 0.8)]);
    let s = e.deserialize(&longer).expect("a valid longer pendulum");
    e.restore(&s).unwrap();
    e.do_step(0.1, 0.01).unwrap();
    assert_eq!(e.get_real(vr(&e, "beam.length")).unwrap(), 0.8);
}

/// The bounds hold no state a run reaches: every shipped scene's states, taken over its first
/// communication steps, restore into a new instance, which goes on bit for bit.
#[test]
fn every_shipped_scenes_states_are_accepted() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 29);
    for path in files {
        let s = fmu_beam::Scene::load(&path).unwrap();
        let h = s.experiment.step_size;
        let mut e = Engine::new(s.clone());
        e.exit_initialization().unwrap();
        for k in 0..6 {
            let bytes = e.serialize(&e.snapshot());
            let mut fresh = Engine::new(s.clone());
            let snapshot = fresh
                .deserialize(&bytes)
                .unwrap_or_else(|err| panic!("{} at step {k}: {err}", s.name));
            fresh.restore(&snapshot).unwrap();
            let t = k as f64 * h;
            e.do_step(t, h).unwrap();
            fresh.do_step(t, h).unwrap();
            let after = |e: &Engine| e.serialize(&e.snapshot());
            assert!(after(&fresh) == after(&e), "{} at step {k}", s.name);
        }
    }
}
