//! The periodic options of the rendering commands: `--periodic auto|N|off` draws the whole
//! wheel from one rotationally periodic sector (found with `auto`, [`cylvol::axis::periodic`]),
//! `--copies K0:K1` only some of its copies. Both are checked before anything is built.

use super::log;
use super::number::show;
use cylvol::axis::periodic::{self, PeriodicRequest};
use cylvol::axis::Axis;
use cylvol::render::{Copies, Topology};
use cylvol::{Error, Mesh};
use serde_json::{json, Value};

/// The periodic options.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct PeriodicArgs {
    /// Draw the whole wheel from one rotationally periodic sector: `auto` finds how many
    /// copies close it (the sector's span must divide 360° and its sides match), `N` draws N
    /// copies each turned by 360°/N; `off` draws the mesh as it is.
    #[arg(long, value_name = "auto|N|off", default_value = "off")]
    pub periodic: PeriodicRequest,
    /// Draw only copies K0 to K1 − 1 of the wheel (copy k is the sector turned by k × 360°/N;
    /// e.g. `0:3` for three quarters of a four-copy wheel); needs `--periodic`.
    #[arg(long, value_name = "K0:K1", value_parser = parse_copies)]
    pub copies: Option<(u32, u32)>,
}

/// Parses `--copies K0:K1` (whole numbers, `K0 < K1`).
pub fn parse_copies(s: &str) -> Result<(u32, u32), String> {
    let parts: Vec<&str> = s.split(':').collect();
    let numbers: Option<Vec<u32>> = parts.iter().map(|p| p.trim().parse().ok()).collect();
    match numbers.as_deref() {
        Some(&[a, b]) if a < b => Ok((a, b)),
        _ => Err(format!(
            "copies '{s}' must be K0:K1, two whole numbers with K0 < K1 (copies K0 to K1 - 1)"
        )),
    }
}

impl PeriodicArgs {
    /// The copies to draw about `axis`, found or checked, and logged; `None` for `off`. An
    /// error where the mesh is no periodic sector (with the reason), where the copies asked
    /// for do not fit, or where `--copies` is given without `--periodic`.
    pub fn copies(&self, mesh: &Mesh, axis: &Axis) -> Result<Option<Copies>, Error> {
        if self.periodic == PeriodicRequest::Off {
            if self.copies.is_some() {
                return Err(Error::Invalid(
                    "--copies needs --periodic (auto or the number of copies)".into(),
                ));
            }
            return Ok(None);
        }
        let Some(found) = periodic::resolve(mesh, axis, self.periodic)? else {
            return Ok(None);
        };
        let copies = Copies::new(mesh, found, self.copies)?;
        let (first, end) = copies.range();
        log(format_args!(
            "periodic: {} copies of a {}° sector make the wheel ({} side faces matched, worst {} \
             of a cell edge); drawing copies {first} to {}",
            found.copies,
            show(found.span_degrees()),
            found.matched_faces,
            show(found.worst_mismatch),
            end - 1
        ));
        if found.matched_faces == 0 && found.copies > 1 {
            log(format_args!(
                "warning: no side face of the sector lands on the other side turned by {}°: \
                 the copies are drawn side by side, and a ray crossing from one into the next \
                 meets the sector's boundary there",
                show(360.0 / f64::from(found.copies))
            ));
        }
        Ok(Some(copies))
    }
}

/// The topology the fast path walks, for the wheel of `copies` where there are copies: the
/// sector's sides joined where they land on each other.
pub fn wheel_topology(topology: Topology, mesh: &Mesh, copies: Option<&Copies>) -> Topology {
    match copies {
        Some(c) => topology.with_periodic_sides(mesh, c.periodicity()).0,
        None => topology,
    }
}

/// The JSON of the copies drawn (`null` for none): how many close the wheel, the copies drawn
/// (`first` to `end` − 1), the sector's span, its side faces joined and their worst mismatch,
/// and the wheel's box.
pub fn json(copies: Option<&Copies>) -> Value {
    match copies {
        None => Value::Null,
        Some(c) => {
            let p = c.periodicity();
            json!({
                "copies": p.copies,
                "first": c.range().0,
                "end": c.range().1,
                "span_deg": p.span_degrees(),
                "matched_faces": p.matched_faces,
                "worst_mismatch": p.worst_mismatch,
                "bounds": c.bounds(),
            })
        }
    }
}
