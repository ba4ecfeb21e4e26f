//! Axis-aligned bounding boxes in Cartesian space, and the exact Cartesian bounds of a cell.
//!
//! A trilinear cell lies in the convex hull of its eight corners (every point is a convex
//! combination of them, the shape functions being non-negative on `[0, 1]³` and summing to 1),
//! so the box of the corners is the cell's exact bounding box.

use glam::DVec3;

/// An axis-aligned box `[min, max]`. The empty box has `min = +∞`, `max = −∞`, so that
/// [`Aabb::union`] and [`Aabb::grow`] start from it naturally.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// The low corner.
    pub min: DVec3,
    /// The high corner.
    pub max: DVec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The empty box (contains nothing; the identity of [`Aabb::union`]).
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// The box `[min, max]` as given.
    pub fn new(min: DVec3, max: DVec3) -> Self {
        Aabb { min, max }
    }

    /// The smallest box holding all the points (empty for no points).
    ///
    /// ```
    /// use cylvol::geometry::bounds::Aabb;
    /// use glam::DVec3;
    /// let b = Aabb::from_points(&[DVec3::ZERO, DVec3::new(1.0, -2.0, 3.0)]);
    /// assert_eq!(b.min, DVec3::new(0.0, -2.0, 0.0));
    /// assert!(b.contains(DVec3::new(0.5, -1.0, 2.9)));
    /// ```
    pub fn from_points(points: &[DVec3]) -> Self {
        points.iter().fold(Self::EMPTY, |b, &p| b.grow(p))
    }

    /// Whether the box holds no point (`min > max` on some axis, or NaN bounds).
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// The smallest box holding both (a NaN bound of `other` is ignored).
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: lower(self.min, other.min),
            max: higher(self.max, other.max),
        }
    }

    /// The smallest box holding this one and the point (a NaN coordinate of `p` is ignored).
    pub fn grow(&self, p: DVec3) -> Aabb {
        Aabb {
            min: lower(self.min, p),
            max: higher(self.max, p),
        }
    }

    /// This box enlarged by `margin` on every side (an empty box stays empty).
    pub fn padded(&self, margin: f64) -> Aabb {
        if self.is_empty() {
            return *self;
        }
        Aabb {
            min: self.min - DVec3::splat(margin),
            max: self.max + DVec3::splat(margin),
        }
    }

    /// Whether the point lies in the closed box (false for NaN).
    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// Whether the two closed boxes share a point.
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    /// `max − min` (zero for an empty box).
    #[inline]
    pub fn extent(&self) -> DVec3 {
        if self.is_empty() {
            DVec3::ZERO
        } else {
            self.max - self.min
        }
    }

    /// The centre of the box.
    pub fn center(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }

    /// The length of the box's diagonal (zero when empty).
    pub fn diagonal(&self) -> f64 {
        self.extent().length()
    }

    /// The area of the box's surface, `2 (dx dy + dy dz + dz dx)` (zero when empty), for the
    /// surface-area heuristic.
    #[inline]
    pub fn surface_area(&self) -> f64 {
        let d = self.extent();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// The volume of the box (zero when empty).
    pub fn volume(&self) -> f64 {
        let d = self.extent();
        d.x * d.y * d.z
    }
}

/// `m` lowered to `p` where `p` is below it, per component; a NaN in `p` is ignored.
///
/// A comparison, not `f64::min` (whose NaN handling costs several instructions, and boxes are
/// grown for every candidate cell a point query tests).
#[inline(always)]
pub(crate) fn lower(m: DVec3, p: DVec3) -> DVec3 {
    DVec3::select(p.cmplt(m), p, m)
}

/// `m` raised to `p` where `p` is above it, per component; a NaN in `p` is ignored (see
/// [`lower`]).
#[inline(always)]
pub(crate) fn higher(m: DVec3, p: DVec3) -> DVec3 {
    DVec3::select(p.cmpgt(m), p, m)
}

/// The Cartesian bounds of a (possibly collapsed) trilinear cell: exactly the box of its
/// corners.
pub fn cell_bounds(corners: &[DVec3; 8]) -> Aabb {
    Aabb::from_points(corners)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::trilinear::{map, CORNER_PARAMETERS};

    #[test]
    fn empty_box_behaves() {
        let e = Aabb::EMPTY;
        assert!(e.is_empty());
        assert!(!e.contains(DVec3::ZERO));
        assert_eq!(e.volume(), 0.0);
        assert_eq!(e.surface_area(), 0.0);
        let b = Aabb::new(DVec3::ZERO, DVec3::ONE);
        assert_eq!(e.union(&b), b);
        assert!(!e.overlaps(&b));
        assert!(!b.contains(DVec3::NAN));
    }

    #[test]
    fn growing_ignores_nan_coordinates() {
        let b = Aabb::from_points(&[DVec3::ZERO, DVec3::new(1.0, f64::NAN, -2.0)]);
        assert_eq!(
            b,
            Aabb::new(DVec3::new(0.0, 0.0, -2.0), DVec3::new(1.0, 0.0, 0.0))
        );
        let nan = Aabb::new(DVec3::NAN, DVec3::NAN);
        assert_eq!(b.union(&nan), b);
        // Every other point as f64::min and max would take it.
        let points = [DVec3::new(-0.0, 3.0, 1e300), DVec3::new(0.0, -3.0, -1e-300)];
        let b = Aabb::from_points(&points);
        assert_eq!(b.min, points[0].min(points[1]));
        assert_eq!(b.max, points[0].max(points[1]));
    }

    #[test]
    fn measures_and_overlap() {
        let b = Aabb::new(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        assert_eq!(b.volume(), 6.0);
        assert_eq!(b.surface_area(), 22.0);
        let c = Aabb::new(DVec3::new(1.0, 2.0, 3.0), DVec3::splat(5.0));
        assert!(b.overlaps(&c)); // touching at a corner counts
        let d = Aabb::new(DVec3::new(1.0 + 1e-12, 0.0, 0.0), DVec3::splat(5.0));
        assert!(!b.overlaps(&d));
        assert!(b.padded(1e-11).overlaps(&d));
    }

    #[test]
    fn cell_bounds_hold_interior_points() {
        let mut c = CORNER_PARAMETERS.map(DVec3::from_array);
        c[6] += DVec3::new(0.4, 0.3, -0.2);
        c[1] -= DVec3::new(0.1, 0.2, 0.3);
        let b = cell_bounds(&c);
        for i in 0..=10 {
            for j in 0..=10 {
                for k in 0..=10 {
                    let p = DVec3::new(i as f64, j as f64, k as f64) / 10.0;
                    assert!(b.contains(map(&c, p)));
                }
            }
        }
    }
}
