//! The tolerance tube around a baseline signal.
//!
//! The baseline `b(s)` is the polyline through its points `(s_j, b_j)` (two points at one
//! time are a jump). At time `t` the tube is
//!
//! ```text
//! lower(t) = min { b(s) - w(s) : s in [t - T, t + T] }
//! upper(t) = max { b(s) + w(s) : s in [t - T, t + T] },   w(s) = atol + rtol |b(s)|
//! ```
//!
//! with `T` the time tolerance, the window clipped to the baseline's span. Since `b` is
//! continuous along its polyline, the union of the intervals `[b(s) - w(s), b(s) + w(s)]`
//! over the window is that one interval: a value `y` at `t` is inside the tube exactly when
//! some baseline time `s` within `T` of `t` has `|y - b(s)| <= atol + rtol |b(s)|`. With
//! `rtol = 0` this is csv-compare's rectangle tube (a rectangle of half-width `T` and
//! half-height `atol` swept along the baseline); with `T = 0` it is numpy's `isclose`
//! against the interpolated baseline.
//!
//! On each segment of the polyline `b` is linear, so `b - w = b - atol - rtol |b|` is
//! concave and `b + w` convex there: the smallest `b - w` and the largest `b + w` over the
//! window are at the ends of segments, that is at the baseline's points inside the window
//! and at the window's two ends. Those are the values evaluated (exactly, no sampling).

/// The tolerances of a comparison.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Relative tolerance, of the baseline's magnitude at each point.
    pub rtol: f64,
    /// Absolute tolerance, in the signal's unit.
    pub atol: f64,
    /// Time tolerance, s: a result value may match the baseline up to this much earlier or later.
    pub time_tol: f64,
}

impl Default for Tolerance {
    /// `rtol = 1e-3`, `atol = 1e-6`, `time_tol = 0`.
    fn default() -> Tolerance {
        Tolerance { rtol: 1e-3, atol: 1e-6, time_tol: 0.0 }
    }
}

impl Tolerance {
    /// Refuses negative or non-finite tolerances, naming the option.
    pub fn check(&self) -> Result<(), String> {
        for (name, v) in [("rtol", self.rtol), ("atol", self.atol), ("time-tol", self.time_tol)] {
            if !(v >= 0.0 && v.is_finite()) {
                return Err(format!("--{name} {v}: expected a finite number >= 0"));
            }
        }
        Ok(())
    }
}

/// A baseline signal: times (not decreasing) and values.
pub struct Baseline<'a> {
    /// Times, s.
    pub time: &'a [f64],
    /// Values.
    pub value: &'a [f64],
}

impl Baseline<'_> {
    /// The polyline's value at `t` inside the span; at a jump time, the value before it.
    fn at(&self, t: f64) -> f64 {
        let (s, v) = (self.time, self.value);
        let i = s.partition_point(|x| *x < t);
        if i == 0 {
            return v[0];
        }
        if i == s.len() {
            return v[s.len() - 1];
        }
        if s[i] == t {
            return v[i];
        }
        let (s0, s1) = (s[i - 1], s[i]);
        let w = (t - s0) / (s1 - s0);
        v[i - 1] + w * (v[i] - v[i - 1])
    }

    /// `(lower, upper)` of the tube at `t` (the window `[a, b]` clipped to the span), or
    /// `None` when the window misses the baseline's span.
    pub fn tube(&self, t: f64, tol: &Tolerance) -> Option<(f64, f64)> {
        let (s, v) = (self.time, self.value);
        let (first, last) = (*s.first()?, *s.last()?);
        // the span is widened by 1e-9 of itself for times written in decimal (a result's
        // 30.000000000000004 s against a baseline's 30 s); the window itself is not
        let slack = 1e-9 * (last - first).abs();
        let (a, b) = (t - tol.time_tol, t + tol.time_tol);
        if a > last + slack || b < first - slack {
            return None;
        }
        let (a, b) = (a.clamp(first, last), b.clamp(first, last));
        let mut lower = f64::INFINITY;
        let mut upper = f64::NEG_INFINITY;
        let mut take = |y: f64| {
            let w = tol.atol + tol.rtol * y.abs();
            lower = lower.min(y - w);
            upper = upper.max(y + w);
            if y.is_nan() {
                lower = f64::NAN;
                upper = f64::NAN;
            }
        };
        // the window's ends (a jump at an end: both sides are among the points below)
        take(self.at(a));
        take(self.at(b));
        let i0 = s.partition_point(|x| *x < a);
        let i1 = s.partition_point(|x| *x <= b);
        for y in &v[i0..i1] {
            take(*y);
        }
        Some((lower, upper))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tol(rtol: f64, atol: f64, time_tol: f64) -> Tolerance {
        Tolerance { rtol, atol, time_tol }
    }

    #[test]
    fn a_ramp_without_time_tolerance_is_interpolated_and_widened_by_atol_and_rtol() {
        // b(s) = s on [0, 2]; at t = 0.5: b = 0.5, w = 0.1 + 0.2 * 0.5 = 0.2
        let (t, y) = ([0.0, 1.0, 2.0], [0.0, 1.0, 2.0]);
        let b = Baseline { time: &t, value: &y };
        assert_eq!(b.tube(0.5, &tol(0.2, 0.1, 0.0)), Some((0.3, 0.7)));
        // time tolerance 0.25 on the ramp: window [0.25, 0.75], b from 0.25 to 0.75,
        // lower 0.25 - (0.1 + 0.05) = 0.1, upper 0.75 + (0.1 + 0.15) = 1.0
        let (lo, hi) = b.tube(0.5, &tol(0.2, 0.1, 0.25)).unwrap();
        assert!((lo - 0.1).abs() < 1e-15 && (hi - 1.0).abs() < 1e-15, "{lo} {hi}");
        // outside the span by more than the time tolerance: no tube
        assert_eq!(b.tube(2.5, &tol(0.0, 0.1, 0.25)), None);
        // within it: the window [1.875, 2.375] clipped to [1.875, 2]
        assert_eq!(b.tube(2.125, &tol(0.0, 0.0, 0.25)), Some((1.875, 2.0)));
    }

    #[test]
    fn a_step_widens_the_tube_over_the_time_tolerance() {
        // a jump from 0 to 1 at s = 1 (two points at one time)
        let (t, y) = ([0.0, 1.0, 1.0, 2.0], [0.0, 0.0, 1.0, 1.0]);
        let b = Baseline { time: &t, value: &y };
        let tt = tol(0.0, 0.01, 0.1);
        // within 0.1 s of the jump: both levels allowed
        assert_eq!(b.tube(0.95, &tt), Some((-0.01, 1.01)));
        assert_eq!(b.tube(1.05, &tt), Some((-0.01, 1.01)));
        // farther: one level
        assert_eq!(b.tube(0.85, &tt), Some((-0.01, 0.01)));
        assert_eq!(b.tube(1.15, &tt), Some((0.99, 1.01)));
    }

    #[test]
    fn a_zero_crossing_inside_the_window_needs_no_point_of_its_own() {
        // b from -1 to 1 over [0, 2] with rtol 0.5, atol 0: at the window [0.9, 1.1], b goes
        // -0.1 .. 0.1; b - w = 1.5 b (b < 0) or 0.5 b (b > 0): smallest -0.15 at 0.9;
        // b + w = 0.5 b or 1.5 b: largest 0.15 at 1.1 (at the crossing both are 0)
        let (t, y) = ([0.0, 2.0], [-1.0, 1.0]);
        let b = Baseline { time: &t, value: &y };
        let (lo, hi) = b.tube(1.0, &tol(0.5, 0.0, 0.1)).unwrap();
        assert!((lo + 0.15).abs() < 1e-12 && (hi - 0.15).abs() < 1e-12, "{lo} {hi}");
        // rtol 2: b - w = 3 b or -b, smallest -0.3 at 0.9; b + w = -b or 3 b, largest 0.3 at 1.1
        let (lo, hi) = b.tube(1.0, &tol(2.0, 0.0, 0.1)).unwrap();
        assert!((lo + 0.3).abs() < 1e-12 && (hi - 0.3).abs() < 1e-12, "{lo} {hi}");
    }
}
