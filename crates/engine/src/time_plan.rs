//! Advancing to a time: the steps from now to an end time, with a fixed Δt that lands on
//! it or an adaptive one whose last step is shortened to reach it.

use umls_constitutive::Constitutive;
use umls_transfer::Kernel;

use crate::error::EngineError;
use crate::settings::TimeStepControl;
use crate::simulation::Simulation;
use crate::transfer::TransferScheme;

/// Most steps a plan may have: a typo in an end time (1e12 for 1.2) should be an error,
/// not a run of years.
pub const MAX_PLANNED_STEPS: f64 = 1e9;

/// Relative tolerance of the end time: a run whose time is within it has arrived, so the
/// round-off of summed steps never adds a step of length ~10⁻¹⁶.
const END_TOLERANCE: f64 = 1e-12;

/// The steps from a simulation's time to an end time ([`Simulation::plan_until`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimePlan {
    /// Steps planned: exact for a fixed Δt, an estimate at the starting wave speed for
    /// an adaptive one.
    pub steps: usize,
    /// The fixed Δt, which lands on the end time, or the adaptive step's cap.
    pub dt: f64,
}

impl<const D: usize, K, M, T> Simulation<D, K, M, T>
where
    K: Kernel<D>,
    M: Constitutive<D>,
    T: TransferScheme,
{
    /// Plans the steps from [`Self::time`] to `end_time` at about `target_dt` each. A
    /// fixed Δt becomes (end − now) / n with n the fewest steps of at most `target_dt`,
    /// so the last step lands on the end time; an adaptive Δt keeps its cap
    /// ([`crate::StepSettings::dt`]) and its steps are estimated from `target_dt`.
    /// Refuses a non-positive span or step, and more than [`MAX_PLANNED_STEPS`] steps.
    pub fn plan_until(&mut self, end_time: f64, target_dt: f64) -> Result<TimePlan, EngineError> {
        let span = end_time - self.time();
        if !(span.is_finite() && span > 0.0) {
            return Err(EngineError::InvalidParameter {
                parameter: "end_time",
                value: end_time,
                reason: "must be finite and after the simulation's time",
            });
        }
        if !(target_dt.is_finite() && target_dt > 0.0) {
            return Err(EngineError::InvalidParameter {
                parameter: "dt",
                value: target_dt,
                reason: "must be finite and positive",
            });
        }
        // A span that is a whole number of steps up to round-off takes that many.
        let planned = (span / target_dt - 1e-9).ceil().max(1.0);
        if planned > MAX_PLANNED_STEPS {
            return Err(EngineError::InvalidParameter {
                parameter: "steps",
                value: planned,
                reason: "more steps than MAX_PLANNED_STEPS (10⁹)",
            });
        }
        let steps = planned as usize;
        if self.settings.time_step == TimeStepControl::Fixed {
            self.settings.dt = span / planned;
        }
        Ok(TimePlan {
            steps,
            dt: self.settings.dt,
        })
    }

    /// Whether the simulation's time has reached `end_time` (to a relative 10⁻¹²).
    pub fn reached(&self, end_time: f64) -> bool {
        self.time() >= end_time * (1.0 - END_TOLERANCE)
    }

    /// Steps with [`Self::step_until`] until `end_time` is reached; the steps taken.
    pub fn advance_to(&mut self, end_time: f64) -> Result<usize, EngineError> {
        let start = self.step_count();
        while !self.reached(end_time) {
            self.step_until(end_time)?;
        }
        Ok(self.step_count() - start)
    }
}
