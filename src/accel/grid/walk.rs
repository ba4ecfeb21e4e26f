//! The walk of a ray from grid cell to grid cell over the cells that reference no kept cell:
//! the grids' side of the structures' ray contract ([`crate::accel::skip`]).
//!
//! The walk goes a whole top cell at a time where it references no kept cell, each step
//! locating the point past the last cell's exit as point location would, so the walk's notion
//! of a cell is the grid's own; exits are computed never later than the true ones (slabs; for
//! a cylindrical grid also the circles `r = r₀, r₁` and the half-planes at the arc's ends).

use glam::DVec3;

use super::{GridMask, MaskedCell, TwoLevelGrid};
use crate::accel::{Coordinates, Counters, RaySpan};
use crate::geometry::bounds::Aabb;
use crate::geometry::pseudo_angle::direction_of_pseudo;

/// The most grid cells [`TwoLevelGrid::next_marked`] walks through before it stops.
pub(crate) const MAX_GRID_WALK: usize = 1 << 16;

/// The largest step, relative to the grid cell's least extent, that
/// [`TwoLevelGrid::next_marked`] takes past a grid cell's exit to leave the cell: thousands
/// of times below the padding of the pieces the grid references (`4e-9` of a mesh cell's
/// diagonal and more; grid cells are shaped like the pieces they hold), so that no point of a
/// kept piece in the next grid cell lies within the step.
const GRID_STEP_LIMIT: f64 = 1e-12;

/// A ray in a grid's coordinates, for the exits from grid cells.
#[derive(Clone, Copy, Debug)]
struct GridRay {
    /// In the cylindrical frame (`(x, y)` across the axis, `h` along it) for a cylindrical
    /// grid, else as given.
    o: DVec3,
    d: DVec3,
    /// Cylindrical or not.
    cylindrical: bool,
    /// The magnitude of the ray's origin (at least 1): what rounding is relative to.
    scale: f64,
}

impl GridRay {
    fn new(coordinates: Coordinates, origin: DVec3, dir: DVec3) -> GridRay {
        let scale = origin.abs().max_element().max(1.0);
        match coordinates {
            Coordinates::Cartesian => GridRay {
                o: origin,
                d: dir,
                cylindrical: false,
                scale,
            },
            Coordinates::Cylindrical(frame) => GridRay {
                o: frame.to_local(origin),
                d: DVec3::new(dir.dot(frame.e1), dir.dot(frame.e2), dir.dot(frame.axis)),
                cylindrical: true,
                scale,
            },
        }
    }

    /// The least extent of `region`, in world units: its box's shortest side, or for a
    /// cylindrical region its radial and axial sides (its arc is as long as its angle times
    /// its radius, which may be anything near the axis).
    fn least_extent(&self, region: &Aabb) -> f64 {
        let e = region.max - region.min;
        if self.cylindrical {
            e.x.min(e.z)
        } else {
            e.min_element()
        }
    }

    /// Where the ray leaves `region` (a box in the grid's coordinates holding the point at
    /// `t`, as the grid classifies it) after `t`: never later than the true exit, and `t`
    /// itself where the point lies on the face it leaves by, or (by rounding) just beyond it.
    /// The slabs (every axis of a Cartesian box, `h` of a cylindrical one) are convex, so
    /// their exit is the nearest face ahead. A cylindrical region is also left through its
    /// outer circle (the later root of `r² = r₁²`), through its inner circle where the ray
    /// reaches it (the earlier root of `r² = r₀²`), and through the half-plane at the end of
    /// its arc that the ray turns towards; any of those crossings a little behind `t` counts
    /// as one at `t` (rounding), and any doubtful one counts (an earlier exit only costs a
    /// step of the walk).
    fn exit(&self, region: &Aabb, t: f64) -> f64 {
        let (o, d) = (self.o, self.d);
        let (lo, hi) = (region.min, region.max);
        let mut exit = f64::INFINITY;
        let slabs = if self.cylindrical { 2..3 } else { 0..3 };
        for a in slabs {
            if d[a] != 0.0 {
                let face = if d[a] > 0.0 { hi[a] } else { lo[a] };
                exit = exit.min((face - o[a]) / d[a]);
            }
        }
        if self.cylindrical {
            let behind = t - 1e-9 * (t.abs() + self.scale);
            // r² along the ray: a t² + 2 b t + c.
            let a = d.x * d.x + d.y * d.y;
            let b = o.x * d.x + o.y * d.y;
            let c = o.x * o.x + o.y * o.y;
            if a > 0.0 {
                let outer = b * b - a * (c - hi.x * hi.x);
                exit = exit.min(if outer >= 0.0 {
                    (-b + outer.sqrt()) / a
                } else {
                    t
                });
                // Inwards through the inner circle at the earlier root (where the ray came
                // out of the hole, at the later one, is an entry).
                let inner = b * b - a * (c - lo.x * lo.x);
                if lo.x > 0.0 && inner > 0.0 {
                    let reach = (-b - inner.sqrt()) / a;
                    if reach >= behind {
                        exit = exit.min(reach);
                    }
                }
            }
            // The half-planes through the axis at the arc's ends (none for a whole turn):
            // where the ray meets the line through the axis along `u`, on `u`'s side. A line
            // turns about the axis one way all along (`ω`, the sign of `o × d` across it), so
            // it leaves by the end it turns towards; through the axis (`ω = 0`) by either.
            if hi.y - lo.y < 4.0 {
                let near = -1e-9 * self.scale;
                let omega = o.x * d.y - o.y * d.x;
                let ends = match omega.partial_cmp(&0.0) {
                    Some(std::cmp::Ordering::Greater) => [None, Some(hi.y)],
                    Some(std::cmp::Ordering::Less) => [Some(lo.y), None],
                    _ => [Some(lo.y), Some(hi.y)],
                };
                for phi in ends.into_iter().flatten() {
                    let (ux, uy) = direction_of_pseudo(phi);
                    let f1 = ux * d.y - uy * d.x;
                    if f1 != 0.0 {
                        let tc = (uy * o.x - ux * o.y) / f1;
                        let along = ux * (o.x + tc * d.x) + uy * (o.y + tc * d.y);
                        if tc >= behind && along >= near {
                            exit = exit.min(tc);
                        }
                    }
                }
            }
        }
        // (NaN, from a degenerate ray, stays at `t`.)
        if exit > t {
            exit
        } else {
            t
        }
    }
}

impl TwoLevelGrid {
    /// The first `t` of `span` from which the ray may lie in a grid cell that references a
    /// kept cell (`mask`, from [`TwoLevelGrid::cells_holding`] with `keep`), with the ray's
    /// exit from that grid cell and a kept cell it references (a hint for locating the sample
    /// there); `None` if no such grid cell lies on the span. Every point of the ray before
    /// the answer lies in grid cells that reference no kept cell, so no kept cell holds it.
    /// Where the walk cannot go on — the ray leaves the grid's domain (the space outside the
    /// mesh, which the fast path crosses by the boundary surface), a step would not leave its
    /// cell, or after [`MAX_GRID_WALK`] cells — it stops there, with no hint: the caller then
    /// samples from there as it would without jumping. `None` for a mask made for another
    /// grid. Top and leaf cells visited are counted in `counters`.
    pub(crate) fn next_marked(
        &self,
        span: RaySpan,
        mask: &GridMask,
        keep: impl Fn(u32) -> bool,
        counters: &mut Counters,
    ) -> Option<(f64, f64, Option<u32>)> {
        let stats = self.stats();
        if !mask.fits(stats.top_cells, stats.leaf_cells) {
            return None;
        }
        let (origin, dir) = (span.origin, span.dir);
        let coordinates = self.coordinates();
        let ray = GridRay::new(coordinates, origin, dir);
        let at = |t: f64, counters: &mut Counters| {
            self.masked_cell_at(coordinates.query(origin + dir * t), mask, counters)
        };
        let mut t = span.t0;
        let mut here = at(t, counters);
        for _ in 0..MAX_GRID_WALK {
            let region = match here {
                MaskedCell::Outside => return Some((t, t, None)),
                MaskedCell::Kept(leaf, region) => {
                    let hint = self.leaf_refs(leaf).iter().copied().find(|&c| keep(c));
                    return Some((t, ray.exit(&region, t), hint));
                }
                MaskedCell::Empty(region) => region,
            };
            let exit = ray.exit(&region, t);
            if exit > span.t1 {
                return None;
            }
            // The exit's point lies on the region's face up to rounding, so it may be
            // classified into the region again: step past it by the least amount that leaves
            // it, far below the pieces' padding, or stop.
            let limit = GRID_STEP_LIMIT * ray.least_extent(&region);
            let mut step = f64::EPSILON * exit.abs().max(ray.scale);
            loop {
                if step > limit || limit.is_nan() {
                    return Some((exit, exit, None));
                }
                let next = at(exit + step, counters);
                if next != here {
                    (t, here) = (exit + step, next);
                    break;
                }
                step *= 2.0;
            }
        }
        Some((t, t, None))
    }
}
