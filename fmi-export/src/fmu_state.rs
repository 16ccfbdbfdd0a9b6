//! The byte format of a serialized FMU state (`fmi2SerializeFMUstate`): magic, format
//! version, the model's GUID (a state belongs to one model), the count of numbers, then
//! the numbers, all little-endian. The numbers are the layer's own (instance
//! state, time, stop time, next event, sample clock), the declared variables the
//! declaration saves ([`crate::Declaration::saved_rows`]) and the model's own internal
//! numbers, each an f64 (Integers and Booleans exactly so).
//!
//! This module knows the layout and checks what it alone can (the header, the flags, the
//! times); [`crate::instance`] maps an instance onto it and checks the rest (the values
//! through the setters' checks, the clock against the model).

use crate::states::Machine;

const MAGIC: &[u8; 8] = b"NIGELFMU";
const VERSION: u32 = 3;
/// Bytes before the numbers: magic, version, GUID length, GUID, count.
fn header_len(guid: &[u8]) -> usize {
    8 + 4 + 4 + guid.len() + 8
}

/// The layer's part of a saved state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LayerNumbers {
    pub machine: Machine,
    pub time: f64,
    pub stop_time: Option<f64>,
    pub next_event: Option<f64>,
    pub iteration_pending: bool,
    /// A sampled model's clock: start, period, and the index of the next sample (as f64).
    pub clock: Option<(f64, f64, f64)>,
    pub presample: bool,
}

impl LayerNumbers {
    /// How many numbers [`LayerNumbers::push_to`] writes.
    pub const COUNT: usize = 12;

    pub fn push_to(&self, out: &mut Vec<f64>) {
        let (start, period, next) = self.clock.unwrap_or((0.0, 0.0, 0.0));
        out.extend([
            self.machine.code(),
            self.time,
            flag(self.stop_time.is_some()),
            self.stop_time.unwrap_or(0.0),
            flag(self.next_event.is_some()),
            self.next_event.unwrap_or(0.0),
            flag(self.iteration_pending),
            flag(self.clock.is_some()),
            start,
            period,
            next,
            flag(self.presample),
        ]);
    }

    /// Reads the first [`LayerNumbers::COUNT`] numbers; `eps(t)` is the time tolerance of
    /// "at the same instant" (a stop time or next event may not lie before the time).
    pub fn read(numbers: &[f64], eps: impl Fn(f64) -> f64) -> Result<Self, String> {
        let n: &[f64; Self::COUNT] = numbers
            .get(..Self::COUNT)
            .and_then(|n| n.try_into().ok())
            .ok_or("serialized state holds fewer numbers than the layer's header")?;
        let machine = Machine::from_code(n[0]).ok_or("serialized state has an unknown instance state")?;
        let time = n[1];
        let stop_time = read_flag(n[2], "stop time")?.then_some(n[3]);
        let next_event = read_flag(n[4], "next event")?.then_some(n[5]);
        let iteration_pending = read_flag(n[6], "event iteration")?;
        if !time.is_finite() || stop_time.is_some_and(|s| !s.is_finite() || s < time - eps(time)) {
            return Err("serialized state has a non-finite time or a stop time before it".into());
        }
        if next_event.is_some_and(|t| !t.is_finite() || t < time - eps(time)) {
            return Err("serialized state has a next event time that is non-finite or past".into());
        }
        let clock = read_flag(n[7], "sample clock")?.then_some((n[8], n[9], n[10]));
        let presample = read_flag(n[11], "before the first sample")?;
        Ok(LayerNumbers { machine, time, stop_time, next_event, iteration_pending, clock, presample })
    }
}

pub(crate) fn flag(b: bool) -> f64 {
    if b {
        1.0
    } else {
        0.0
    }
}

/// A saved flag: exactly 0 or 1.
pub(crate) fn read_flag(x: f64, what: &str) -> Result<bool, String> {
    if x == 0.0 || x == 1.0 {
        Ok(x == 1.0)
    } else {
        Err(format!("serialized {what} flag is {x}, not 0 or 1"))
    }
}

/// The bytes of a state of the model with this GUID.
pub(crate) fn encode(guid: &str, numbers: &[f64]) -> Vec<u8> {
    let guid = guid.as_bytes();
    let mut out = Vec::with_capacity(header_len(guid) + numbers.len() * 8);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&(guid.len() as u32).to_le_bytes());
    out.extend_from_slice(guid);
    out.extend_from_slice(&(numbers.len() as u64).to_le_bytes());
    for x in numbers {
        out.extend_from_slice(&x.to_le_bytes());
    }
    out
}

/// The numbers of bytes from [`encode`] for the model with this GUID, at least
/// `min_count` of them; anything else is refused with the reason.
pub(crate) fn decode(guid: &str, bytes: &[u8], min_count: usize) -> Result<Vec<f64>, String> {
    let mut rest = bytes;
    let mut take = |n: usize| -> Result<&[u8], String> {
        if rest.len() < n {
            return Err(format!("serialized state truncated ({} bytes)", bytes.len()));
        }
        let (head, tail) = rest.split_at(n);
        rest = tail;
        Ok(head)
    };
    if take(8)? != MAGIC {
        return Err("not a serialized FMU state of this layer (bad magic)".into());
    }
    let version = u32::from_le_bytes(take(4)?.try_into().unwrap_or_default());
    if version != VERSION {
        return Err(format!("serialized state version {version}, expected {VERSION}"));
    }
    let guid_len = u32::from_le_bytes(take(4)?.try_into().unwrap_or_default()) as usize;
    if guid_len > 256 {
        return Err("serialized state has an implausible GUID length".into());
    }
    if take(guid_len)? != guid.as_bytes() {
        return Err("serialized state belongs to another model (GUID differs)".into());
    }
    let count = u64::from_le_bytes(take(8)?.try_into().unwrap_or_default());
    let header = 8 + 4 + 4 + guid_len + 8;
    if count.checked_mul(8) != Some((bytes.len() - header) as u64) || (count as usize) < min_count {
        return Err("serialized state length does not match its header".into());
    }
    Ok(take(count as usize * 8)?
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap_or_default()))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_round_trip_bit_for_bit_and_bad_bytes_are_refused_with_the_reason() {
        let layer = LayerNumbers {
            machine: Machine::StepComplete,
            time: 0.125,
            stop_time: Some(30.0),
            next_event: None,
            iteration_pending: false,
            clock: Some((0.0, 1e-3, 126.0)),
            presample: false,
        };
        let mut numbers = Vec::new();
        layer.push_to(&mut numbers);
        assert_eq!(numbers.len(), LayerNumbers::COUNT);
        numbers.extend([-0.0, f64::MIN_POSITIVE, 1e300]);
        let bytes = encode("{guid}", &numbers);
        let back = decode("{guid}", &bytes, LayerNumbers::COUNT).unwrap();
        assert_eq!(
            back.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            numbers.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
        assert_eq!(LayerNumbers::read(&back, |_| 0.0), Ok(layer));

        assert!(decode("{other}", &bytes, 0).unwrap_err().contains("another model"));
        assert!(decode("{guid}", &bytes[..bytes.len() - 1], 0).unwrap_err().contains("does not match its header"));
        assert!(decode("{guid}", &bytes, numbers.len() + 1).unwrap_err().contains("does not match its header"));
        assert!(decode("{guid}", &bytes[..10], 0).unwrap_err().contains("truncated"));
        let mut bad = bytes.clone();
        bad[0] = b'X';
        assert!(decode("{guid}", &bad, 0).unwrap_err().contains("bad magic"));
        let mut flags = numbers.clone();
        flags[6] = 0.5;
        assert!(LayerNumbers::read(&flags, |_| 0.0).unwrap_err().contains("event iteration flag is 0.5"));
        let mut early = numbers.clone();
        early[3] = 0.1; // stop time before the time
        assert!(LayerNumbers::read(&early, |_| 0.0).unwrap_err().contains("stop time before it"));
    }
}
