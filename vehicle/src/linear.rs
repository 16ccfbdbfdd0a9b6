//! The small-angle linearization of the paper (Eq. 2.2) in closed form.

use nalgebra::{Matrix2, Matrix2x4, Vector2};

use crate::params::VehicleParams;

/// Which disturbance column `[d1; d2]` to use (see `docs/synthesis.md`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DisturbanceColumn {
    /// `d2 = (l_f - l_r)/2` as printed in Eq. 2.2 (reproduces the published numbers).
    Paper,
    /// `d2 = (l_f - l_r)/(2 I_z)`: the physically correct moment arm over inertia.
    Physical,
}

/// `x' = A x + B u + d w` with `x = [beta, r]`, `u = [delta_FL, delta_FR, delta_RL, delta_RR]`,
/// `w = F_sw`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearModel {
    pub a: Matrix2<f64>,
    pub b: Matrix2x4<f64>,
    pub d_physical: Vector2<f64>,
    pub d_paper: Vector2<f64>,
}

impl LinearModel {
    pub fn disturbance(&self, column: DisturbanceColumn) -> Vector2<f64> {
        match column {
            DisturbanceColumn::Paper => self.d_paper,
            DisturbanceColumn::Physical => self.d_physical,
        }
    }
}

/// Eq. 2.2 at speed `v` and friction `mu` (FL, FR, RL, RR). Affine in `mu`.
pub fn linear_model(p: &VehicleParams, mu: [f64; 4], v: f64) -> LinearModel {
    let pos = p.wheel_positions();
    let (mut s0, mut s1, mut s2) = (0.0, 0.0, 0.0);
    let mut b = Matrix2x4::zeros();
    for i in 0..4 {
        let k = mu[i] * p.c[i];
        let xi = pos[i].0;
        s0 += k;
        s1 += xi * k;
        s2 += xi * xi * k;
        b[(0, i)] = k / (p.m * v);
        b[(1, i)] = xi * k / p.i_z;
    }
    let a = Matrix2::new(-s0 / (p.m * v), -s1 / (p.m * v * v) - 1.0, -s1 / p.i_z, -s2 / (p.i_z * v));
    LinearModel {
        a,
        b,
        d_physical: Vector2::new(1.0 / (p.m * v), p.x_c() / p.i_z),
        d_paper: Vector2::new(1.0 / (p.m * v), p.x_c()),
    }
}
