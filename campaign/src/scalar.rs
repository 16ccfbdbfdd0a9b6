//! A value written into a variable: a campaign description's TOML scalar, typed.

/// A value written into a variable: the description's TOML scalar, typed.
#[derive(Clone, Debug, PartialEq)]
pub enum Scalar {
    /// A real number.
    Real(f64),
    /// An integer.
    Integer(i64),
    /// A Boolean.
    Boolean(bool),
}

impl Scalar {
    /// The number in the results (Booleans as 0 / 1).
    pub fn number(&self) -> f64 {
        match *self {
            Scalar::Real(x) => x,
            Scalar::Integer(i) => i as f64,
            Scalar::Boolean(b) => f64::from(u8::from(b)),
        }
    }

    pub(crate) fn describe(&self) -> String {
        match self {
            Scalar::Real(x) => format!("{x} (Real)"),
            Scalar::Integer(i) => format!("{i} (Integer)"),
            Scalar::Boolean(b) => format!("{b} (Boolean)"),
        }
    }
}
