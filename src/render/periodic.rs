//! Rotationally periodic copies of a sector ([`Copies`]), drawn from the sector's own mesh,
//! structure and topology: the whole wheel at the sector's memory.
//!
//! Copy `k` of `N` is the sector turned by `k · 360°/N` about the periodicity's axis; it fills
//! the wedge of angles `[s + k·α, s + (k+1)·α)`, `s` the sector's start angle and `α = 360°/N`
//! the pitch. A ray is cut where it crosses from one wedge into the next (the half-planes
//! through the axis at `s + j·α`, and the axis itself, where every wedge meets), and each piece
//! is cast in its copy's frame — the piece turned back by `k·α` lies in the sector — into one
//! accumulator, front to back. The pieces' ends on the half-planes are where the medium goes
//! on into the next copy: their side is found by locating the point in the sector, the last
//! sample of a piece stands for the ray up to the half-plane and the first of the next one
//! from it, so the segments tile the ray with neither gap nor overlap. The sector's side faces
//! that land on each other are joined in its topology
//! ([`super::Topology::with_periodic_sides`]), so no boundary is met there.

use glam::{DMat3, DVec3};

use crate::axis::periodic::Periodicity;
use crate::error::show_number;
use crate::geometry::bounds::Aabb;
use crate::geometry::cylindrical::CylFrame;
use crate::{Error, Mesh};

/// Which copies of a periodic sector to draw: copies `first..end` of the periodicity's `N`
/// (all of them, or a cut-away of the wheel).
///
/// ```
/// use cylvol::axis::periodic;
/// use cylvol::render::Copies;
/// let mesh = cylvol::input::load("tests/data/mixer.vtk", &Default::default()).unwrap();
/// let found = periodic::detect(&mesh, &cylvol::axis::detect(&mesh)).unwrap();
/// let all = Copies::new(&mesh, found, None).unwrap();
/// assert_eq!(all.range(), (0, 4));
/// let three = Copies::new(&mesh, found, Some((0, 3))).unwrap();
/// assert_eq!(three.count(), 3);
/// assert!(Copies::new(&mesh, found, Some((2, 5))).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Copies {
    periodicity: Periodicity,
    frame: CylFrame,
    first: u32,
    end: u32,
    /// The wheel's box: the cylinder about the axis that holds every copy.
    wheel: Aabb,
}

impl Copies {
    /// Copies `range` (`first..end`, `None` for all) of `periodicity`'s wheel of `mesh` (the
    /// sector). A range outside `0..N`, or empty, is an error.
    pub fn new(
        mesh: &Mesh,
        periodicity: Periodicity,
        range: Option<(u32, u32)>,
    ) -> Result<Copies, Error> {
        let n = periodicity.copies;
        let (first, end) = range.unwrap_or((0, n));
        if first >= end || end > n {
            return Err(Error::Invalid(format!(
                "copies {first}:{end} are not a range of the wheel's {n} copies (0:{n} draws \
                 them all; copy k is the sector turned by k x {}°)",
                show_number(360.0 / f64::from(n))
            )));
        }
        let frame = periodicity.frame();
        let wheel = wheel_box(mesh, &frame);
        Ok(Copies {
            periodicity,
            frame,
            first,
            end,
            wheel,
        })
    }

    /// The periodicity the copies follow.
    pub fn periodicity(&self) -> &Periodicity {
        &self.periodicity
    }

    /// The copies drawn, `(first, end)`.
    pub fn range(&self) -> (u32, u32) {
        (self.first, self.end)
    }

    /// How many copies are drawn.
    pub fn count(&self) -> u32 {
        self.end - self.first
    }

    /// The box of the whole wheel (a cylinder about the axis holding every copy).
    pub(crate) fn wheel_box(&self) -> &Aabb {
        &self.wheel
    }

    /// The wheel's bounds, `[xmin, xmax, ymin, ymax, zmin, zmax]`, as a mesh gives its own:
    /// the box of the cylinder about the axis that holds every copy (for a camera to frame).
    pub fn bounds(&self) -> [f64; 6] {
        let (a, b) = (self.wheel.min, self.wheel.max);
        [a.x, b.x, a.y, b.y, a.z, b.z]
    }

    /// The angle copy `k` is turned by, in radians.
    fn angle(&self, copy: u32) -> f64 {
        f64::from(copy) * self.periodicity.pitch()
    }

    /// The point `p` of copy `copy`, turned back into the sector.
    pub(crate) fn point_in_sector(&self, copy: u32, p: DVec3) -> DVec3 {
        crate::axis::periodic::turn(&self.frame, p, -self.angle(copy))
    }

    /// The direction `d` in copy `copy`, turned back into the sector.
    pub(crate) fn dir_in_sector(&self, copy: u32, d: DVec3) -> DVec3 {
        self.turn_dir(d, -self.angle(copy))
    }

    /// The sector's vector `v` as it points in copy `copy` (turned with the copy).
    pub(crate) fn dir_in_copy(&self, copy: u32, v: DVec3) -> DVec3 {
        self.turn_dir(v, self.angle(copy))
    }

    /// The rotation that turns the sector's vectors into copy `copy`'s.
    pub(crate) fn turn_of(&self, copy: u32) -> DMat3 {
        let turn = |v| self.dir_in_copy(copy, v);
        DMat3::from_cols(turn(DVec3::X), turn(DVec3::Y), turn(DVec3::Z))
    }

    /// `d` turned by `angle` about the axis.
    fn turn_dir(&self, d: DVec3, angle: f64) -> DVec3 {
        let f = &self.frame;
        let (s, c) = angle.sin_cos();
        let (x, y) = (d.dot(f.e1), d.dot(f.e2));
        f.e1 * (x * c - y * s) + f.e2 * (x * s + y * c) + f.axis * d.dot(f.axis)
    }

    /// `[min, max]` of what `volume` draws over these copies: its own range, or where it draws
    /// a vector's component, which turns with the copies, the range over the copies drawn
    /// (the range a transfer function for the wheel spans).
    pub fn scalar_range(&self, volume: &super::Volume) -> Result<[f64; 2], Error> {
        let turns: Vec<DMat3> = (self.first..self.end).map(|k| self.turn_of(k)).collect();
        Ok(super::field::turned_range(volume.mesh(), &turns)?.unwrap_or(volume.scalar_range()))
    }

    /// The copy whose wedge holds the angle `theta`.
    fn copy_at(&self, theta: f64) -> u32 {
        let n = self.periodicity.copies;
        let u = (theta - self.periodicity.start).rem_euclid(std::f64::consts::TAU)
            / self.periodicity.pitch();
        (u.floor() as u32).min(n - 1)
    }

    /// The pieces of the ray `origin + t dir` over `[t_in, t_out]` in the drawn copies, front
    /// to back, into `out` (cleared first).
    pub(crate) fn pieces(
        &self,
        origin: DVec3,
        dir: DVec3,
        (t_in, t_out): (f64, f64),
        out: &mut Vec<Piece>,
    ) {
        out.clear();
        let f = &self.frame;
        let o = DVec3::new(
            (origin - f.origin).dot(f.e1),
            (origin - f.origin).dot(f.e2),
            0.0,
        );
        let d = DVec3::new(dir.dot(f.e1), dir.dot(f.e2), 0.0);
        let mut cuts = Vec::new();
        let dd = d.length_squared();
        if dd > 0.0 {
            // Where the ray passes nearest the axis: its angle turns one way on either side.
            let t_near = -o.dot(d) / dd;
            let mut spans = vec![(t_in, t_out)];
            if t_near > t_in && t_near < t_out {
                spans = vec![(t_in, t_near), (t_near, t_out)];
                cuts.push(t_near);
            }
            for (a, b) in spans {
                self.wedge_crossings(o, d, (a, b), &mut cuts);
            }
        }
        cuts.retain(|&t| t > t_in && t < t_out);
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let mut t0 = t_in;
        for t1 in cuts.into_iter().chain(std::iter::once(t_out)) {
            if t1 > t0 {
                let mid = o + d * (0.5 * (t0 + t1));
                let copy = self.copy_at(mid.y.atan2(mid.x));
                match out.last_mut() {
                    // The cut at the axis's nearest point may leave the ray in its wedge.
                    Some(last) if last.copy == copy && last.t1 == t0 => last.t1 = t1,
                    _ if copy >= self.first && copy < self.end => out.push(Piece { t0, t1, copy }),
                    _ => {}
                }
            }
            t0 = t1;
        }
    }

    /// The `t` at which the ray `o + t d` (in the frame's plane) crosses the wedges'
    /// half-planes over `(a, b)`, where its angle turns one way.
    fn wedge_crossings(&self, o: DVec3, d: DVec3, (a, b): (f64, f64), cuts: &mut Vec<f64>) {
        let turn = o.x * d.y - o.y * d.x;
        if turn == 0.0 {
            // Through the axis: the angle is constant on either side.
            return;
        }
        let at = |t: f64| {
            let p = o + d * t;
            p.y.atan2(p.x)
        };
        let sign = turn.signum();
        let (theta_a, theta_b) = (at(a), at(b));
        let sweep = ((theta_b - theta_a) * sign).rem_euclid(std::f64::consts::TAU);
        let pitch = self.periodicity.pitch();
        let start = self.periodicity.start;
        let u = (theta_a - start) / pitch;
        let mut j = if sign > 0.0 {
            u.floor() + 1.0
        } else {
            u.ceil() - 1.0
        };
        for _ in 0..=self.periodicity.copies {
            let phi = start + j * pitch;
            if ((phi - theta_a) * sign).rem_euclid(std::f64::consts::TAU) >= sweep {
                break;
            }
            // The line crosses the plane of angle φ where its normal's component vanishes.
            let n = DVec3::new(-phi.sin(), phi.cos(), 0.0);
            let nd = n.dot(d);
            if nd != 0.0 {
                cuts.push(-n.dot(o) / nd);
            }
            j += sign;
        }
    }
}

/// A piece of a ray in one copy: `[t0, t1]` in copy `copy`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Piece {
    /// Where it starts.
    pub(crate) t0: f64,
    /// Where it ends.
    pub(crate) t1: f64,
    /// The copy.
    pub(crate) copy: u32,
}

/// The box of the cylinder about `frame`'s axis that holds every copy of `mesh`: its largest
/// radius, its heights.
fn wheel_box(mesh: &Mesh, frame: &CylFrame) -> Aabb {
    let (mut r_max, mut h0, mut h1) = (0.0f64, f64::INFINITY, f64::NEG_INFINITY);
    for &p in mesh.points() {
        let l = frame.to_local(p);
        r_max = r_max.max(l.x.hypot(l.y));
        h0 = h0.min(l.z);
        h1 = h1.max(l.z);
    }
    let (a, b) = (
        frame.origin + frame.axis * h0,
        frame.origin + frame.axis * h1,
    );
    let a2 = frame.axis * frame.axis;
    let half = DVec3::new(
        (1.0 - a2.x).max(0.0).sqrt(),
        (1.0 - a2.y).max(0.0).sqrt(),
        (1.0 - a2.z).max(0.0).sqrt(),
    ) * r_max;
    Aabb::new(a.min(b) - half, a.max(b) + half)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axis::Axis;

    fn quarter() -> Copies {
        let periodicity = Periodicity {
            copies: 4,
            axis: Axis::Z,
            start: 0.0,
            span: std::f64::consts::FRAC_PI_2,
            matched_faces: 0,
            unmatched_side_faces: 0,
            worst_mismatch: 0.0,
        };
        let frame = periodicity.frame();
        Copies {
            periodicity,
            frame,
            first: 0,
            end: 4,
            wheel: Aabb::new(DVec3::splat(-1.0), DVec3::splat(1.0)),
        }
    }

    #[test]
    fn a_ray_across_the_wheel_is_cut_at_each_wedge() {
        let c = quarter();
        let mut out = Vec::new();
        // Along y = 0.5 from x = -2 to 2: through copies 1 (θ 90°–180°) then 0.
        c.pieces(DVec3::new(-2.0, 0.5, 0.0), DVec3::X, (0.0, 4.0), &mut out);
        assert_eq!(out.len(), 2, "{out:?}");
        assert_eq!((out[0].copy, out[1].copy), (1, 0));
        assert!((out[0].t1 - 2.0).abs() < 1e-12 && out[1].t0 == out[0].t1);
        // Through the axis along y = x: copy 2 then copy 0, cut at the axis.
        let d = DVec3::new(1.0, 1.0, 0.0).normalize();
        c.pieces(DVec3::new(-1.0, -1.0, 0.3), d, (0.0, 3.0), &mut out);
        assert_eq!(out.iter().map(|p| p.copy).collect::<Vec<_>>(), vec![2, 0]);
        assert!((out[0].t1 - 2f64.sqrt()).abs() < 1e-12);
        // Parallel to the axis: one piece.
        c.pieces(DVec3::new(0.3, -0.2, -1.0), DVec3::Z, (0.0, 2.0), &mut out);
        assert_eq!(
            out,
            vec![Piece {
                t0: 0.0,
                t1: 2.0,
                copy: 3
            }]
        );
    }

    #[test]
    fn pieces_tile_the_ray_and_lie_in_their_wedges() {
        let c = quarter();
        let mut out = Vec::new();
        let mut rng = crate::accel::probe::SplitMix64::new(7);
        for _ in 0..500 {
            let o = DVec3::new(rng.unit(), rng.unit(), rng.unit()) * 4.0 - 2.0;
            let d = (DVec3::new(rng.unit(), rng.unit(), rng.unit()) - 0.5).normalize();
            c.pieces(o, d, (0.0, 5.0), &mut out);
            assert_eq!(out[0].t0, 0.0);
            assert_eq!(out.last().unwrap().t1, 5.0);
            for w in out.windows(2) {
                assert_eq!(w[0].t1, w[1].t0);
                assert_ne!(w[0].copy, w[1].copy);
            }
            for p in &out {
                // The piece turned back into the sector lies in its wedge [0, 90°].
                for s in [0.01, 0.5, 0.99] {
                    let q = c.point_in_sector(p.copy, o + d * (p.t0 + s * (p.t1 - p.t0)));
                    let t = q.y.atan2(q.x);
                    assert!(
                        (-1e-9..=std::f64::consts::FRAC_PI_2 + 1e-9).contains(&t),
                        "{p:?} {t}"
                    );
                }
            }
        }
    }
}
