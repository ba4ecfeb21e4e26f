//! `cylvol info INPUT [--json]`: counts, cell types, scalars (and which hold NaN or infinite
//! values, how many), bounds and the machine axis.

use serde::Serialize;

use super::number::show;
use super::InputArgs;
use cylvol::axis::periodic::{self, NotPeriodic, Periodicity};
use cylvol::axis::Axis;
use cylvol::{Error, Mesh};

/// Arguments of `cylvol info`.
#[derive(clap::Args, Debug)]
pub struct InfoArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Print JSON on standard output.
    #[arg(long)]
    json: bool,
}

/// What `cylvol info --json` prints.
#[derive(Serialize, Debug)]
pub struct Info {
    points: usize,
    cells: usize,
    cell_types: serde_json::Map<String, serde_json::Value>,
    scalars: Vec<String>,
    point_scalars: Vec<String>,
    cell_scalars: Vec<String>,
    active_scalar: Option<String>,
    active_association: Option<String>,
    scalar_range: Option<[f64; 2]>,
    /// The arrays holding NaN or infinite values, which cannot be drawn.
    non_finite: Vec<NonFiniteJson>,
    bounds: [f64; 6],
    axis: AxisJson,
    periodic: PeriodicJson,
}

/// Whether the mesh is one periodic sector of a wheel about the axis.
#[derive(Serialize, Debug)]
struct PeriodicJson {
    /// The copies that close the wheel; `None` when the mesh is no periodic sector.
    copies: Option<u32>,
    /// The sector's span in degrees (absent for a full ring).
    #[serde(skip_serializing_if = "Option::is_none")]
    span_deg: Option<f64>,
    /// The angle where the sector starts about the axis, in degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    start_deg: Option<f64>,
    /// Pairs of boundary faces matched between the two sides.
    #[serde(skip_serializing_if = "Option::is_none")]
    matched_faces: Option<usize>,
    /// The worst distance between matched side points, in units of their face's shortest edge.
    #[serde(skip_serializing_if = "Option::is_none")]
    worst_mismatch: Option<f64>,
    /// Why the mesh is no periodic sector.
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<String>,
}

impl PeriodicJson {
    fn of(found: Result<Periodicity, NotPeriodic>) -> PeriodicJson {
        match found {
            Ok(p) => PeriodicJson {
                copies: Some(p.copies),
                span_deg: Some(p.span_degrees()),
                start_deg: Some(p.start.to_degrees()),
                matched_faces: Some(p.matched_faces),
                worst_mismatch: Some(p.worst_mismatch),
                reason: None,
            },
            Err(e) => PeriodicJson {
                copies: None,
                span_deg: None,
                start_deg: None,
                matched_faces: None,
                worst_mismatch: None,
                reason: Some(e.to_string()),
            },
        }
    }

    /// One line for the text report.
    fn line(&self) -> String {
        match (self.copies, self.span_deg, self.worst_mismatch, &self.reason) {
            (Some(n), Some(span), Some(worst), _) => format!(
                "{n} copies of a {}° sector make the wheel ({} side faces matched, worst {} of a cell edge)",
                show(span),
                self.matched_faces.unwrap_or(0),
                show(worst)
            ),
            (_, _, _, Some(reason)) => format!("no: {reason}"),
            _ => "no".to_string(),
        }
    }
}

/// An array holding NaN or infinite values: `count` of its `values` values.
#[derive(Serialize, Debug)]
struct NonFiniteJson {
    association: String,
    name: String,
    count: usize,
    values: usize,
}

#[derive(Serialize, Debug)]
struct AxisJson {
    origin: [f64; 3],
    direction: [f64; 3],
    /// `detected` or `given`.
    source: &'static str,
    /// For a detected axis: whether the mesh clearly turns about it (false for a Cartesian box).
    #[serde(skip_serializing_if = "Option::is_none")]
    clear: Option<bool>,
}

/// Gathers the description of a mesh, about the axis given or detected (`clear` as reported by
/// detection, `None` for a given axis).
pub fn describe(mesh: &Mesh, axis: Axis, clear: Option<bool>) -> Info {
    let names = |arrays: &[cylvol::DataArray]| -> Vec<String> {
        arrays.iter().map(|a| a.name.clone()).collect()
    };
    let point_scalars = names(mesh.point_data());
    let cell_scalars = names(mesh.cell_data());
    let mut scalars = point_scalars.clone();
    for n in &cell_scalars {
        if !scalars.contains(n) {
            scalars.push(n.clone());
        }
    }
    Info {
        points: mesh.point_count(),
        cells: mesh.cell_count(),
        cell_types: mesh
            .kind_counts()
            .iter()
            .map(|(k, n)| (k.name().to_string(), (*n).into()))
            .collect(),
        scalars,
        point_scalars,
        cell_scalars,
        active_scalar: mesh
            .active_scalar()
            .map(|a| a.selector(mesh.point_data(), mesh.cell_data())),
        active_association: mesh.active_scalar().map(|a| a.association.to_string()),
        scalar_range: mesh.scalar_range(),
        non_finite: mesh
            .non_finite_arrays()
            .into_iter()
            .map(|a| NonFiniteJson {
                association: a.association.to_string(),
                name: a.name,
                count: a.count,
                values: a.values,
            })
            .collect(),
        bounds: mesh.bounds(),
        axis: AxisJson {
            origin: axis.origin.to_array(),
            direction: axis.direction.to_array(),
            source: if clear.is_some() { "detected" } else { "given" },
            clear,
        },
        periodic: PeriodicJson::of(periodic::detect(mesh, &axis)),
    }
}

pub fn run(args: &InfoArgs) -> Result<(), Error> {
    let mesh = args.input.load()?;
    let (axis, clear) = args.input.axis(&mesh);
    let info = describe(&mesh, axis, clear);
    if args.json {
        let text = serde_json::to_string_pretty(&info)
            .map_err(|e| Error::Invalid(format!("JSON output failed: {e}")))?;
        outln!("{text}");
        return Ok(());
    }
    let types: Vec<String> = mesh
        .kind_counts()
        .iter()
        .filter(|(_, n)| *n > 0)
        .map(|(k, n)| format!("{k} {n}"))
        .collect();
    outln!("{}", args.input.input);
    outln!("  points         {}", info.points);
    outln!("  cells          {} ({})", info.cells, types.join(", "));
    outln!("  point scalars  {}", info.point_scalars.join(", "));
    outln!("  cell scalars   {}", info.cell_scalars.join(", "));
    match (&info.active_scalar, info.scalar_range) {
        (Some(name), Some([lo, hi])) => outln!(
            "  active scalar  {name} ({}) range [{}, {}]",
            info.active_association.as_deref().unwrap_or("?"),
            show(lo),
            show(hi)
        ),
        _ => outln!("  active scalar  none"),
    }
    for a in &info.non_finite {
        outln!(
            "  non-finite     {} array '{}': {} of {} values {} NaN or infinite (not drawable)",
            a.association,
            a.name,
            a.count,
            a.values,
            if a.count == 1 { "is" } else { "are" }
        );
    }
    let b = info.bounds.map(show);
    outln!(
        "  bounds         x [{}, {}]  y [{}, {}]  z [{}, {}]",
        b[0],
        b[1],
        b[2],
        b[3],
        b[4],
        b[5]
    );
    let (o, d) = (info.axis.origin, info.axis.direction);
    outln!(
        "  axis           origin ({:.6}, {:.6}, {:.6}) direction ({:.6}, {:.6}, {:.6}), {}",
        o[0],
        o[1],
        o[2],
        d[0],
        d[1],
        d[2],
        match clear {
            None => "given",
            Some(true) => "detected",
            Some(false) => "detected, but no clear axis: the mesh does not turn about one",
        }
    );
    outln!("  periodic       {}", info.periodic.line());
    Ok(())
}
