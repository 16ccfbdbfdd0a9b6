//! Connections between integers, carried exactly. The value buffer of the plan holds f64s,
//! and an FMI 3.0 Int64 or UInt64 beyond 2^53 is no f64. The output of an integer
//! connection therefore has a second slot beside its own: its own slot holds the nearest
//! f64 (what the recorder and Real inputs read, as before), the second one the residual,
//! the integer minus that f64. For |v| < 2^64 the residual is at most 2^10 in magnitude
//! (half the f64 spacing there, 2^11), an integer that an f64 holds exactly, so the two
//! slots together give the value to the bit.
//!
//! A connection is carried as an integer when both ends are integers of the FMU's types
//! (Int8 .. UInt64, Enumeration; FMI 2.0 Integer as Int32), no linear transformation
//! applies, and either the output is 64-bit or the view holds the two ends as different
//! base types (an Int64, UInt64 or UInt32 is a Real of the view, the smaller ones
//! Integers). At the input the value is checked against the input's type: a value out of
//! its range (a negative Int64 into a UInt64, 300 into a UInt8) is an error naming both
//! ends, the value and the time, never wrapped or clamped.

use crate::error::{Error, Result};
use crate::fmi3::{ExactKind, IntegerType};
use crate::fmu::Instance;
use crate::system::{BaseType, Connection, System, VariableRef};
use std::collections::HashMap;

/// How an integer output is read exactly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Read {
    /// An Int64 or UInt64: its value as the FMU holds it ([`Instance::get_exact`]).
    Wide,
    /// A Real of the view holding a UInt32 (every one an f64).
    Real,
    /// An Integer of the view.
    Integer,
}

/// How an integer input is set once its value is checked against its type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Write {
    /// An Int64 or UInt64 ([`Instance::set_exact_integer`]).
    Wide,
    /// A Real of the view holding a UInt32.
    Real,
    /// An Integer of the view.
    Integer,
}

/// The input end of an integer connection.
#[derive(Clone, Debug)]
pub(crate) struct Sink {
    write: Write,
    to_type: IntegerType,
    /// `instance.variable` of the two ends, for the error.
    from: String,
    to: String,
}

/// One element of an op carrying integers: the residual slot of the output, and for a set
/// the input it goes to.
#[derive(Clone, Debug)]
pub(crate) enum Link {
    /// Get: the output's residual slot and how it is read.
    Source { residual: usize, read: Read },
    /// Set: the residual slot of the output feeding the input, and the input.
    Sink { residual: usize, sink: Box<Sink> },
}

impl Link {
    /// The residual slot.
    pub(crate) fn residual(&self) -> usize {
        match self {
            Link::Source { residual, .. } | Link::Sink { residual, .. } => *residual,
        }
    }
}

/// Whether `c` is carried as an integer (see the module's text).
pub(crate) fn carries_integer(system: &System, c: &Connection) -> bool {
    let fmu = |r: &VariableRef| &system.instances[r.instance].fmu;
    let integer = |r: &VariableRef| fmu(r).integer_type(r.value_reference).is_some();
    let wide = fmu(&c.from).exact_kind(c.from.value_reference).is_some_and(|k| k != ExactKind::Binary);
    c.gain == 1.0
        && c.offset == 0.0
        && integer(&c.from)
        && integer(&c.to)
        && (wide || c.from.base_type != c.to.base_type)
}

/// The residual slot of every output among `sources` that feeds an integer connection,
/// numbered after the slots of `sources`.
pub(crate) fn residual_slots(system: &System, sources: &[VariableRef]) -> HashMap<VariableRef, usize> {
    let mut residuals = HashMap::new();
    for s in sources {
        let feeds = system.connections.iter().any(|c| c.from == *s && carries_integer(system, c));
        if feeds && !residuals.contains_key(s) {
            residuals.insert(s.clone(), sources.len() + residuals.len());
        }
    }
    residuals
}

/// The link of a get of `r`, if it is an integer connection's output.
pub(crate) fn source_link(system: &System, residuals: &HashMap<VariableRef, usize>, r: &VariableRef) -> Option<Link> {
    let residual = *residuals.get(r)?;
    let wide = system.instances[r.instance].fmu.exact_kind(r.value_reference).is_some();
    let read = match r.base_type {
        _ if wide => Read::Wide,
        BaseType::Real => Read::Real,
        _ => Read::Integer,
    };
    Some(Link::Source { residual, read })
}

/// The link of the set of `c`'s input, if `c` is an integer connection.
pub(crate) fn sink_link(system: &System, residuals: &HashMap<VariableRef, usize>, c: &Connection) -> Option<Link> {
    if !carries_integer(system, c) {
        return None;
    }
    let residual = *residuals.get(&c.from)?;
    let fmu = &system.instances[c.to.instance].fmu;
    let to_type = fmu.integer_type(c.to.value_reference)?;
    let write = match c.to.base_type {
        _ if fmu.exact_kind(c.to.value_reference).is_some() => Write::Wide,
        BaseType::Real => Write::Real,
        _ => Write::Integer,
    };
    let sink = Box::new(Sink { write, to_type, from: system.name_of(&c.from), to: system.name_of(&c.to) });
    Some(Link::Sink { residual, sink })
}

/// Reads the integer output `vr` of `inst`.
pub(crate) fn read(inst: &mut Instance, vr: u32, read: Read) -> Result<i128> {
    Ok(match read {
        Read::Wide => match inst.get_exact(vr)? {
            crate::fmi3::Exact::Integer(v) => v,
            other => unreachable!("an Int64 or UInt64 reads as an integer, not {other:?}"),
        },
        Read::Real => {
            let mut x = [0.0];
            inst.get_real(&[vr], &mut x)?;
            x[0] as i128
        }
        Read::Integer => {
            let mut x = [0];
            inst.get_integer(&[vr], &mut x)?;
            i128::from(x[0])
        }
    })
}

/// Sets the input `vr` of `inst` to `value`, checked against the input's type.
pub(crate) fn write(inst: &mut Instance, vr: u32, value: i128, sink: &Sink) -> Result<()> {
    if !sink.to_type.holds(value) {
        return Err(out_of_range(inst, value, sink));
    }
    // in range: a UInt32 or a type of the view's Integers is an f64 and an i32 exactly
    match sink.write {
        Write::Wide => inst.set_exact_integer(vr, value)?,
        Write::Real => inst.set_real(&[vr], &[value as f64])?,
        Write::Integer => inst.set_integer(&[vr], &[value as i32])?,
    }
    Ok(())
}

#[cold]
fn out_of_range(inst: &Instance, value: i128, sink: &Sink) -> Error {
    let t = &sink.to_type;
    Error::Connection {
        from: sink.from.clone(),
        to: sink.to.clone(),
        reason: format!(
            "{} = {value} at t = {} s is outside the range of {} ({}, {} to {}): the master neither wraps nor clamps it",
            sink.from,
            inst.time(),
            sink.to,
            t.name,
            t.min,
            t.max
        ),
    }
}

/// The value as its nearest f64 and the residual (see the module's text).
#[inline]
pub(crate) fn split(value: i128) -> (f64, f64) {
    let nearest = value as f64;
    (nearest, (value - nearest as i128) as f64)
}

/// The value of the two slots of [`split`].
#[inline]
pub(crate) fn join(nearest: f64, residual: f64) -> i128 {
    nearest as i128 + residual as i128
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The two slots hold every value of both 64-bit types to the bit: the ends of the
    /// ranges, 2^53 + 1 (the first integer no f64 holds), 2^62 + 1, u64::MAX - 1.
    #[test]
    fn split_and_join_are_exact() {
        let values = [
            i128::from(i64::MIN),
            i128::from(i64::MIN) + 1,
            -(1i128 << 53) - 1,
            -1,
            0,
            (1 << 53) + 1,
            (1 << 62) + 1,
            i128::from(i64::MAX),
            i128::from(i64::MAX) + 1,
            i128::from(u64::MAX) - 1,
            i128::from(u64::MAX),
        ];
        for v in values {
            let (nearest, residual) = split(v);
            assert_eq!(join(nearest, residual), v, "{v}");
            assert_eq!(nearest, v as f64, "{v}: the nearest f64, as the recorder reads it");
            // half the spacing of the f64s at 2^63 .. 2^64 (2^11) at most
            assert!(residual.abs() <= 1024.0, "{v}: {residual}");
        }
    }
}
