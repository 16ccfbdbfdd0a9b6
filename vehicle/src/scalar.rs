//! A small scalar abstraction so that one right-hand side serves both plain `f64`
//! evaluation and forward-mode automatic differentiation (exact directional derivatives).

use core::ops::{Add, Div, Mul, Neg, Sub};

use crate::fastmath;

/// The operations the vehicle right-hand side needs.
///
/// Comparisons (`value()`) decide branches (clamps, fades); the branch taken is then
/// differentiated exactly, which is the usual convention for piecewise-smooth models.
pub trait Scalar:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    fn constant(v: f64) -> Self;
    fn value(self) -> f64;
    fn sin(self) -> Self;
    fn cos(self) -> Self;
    /// `(sin, cos)` at once.
    fn sin_cos(self) -> (Self, Self) {
        (self.sin(), self.cos())
    }
    /// [`Scalar::sin_cos`] of four values (the four wheels), the same results lane by lane.
    fn sin_cos4(v: [Self; 4]) -> ([Self; 4], [Self; 4]) {
        let p = v.map(Self::sin_cos);
        (p.map(|q| q.0), p.map(|q| q.1))
    }
    fn abs(self) -> Self;
    /// Square root, with derivative 0 at 0 (where it is infinite).
    fn sqrt(self) -> Self;
    /// `atan2(self, x)`, with derivative 0 at the origin (where it is undefined).
    fn atan2(self, x: Self) -> Self;
    /// `atan2` of four pairs (the tire slip angles of the four wheels): for `f64` (and the
    /// values of [`Dual`]) [`fastmath::atan2x4`], within 2 ulp of [`Scalar::atan2`].
    fn atan2x4(y: [Self; 4], x: [Self; 4]) -> [Self; 4] {
        core::array::from_fn(|i| y[i].atan2(x[i]))
    }
    /// `sqrt(self^2 + y^2)`, with derivative 0 at the origin.
    fn hypot(self, y: Self) -> Self;

    fn min_s(self, other: Self) -> Self {
        if other.value() < self.value() {
            other
        } else {
            self
        }
    }
    fn max_s(self, other: Self) -> Self {
        if other.value() > self.value() {
            other
        } else {
            self
        }
    }
    fn clamp_s(self, lo: Self, hi: Self) -> Self {
        self.max_s(lo).min_s(hi)
    }
}

/// `sin`, `cos` and the four-wheel `atan2x4` (the tire slip angles) are those of
/// [`fastmath`] (within 2 ulp of glibc, the same bits on every CPU), for the plant and its
/// dual-number derivatives alike. The single `atan2` stays the C library's: it gives the
/// body slip angle `beta`, which importers and the test bench's reference loop compute from
/// the states with the standard `f64::atan2`, bit for bit the same.
impl Scalar for f64 {
    #[inline]
    fn constant(v: f64) -> Self {
        v
    }
    #[inline]
    fn value(self) -> f64 {
        self
    }
    #[inline]
    fn sin(self) -> Self {
        fastmath::sin_cos(self).0
    }
    #[inline]
    fn cos(self) -> Self {
        fastmath::sin_cos(self).1
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        fastmath::sin_cos(self)
    }
    #[inline(always)]
    fn sin_cos4(v: [Self; 4]) -> ([Self; 4], [Self; 4]) {
        fastmath::sin_cos4(v)
    }
    #[inline]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        f64::atan2(self, x)
    }
    #[inline(always)]
    fn atan2x4(y: [Self; 4], x: [Self; 4]) -> [Self; 4] {
        fastmath::atan2x4(y, x)
    }
    #[inline]
    fn hypot(self, y: Self) -> Self {
        f64::hypot(self, y)
    }
}

/// A forward-mode dual number `v + d ε` (one tangent direction).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Dual {
    pub v: f64,
    pub d: f64,
}

impl Dual {
    pub const fn new(v: f64, d: f64) -> Self {
        Dual { v, d }
    }
}

impl Add for Dual {
    type Output = Dual;
    #[inline]
    fn add(self, o: Dual) -> Dual {
        Dual::new(self.v + o.v, self.d + o.d)
    }
}
impl Sub for Dual {
    type Output = Dual;
    #[inline]
    fn sub(self, o: Dual) -> Dual {
        Dual::new(self.v - o.v, self.d - o.d)
    }
}
impl Mul for Dual {
    type Output = Dual;
    #[inline]
    fn mul(self, o: Dual) -> Dual {
        Dual::new(self.v * o.v, self.d * o.v + self.v * o.d)
    }
}
impl Div for Dual {
    type Output = Dual;
    #[inline]
    fn div(self, o: Dual) -> Dual {
        Dual::new(self.v / o.v, (self.d * o.v - self.v * o.d) / (o.v * o.v))
    }
}
impl Neg for Dual {
    type Output = Dual;
    #[inline]
    fn neg(self) -> Dual {
        Dual::new(-self.v, -self.d)
    }
}
impl Add<f64> for Dual {
    type Output = Dual;
    #[inline]
    fn add(self, o: f64) -> Dual {
        Dual::new(self.v + o, self.d)
    }
}
impl Sub<f64> for Dual {
    type Output = Dual;
    #[inline]
    fn sub(self, o: f64) -> Dual {
        Dual::new(self.v - o, self.d)
    }
}
impl Mul<f64> for Dual {
    type Output = Dual;
    #[inline]
    fn mul(self, o: f64) -> Dual {
        Dual::new(self.v * o, self.d * o)
    }
}
impl Div<f64> for Dual {
    type Output = Dual;
    #[inline]
    fn div(self, o: f64) -> Dual {
        Dual::new(self.v / o, self.d / o)
    }
}

impl Scalar for Dual {
    #[inline]
    fn constant(v: f64) -> Self {
        Dual::new(v, 0.0)
    }
    #[inline]
    fn value(self) -> f64 {
        self.v
    }
    #[inline]
    fn sin(self) -> Self {
        let (s, c) = fastmath::sin_cos(self.v);
        Dual::new(s, self.d * c)
    }
    #[inline]
    fn cos(self) -> Self {
        let (s, c) = fastmath::sin_cos(self.v);
        Dual::new(c, -self.d * s)
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = fastmath::sin_cos(self.v);
        (Dual::new(s, self.d * c), Dual::new(c, -self.d * s))
    }
    #[inline]
    fn abs(self) -> Self {
        if self.v < 0.0 {
            -self
        } else {
            self
        }
    }
    #[inline]
    fn sqrt(self) -> Self {
        let q = self.v.sqrt();
        Dual::new(q, if q > 0.0 { self.d / (2.0 * q) } else { 0.0 })
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        let r2 = self.v * self.v + x.v * x.v;
        let d = if r2 > 0.0 { (x.v * self.d - self.v * x.d) / r2 } else { 0.0 };
        Dual::new(self.v.atan2(x.v), d)
    }
    #[inline]
    fn atan2x4(y: [Self; 4], x: [Self; 4]) -> [Self; 4] {
        // the values of the f64 path (fastmath), the derivative of atan2
        let v = fastmath::atan2x4(y.map(|a| a.v), x.map(|a| a.v));
        core::array::from_fn(|i| {
            let (yv, xv) = (y[i].v, x[i].v);
            let r2 = yv * yv + xv * xv;
            let d = if r2 > 0.0 { (xv * y[i].d - yv * x[i].d) / r2 } else { 0.0 };
            Dual::new(v[i], d)
        })
    }
    #[inline]
    fn hypot(self, y: Self) -> Self {
        let h = self.v.hypot(y.v);
        let d = if h > 0.0 { (self.v * self.d + y.v * y.d) / h } else { 0.0 };
        Dual::new(h, d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fd<F: Fn(f64) -> f64>(f: F, x: f64) -> f64 {
        let h = 1e-6;
        (f(x + h) - f(x - h)) / (2.0 * h)
    }

    #[test]
    fn dual_derivatives_match_central_differences() {
        let x = 0.37;
        let f = |t: Dual| (t * t).sin() / (t.cos() + 2.0) + t.atan2(Dual::constant(0.5) + t) - t.hypot(t * 3.0);
        let g = |t: f64| (t * t).sin() / (t.cos() + 2.0) + t.atan2(0.5 + t) - t.hypot(t * 3.0);
        let d = f(Dual::new(x, 1.0));
        assert!((d.v - g(x)).abs() < 1e-15);
        assert!((d.d - fd(g, x)).abs() < 1e-8, "{} vs {}", d.d, fd(g, x));
    }

    #[test]
    fn dual_atan2x4_has_the_f64_values_and_the_derivative_of_atan2() {
        let y = [0.3, -2.0, 1e-3, 0.0];
        let x = [0.7, 0.5, -4.0, 0.0];
        let dy = [1.0, -0.5, 2.0, 1.0];
        let dx = [0.25, 1.0, -1.0, 1.0];
        let yd: [Dual; 4] = core::array::from_fn(|i| Dual::new(y[i], dy[i]));
        let xd: [Dual; 4] = core::array::from_fn(|i| Dual::new(x[i], dx[i]));
        let v = Dual::atan2x4(yd, xd);
        let plain = f64::atan2x4(y, x);
        for i in 0..4 {
            assert_eq!(v[i].v.to_bits(), plain[i].to_bits());
            // d/dt atan2(y + t dy, x + t dx) by central differences (0 at the origin)
            let g = |t: f64| (y[i] + t * dy[i]).atan2(x[i] + t * dx[i]);
            let want = if i == 3 { 0.0 } else { fd(g, 0.0) };
            assert!((v[i].d - want).abs() < 1e-7, "lane {i}: {} vs {want}", v[i].d);
        }
    }

    #[test]
    fn dual_is_finite_at_the_origin() {
        let z = Dual::new(0.0, 1.0);
        assert_eq!(z.atan2(z).d, 0.0);
        assert_eq!(z.hypot(z).d, 0.0);
    }
}
