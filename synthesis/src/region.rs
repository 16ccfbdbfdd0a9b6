//! Pole regions as data: LMI regions (Chilali and Gahinet) and their intersections.
//!
//! An LMI region is `R = { z : f_R(z) = L + M z + M' conj(z) < 0 }` with `L` symmetric.
//! A matrix `A` has all its eigenvalues in `R` if (and only if) there is `X > 0` with
//! `L ⊗ X + M ⊗ (A X) + M' ⊗ (A X)' < 0` (the paper's Lemma 1, Eq. 3.6). With state
//! feedback, `A X` becomes `A X + B Y`. An intersection of regions is imposed by one such
//! LMI per region, all with the same `X`.

use std::fmt;

use nalgebra::{Complex, DMatrix};

/// A point of the complex plane.
pub type Complex64 = Complex<f64>;
use serde::Serialize;

/// One convex LMI region of the complex plane.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Region {
    /// `Re(s) < alpha`. LMI: `A X + (A X)' - 2 alpha X < 0` (`L = -2 alpha`, `M = 1`).
    HalfPlane {
        /// Abscissa `alpha`.
        alpha: f64,
    },
    /// Conic sector with its apex at the origin, symmetric about the negative real axis,
    /// of inner angle `2 theta` (`half_angle = theta` in rad, `0 < theta < pi/2`):
    /// `Re(s) < 0` and `|Im(s)| < tan(theta) |Re(s)|`.
    /// LMI: `[[sin t (N + N'), cos t (N - N')], [cos t (N' - N), sin t (N + N')]] < 0` with
    /// `N = A X` (`L = 0`, `M = [[sin t, cos t], [-cos t, sin t]]`).
    Sector {
        /// Half the inner angle, from the negative real axis (rad).
        half_angle: f64,
    },
    /// Open disk `|s - center| < radius` with a real centre.
    /// LMI: `[[-r X, N - c X], [N' - c X, -r X]] < 0` with `N = A X`
    /// (`L = [[-r, -c], [-c, -r]]`, `M = [[0, 1], [0, 0]]`).
    Disk {
        /// Real centre `c`.
        center: f64,
        /// Radius `r > 0`.
        radius: f64,
    },
}

/// A refused region.
#[derive(Clone, Debug, PartialEq)]
pub struct RegionError(pub String);

impl fmt::Display for RegionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "invalid pole region: {}", self.0)
    }
}

impl std::error::Error for RegionError {}

impl Region {
    /// `Re(s) < alpha`.
    pub fn half_plane(alpha: f64) -> Self {
        Region::HalfPlane { alpha }
    }
    /// Sector of inner angle `deg` degrees (the paper's is 135).
    pub fn sector_inner_angle_deg(deg: f64) -> Self {
        Region::Sector { half_angle: 0.5 * deg.to_radians() }
    }
    /// `|s - center| < radius`.
    pub fn disk(center: f64, radius: f64) -> Self {
        Region::Disk { center, radius }
    }

    /// Refuses NaN, infinities and degenerate shapes.
    pub fn validate(&self) -> Result<(), RegionError> {
        match *self {
            Region::HalfPlane { alpha } if !alpha.is_finite() => {
                Err(RegionError(format!("half-plane Re(s) < {alpha}: alpha must be finite")))
            }
            Region::Sector { half_angle }
                if !(half_angle.is_finite() && half_angle > 0.0 && half_angle < std::f64::consts::FRAC_PI_2) =>
            {
                Err(RegionError(format!(
                    "sector of inner angle {} deg: must be strictly between 0 and 180 deg",
                    2.0 * half_angle.to_degrees()
                )))
            }
            Region::Disk { center, radius } if !(center.is_finite() && radius.is_finite() && radius > 0.0) => {
                Err(RegionError(format!("disk |s - {center}| < {radius}: need a finite centre and a radius > 0")))
            }
            _ => Ok(()),
        }
    }

    /// The characteristic matrices `(L, M)` of `f_R(z) = L + M z + M' conj(z)`.
    pub fn characteristic(&self) -> (DMatrix<f64>, DMatrix<f64>) {
        match *self {
            Region::HalfPlane { alpha } => {
                (DMatrix::from_element(1, 1, -2.0 * alpha), DMatrix::from_element(1, 1, 1.0))
            }
            Region::Sector { half_angle } => {
                let (s, c) = half_angle.sin_cos();
                (DMatrix::zeros(2, 2), DMatrix::from_row_slice(2, 2, &[s, c, -c, s]))
            }
            Region::Disk { center, radius } => (
                DMatrix::from_row_slice(2, 2, &[-radius, -center, -center, -radius]),
                DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]),
            ),
        }
    }

    /// Signed distance-like margin of a point: positive inside, negative outside, in the
    /// units of the complex plane (distance to the boundary for the half-plane and disk,
    /// distance to the nearer sector edge for the sector).
    pub fn margin(&self, s: Complex64) -> f64 {
        match *self {
            Region::HalfPlane { alpha } => alpha - s.re,
            Region::Sector { half_angle } => {
                // distance to the edges; the edge rays point along -cos t +- i sin t
                let (sn, cs) = half_angle.sin_cos();
                // signed distance to the line through 0 with direction (-cs, sn): inside is
                // below it (for Im >= 0)
                let y = s.im.abs();
                -(s.re * sn + y * cs)
            }
            Region::Disk { center, radius } => radius - (s - Complex64::new(center, 0.0)).norm(),
        }
    }

    /// Whether `s` lies in the open region.
    pub fn contains(&self, s: Complex64) -> bool {
        self.margin(s) > 0.0
    }

    /// Human-readable description.
    pub fn describe(&self) -> String {
        match *self {
            Region::HalfPlane { alpha } => format!("Re(s) < {alpha}"),
            Region::Sector { half_angle } => {
                format!("sector of inner angle {} deg", (2.0 * half_angle.to_degrees() * 1e6).round() / 1e6)
            }
            Region::Disk { center, radius } => format!("|s - ({center})| < {radius}"),
        }
    }
}

/// An intersection of LMI regions (empty = the open left half-plane is *not* implied:
/// no pole constraint at all; stability then comes from the H2/H-inf LMIs).
#[derive(Clone, Debug, PartialEq, Serialize, Default)]
pub struct PoleRegion {
    /// The regions whose intersection is required.
    pub parts: Vec<Region>,
}

impl PoleRegion {
    /// The paper's region: `Re(s) < -0.1` and the 135-degree sector.
    pub fn paper() -> Self {
        PoleRegion { parts: vec![Region::half_plane(-0.1), Region::sector_inner_angle_deg(135.0)] }
    }
    /// No constraint.
    pub fn none() -> Self {
        PoleRegion { parts: vec![] }
    }
    /// Adds a region to the intersection.
    pub fn and(mut self, r: Region) -> Self {
        self.parts.push(r);
        self
    }
    /// Validates every part.
    pub fn validate(&self) -> Result<(), RegionError> {
        self.parts.iter().try_for_each(|r| r.validate())
    }
    /// The smallest margin over the parts (positive = inside all).
    pub fn margin(&self, s: Complex64) -> f64 {
        self.parts.iter().map(|r| r.margin(s)).fold(f64::INFINITY, f64::min)
    }
    /// Whether `s` lies inside every part.
    pub fn contains(&self, s: Complex64) -> bool {
        self.parts.iter().all(|r| r.contains(s))
    }
    /// Human-readable description.
    pub fn describe(&self) -> String {
        if self.parts.is_empty() {
            "no pole region".into()
        } else {
            self.parts.iter().map(|r| r.describe()).collect::<Vec<_>>().join(" and ")
        }
    }
}
