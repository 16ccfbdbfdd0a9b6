//! Sampled (discrete-time) models: the sample clock the layer keeps for them.
//!
//! A model that answers [`crate::Model::sample_period`] is sampled: the layer counts its
//! samples as integers from the start time, sample `k` at `t_k = start + k period` (one
//! rounding, so no drift whatever the run's length), calls [`crate::Model::sample`] at
//! each `t_k` (a time event in Model Exchange; inside `fmi2DoStep` in Co-Simulation, an
//! instant at a step's end lazily at the next read or step, so that it sees the inputs of
//! `t_k`), and before sample 0 answers reads of the discrete outputs from what sample 0
//! will latch. The held outputs are the model's own fields, set by `sample`. The count
//! `k`, the start time and the period are the layer's part of the FMU state, checked
//! against the time and the next event when a state is loaded.
//!
//! A model with a last sample ([`crate::Model::sample_end`]) ends the FMI way at it,
//! `t_end = start + last period`: in Model Exchange the event at `t_end` reports
//! `terminateSimulation` and no next event; in Co-Simulation a step to `t_end` is the last
//! one, a step past it integrates to `t_end` and returns `fmi2Discard` with
//! `fmi2GetBooleanStatus(fmi2Terminated) = fmi2True` and `fmi2LastSuccessfulTime = t_end`;
//! a stop time past `t_end` is refused at `fmi2SetupExperiment` (and when initialization
//! ends, for a last sample set after it).

/// Smallest distance between two time instants the layer tells apart \[s\], besides the
/// rounding of the times themselves: a master that accumulates `t += h` drifts from the
/// exact grid by about 1e-11 s after 30 000 steps of 1 ms, far below it; no sample period
/// of ours is within three orders of magnitude of it (the controller's smallest is 1 us).
pub const TIME_RESOLUTION: f64 = 1e-9;

/// Most samples one `fmi2DoStep` may run (1000 s at 1 ms): a longer step is refused
/// before it starts, with `fmi2Discard`, rather than keeping the importer for hours.
pub const MAX_SAMPLES_PER_STEP: f64 = 1e6;

/// Unit in the last place of `t` (of 1 for |t| < 1).
pub fn ulp(t: f64) -> f64 {
    let a = t.abs().max(1.0);
    f64::from_bits(a.to_bits() + 1) - a
}

/// Two times closer than this are one instant: [`TIME_RESOLUTION`] plus two units in the
/// last place of `t` (the rounding of `start + k period` and of the master's `t + h`,
/// each half a unit). It does not grow with |t| beyond what an f64 can resolve there.
pub fn instant_tolerance(t: f64) -> f64 {
    TIME_RESOLUTION + 2.0 * ulp(t)
}

/// The last sample of a sampled model and the variable that sets it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleEnd {
    /// Index of the last sample: samples `0 ..= last` exist, the simulation ends at the last.
    pub last: u64,
    /// The parameter that sets it (named in the messages), e.g. `"duration"`.
    pub variable: &'static str,
}

/// The layer's sample clock of one instance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleClock {
    /// Time of sample 0 (the start time of `fmi2SetupExperiment`).
    pub start: f64,
    /// Sample period \[s\].
    pub period: f64,
    /// Samples run so far: the next sample is `next`.
    pub next: u64,
    /// The last sample, if the model has one.
    pub end: Option<SampleEnd>,
}

impl SampleClock {
    /// Time of sample `k`: one rounding of the exact `start + k period`.
    pub fn time_of(&self, k: u64) -> f64 {
        self.start + k as f64 * self.period
    }

    /// Where the samples end (the time of the last), if they do.
    pub fn end_time(&self) -> Option<f64> {
        self.end.map(|e| self.time_of(e.last))
    }

    /// Whether sample `next` exists.
    pub fn has_next(&self) -> bool {
        !matches!(self.end, Some(e) if self.next > e.last)
    }

    /// The next time event: the next sample, if there is one.
    pub fn next_event(&self) -> Option<f64> {
        self.has_next().then(|| self.time_of(self.next))
    }

    /// Whether the grid can be held at time `t`: the rounding of `t` must stay well
    /// inside a period, so that each communication point falls on one sample.
    pub fn check_resolution(&self, t: f64) -> Result<(), String> {
        if instant_tolerance(t) < self.period / 4.0 {
            Ok(())
        } else {
            Err(format!(
                "t = {t} s cannot resolve the sample period {} s (an f64 resolves {:e} s there): \
                 start the experiment nearer to 0",
                self.period,
                ulp(t)
            ))
        }
    }
}
