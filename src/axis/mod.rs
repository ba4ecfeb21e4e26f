//! The axis a machine turns about: the [`Axis`] type, its textual form for `--axis` overrides,
//! and its detection from a mesh ([`detect()`], [`detect_with_report`]); and whether a mesh is
//! one periodic sector of a wheel about it ([`periodic`]).
//!
//! The cylindrical acceleration structures are built in (r, θ, h) about this axis, so it should
//! be the line the turbomachine's cells were laid out around: then each cell hugs a box in
//! (r, θ, h). Detection ([`fn@detect`], [`detect_with_report`]) fits the line about which the
//! sampled cells' edges are circumferential or meridional (robustly, so twisted blades and
//! interpolated block interiors do not mislead it) and reports whether that line explains the
//! mesh clearly better than a straight sweep; the method, its constants and what was measured
//! on the real meshes are documented in [`mod@detect`].
//!
//! # Conventions
//! - `direction` is a unit vector whose component of largest magnitude is positive (on a tie,
//!   the first of x, y, z among the largest); so `-z` and `z` give the same [`Axis`].
//! - `origin` is a point on the line. [`Axis::new`] keeps the point it is given; detection and
//!   [`Axis::through_nearest`] place it at the point of the line nearest a reference point (the
//!   mesh's bounding-box centre for detection).
//!
//! # Textual form
//! `"ox,oy,oz:dx,dy,dz"` (origin, then a direction of any non-zero length), or one of the
//! shortcuts `x`, `y`, `z` (that coordinate axis through the origin `0,0,0`). Whitespace
//! around numbers and separators is ignored; the shortcuts are case-insensitive.
//!
//! ```
//! use cylvol::axis::Axis;
//! let a: Axis = "1,2,3:0,0,-2".parse().unwrap();
//! assert_eq!(a.direction, glam::DVec3::Z);
//! assert_eq!(a.origin, glam::DVec3::new(1.0, 2.0, 3.0));
//! assert_eq!("x".parse::<Axis>().unwrap(), Axis::X);
//! assert!("1,2:0,0,1".parse::<Axis>().is_err());
//! ```

pub mod detect;
mod optimize;
pub mod periodic;

use std::fmt;
use std::str::FromStr;

use glam::DVec3;

pub use detect::{
    detect, detect_with_report, residual_about, Detection, CLEAR_AXIS_GAIN, COARSE_CELLS,
    INLIER_TOLERANCE, MIN_CLEAR_INLIERS, SAMPLE_CELLS,
};

/// A line: the machine axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axis {
    /// A point on the axis.
    pub origin: DVec3,
    /// Unit direction, its component of largest magnitude positive.
    pub direction: DVec3,
}

/// Why an axis could not be made or parsed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("invalid axis '{input}': {reason}")]
pub struct AxisError {
    /// The text (or a description of the values) that was rejected.
    pub input: String,
    /// What is wrong with it.
    pub reason: String,
}

impl From<AxisError> for crate::Error {
    fn from(e: AxisError) -> crate::Error {
        crate::Error::Invalid(e.to_string())
    }
}

impl Axis {
    /// The x axis through the origin.
    pub const X: Axis = Axis {
        origin: DVec3::ZERO,
        direction: DVec3::X,
    };
    /// The y axis through the origin.
    pub const Y: Axis = Axis {
        origin: DVec3::ZERO,
        direction: DVec3::Y,
    };
    /// The z axis through the origin.
    pub const Z: Axis = Axis {
        origin: DVec3::ZERO,
        direction: DVec3::Z,
    };

    /// An axis through `origin` along `direction` (any non-zero length; it is normalised and
    /// its sign made canonical, see the module docs). Errors on non-finite values or a
    /// direction too short to normalise.
    ///
    /// ```
    /// use cylvol::axis::Axis;
    /// use glam::DVec3;
    /// let a = Axis::new(DVec3::ZERO, DVec3::new(0.0, -3.0, 0.0)).unwrap();
    /// assert_eq!(a.direction, DVec3::Y);
    /// assert!(Axis::new(DVec3::ZERO, DVec3::ZERO).is_err());
    /// ```
    pub fn new(origin: DVec3, direction: DVec3) -> Result<Axis, AxisError> {
        let err = |reason: &str| AxisError {
            input: format!("{}:{}", fmt_vec(origin), fmt_vec(direction)),
            reason: reason.to_string(),
        };
        if !origin.is_finite() {
            return Err(err("the origin is not finite"));
        }
        if !direction.is_finite() {
            return Err(err("the direction is not finite"));
        }
        let len = direction.length();
        // Normalising needs a length whose reciprocal is finite and a result of unit length.
        let unit = direction / len;
        if len == 0.0 || !unit.is_finite() || (unit.length() - 1.0).abs() > 1e-9 {
            return Err(err("the direction has zero length"));
        }
        Ok(Axis {
            origin,
            direction: canonical_direction(unit),
        })
    }

    /// The same line with its origin moved to the point of the line nearest `point`.
    ///
    /// ```
    /// use cylvol::axis::Axis;
    /// use glam::DVec3;
    /// let a = Axis::Z.through_nearest(DVec3::new(1.0, 2.0, 3.0));
    /// assert_eq!(a.origin, DVec3::new(0.0, 0.0, 3.0));
    /// ```
    pub fn through_nearest(self, point: DVec3) -> Axis {
        let t = (point - self.origin).dot(self.direction);
        Axis {
            origin: self.origin + self.direction * t,
            direction: self.direction,
        }
    }

    /// Distance from `point` to the line.
    pub fn distance_to(&self, point: DVec3) -> f64 {
        let q = point - self.origin;
        (q - self.direction * q.dot(self.direction)).length()
    }

    /// The angle in radians, in `[0, π/2]`, between this line and another (direction signs do
    /// not matter).
    pub fn angle_to(&self, other: &Axis) -> f64 {
        let c = self.direction.dot(other.direction).abs();
        let s = self.direction.cross(other.direction).length();
        s.atan2(c)
    }

    /// An orthonormal right-handed frame `(u, v, direction)` about the axis: `u` is the unit
    /// vector perpendicular to the axis closest to the coordinate axis least aligned with it,
    /// `v = direction × u`. Cylindrical coordinates use θ = 0 along `u`.
    /// (The same frame as [`crate::geometry::cylindrical::CylFrame::new`]; NaN vectors for an
    /// axis whose fields were set to a zero or non-finite direction.)
    pub fn frame(&self) -> (DVec3, DVec3, DVec3) {
        match crate::geometry::cylindrical::CylFrame::new(self.origin, self.direction) {
            Some(f) => (f.e1, f.e2, f.axis),
            None => (DVec3::NAN, DVec3::NAN, DVec3::NAN),
        }
    }

    /// Cylindrical coordinates `(r, θ, h)` of `point` about this axis in the [`Axis::frame`]:
    /// `r ≥ 0`, `θ ∈ (−π, π]`, `h` along `direction` from `origin`.
    pub fn cylindrical(&self, point: DVec3) -> DVec3 {
        let (u, v, d) = self.frame();
        let q = point - self.origin;
        let (x, y) = (q.dot(u), q.dot(v));
        DVec3::new(x.hypot(y), y.atan2(x), q.dot(d))
    }
}

/// The sign of `d` flipped, if needed, so its component of largest magnitude is positive.
fn canonical_direction(d: DVec3) -> DVec3 {
    let a = d.abs();
    let major = if a.x >= a.y && a.x >= a.z {
        d.x
    } else if a.y >= a.z {
        d.y
    } else {
        d.z
    };
    if major < 0.0 {
        -d
    } else {
        d
    }
}

fn fmt_vec(v: DVec3) -> String {
    format!("{},{},{}", v.x, v.y, v.z)
}

impl fmt::Display for Axis {
    /// The textual form `ox,oy,oz:dx,dy,dz`, which [`Axis::from_str`] reads back exactly.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", fmt_vec(self.origin), fmt_vec(self.direction))
    }
}

impl FromStr for Axis {
    type Err = AxisError;

    /// Parses `ox,oy,oz:dx,dy,dz` or `x`, `y`, `z` (see the module docs).
    fn from_str(s: &str) -> Result<Axis, AxisError> {
        let err = |reason: String| AxisError {
            input: s.to_string(),
            reason,
        };
        let trimmed = s.trim();
        match trimmed.to_ascii_lowercase().as_str() {
            "x" => return Ok(Axis::X),
            "y" => return Ok(Axis::Y),
            "z" => return Ok(Axis::Z),
            "" => return Err(err("empty; expected x, y, z or ox,oy,oz:dx,dy,dz".into())),
            _ => {}
        }
        let (o, d) = trimmed.split_once(':').ok_or_else(|| {
            err(
                "expected x, y, z or 'ox,oy,oz:dx,dy,dz' (origin and direction separated by ':')"
                    .into(),
            )
        })?;
        let triple = |part: &str, what: &str| -> Result<DVec3, AxisError> {
            let fields: Vec<&str> = part.split(',').map(str::trim).collect();
            if fields.len() != 3 {
                return Err(err(format!(
                    "the {what} needs 3 comma-separated numbers, got {}",
                    fields.len()
                )));
            }
            let mut v = [0.0; 3];
            for (slot, field) in v.iter_mut().zip(&fields) {
                *slot = field
                    .parse::<f64>()
                    .map_err(|_| err(format!("the {what} has '{field}', which is not a number")))?;
                if !slot.is_finite() {
                    return Err(err(format!("the {what} has a non-finite value '{field}'")));
                }
            }
            Ok(DVec3::from_array(v))
        };
        let origin = triple(o, "origin")?;
        let direction = triple(d, "direction")?;
        Axis::new(origin, direction).map_err(|e| err(e.reason))
    }
}
