//! Rotational periodicity: a sector mesh whose `N` copies, each turned by `360°/N` about the
//! machine axis, make the whole wheel.
//!
//! Turbomachinery CFD runs one blade passage or one sector with rotationally periodic
//! boundaries. [`detect`] finds whether a mesh is such a sector and how many copies close the
//! wheel; [`check_copies`] checks a number of copies a user forces. Both work about an [`Axis`]
//! (the detected machine axis, or one given).
//!
//! # What is checked
//! - **The sector's angle.** The arc of angles about the axis that the mesh's points cover
//!   (start and span, exact from the points). A mesh whose cells go all the way round is a full
//!   ring, not a sector.
//! - **A whole number of copies.** `360° / span` must be within [`SPAN_TOLERANCE`] (relative) of
//!   a whole number `N ≥ 2`.
//! - **Matching sides.** Every boundary face on the sector's two angular extremes (its points
//!   within a hair of the start or end angle) must land, turned by `±360°/N`, on a boundary face
//!   of the other side: each of its points on a boundary point within [`MATCH_TOLERANCE`] of the
//!   face's shortest edge. The worst such distance is reported, in units of that edge.
//!
//! A forced count ([`check_copies`]) is refused when its copies would overlap or leave gaps
//! (`N × span` not 360° within the tolerance), whether or not the sides' points match (meshes
//! whose periodic sides are not conformal are common); how well they match is reported.
//!
//! ```
//! use cylvol::axis::periodic;
//! // The OpenFOAM mixer: a 90° sector about z, four copies make the wheel.
//! let mesh = cylvol::input::load("tests/data/mixer.vtk", &Default::default()).unwrap();
//! let found = periodic::detect(&mesh, &cylvol::axis::detect(&mesh)).unwrap();
//! assert_eq!(found.copies, 4);
//! assert!((found.span_degrees() - 90.0).abs() < 1e-6);
//! assert!(found.worst_mismatch < 1e-6);
//! // Three copies of it would leave a gap of 90°.
//! assert!(periodic::check_copies(&mesh, &found.axis, 3).is_err());
//! ```

use std::collections::{HashMap, HashSet};
use std::f64::consts::TAU;
use std::fmt;
use std::str::FromStr;

use glam::DVec3;

use super::Axis;
use crate::error::show_number;
use crate::geometry::cylindrical::{CylFrame, ThetaInterval};
use crate::mesh::topology::{face_vertices, FaceKey, FaceNeighbours};
use crate::{Error, Mesh};

/// How far `360° / span` may be from a whole number, relative to it.
pub const SPAN_TOLERANCE: f64 = 0.01;

/// How far a side's point, turned onto the other side, may be from that side's point, in units
/// of the shortest edge of its face.
pub const MATCH_TOLERANCE: f64 = 0.01;

/// The most copies a wheel may have.
pub const MAX_COPIES: u32 = 3600;

/// Points this close to the axis, relative to the largest radius, have no angle.
const ON_AXIS: f64 = 1e-9;

/// What a user asks for: find the copies, or draw a given number.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PeriodicRequest {
    /// No periodic copies: the mesh as it is.
    #[default]
    Off,
    /// Find whether the mesh is a periodic sector and how many copies close the wheel.
    Auto,
    /// Draw this many copies (at least 1), the sector's span being `360° / N`.
    Copies(u32),
}

impl fmt::Display for PeriodicRequest {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PeriodicRequest::Off => f.write_str("off"),
            PeriodicRequest::Auto => f.write_str("auto"),
            PeriodicRequest::Copies(n) => write!(f, "{n}"),
        }
    }
}

impl FromStr for PeriodicRequest {
    type Err = Error;

    /// `off`, `auto`, or a whole number of copies from 1 to [`MAX_COPIES`].
    ///
    /// ```
    /// use cylvol::axis::periodic::PeriodicRequest;
    /// assert_eq!("auto".parse::<PeriodicRequest>().unwrap(), PeriodicRequest::Auto);
    /// assert_eq!("12".parse::<PeriodicRequest>().unwrap(), PeriodicRequest::Copies(12));
    /// assert!("0".parse::<PeriodicRequest>().is_err());
    /// assert!("2.5".parse::<PeriodicRequest>().is_err());
    /// ```
    fn from_str(s: &str) -> Result<Self, Error> {
        let t = s.trim();
        if t.eq_ignore_ascii_case("auto") {
            return Ok(PeriodicRequest::Auto);
        }
        if t.eq_ignore_ascii_case("off") {
            return Ok(PeriodicRequest::Off);
        }
        match t.parse::<u32>() {
            Ok(n) if (1..=MAX_COPIES).contains(&n) => Ok(PeriodicRequest::Copies(n)),
            _ => Err(Error::Invalid(format!(
                "periodic copies '{s}': expected auto, off, or a whole number from 1 to {MAX_COPIES}"
            ))),
        }
    }
}

/// A periodic sector: how many copies make the wheel, and where the sector lies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Periodicity {
    /// The number of copies that close the wheel (each turned by `360° / copies`).
    pub copies: u32,
    /// The axis the copies turn about.
    pub axis: Axis,
    /// The angle where the sector starts, in radians, about [`Periodicity::frame`]
    /// (counter-clockwise about the axis direction).
    pub start: f64,
    /// The sector's angular span, in radians, from its points.
    pub span: f64,
    /// Boundary faces of one side matched with a face of the other side.
    pub matched_faces: usize,
    /// Faces on the sector's angular extremes that found no partner on the other side.
    pub unmatched_side_faces: usize,
    /// The largest distance between a matched side's point, turned, and its partner, in units
    /// of the shortest edge of its face (0 when no face matched).
    pub worst_mismatch: f64,
}

impl Periodicity {
    /// The angle between two copies, `360° / copies`, in radians.
    pub fn pitch(&self) -> f64 {
        TAU / f64::from(self.copies)
    }

    /// The sector's span in degrees.
    pub fn span_degrees(&self) -> f64 {
        self.span.to_degrees()
    }

    /// The cylindrical frame the angles are measured in.
    pub fn frame(&self) -> CylFrame {
        frame_of(&self.axis)
    }
}

/// Why a mesh is not (or not with the copies asked for) a periodic sector.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NotPeriodic {
    /// The mesh has no cells off the axis.
    #[error("the mesh has no cells away from the axis: it is no sector of a wheel")]
    Empty,
    /// The mesh goes all the way round the axis.
    #[error("the mesh is a full ring about the axis (its cells go all the way round): there is no sector to copy")]
    FullRing,
    /// `360° / span` is not a whole number.
    #[error(
        "the sector spans {span}°, and 360° / {span}° = {ratio} is not a whole number of copies \
         (within {tolerance} %); give the number of copies to draw it anyway"
    )]
    SpanDoesNotDivide {
        /// The span, in degrees, as shown.
        span: String,
        /// `360° / span`, as shown.
        ratio: String,
        /// The tolerance, in percent.
        tolerance: String,
    },
    /// The two sides do not land on each other.
    #[error(
        "the sector spans {span}° ({copies} copies), but its sides do not match: {unmatched} of \
         the {side} boundary faces on its angular extremes land on no face of the other side \
         when turned by {pitch}° ({worst}; at most {tolerance} of an edge allowed); give the \
         number of copies to draw it anyway"
    )]
    SidesDoNotMatch {
        /// The span, in degrees, as shown.
        span: String,
        /// The copies `360° / span` suggests.
        copies: u32,
        /// `360° / copies`, as shown.
        pitch: String,
        /// Faces on the extremes without a partner.
        unmatched: usize,
        /// Faces on the extremes.
        side: usize,
        /// How far the worst point lands from the other side, in words.
        worst: String,
        /// [`MATCH_TOLERANCE`], as shown.
        tolerance: String,
    },
    /// A forced count whose copies overlap or leave gaps.
    #[error(
        "{copies} copies of a sector spanning {span}° cover {cover}°, not 360°: they would {what} \
         (the sector's span must be 360° / {copies} = {pitch}° within {tolerance} %)"
    )]
    CopiesDoNotFit {
        /// The copies asked for.
        copies: u32,
        /// The span, in degrees, as shown.
        span: String,
        /// `copies × span`, as shown.
        cover: String,
        /// `overlap` or `leave gaps`.
        what: &'static str,
        /// `360° / copies`, as shown.
        pitch: String,
        /// The tolerance, in percent.
        tolerance: String,
    },
    /// No boundary face lies on the sector's start or end angle.
    #[error(
        "the sector spans {span}° ({copies} copies), but no boundary face lies on its start or \
         end angle: its sides are not surfaces of constant angle about the axis, so one cannot \
         be matched with the other; give the number of copies to draw it anyway"
    )]
    NoSides {
        /// The span, in degrees, as shown.
        span: String,
        /// The copies `360° / span` suggests.
        copies: u32,
    },
    /// The axis has no direction.
    #[error("the axis has no direction")]
    BadAxis,
}

impl From<NotPeriodic> for Error {
    fn from(e: NotPeriodic) -> Error {
        Error::Invalid(format!("not a periodic sector: {e}"))
    }
}

/// Finds whether `mesh` is a periodic sector about `axis`, and how many copies close the wheel
/// (see the module docs for what is checked).
pub fn detect(mesh: &Mesh, axis: &Axis) -> Result<Periodicity, NotPeriodic> {
    let sector = Sector::of(mesh, axis)?;
    let ratio = TAU / sector.arc.width();
    let copies = ratio.round();
    if copies < 2.0 || (ratio - copies).abs() > SPAN_TOLERANCE * copies {
        return Err(NotPeriodic::SpanDoesNotDivide {
            span: degrees(sector.arc.width()),
            ratio: format!("{ratio:.3}"),
            tolerance: show_number(SPAN_TOLERANCE * 100.0),
        });
    }
    let copies = copies as u32;
    let sides = match_sides(mesh, &sector, TAU / f64::from(copies));
    if sides.on_extremes == 0 {
        return Err(NotPeriodic::NoSides {
            span: degrees(sector.arc.width()),
            copies,
        });
    }
    if sides.unmatched > 0 || sides.matched == 0 {
        return Err(NotPeriodic::SidesDoNotMatch {
            span: degrees(sector.arc.width()),
            copies,
            pitch: degrees(TAU / f64::from(copies)),
            unmatched: sides.unmatched,
            side: sides.on_extremes,
            worst: if sides.worst.is_finite() {
                format!(
                    "the worst point lands {:.3} of its face's shortest edge away",
                    sides.worst
                )
            } else {
                "some points land with no boundary point within a cell of them".into()
            },
            tolerance: show_number(MATCH_TOLERANCE),
        });
    }
    Ok(sector.periodicity(copies, &sides))
}

/// Checks that `copies` copies of `mesh` turned about `axis` make the wheel: the sector's span
/// is `360° / copies` within [`SPAN_TOLERANCE`]. How well the sides match is reported, not
/// required. One copy is the mesh itself, whatever it spans.
pub fn check_copies(mesh: &Mesh, axis: &Axis, copies: u32) -> Result<Periodicity, NotPeriodic> {
    let sector = Sector::of(mesh, axis);
    if copies == 1 {
        // The mesh alone: a full ring is fine too.
        let (start, span) = match &sector {
            Ok(s) => (s.arc.start(), s.arc.width()),
            Err(_) => (0.0, TAU),
        };
        return Ok(Periodicity {
            copies,
            axis: *axis,
            start,
            span,
            matched_faces: 0,
            unmatched_side_faces: 0,
            worst_mismatch: 0.0,
        });
    }
    let sector = sector?;
    let pitch = TAU / f64::from(copies);
    let span = sector.arc.width();
    if (span - pitch).abs() > SPAN_TOLERANCE * pitch {
        return Err(NotPeriodic::CopiesDoNotFit {
            copies,
            span: degrees(span),
            cover: degrees(span * f64::from(copies)),
            what: if span > pitch {
                "overlap"
            } else {
                "leave gaps"
            },
            pitch: degrees(pitch),
            tolerance: show_number(SPAN_TOLERANCE * 100.0),
        });
    }
    let sides = match_sides(mesh, &sector, pitch);
    Ok(sector.periodicity(copies, &sides))
}

/// The faces of the sector's start side (`(cell, face)`, 0–5 in VTK's face order) each with
/// the face of its end side it lands on turned by the pitch: the faces a periodic wheel joins.
/// `neighbours` are the mesh's face neighbours (the faces without one are its boundary). Empty
/// where no side face matches (sides that are not conformal, or not surfaces of constant angle).
pub fn side_pairs(
    mesh: &Mesh,
    neighbours: &FaceNeighbours,
    periodicity: &Periodicity,
) -> Vec<[(u32, u8); 2]> {
    let Ok(mut sector) = Sector::about(mesh, &periodicity.axis) else {
        return Vec::new();
    };
    sector.faces = boundary_faces(mesh, neighbours);
    match_sides(mesh, &sector, periodicity.pitch()).pairs
}

/// Resolves a request: `Ok(None)` for [`PeriodicRequest::Off`], the sector found or checked
/// otherwise.
pub fn resolve(
    mesh: &Mesh,
    axis: &Axis,
    request: PeriodicRequest,
) -> Result<Option<Periodicity>, NotPeriodic> {
    match request {
        PeriodicRequest::Off => Ok(None),
        PeriodicRequest::Auto => detect(mesh, axis).map(Some),
        PeriodicRequest::Copies(n) => check_copies(mesh, axis, n).map(Some),
    }
}

/// The copies `first..end` of the wheel that `periodicity` makes of `mesh`, as one mesh: copy
/// `k`'s points turned by `k · 360°/N` about the axis, its cells and arrays after copy
/// `k − 1`'s, as VTK's `vtkAngularPeriodicFilter` makes them (the points where copies meet are
/// kept once per copy). Three-component arrays are vectors and turn with their copy; every
/// other array is copied as it is. The active scalar stays the same array.
pub fn replicate(
    mesh: &Mesh,
    periodicity: &Periodicity,
    (first, end): (u32, u32),
) -> Result<Mesh, Error> {
    let n = periodicity.copies;
    if first >= end || end > n {
        return Err(Error::Invalid(format!(
            "copies {first}:{end} are not a range of the wheel's {n} copies"
        )));
    }
    let frame = periodicity.frame();
    let count = (end - first) as usize;
    let points_per = mesh.point_count();
    if (points_per * count) as u64 > u64::from(u32::MAX) {
        return Err(Error::Invalid(format!(
            "{count} copies of {points_per} points are more than 32-bit point ids address"
        )));
    }
    let angles: Vec<f64> = (first..end)
        .map(|k| f64::from(k) * periodicity.pitch())
        .collect();
    let points = angles
        .iter()
        .flat_map(|&a| mesh.points().iter().map(move |&p| turn(&frame, p, a)))
        .collect();
    let cells = (0..count)
        .flat_map(|k| {
            let offset = (k * points_per) as u32;
            mesh.cells().iter().map(move |c| c.map(|i| i + offset))
        })
        .collect();
    let kinds = mesh.kinds().repeat(count);
    let copy_arrays = |arrays: &[crate::DataArray]| -> Vec<crate::DataArray> {
        arrays
            .iter()
            .map(|a| {
                let values = angles
                    .iter()
                    .flat_map(|&angle| turned_values(&frame, a, angle))
                    .collect();
                crate::DataArray {
                    name: a.name.clone(),
                    components: a.components,
                    values,
                }
            })
            .collect()
    };
    let mut out = Mesh::from_parts(crate::MeshParts {
        points,
        cells,
        kinds,
        point_data: copy_arrays(mesh.point_data()),
        cell_data: copy_arrays(mesh.cell_data()),
    })?;
    if let Some(active) = mesh.active_scalar() {
        let name = active.selector(mesh.point_data(), mesh.cell_data());
        out.set_active_scalar(&name)?;
    }
    Ok(out)
}

/// The values of array `a` in a copy turned by `angle`: a vector's tuples turned with it.
fn turned_values(frame: &CylFrame, a: &crate::DataArray, angle: f64) -> Vec<f64> {
    if a.components != 3 {
        return a.values.clone();
    }
    let (s, c) = angle.sin_cos();
    a.values
        .chunks_exact(3)
        .flat_map(|v| {
            let v = DVec3::new(v[0], v[1], v[2]);
            let (x, y) = (v.dot(frame.e1), v.dot(frame.e2));
            let w = frame.e1 * (x * c - y * s)
                + frame.e2 * (x * s + y * c)
                + frame.axis * v.dot(frame.axis);
            [w.x, w.y, w.z]
        })
        .collect()
}

/// An angle in radians shown in degrees to a thousandth, without trailing zeros.
fn degrees(radians: f64) -> String {
    let text = format!("{:.3}", radians.to_degrees());
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn frame_of(axis: &Axis) -> CylFrame {
    CylFrame::new(axis.origin, axis.direction).unwrap_or(CylFrame {
        origin: axis.origin,
        axis: DVec3::Z,
        e1: DVec3::X,
        e2: DVec3::Y,
    })
}

/// The point `p` turned by `angle` (radians, counter-clockwise about the frame's axis).
pub fn turn(frame: &CylFrame, p: DVec3, angle: f64) -> DVec3 {
    let l = frame.to_local(p);
    let (s, c) = angle.sin_cos();
    frame.origin
        + frame.e1 * (l.x * c - l.y * s)
        + frame.e2 * (l.x * s + l.y * c)
        + frame.axis * l.z
}

/// The arc a mesh covers about an axis.
struct Sector {
    frame: CylFrame,
    axis: Axis,
    arc: ThetaInterval,
    /// Each point's angle (NaN on the axis).
    angles: Vec<f64>,
    /// The mesh's boundary faces (empty until [`Sector::of`] fills them in).
    faces: Vec<Face>,
}

impl Sector {
    /// The sector about `axis`, or about the line where its two planar sides meet when it has
    /// such sides (a detected axis is off by a hair; the sides fix it exactly).
    fn of(mesh: &Mesh, axis: &Axis) -> Result<Sector, NotPeriodic> {
        let rough = Sector::about(mesh, axis)?;
        let neighbours =
            FaceNeighbours::build_with_tolerance(mesh, FaceNeighbours::seam_tolerance(mesh));
        let faces = boundary_faces(mesh, &neighbours);
        let mut sector = match rough.sides_meet(mesh, &faces) {
            Some(exact) => Sector::about(mesh, &exact)?,
            None => rough,
        };
        sector.faces = faces;
        Ok(sector)
    }

    fn about(mesh: &Mesh, axis: &Axis) -> Result<Sector, NotPeriodic> {
        let frame = CylFrame::new(axis.origin, axis.direction).ok_or(NotPeriodic::BadAxis)?;
        let cyl: Vec<(f64, f64)> = mesh
            .points()
            .iter()
            .map(|&p| {
                let (r, t, _) = frame.to_cylindrical(p);
                (r, t)
            })
            .collect();
        let r_max = cyl.iter().map(|c| c.0).fold(0.0, f64::max);
        let angles: Vec<f64> = cyl
            .iter()
            .map(|&(r, t)| if r > ON_AXIS * r_max { t } else { f64::NAN })
            .collect();
        let used = used_points(mesh);
        let arc = ThetaInterval::from_angles(
            angles
                .iter()
                .zip(&used)
                .filter(|(a, &u)| u && !a.is_nan())
                .map(|(&a, _)| a),
        );
        if arc.is_empty() {
            return Err(NotPeriodic::Empty);
        }
        if arc.is_full() || cells_close_the_ring(mesh, &angles, &arc) {
            return Err(NotPeriodic::FullRing);
        }
        Ok(Sector {
            frame,
            axis: *axis,
            arc,
            angles,
            faces: Vec::new(),
        })
    }

    /// The line where the planes of the sector's two sides meet: the sides being the boundary
    /// faces facing round the axis (normal within [`SIDE_NORMAL`] of the circumferential
    /// direction) within a tenth of the span from either extreme. `None` when either side has
    /// no such face, is not planar, or the planes are parallel.
    fn sides_meet(&self, mesh: &Mesh, faces: &[Face]) -> Option<Axis> {
        let band = 0.1 * self.arc.width();
        let mut sides: [Vec<DVec3>; 2] = [Vec::new(), Vec::new()];
        for face in faces {
            let p = face.ids.map(|i| mesh.points()[i as usize]);
            let Some(normal) = (p[2] - p[0]).cross(p[3] - p[1]).try_normalize() else {
                continue;
            };
            let centre = (p[0] + p[1] + p[2] + p[3]) * 0.25;
            let l = self.frame.to_local(centre);
            let Some(round) = (self.frame.e2 * l.x - self.frame.e1 * l.y).try_normalize() else {
                continue;
            };
            if normal.dot(round).abs() < SIDE_NORMAL {
                continue;
            }
            let (_, t, _) = self.frame.to_cylindrical(centre);
            let from_start = (t - self.arc.start()).rem_euclid(TAU);
            if from_start <= band {
                sides[0].extend(p);
            } else if (from_start - self.arc.width()).abs() <= band {
                sides[1].extend(p);
            }
        }
        let [a, b] = [plane_of(&sides[0])?, plane_of(&sides[1])?];
        let direction = a.0.cross(b.0).try_normalize()?;
        let direction = if direction.dot(self.frame.axis) < 0.0 {
            -direction
        } else {
            direction
        };
        // The point of both planes nearest the rough axis's origin.
        let rows = [a.0, b.0, direction];
        let rhs = [a.1, b.1, direction.dot(self.frame.origin)];
        let origin = solve3(rows, rhs)?;
        Some(
            Axis::new(origin, direction)
                .ok()?
                .through_nearest(self.frame.origin),
        )
    }

    fn periodicity(&self, copies: u32, sides: &Sides) -> Periodicity {
        Periodicity {
            copies,
            axis: self.axis,
            start: self.arc.start(),
            span: self.arc.width(),
            matched_faces: sides.matched,
            unmatched_side_faces: sides.unmatched,
            worst_mismatch: sides.worst,
        }
    }

    /// Whether point `i` lies on the sector's start (`Some(false)`) or end (`Some(true)`) angle.
    fn extreme(&self, i: u32) -> Option<bool> {
        let a = self.angles[i as usize];
        if a.is_nan() {
            return None;
        }
        let eps = EXTREME * self.arc.width();
        let from_start = (a - self.arc.start()).rem_euclid(TAU);
        if from_start <= eps || from_start >= TAU - eps {
            Some(false)
        } else if (from_start - self.arc.width()).abs() <= eps {
            Some(true)
        } else {
            None
        }
    }
}

/// A point within this fraction of the span from the sector's start or end angle lies on that
/// side.
const EXTREME: f64 = 1e-5;

/// How closely a side face's normal must follow the circumferential direction (cosine).
const SIDE_NORMAL: f64 = 0.95;

/// A side whose points lie off its plane by more than this fraction of its extent is not planar.
const PLANAR: f64 = 1e-4;

/// The plane through `points` (unit normal `n` and `d = n · x`), or `None` when there are too
/// few points or they do not lie on one plane.
fn plane_of(points: &[DVec3]) -> Option<(DVec3, f64)> {
    if points.len() < 3 {
        return None;
    }
    let centre = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    let mut m = [[0.0; 3]; 3];
    for p in points {
        let d = (*p - centre).to_array();
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v += d[i] * d[j];
            }
        }
    }
    let (_, vectors) = super::optimize::symmetric_eigen(m);
    let normal = DVec3::new(vectors[0][2], vectors[1][2], vectors[2][2]).try_normalize()?;
    let extent = points
        .iter()
        .map(|p| p.distance(centre))
        .fold(0.0, f64::max);
    let off = points
        .iter()
        .map(|p| (*p - centre).dot(normal).abs())
        .fold(0.0, f64::max);
    (extent > 0.0 && off <= PLANAR * extent).then_some((normal, normal.dot(centre)))
}

/// Solves the 3×3 system whose rows are `rows` (Cramer's rule); `None` when it is singular.
fn solve3(rows: [DVec3; 3], rhs: [f64; 3]) -> Option<DVec3> {
    let det = rows[0].dot(rows[1].cross(rows[2]));
    if det.abs() < 1e-12 || !det.is_finite() {
        return None;
    }
    let cols = glam::DMat3::from_cols(rows[0], rows[1], rows[2]).transpose();
    let x = cols.inverse() * DVec3::from_array(rhs);
    x.is_finite().then_some(x)
}

fn used_points(mesh: &Mesh) -> Vec<bool> {
    let mut used = vec![false; mesh.point_count()];
    for cell in mesh.cells() {
        for &i in cell {
            used[i as usize] = true;
        }
    }
    used
}

/// Whether some cell's own arc covers the middle of the gap the points leave (a full ring whose
/// points leave one gap no wider than a cell).
fn cells_close_the_ring(mesh: &Mesh, angles: &[f64], arc: &ThetaInterval) -> bool {
    let gap_middle = arc.end() + 0.5 * (TAU - arc.width());
    mesh.cells().iter().any(|cell| {
        let corners = cell.iter().map(|&i| angles[i as usize]);
        if corners.clone().any(f64::is_nan) {
            return false;
        }
        let own = ThetaInterval::from_angles(corners);
        own.width() < std::f64::consts::PI && own.contains(gap_middle)
    })
}

/// The result of matching the sides.
struct Sides {
    matched: usize,
    unmatched: usize,
    on_extremes: usize,
    worst: f64,
    /// Each matched face of the sector's start with its partner on the end: `(cell, face)`.
    pairs: Vec<[(u32, u8); 2]>,
}

/// Matches the boundary faces of the sector's start with those of its end turned by `pitch`.
fn match_sides(mesh: &Mesh, sector: &Sector, pitch: f64) -> Sides {
    let faces = &sector.faces;
    let keys: HashMap<FaceKey, (u32, u8)> = faces
        .iter()
        .map(|f| (FaceKey::new(f.ids), (f.cell, f.face)))
        .collect();
    let index = PointIndex::new(mesh, faces);
    let mut sides = Sides {
        matched: 0,
        unmatched: 0,
        on_extremes: 0,
        worst: 0.0,
        pairs: Vec::new(),
    };
    for face in faces {
        let ends: Vec<Option<bool>> = face.ids.iter().map(|&i| sector.extreme(i)).collect();
        let side = match ends[..] {
            [Some(a), Some(b), Some(c), Some(d)] if a == b && b == c && c == d => a,
            _ => continue,
        };
        sides.on_extremes += 1;
        // A start face turns forward onto the end; an end face backward onto the start.
        let angle = if side { -pitch } else { pitch };
        let edge = face.shortest_edge(mesh);
        let mut partner = [0u32; 4];
        let mut worst = 0.0f64;
        let mut found = true;
        for (k, &i) in face.ids.iter().enumerate() {
            let p = turn(&sector.frame, mesh.points()[i as usize], angle);
            match index.nearest(mesh, p) {
                Some((j, d)) => {
                    partner[k] = j;
                    worst = worst.max(d / edge);
                }
                None => found = false,
            }
        }
        let other = keys.get(&FaceKey::new(partner)).copied();
        let matched = found
            && worst <= MATCH_TOLERANCE
            && other.is_some()
            && partner.iter().all(|&j| sector.extreme(j) == Some(!side));
        if let (true, Some(other)) = (matched, other) {
            sides.matched += 1;
            sides.worst = sides.worst.max(worst);
            if !side {
                sides.pairs.push([(face.cell, face.face), other]);
            }
        } else {
            sides.unmatched += 1;
            if found {
                sides.worst = sides.worst.max(worst);
            } else {
                sides.worst = f64::INFINITY;
            }
        }
    }
    // Each pair is counted from both sides.
    sides.matched /= 2;
    sides
}

/// A boundary face: its cell, its index in the cell (0–5) and its four point ids as the cell
/// lists them.
struct Face {
    cell: u32,
    face: u8,
    ids: [u32; 4],
}

impl Face {
    fn shortest_edge(&self, mesh: &Mesh) -> f64 {
        let p = |k: usize| mesh.points()[self.ids[k] as usize];
        (0..4)
            .map(|k| p(k).distance(p((k + 1) % 4)))
            .filter(|&d| d > 0.0)
            .fold(f64::INFINITY, f64::min)
    }
}

fn boundary_faces(mesh: &Mesh, neighbours: &FaceNeighbours) -> Vec<Face> {
    let mut faces = Vec::new();
    for (c, cell) in mesh.cells().iter().enumerate() {
        for f in 0..6 {
            if neighbours.neighbour(c as u32, f).is_some() {
                continue;
            }
            let s = face_vertices(f);
            let ids = [cell[s[0]], cell[s[1]], cell[s[2]], cell[s[3]]];
            if FaceKey::new(ids).is_degenerate() || neighbours.is_seam(c as u32, f) {
                continue;
            }
            faces.push(Face {
                cell: c as u32,
                face: f as u8,
                ids,
            });
        }
    }
    faces
}

/// The boundary faces' points hashed in cubes of the faces' median shortest edge.
struct PointIndex {
    size: f64,
    cubes: HashMap<[i64; 3], Vec<u32>>,
}

impl PointIndex {
    fn new(mesh: &Mesh, faces: &[Face]) -> PointIndex {
        let mut edges: Vec<f64> = faces
            .iter()
            .map(|f| f.shortest_edge(mesh))
            .filter(|e| e.is_finite())
            .collect();
        let size = if edges.is_empty() {
            1.0
        } else {
            let mid = edges.len() / 2;
            *edges.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        let mut seen = HashSet::new();
        let mut cubes: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for f in faces {
            for &i in &f.ids {
                if seen.insert(i) {
                    let key = cube(mesh.points()[i as usize], size);
                    cubes.entry(key).or_default().push(i);
                }
            }
        }
        PointIndex { size, cubes }
    }

    /// The boundary point nearest `p` within one cube's size, and its distance.
    fn nearest(&self, mesh: &Mesh, p: DVec3) -> Option<(u32, f64)> {
        let [x, y, z] = cube(p, self.size);
        let mut best: Option<(u32, f64)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(ids) = self.cubes.get(&[x + dx, y + dy, z + dz]) else {
                        continue;
                    };
                    for &i in ids {
                        let d = mesh.points()[i as usize].distance(p);
                        if best.map_or(true, |(_, b)| d < b) {
                            best = Some((i, d));
                        }
                    }
                }
            }
        }
        best.filter(|&(_, d)| d <= self.size)
    }
}

fn cube(p: DVec3, size: f64) -> [i64; 3] {
    let q = p / size;
    [q.x.floor() as i64, q.y.floor() as i64, q.z.floor() as i64]
}
