//! The scene the rendering commands share (`render`, `bench`, `accuracy`, `demo`): the
//! structure chosen by `auto`, the default transfer function from the scalar range and the
//! mesh's diagonal, the camera from a `--view` preset, and the face neighbours of the fast
//! path. One place, so that every command renders the same picture of the same mesh.

use std::time::Instant;

use super::log;
use super::number::show;
use cylvol::accel::Accel;
use cylvol::accel::StructureKind;
use cylvol::axis::Axis;
use cylvol::render::Topology;
use cylvol::render::{TransferFunction, MAX_SAMPLES_PER_RAY};
use cylvol::{Error, Mesh};

/// The default `--view`: VTK's reset camera (looking down `−z` at the bounds' centre).
pub const DEFAULT_VIEW: [f64; 3] = [0.0, 0.0, 1.0];

/// Maximum opacity of the default transfer function, per hundredth of the mesh's diagonal.
pub const MAX_OPACITY: f64 = 0.3;

/// Parses a `--view AZIMUTH,ELEVATION,ZOOM` preset (degrees, degrees, a factor > 0).
pub fn parse_view(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("view '{s}' is not AZIMUTH,ELEVATION,ZOOM"))?;
    match v[..] {
        [a, e, z] if a.is_finite() && e.is_finite() && z > 0.0 && z.is_finite() => Ok([a, e, z]),
        _ => Err(format!(
            "view '{s}' must be three finite numbers AZIMUTH,ELEVATION,ZOOM with ZOOM > 0"
        )),
    }
}

/// Parses a `--max-error E`: a positive, finite number of 1/255.
pub fn parse_max_error(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(e) if e > 0.0 && e.is_finite() => Ok(e),
        _ => Err(format!(
            "max error '{s}' must be a positive number of 1/255 of a pixel's RGBA"
        )),
    }
}

/// Parses a square image side `N` (1 to 16384).
pub fn parse_side(s: &str) -> Result<u32, String> {
    let n: u32 = s
        .trim()
        .parse()
        .map_err(|_| format!("size '{s}' is not a whole number of pixels"))?;
    if n == 0 || n > 16384 {
        return Err(format!("size '{s}' must be between 1 and 16384"));
    }
    Ok(n)
}

/// A `--structure` argument: one of the four structures, or `auto`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StructureChoice {
    /// Chosen for the mesh ([`structure`]).
    Auto,
    /// This one.
    Kind(StructureKind),
}

impl std::str::FromStr for StructureChoice {
    type Err = String;

    /// `auto` or a structure's name; an error lists all five.
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(StructureChoice::Auto);
        }
        s.parse().map(StructureChoice::Kind).map_err(|_| {
            let names: Vec<&str> = StructureKind::ALL.iter().map(|k| k.name()).collect();
            format!(
                "unknown structure '{s}' (expected {} or auto)",
                names.join(", ")
            )
        })
    }
}

/// The structure a `--structure` argument names. `auto` predicts the cost of each family from
/// the surface area of a sample of cells' bounds about the axis and takes the cheaper BVH
/// ([`cylvol::accel::choose::auto_structure`]): cylindrical for turbomachinery meshes,
/// Cartesian for a Cartesian block.
pub fn structure(choice: StructureChoice, mesh: &Mesh, axis: &Axis) -> StructureKind {
    match choice {
        StructureChoice::Auto => {
            let ratio = cylvol::accel::choose::cylindrical_area_ratio(mesh, axis);
            let kind = cylvol::accel::choose::structure_for_ratio(ratio);
            if let Some(r) = ratio {
                log(format_args!(
                    "auto: cylindrical ÷ Cartesian bound area {r:.3} over sampled cells → {kind}"
                ));
            }
            kind
        }
        StructureChoice::Kind(kind) => kind,
    }
}

/// The mesh to render, refused before anything is built for it where it holds no point or
/// cell array, or where the array to draw holds NaN or infinite values
/// ([`Mesh::drawn_scalars`]; the renderer's own refusal comes only after the structure's
/// build).
pub fn renderable(mesh: Mesh) -> Result<Mesh, Error> {
    match mesh.drawn_scalars() {
        Ok(_) => Ok(mesh),
        Err(e) if mesh.active_scalar().is_none() => Err(e),
        Err(e) => {
            let finite: Vec<String> = drawable_arrays(&mesh);
            let choice = if finite.is_empty() {
                "; no array of this mesh is finite everywhere".to_string()
            } else {
                format!(" with --scalar ({})", finite.join(", "))
            };
            Err(Error::Invalid(format!("{e}{choice}")))
        }
    }
}

/// The arrays whose values are all finite, each as `--scalar` names it.
fn drawable_arrays(mesh: &Mesh) -> Vec<String> {
    let bad = mesh.non_finite_arrays();
    let is_bad = |association, name: &str| {
        bad.iter()
            .any(|b| b.association == association && b.name == name)
    };
    let (point, cell) = (mesh.point_data(), mesh.cell_data());
    let tagged = point
        .iter()
        .enumerate()
        .map(|(i, a)| (cylvol::Association::Point, i, a))
        .chain(
            cell.iter()
                .enumerate()
                .map(|(i, a)| (cylvol::Association::Cell, i, a)),
        );
    tagged
        .filter(|(association, _, a)| !is_bad(*association, &a.name))
        .map(|(association, array, a)| {
            cylvol::mesh::ActiveScalar {
                association,
                array,
                component: a.default_component(),
            }
            .selector(point, cell)
        })
        .collect()
}

/// The length of the mesh's bounding-box diagonal.
pub fn diagonal(mesh: &Mesh) -> f64 {
    diagonal_of(mesh.bounds())
}

/// The length of the diagonal of `bounds` (`[xmin, xmax, ymin, ymax, zmin, zmax]`).
pub fn diagonal_of(b: [f64; 6]) -> f64 {
    ((b[1] - b[0]).powi(2) + (b[3] - b[2]).powi(2) + (b[5] - b[4]).powi(2)).sqrt()
}

/// The range a transfer function is laid over (the default one, and `--opacity` and
/// `--color` percentages) for the scalar range `[lo, hi]`: the range itself, or for a
/// constant field, whose range is empty, `[v − d, v + d]` with `d = max(10⁻⁶, 10⁻⁶ |v|)`,
/// as vtkCylVolMapper samples a caller's transfer function over a constant array: the value
/// then takes the function's middle, and the field is drawn as that, not left out.
pub fn transfer_range([lo, hi]: [f64; 2]) -> [f64; 2] {
    if hi > lo {
        return [lo, hi];
    }
    let d = (lo.abs() * 1e-6).max(1e-6);
    [lo - d, lo + d]
}

/// What a user should know of a constant field before it is drawn (its one value, the
/// empty range, what the picture shows and how to choose otherwise); `None` for a field
/// that varies.
pub fn constant_field_warning(mesh: &Mesh, [lo, hi]: [f64; 2]) -> Option<String> {
    if hi > lo {
        return None;
    }
    let active = mesh.active_scalar()?;
    let scalar = active.selector(mesh.point_data(), mesh.cell_data());
    let [a, b] = transfer_range([lo, hi]).map(show);
    let v = show(lo);
    Some(format!(
        "the scalar {scalar} is {v} everywhere: its range [{v}, {v}] is empty, so the \
         transfer function is laid over [{a}, {b}] and every sample takes its middle (the \
         colour and opacity at 50 %): the picture shows where the mesh is, not a field; give \
         --opacity and --color with values rather than percentages (e.g. --opacity {v}:0.05) \
         to choose how it looks, or render a varying array with --scalar"
    ))
}

/// The default transfer function over the scalar range `[lo, hi]`
/// ([`TransferFunction::default_for_range`]) with a maximum opacity of [`MAX_OPACITY`] per
/// hundredth of the scene's bounding-box diagonal `diagonal` (a mesh's, or the wheel of a
/// periodic sector's copies).
pub fn transfer_over(diagonal: f64, [lo, hi]: [f64; 2]) -> TransferFunction {
    TransferFunction::default_for_range(lo, hi, MAX_OPACITY, (diagonal / 100.0).max(1e-300))
}

/// The face neighbours the fast path walks (duplicated seams joined by position, the faces
/// left open checked against the structure), logged.
pub fn neighbours(mesh: &Mesh, accel: &Accel) -> Topology {
    let started = Instant::now();
    let n = cylvol::render::face_neighbours(mesh, accel);
    log(format_args!(
        "face neighbours: {} boundary faces, {} seam faces joined, {} hanging faces, {:.2} s",
        n.boundary_face_count(),
        n.seam_faces(),
        n.hanging_faces().unwrap_or(0),
        started.elapsed().as_secs_f64()
    ));
    n
}

/// How the samples are placed: `(step, max_error)` from `--step` and `--max-error`. An error
/// given renders error-bounded from the step (given, or the default); without one, every ray
/// is sampled at the fixed step (given, or the default: half the mean cell size, which is at
/// least as accurate as VTK's ray caster on every mesh measured, and faster than an
/// error-bounded render today).
pub fn sampling(
    mesh: &Mesh,
    step: Option<f64>,
    max_error: Option<f64>,
) -> Result<(f64, Option<f64>), Error> {
    Ok((self::step(mesh, step)?, max_error))
}

/// The sample spacing: `--step` when given (it must be positive and finite, and not so small
/// that a ray across the mesh would take more than
/// [`cylvol::render::MAX_SAMPLES_PER_RAY`] samples), else
/// [`cylvol::render::default_step`] (half the mean cell size).
pub fn step(mesh: &Mesh, given: Option<f64>) -> Result<f64, Error> {
    let Some(s) = given else {
        return Ok(cylvol::render::default_step(mesh));
    };
    if !(s > 0.0 && s.is_finite()) {
        return Err(Error::Invalid(format!(
            "--step {} must be positive and finite",
            show(s)
        )));
    }
    let diagonal = diagonal(mesh);
    let samples = diagonal / s;
    if samples > MAX_SAMPLES_PER_RAY {
        return Err(Error::Invalid(format!(
            "--step {} is too small for this mesh: a ray across its diagonal ({}) would take {} \
             samples (at most {}); give a step of at least {}",
            show(s),
            show(diagonal),
            show(samples),
            show(MAX_SAMPLES_PER_RAY),
            show(diagonal / MAX_SAMPLES_PER_RAY)
        )));
    }
    Ok(s)
}
