//! The FMI 3.0 co-simulation ABI, called as an importer would, beside the FMI 2.0 ABI on the
//! same resources (a clamped cantilever, case C1, N = 4): the same run bit for bit, the shape
//! array equal to 2.0's scalars, an FMU state round trip, refused calls that change nothing, a
//! discarded step (a retry, then terminateSimulation), the functions it does not provide, and
//! instantiation's refusals.

// Calling the C ABI takes unsafe code: these tests live in `fmi3/`, where the crate allows it.

use super::exports::*;
use super::types::*;
use crate::fmi2::exports as v2;
use crate::fmi2::types as t2;
use crate::unit::variables::{Declared, Layout3, VariableTable};
use crate::Scene;
use std::ffi::{CStr, CString};
use std::os::raw::{c_int, c_void};
use std::path::PathBuf;
use std::ptr::{null, null_mut};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

const SCENE: &str = r#"
name = "cantilever"
[solver]
adaptive = false
max_step = 1e-3
rho_inf = 1.0
[[beam]]
name = "beam"
length = 2.0
elements = 4
material = { rho = 2700.0, E = 72e9 }
section = { shape = "rectangle", a = 0.01, b = 0.01 }
initial = { tip_displacement = 0.01 }
[[joint]]
name = "clamp"
type = "weld"
frames = ["world", "beam.a"]
"#;

const TOKEN: &str = "{5c1a0e3e-c1c1-4b7e-9a2e-000000000003}";
const H: f64 = 1e-3;

use fmi3Status::*;

/// A resources directory in the temporary directory, removed on drop.
struct Resources(PathBuf);

impl Resources {
    fn new() -> Resources {
        static COUNT: AtomicUsize = AtomicUsize::new(0);
        let n = COUNT.fetch_add(1, Ordering::SeqCst);
        let dir = std::env::temp_dir().join(format!(
            "fmu-beam-fmi3-abi-{}-{n}/resources",
            std::process::id()
        ));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("scene.toml"), SCENE).unwrap();
        std::fs::write(dir.join("guid.txt"), TOKEN).unwrap();
        Resources(dir)
    }

    /// As FMI 3.0 passes it: a path with a trailing separator.
    fn path(&self) -> CString {
        CString::new(format!("{}/", self.0.display())).unwrap()
    }
}

impl Drop for Resources {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(self.0.parent().unwrap());
    }
}

#[derive(Default)]
struct Log(Mutex<Vec<(c_int, String)>>);

impl Log {
    fn last(&self) -> String {
        let all = self.0.lock().unwrap();
        all.last().map(|m| m.1.clone()).unwrap_or_default()
    }
}

unsafe extern "C" fn log_message(
    env: fmi3InstanceEnvironment,
    status: c_int,
    _category: fmi3String,
    message: fmi3String,
) {
    // SAFETY: `env` is the `Log` the test passed; `message` a C string.
    let (log, text) = unsafe {
        (
            &*env.cast::<Log>(),
            CStr::from_ptr(message).to_string_lossy().into_owned(),
        )
    };
    log.0.lock().unwrap().push((status, text));
}

fn table() -> VariableTable {
    VariableTable::build(&Scene::from_toml_str(SCENE, "inline").unwrap())
}

/// An instance in Instantiated, logging into `log`.
fn instantiate(res: &Resources, log: &Log, token: &str, event_mode: bool) -> fmi3Instance {
    let (name, token, path) = (
        CString::new("i").unwrap(),
        CString::new(token).unwrap(),
        res.path(),
    );
    // SAFETY: valid strings and callback; `log` outlives the instance in every test.
    unsafe {
        fmi3InstantiateCoSimulation(
            name.as_ptr(),
            token.as_ptr(),
            path.as_ptr(),
            0,
            0,
            u8::from(event_mode),
            0,
            null(),
            0,
            (log as *const Log).cast_mut().cast::<c_void>(),
            Some(log_message),
            null(),
        )
    }
}

/// An instance in Step Mode at t = 0.
fn initialized(res: &Resources, log: &Log) -> fmi3Instance {
    let c = instantiate(res, log, TOKEN, false);
    assert!(!c.is_null(), "{}", log.last());
    // SAFETY: a live instance.
    unsafe {
        assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0), fmi3OK);
        assert_eq!(fmi3ExitInitializationMode(c), fmi3OK);
    }
    c
}

struct Step {
    status: fmi3Status,
    terminate: bool,
    last: f64,
}

fn step(c: fmi3Instance, t: f64) -> Step {
    let (mut event, mut terminate, mut early, mut last) = (9u8, 9u8, 9u8, f64::NAN);
    // SAFETY: a live instance, valid outputs.
    let status = unsafe {
        fmi3DoStep(
            c,
            t,
            H,
            0,
            &mut event,
            &mut terminate,
            &mut early,
            &mut last,
        )
    };
    if status != fmi3Error {
        assert_eq!((event, early), (0, 0), "no events, no early return");
    }
    Step {
        status,
        terminate: terminate == 1,
        last,
    }
}

/// Every FMI 3.0 Float64 value of the unit but `time`, in layout order (arrays expanded).
fn floats(c: fmi3Instance, layout: &Layout3, table: &VariableTable) -> Vec<f64> {
    let vrs: Vec<u32> = layout
        .variables
        .iter()
        .filter(|v| v.declared != Declared::Time)
        .filter(|v| {
            table.variables[v.declared.elements().start as usize].ty == crate::VarType::Real
        })
        .map(|v| v.vr)
        .collect();
    let n: usize = vrs
        .iter()
        .map(|&vr| layout.get(vr).unwrap().declared.values())
        .sum();
    let mut out = vec![0.0; n];
    // SAFETY: a live instance, arrays of the sizes passed.
    let s = unsafe { fmi3GetFloat64(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr(), n) };
    assert_eq!(s, fmi3OK);
    out
}

/// The 2.0 unit on the same resources, in step mode at t = 0.
fn fmi2_initialized(res: &Resources) -> t2::fmi2Component {
    let callbacks = t2::fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: null_mut(),
    };
    let (name, guid) = (CString::new("i").unwrap(), CString::new(TOKEN).unwrap());
    let uri = CString::new(format!("file://{}", res.0.display())).unwrap();
    // SAFETY: valid arguments; the callbacks are copied by the instance.
    unsafe {
        let c = v2::fmi2Instantiate(
            name.as_ptr(),
            t2::fmi2CoSimulation,
            guid.as_ptr(),
            uri.as_ptr(),
            &callbacks,
            0,
            0,
        );
        assert!(!c.is_null());
        assert_eq!(
            v2::fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0),
            t2::fmi2Status::fmi2OK
        );
        assert_eq!(v2::fmi2EnterInitializationMode(c), t2::fmi2Status::fmi2OK);
        assert_eq!(v2::fmi2ExitInitializationMode(c), t2::fmi2Status::fmi2OK);
        c
    }
}

#[test]
fn a_run_equals_the_fmi2_units_bit_for_bit_and_the_shape_array_its_scalars() {
    let (res, log, table) = (Resources::new(), Log::default(), table());
    let layout = Layout3::of(&table);
    let c3 = initialized(&res, &log);
    let c2 = fmi2_initialized(&res);
    // the 2.0 unit's Real variables, in the order the 3.0 layout expands them
    let reals2: Vec<u32> = layout
        .variables
        .iter()
        .filter(|v| v.declared != Declared::Time)
        .flat_map(|v| v.declared.elements())
        .filter(|&vr| table.variables[vr as usize].ty == crate::VarType::Real)
        .collect();
    assert!(layout
        .variables
        .iter()
        .any(|v| matches!(v.declared, Declared::Array { .. })));
    for k in 0..50 {
        let t = k as f64 * H;
        let s = step(c3, t);
        assert_eq!((s.status, s.terminate), (fmi3OK, false), "{}", log.last());
        assert!((s.last - (t + H)).abs() < 1e-12, "{} {}", s.last, t + H);
        // SAFETY: a live instance.
        assert_eq!(
            unsafe { v2::fmi2DoStep(c2, t, H, 1) },
            t2::fmi2Status::fmi2OK
        );
        let mut v2s = vec![0.0; reals2.len()];
        // SAFETY: arrays of the sizes passed.
        let st = unsafe { v2::fmi2GetReal(c2, reals2.as_ptr(), reals2.len(), v2s.as_mut_ptr()) };
        assert_eq!(st, t2::fmi2Status::fmi2OK);
        let v3s = floats(c3, &layout, &table);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&v3s), bits(&v2s), "at t = {}", t + H);
    }
    // SAFETY: live instances, freed once.
    unsafe {
        v2::fmi2FreeInstance(c2);
        fmi3FreeInstance(c3);
    }
}

#[test]
fn an_fmu_state_round_trip_goes_on_bit_for_bit_also_serialized() {
    let (res, log, table) = (Resources::new(), Log::default(), table());
    let layout = Layout3::of(&table);
    let c = initialized(&res, &log);
    for k in 0..10 {
        step(c, k as f64 * H);
    }
    let mut state: fmi3FMUState = null_mut();
    // SAFETY: a live instance and state slot.
    unsafe { assert_eq!(fmi3GetFMUState(c, &mut state), fmi3OK) };
    let run = |c| {
        (10..20)
            .map(|k| {
                step(c, k as f64 * H);
                floats(c, &layout, &table)
            })
            .collect::<Vec<_>>()
    };
    let first = run(c);
    // SAFETY: as above.
    unsafe { assert_eq!(fmi3SetFMUState(c, state), fmi3OK) };
    assert_eq!(run(c), first);
    let mut size = 0usize;
    // SAFETY: as above; a buffer of the size asked.
    unsafe {
        assert_eq!(fmi3SerializedFMUStateSize(c, state, &mut size), fmi3OK);
        let mut bytes = vec![0u8; size];
        assert_eq!(
            fmi3SerializeFMUState(c, state, bytes.as_mut_ptr(), size),
            fmi3OK
        );
        let mut back: fmi3FMUState = null_mut();
        assert_eq!(
            fmi3DeserializeFMUState(c, bytes.as_ptr(), size, &mut back),
            fmi3OK
        );
        assert_eq!(fmi3SetFMUState(c, back), fmi3OK);
        assert_eq!(run(c), first);
        assert_eq!(fmi3FreeFMUState(c, &mut back), fmi3OK);
        assert_eq!(fmi3FreeFMUState(c, &mut state), fmi3OK);
        assert!(state.is_null());
        fmi3FreeInstance(c);
    }
}

#[test]
fn refused_calls_return_error_and_change_nothing() {
    let (res, log, table) = (Resources::new(), Log::default(), table());
    let layout = Layout3::of(&table);
    let reference = initialized(&res, &log);
    let c = instantiate(&res, &log, TOKEN, false);
    let shape = layout
        .variables
        .iter()
        .find_map(|v| match v.declared {
            Declared::Array { first, len } => Some((first, len as usize)),
            _ => None,
        })
        .unwrap();
    let fixed = table.by_name("beam.E").unwrap().vr;
    let mut out = vec![0.0; shape.1];
    let mut b = 0u8;
    // SAFETY: live instances; the NULL and wrong arguments are what is tested.
    unsafe {
        // illegal sequence: a step before initialization
        assert_eq!(step(c, 0.0).status, fmi3Error);
        assert!(
            log.last().contains("illegal call sequence"),
            "{}",
            log.last()
        );
        assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0), fmi3OK);
        assert_eq!(fmi3ExitInitializationMode(c), fmi3OK);
        // a fixed parameter after initialization, NaN, unknown references, wrong counts, NULL
        let e = 1.0;
        assert_eq!(fmi3SetFloat64(c, &fixed, 1, &e, 1), fmi3Error);
        let nan = f64::NAN;
        assert_eq!(fmi3SetFloat64(c, &fixed, 1, &nan, 1), fmi3Error);
        let element = shape.0 + 1;
        assert_eq!(
            fmi3GetFloat64(c, &element, 1, out.as_mut_ptr(), 1),
            fmi3Error
        );
        assert!(
            log.last().contains("unknown value reference"),
            "{}",
            log.last()
        );
        let beyond = 1_000_000u32;
        assert_eq!(
            fmi3GetFloat64(c, &beyond, 1, out.as_mut_ptr(), 1),
            fmi3Error
        );
        assert_eq!(
            fmi3GetFloat64(c, &shape.0, 1, out.as_mut_ptr(), shape.1 - 1),
            fmi3Error
        );
        assert!(log.last().contains("nValues"), "{}", log.last());
        assert_eq!(
            fmi3GetFloat64(c, &shape.0, 1, null_mut(), shape.1),
            fmi3Error
        );
        assert_eq!(fmi3GetFloat64(c, null(), 1, out.as_mut_ptr(), 1), fmi3Error);
        assert_eq!(fmi3GetBoolean(c, &shape.0, 1, &mut b, 1), fmi3Error);
        assert!(log.last().contains("not Boolean"), "{}", log.last());
        let (mut x, mut y) = (0u8, 0u8);
        let mut last = 0.0;
        assert_eq!(
            fmi3DoStep(c, 0.0, H, 0, null_mut(), &mut x, &mut y, &mut last),
            fmi3Error
        );
        assert_eq!(fmi3GetFMUState(c, null_mut()), fmi3Error);
        assert_eq!(step(c, 0.0).status, fmi3OK);
        assert_eq!(step(reference, 0.0).status, fmi3OK);
        // a step that does not start at the unit's time
        assert_eq!(step(c, 5.0 * H).status, fmi3Error);
        assert_eq!(
            floats(c, &layout, &table),
            floats(reference, &layout, &table)
        );
        for k in 1..5 {
            step(c, k as f64 * H);
            step(reference, k as f64 * H);
        }
        assert_eq!(
            floats(c, &layout, &table),
            floats(reference, &layout, &table)
        );
        // the shape array reads as one call
        assert_eq!(
            fmi3GetFloat64(c, &shape.0, 1, out.as_mut_ptr(), shape.1),
            fmi3OK
        );
        // time, the independent variable
        let time = table.variables.len() as u32;
        assert_eq!(fmi3GetFloat64(c, &time, 1, out.as_mut_ptr(), 1), fmi3OK);
        assert_eq!(out[0], 5.0 * H);
        assert_eq!(fmi3SetFloat64(c, &time, 1, &e, 1), fmi3Error);
        // NULL instance
        assert_eq!(fmi3Terminate(null_mut()), fmi3Error);
        fmi3FreeInstance(c);
        fmi3FreeInstance(reference);
    }
}

#[test]
fn what_the_unit_does_not_provide_is_refused_with_a_message() {
    let (res, log) = (Resources::new(), Log::default());
    let c = initialized(&res, &log);
    // SAFETY: a live instance; the refused functions touch no argument.
    unsafe {
        assert_eq!(fmi3EnterEventMode(c), fmi3Error);
        assert!(
            log.last().contains("hasEventMode = false"),
            "{}",
            log.last()
        );
        assert_eq!(fmi3SetTime(c, 0.0), fmi3Error);
        assert!(log.last().contains("co-simulation only"), "{}", log.last());
        assert_eq!(
            fmi3GetAdjointDerivative(c, null(), 0, null(), 0, null(), 0, null_mut(), 0),
            fmi3Error
        );
        let vr = 0u32;
        let mut x = 0i64;
        assert_eq!(fmi3GetInt64(c, &vr, 1, &mut x, 1), fmi3Error);
        assert_eq!(fmi3GetInt64(c, null(), 0, null_mut(), 0), fmi3OK);
        // still usable
        assert_eq!(step(c, 0.0).status, fmi3OK);
        assert_eq!(fmi3Terminate(c), fmi3OK);
        fmi3FreeInstance(c);
        assert!(CStr::from_ptr(fmi3GetVersion()).to_str() == Ok("3.0"));
    }
}

#[test]
fn instantiation_refuses_a_wrong_token_and_event_mode() {
    let (res, log) = (Resources::new(), Log::default());
    assert!(instantiate(&res, &log, "{wrong}", false).is_null());
    assert!(log.last().contains("instantiationToken"), "{}", log.last());
    assert!(instantiate(&res, &log, TOKEN, true).is_null());
    assert!(log.last().contains("eventModeUsed"), "{}", log.last());
}

/// A step over the work budget returns fmi3Discard with the state back at its start
/// (lastSuccessfulTime, outputs unchanged) and terminateSimulation = false: a retry may pass.
/// The same step again fails the same way: terminateSimulation = true, StepDiscarded, and only
/// fmi3Terminate, a state or a reset are left; a state set brings back Step Mode.
#[test]
fn a_discarded_step_may_be_retried_and_a_repeated_one_ends_the_run() {
    let (res, log, table) = (Resources::new(), Log::default(), table());
    let layout = Layout3::of(&table);
    let c = initialized(&res, &log);
    for k in 0..5 {
        step(c, k as f64 * H);
    }
    let good = floats(c, &layout, &table);
    let mut state: fmi3FMUState = null_mut();
    let budget = table.by_name("solver.step_budget").unwrap().vr;
    let long_step = |c| {
        let (mut e, mut s, mut r, mut last) = (9u8, 9u8, 9u8, f64::NAN);
        // SAFETY: a live instance, valid outputs.
        let status =
            unsafe { fmi3DoStep(c, 5.0 * H, 2.0 * H, 0, &mut e, &mut s, &mut r, &mut last) };
        (status, e, s, r, last)
    };
    // SAFETY: a live instance and state slot.
    unsafe {
        assert_eq!(fmi3GetFMUState(c, &mut state), fmi3OK);
        assert_eq!(fmi3SetInt32(c, &budget, 1, &1, 1), fmi3OK, "{}", log.last());
    }
    let (status, event, terminate, early, last) = long_step(c);
    assert_eq!(
        (status, event, terminate, early),
        (fmi3Discard, 0, 0, 0),
        "{}",
        log.last()
    );
    assert!(
        (last - 5.0 * H).abs() < 1e-12 && log.last().contains("retry"),
        "{}",
        log.last()
    );
    assert_eq!(
        floats(c, &layout, &table),
        good,
        "the last good state stays readable"
    );
    let (status, _, terminate, _, last) = long_step(c);
    assert_eq!((status, terminate), (fmi3Discard, 1), "{}", log.last());
    assert!(
        log.last().contains("terminateSimulation = true"),
        "{}",
        log.last()
    );
    assert!((last - 5.0 * H).abs() < 1e-12);
    assert_eq!(step(c, 5.0 * H).status, fmi3Error, "no step once ended");
    assert!(
        log.last().contains("ended the simulation"),
        "{}",
        log.last()
    );
    assert_eq!(floats(c, &layout, &table), good);
    // SAFETY: as above.
    unsafe {
        assert_eq!(fmi3SetFMUState(c, state), fmi3OK);
        assert_eq!(step(c, 5.0 * H).status, fmi3OK, "{}", log.last());
        assert_eq!(fmi3FreeFMUState(c, &mut state), fmi3OK);
        assert_eq!(fmi3Terminate(c), fmi3OK);
        fmi3FreeInstance(c);
    }
}
