//! The calls of a [`Slave`], each in the FMU's version: one method a call of FMI 2.0, its FMI
//! 3.0 counterpart where the two differ.
//!
//! Where FMI 3.0 differs, the slave keeps FMI 2.0's calls and bridges them: the experiment of
//! `setup_experiment` is passed on by fmi3EnterInitializationMode; fmi3DoStep's
//! `terminateSimulation` and `lastSuccessfulTime` are kept for [`Slave::terminated`] and
//! [`Slave::last_successful_time`] (FMI 2.0 asks fmi2GetBooleanStatus and fmi2GetRealStatus);
//! a get or set of an FMI 3.0 array moves all its elements (the count of values from the model
//! description); FMI 3.0 has no input derivatives ([`SlaveError::NotInFmi3`]).

use super::{Live, Slave, SlaveError};
use crate::binding::{FmuState, Refusal, Status};
use crate::fmi2_binding;
use crate::platform::FmiVersion;

/// The name of a call in the slave's version: `fmi2<v2>` or `fmi3<v3>`.
macro_rules! named {
    ($slave:expr, $v2:literal, $v3:literal) => {
        match $slave.model_description.fmi_version {
            FmiVersion::V2 => concat!("fmi2", $v2),
            FmiVersion::V3 => concat!("fmi3", $v3),
        }
    };
}

/// The live instance (a borrow of that field alone), or [`SlaveError::NotInstantiated`].
macro_rules! live {
    ($slave:expr, $function:expr) => {
        $slave
            .instance
            .as_mut()
            .ok_or(SlaveError::NotInstantiated {
                function: $function,
            })?
    };
}

impl Slave {
    /// The number of values of the variables `vr` (an FMI 3.0 array's elements).
    fn values_of(&self, vr: &[u32]) -> usize {
        self.model_description.values_of(vr)
    }

    /// `fmi2SetupExperiment`; FMI 3.0 passes the experiment with fmi3EnterInitializationMode,
    /// so it is kept until then.
    pub fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> Result<Status, SlaveError> {
        const F: &str = "fmi2SetupExperiment";
        match live!(self, F) {
            Live::V2(i) => {
                let s = i.setup_experiment(tolerance, start_time, stop_time);
                self.check(F, s)
            }
            Live::V3(_) => {
                self.experiment = (tolerance, start_time, stop_time);
                Ok(Status::Ok)
            }
        }
    }

    pub fn enter_initialization_mode(&mut self) -> Result<Status, SlaveError> {
        let (tolerance, start, stop) = self.experiment;
        let f = named!(self, "EnterInitializationMode", "EnterInitializationMode");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.enter_initialization_mode(),
            Live::V3(i) => i.enter_initialization_mode(tolerance, start, stop),
        };
        self.check(f, s)
    }

    pub fn exit_initialization_mode(&mut self) -> Result<Status, SlaveError> {
        let f = named!(self, "ExitInitializationMode", "ExitInitializationMode");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.exit_initialization_mode(),
            Live::V3(i) => i.exit_initialization_mode(),
        };
        self.check(f, s)
    }

    /// One communication step; FMI 3.0's outputs kept for [`Slave::terminated`] and
    /// [`Slave::last_successful_time`]. An FMI 3.0 step that returns early is an error: the
    /// master instantiates without early return.
    pub fn do_step(&mut self, t: f64, h: f64, no_set_prior: bool) -> Result<Status, SlaveError> {
        let f = named!(self, "DoStep", "DoStep");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.do_step(t, h, no_set_prior),
            Live::V3(i) => {
                let (s, outcome) = i.do_step(t, h, no_set_prior);
                self.last_step = Some(outcome);
                if s.is_success() && outcome.early_return {
                    return Err(SlaveError::EarlyReturn {
                        t,
                        at: outcome.last_successful_time,
                    });
                }
                s
            }
        };
        self.check(f, s)
    }

    /// Whether the FMU asks to end the simulation (after a Discard): fmi2GetBooleanStatus
    /// (fmi2Terminated), or the last fmi3DoStep's `terminateSimulation`. False when an FMI 2.0
    /// FMU does not export the function or does not answer it (fmi2Error, as an FMU that never
    /// ends a simulation may); what it logged then is dropped.
    pub fn terminated(&mut self) -> Result<bool, SlaveError> {
        const F: &str = "fmi2GetBooleanStatus";
        let asked = match live!(self, F) {
            Live::V2(i) => i.get_boolean_status(fmi2_binding::fmi2Terminated),
            Live::V3(_) => {
                return Ok(self.last_step.is_some_and(|o| o.terminate_simulation));
            }
        };
        match asked {
            Ok((s, value)) if s.is_success() => Ok(value),
            Ok(_) | Err(Refusal::NotExported(_)) => {
                let _ = self.take_messages();
                Ok(false)
            }
            Err(r) => Err(Self::refused(F, r)),
        }
    }

    /// The time of the FMU's last good state: fmi2GetRealStatus(fmi2LastSuccessfulTime), or
    /// the last fmi3DoStep's `lastSuccessfulTime`.
    pub fn last_successful_time(&mut self) -> Result<f64, SlaveError> {
        const F: &str = "fmi2GetRealStatus";
        let asked = match live!(self, F) {
            Live::V2(i) => i.get_real_status(fmi2_binding::fmi2LastSuccessfulTime),
            Live::V3(_) => {
                return self
                    .last_step
                    .map(|o| o.last_successful_time)
                    .filter(|t| t.is_finite())
                    .ok_or(SlaveError::NoStepYet {
                        function: "fmi3DoStep",
                    });
            }
        };
        match asked {
            Ok((s, value)) => self.check(F, s).map(|_| value),
            Err(r) => Err(Self::refused(F, r)),
        }
    }

    pub fn terminate(&mut self) -> Result<Status, SlaveError> {
        let f = named!(self, "Terminate", "Terminate");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.terminate(),
            Live::V3(i) => i.terminate(),
        };
        self.check(f, s)
    }

    pub fn reset(&mut self) -> Result<Status, SlaveError> {
        let f = named!(self, "Reset", "Reset");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.reset(),
            Live::V3(i) => i.reset(),
        };
        self.last_step = None;
        self.check(f, s)
    }

    /// The values of the Real (Float64) variables `vr`: one a scalar, an array's elements.
    pub fn get_real(&mut self, vr: &[u32]) -> Result<Vec<f64>, SlaveError> {
        let mut values = vec![0.0; self.values_of(vr)];
        let f = named!(self, "GetReal", "GetFloat64");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.get_real(vr, &mut values),
            Live::V3(i) => i.get_float64(vr, &mut values),
        };
        self.check(f, s).map(|_| values)
    }

    /// Sets the Real (Float64) variables `vr`: `values` holds one value a scalar, an array's
    /// elements.
    pub fn set_real(&mut self, vr: &[u32], values: &[f64]) -> Result<Status, SlaveError> {
        let f = named!(self, "SetReal", "SetFloat64");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.set_real(vr, values),
            Live::V3(i) => i.set_float64(vr, values),
        };
        self.check(f, s)
    }

    pub fn get_integer(&mut self, vr: &[u32]) -> Result<Vec<i32>, SlaveError> {
        let mut values = vec![0; self.values_of(vr)];
        let f = named!(self, "GetInteger", "GetInt32");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.get_integer(vr, &mut values),
            Live::V3(i) => i.get_int32(vr, &mut values),
        };
        self.check(f, s).map(|_| values)
    }

    pub fn set_integer(&mut self, vr: &[u32], values: &[i32]) -> Result<Status, SlaveError> {
        let f = named!(self, "SetInteger", "SetInt32");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.set_integer(vr, values),
            Live::V3(i) => i.set_int32(vr, values),
        };
        self.check(f, s)
    }

    pub fn get_boolean(&mut self, vr: &[u32]) -> Result<Vec<bool>, SlaveError> {
        let n = self.values_of(vr);
        let f = named!(self, "GetBoolean", "GetBoolean");
        let live = live!(self, f);
        let (s, values) = match live {
            Live::V2(i) => {
                let mut v = vec![0i32; n];
                (
                    i.get_boolean(vr, &mut v),
                    v.iter().map(|&b| b != 0).collect(),
                )
            }
            Live::V3(i) => {
                let mut v = vec![0u8; n];
                (
                    i.get_boolean(vr, &mut v),
                    v.iter().map(|&b| b != 0).collect(),
                )
            }
        };
        self.check(f, s).map(|_| values)
    }

    pub fn set_boolean(&mut self, vr: &[u32], values: &[bool]) -> Result<Status, SlaveError> {
        let f = named!(self, "SetBoolean", "SetBoolean");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => {
                let ints: Vec<i32> = values.iter().map(|&b| b as i32).collect();
                i.set_boolean(vr, &ints)
            }
            Live::V3(i) => {
                let bytes: Vec<u8> = values.iter().map(|&b| b as u8).collect();
                i.set_boolean(vr, &bytes)
            }
        };
        self.check(f, s)
    }

    /// `fmi2SetRealInputDerivatives`; refused for FMI 3.0, which has none.
    pub fn set_real_input_derivatives(
        &mut self,
        vr: &[u32],
        order: &[i32],
        values: &[f64],
    ) -> Result<Status, SlaveError> {
        const F: &str = "fmi2SetRealInputDerivatives";
        let s = match live!(self, F) {
            Live::V2(i) => i
                .set_real_input_derivatives(vr, order, values)
                .map_err(|r| Self::refused(F, r))?,
            Live::V3(_) => return Err(SlaveError::NotInFmi3 { function: F }),
        };
        self.check(F, s)
    }

    /// Σ_j ∂unknown_i/∂known_j dv_j for each unknown (each element of an FMI 3.0 array);
    /// `dv_known` holds a value per known (per element).
    pub fn get_directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
    ) -> Result<Vec<f64>, SlaveError> {
        let mut out = vec![0.0; self.values_of(unknowns)];
        let f = named!(self, "GetDirectionalDerivative", "GetDirectionalDerivative");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.get_directional_derivative(unknowns, knowns, dv_known, &mut out),
            Live::V3(i) => i.get_directional_derivative(unknowns, knowns, dv_known, &mut out),
        }
        .map_err(|r| Self::refused(f, r))?;
        self.check(f, s).map(|_| out)
    }

    /// GetFMUstate into an empty state or one this instance made before.
    pub fn get_fmu_state(&mut self, state: &mut FmuState) -> Result<Status, SlaveError> {
        let f = named!(self, "GetFMUstate", "GetFMUState");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.get_fmu_state(state),
            Live::V3(i) => i.get_fmu_state(state),
        }
        .map_err(|r| Self::refused(f, r))?;
        self.check(f, s)
    }

    pub fn set_fmu_state(&mut self, state: &FmuState) -> Result<Status, SlaveError> {
        let f = named!(self, "SetFMUstate", "SetFMUState");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.set_fmu_state(state),
            Live::V3(i) => i.set_fmu_state(state),
        }
        .map_err(|r| Self::refused(f, r))?;
        self.check(f, s)
    }

    pub fn free_fmu_state(&mut self, state: &mut FmuState) -> Result<Status, SlaveError> {
        let f = named!(self, "FreeFMUstate", "FreeFMUState");
        let live = live!(self, f);
        let s = match live {
            Live::V2(i) => i.free_fmu_state(state),
            Live::V3(i) => i.free_fmu_state(state),
        }
        .map_err(|r| Self::refused(f, r))?;
        self.check(f, s)
    }
}
