//! The status an FMI function returns, for both generations (`fmi2Status` and
//! `fmi3Status` have the same values).

use std::fmt;

/// FMI 2.0 status codes (`fmi2Status`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// `fmi2OK`.
    Ok,
    /// `fmi2Warning`.
    Warning,
    /// `fmi2Discard`.
    Discard,
    /// `fmi2Error`.
    Error,
    /// `fmi2Fatal`.
    Fatal,
    /// `fmi2Pending` (asynchronous doStep: refused by this master).
    Pending,
    /// Any other integer: a broken FMU.
    Invalid(i32),
}

impl Status {
    /// From the C integer.
    pub fn from_raw(raw: i32) -> Status {
        match raw {
            0 => Status::Ok,
            1 => Status::Warning,
            2 => Status::Discard,
            3 => Status::Error,
            4 => Status::Fatal,
            5 => Status::Pending,
            other => Status::Invalid(other),
        }
    }

    /// The C integer.
    pub fn to_raw(self) -> i32 {
        match self {
            Status::Ok => 0,
            Status::Warning => 1,
            Status::Discard => 2,
            Status::Error => 3,
            Status::Fatal => 4,
            Status::Pending => 5,
            Status::Invalid(v) => v,
        }
    }
}

impl Status {
    /// The status as the generation of `function` spells it: `fmi3Error` after an `fmi3*`
    /// call, `fmi2Error` otherwise (the two enumerations have the same values).
    pub fn spelled_for(self, function: &str) -> String {
        let name = self.to_string();
        match name.strip_prefix("fmi2") {
            Some(rest) if function.starts_with("fmi3") => format!("fmi3{rest}"),
            _ => name,
        }
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Status::Ok => f.write_str("fmi2OK"),
            Status::Warning => f.write_str("fmi2Warning"),
            Status::Discard => f.write_str("fmi2Discard"),
            Status::Error => f.write_str("fmi2Error"),
            Status::Fatal => f.write_str("fmi2Fatal"),
            Status::Pending => f.write_str("fmi2Pending"),
            Status::Invalid(v) => write!(f, "invalid status {v}"),
        }
    }
}

#[cfg(test)]
mod status_spelling {
    use super::Status;

    #[test]
    fn a_status_is_spelled_in_the_generation_of_the_call_that_returned_it() {
        assert_eq!(Status::Error.spelled_for("fmi3DoStep"), "fmi3Error");
        assert_eq!(Status::Discard.spelled_for("fmi3SetFloat64"), "fmi3Discard");
        assert_eq!(Status::Error.spelled_for("fmi2DoStep"), "fmi2Error");
        assert_eq!(Status::Invalid(7).spelled_for("fmi3DoStep"), "invalid status 7");
    }
}
