//! Unit definitions from the unit's name: `"N.m"`, `"m/s2"`, `"rad.s/rad"`, `"1/s"` give
//! their SI base-unit exponents, so that a model writes a variable's unit once (on the
//! variable) and the layer writes the `<UnitDefinitions>` of `modelDescription.xml`.
//!
//! The names follow the unit syntax of Modelica and of the FMI 2.0 standard's examples
//! (section 2.2.2): a product of factors joined by `.`, optionally one `/` with the
//! denominator's factors after it; a factor is a symbol with an optional integer exponent
//! (`m2`, `s-1`); `1` stands for no unit (`1/s`). Symbols: the SI base units `kg`, `m`,
//! `s`, `A`, `K`, `mol`, `cd`, the radian `rad` (FMI keeps it as a base unit of its own, so
//! that `rad/s` and `1/s` stay apart), and the derived units `N`, `J`, `W`, `Pa`, `Hz`,
//! `V`, `C`. Prefixes (`mm`, `km`) and factors other than 1 are not derived: declare those
//! units explicitly with [`si_unit`] or a full [`model_description::Unit`].

use model_description as md;

/// A unit with base-unit exponents `[kg, m, s, rad]`.
pub fn si_unit(name: &str, kg: i32, m: i32, s: i32, rad: i32) -> md::Unit {
    md::Unit {
        name: name.to_string(),
        base_unit: Some(md::BaseUnit { kg, m, s, rad, factor: 1.0, ..Default::default() }),
    }
}

/// Exponents of kg, m, s, A, K, mol, cd, rad.
type Exponents = [i32; 8];

const SYMBOLS: [(&str, Exponents); 15] = [
    ("kg", [1, 0, 0, 0, 0, 0, 0, 0]),
    ("m", [0, 1, 0, 0, 0, 0, 0, 0]),
    ("s", [0, 0, 1, 0, 0, 0, 0, 0]),
    ("A", [0, 0, 0, 1, 0, 0, 0, 0]),
    ("K", [0, 0, 0, 0, 1, 0, 0, 0]),
    ("mol", [0, 0, 0, 0, 0, 1, 0, 0]),
    ("cd", [0, 0, 0, 0, 0, 0, 1, 0]),
    ("rad", [0, 0, 0, 0, 0, 0, 0, 1]),
    ("N", [1, 1, -2, 0, 0, 0, 0, 0]),
    ("J", [1, 2, -2, 0, 0, 0, 0, 0]),
    ("W", [1, 2, -3, 0, 0, 0, 0, 0]),
    ("Pa", [1, -1, -2, 0, 0, 0, 0, 0]),
    ("Hz", [0, 0, -1, 0, 0, 0, 0, 0]),
    ("V", [1, 2, -3, -1, 0, 0, 0, 0]),
    ("C", [0, 0, 1, 1, 0, 0, 0, 0]),
];

/// The exponents of one factor such as `m2`, `s-1` or `1`.
fn factor(text: &str) -> Result<Exponents, String> {
    if text == "1" {
        return Ok([0; 8]);
    }
    let split = text.find(|c: char| c.is_ascii_digit() || c == '-').unwrap_or(text.len());
    let (symbol, power) = text.split_at(split);
    let power: i32 = match power {
        "" => 1,
        p => p.parse().map_err(|_| format!("\"{text}\": the exponent \"{p}\" is not an integer"))?,
    };
    let (_, base) = SYMBOLS.iter().find(|(s, _)| *s == symbol).ok_or_else(|| {
        let known: Vec<&str> = SYMBOLS.iter().map(|(s, _)| *s).collect();
        format!("\"{symbol}\" is not a unit symbol the layer derives (known: {})", known.join(", "))
    })?;
    Ok(base.map(|e| e * power))
}

/// The exponents of a product `a.b.c`.
fn product(text: &str) -> Result<Exponents, String> {
    let mut sum = [0; 8];
    for part in text.split('.') {
        if part.is_empty() {
            return Err("an empty factor (two dots, or a dot at an end)".to_string());
        }
        let e = factor(part)?;
        sum.iter_mut().zip(e).for_each(|(s, e)| *s += e);
    }
    Ok(sum)
}

/// The unit definition of unit `name` with factor 1, derived from its name.
pub fn derived_unit(name: &str) -> Result<md::Unit, String> {
    let wrap = |e: String| format!("unit \"{name}\": {e}");
    let (numerator, denominator) = match name.split_once('/') {
        Some((n, d)) if d.contains('/') => return Err(wrap(format!("more than one '/' in \"{n}/{d}\""))),
        Some((n, d)) => (n, Some(d)),
        None => (name, None),
    };
    let mut e = product(numerator).map_err(wrap)?;
    if let Some(d) = denominator {
        let below = product(d).map_err(wrap)?;
        e.iter_mut().zip(below).for_each(|(e, b)| *e -= b);
    }
    let [kg, m, s, a, k, mol, cd, rad] = e;
    Ok(md::Unit {
        name: name.to_string(),
        base_unit: Some(md::BaseUnit { kg, m, s, a, k, mol, cd, rad, factor: 1.0, ..Default::default() }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exponents(name: &str) -> Exponents {
        let b = derived_unit(name).unwrap().base_unit.unwrap();
        assert_eq!((b.factor, b.offset), (1.0, 0.0), "{name}");
        [b.kg, b.m, b.s, b.a, b.k, b.mol, b.cd, b.rad]
    }

    #[test]
    fn the_units_of_our_fmus_have_their_si_exponents() {
        // written out by hand from the definitions (N = kg m s-2)
        let cases: [(&str, Exponents); 18] = [
            ("1/s", [0, 0, -1, 0, 0, 0, 0, 0]),
            ("N", [1, 1, -2, 0, 0, 0, 0, 0]),
            ("N.m", [1, 2, -2, 0, 0, 0, 0, 0]),
            ("N.s/m", [1, 0, -1, 0, 0, 0, 0, 0]),
            ("N/m", [1, 0, -2, 0, 0, 0, 0, 0]),
            ("N/rad", [1, 1, -2, 0, 0, 0, 0, -1]),
            ("kg", [1, 0, 0, 0, 0, 0, 0, 0]),
            ("kg.m2", [1, 2, 0, 0, 0, 0, 0, 0]),
            ("m", [0, 1, 0, 0, 0, 0, 0, 0]),
            ("m/s", [0, 1, -1, 0, 0, 0, 0, 0]),
            ("m/s2", [0, 1, -2, 0, 0, 0, 0, 0]),
            ("rad", [0, 0, 0, 0, 0, 0, 0, 1]),
            ("rad.s/rad", [0, 0, 1, 0, 0, 0, 0, 0]),
            ("rad/m", [0, -1, 0, 0, 0, 0, 0, 1]),
            ("rad/rad", [0; 8]),
            ("rad/s", [0, 0, -1, 0, 0, 0, 0, 1]),
            ("rad/s2", [0, 0, -2, 0, 0, 0, 0, 1]),
            ("s", [0, 0, 1, 0, 0, 0, 0, 0]),
        ];
        for (name, e) in cases {
            assert_eq!(exponents(name), e, "{name}");
        }
        // the same units as the explicit `si_unit` writes them
        for (name, kg, m, s, rad) in [("N.m", 1, 2, -2, 0), ("rad/s2", 0, 0, -2, 1), ("N.s/m", 1, 0, -1, 0)] {
            assert_eq!(derived_unit(name).unwrap(), si_unit(name, kg, m, s, rad));
        }
        assert_eq!(exponents("W"), exponents("J/s"));
        assert_eq!(exponents("Pa"), exponents("N/m2"));
        assert_eq!(exponents("m.s-2"), exponents("m/s2"));
    }

    #[test]
    fn names_the_layer_cannot_derive_are_refused_with_the_reason() {
        for (name, why) in [
            ("mm", "\"mm\" is not a unit symbol"),
            ("deg", "\"deg\" is not a unit symbol"),
            ("m/s/s", "more than one '/'"),
            ("N..m", "an empty factor"),
            ("m2.5", "\"\" is not a unit symbol"),
            ("m^2", "\"m^\" is not a unit symbol"),
            ("sx", "\"sx\" is not a unit symbol"),
            ("", "an empty factor"),
        ] {
            let e = derived_unit(name).unwrap_err();
            assert!(e.starts_with(&format!("unit \"{name}\": ")) && e.contains(why), "{name}: {e}");
        }
    }
}
