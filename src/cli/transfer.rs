//! The transfer-function options of `cylvol render` and `cylvol bench`: `--opacity`,
//! `--color` and `--unit-distance`, VTK's `vtkPiecewiseFunction`, `vtkColorTransferFunction`
//! and `ScalarOpacityUnitDistance` on the command line.
//!
//! A point's scalar is a value (`0.25`, `-3e4`) or a percentage of the active scalar's range
//! (`35%`), so that one command line fits any mesh. Once resolved, the points must come in
//! increasing scalar order, or the command says which one is out of place. What the options
//! leave out comes from the default transfer function ([`super::scene::transfer`]).

use super::number::show;
use cylvol::render::TransferFunction;
use cylvol::render::VTK_MAPPER_TABLE_ENTRIES;
use cylvol::Error;

/// Where a point sits on the scalar axis (or a distance), as written: absolute, or a
/// percentage of a range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Abscissa {
    /// A scalar value.
    Value(f64),
    /// A percentage of the scalar range (0 % is its low end, 100 % its high end).
    Percent(f64),
}

impl Abscissa {
    /// The scalar value this stands for over `[lo, hi]` (for a distance, `[0, length]`).
    pub fn resolve(self, [lo, hi]: [f64; 2]) -> f64 {
        match self {
            Abscissa::Value(v) => v,
            Abscissa::Percent(p) => lo + (hi - lo) * p / 100.0,
        }
    }
}

/// Points of a piecewise-linear function: an abscissa and `N` values each.
#[derive(Clone, Debug, PartialEq)]
pub struct Points<const N: usize>(pub Vec<(Abscissa, [f64; N])>);

/// The transfer-function options, shared by the commands that render one scene.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct TransferArgs {
    /// Opacity per unit distance as `S:A` points, S a scalar value or a percentage of the
    /// scalar range (`35%`), A in [0, 1], in increasing S: `0%:0,35%:0.1,70%:0.5,100%:1`
    /// (default: zero over the lowest 25 % of the range, rising to 0.3 at its top).
    #[arg(long, value_name = "S:A,S:A,...", value_parser = parse_opacity, allow_hyphen_values = true)]
    pub opacity: Option<Points<1>>,
    /// Colour as `S:R:G:B` points (components in [0, 1]), S as for `--opacity`:
    /// `0%:0.1:0.2:0.9,100%:0.9:0.1:0.1` (default: cool to warm).
    #[arg(long, value_name = "S:R:G:B,...", value_parser = parse_color, allow_hyphen_values = true)]
    pub color: Option<Points<3>>,
    /// The distance over which `--opacity` applies (VTK's `ScalarOpacityUnitDistance`), in
    /// world units or as a percentage of the mesh's bounding-box diagonal (`10%`; default 1 %).
    #[arg(long, value_name = "D", value_parser = parse_abscissa, allow_hyphen_values = true)]
    pub unit_distance: Option<Abscissa>,
    /// How the opacity is read: `sampled`, the opacity of a unit distance (VTK's image-data
    /// mappers; the default), or `attenuation`, an attenuation coefficient per unit distance
    /// (VTK's unstructured ray caster, and vtkCylVolMapper by default): a unit of distance
    /// then lets `e^(−A)` through.
    #[arg(long, value_enum, value_name = "CONVENTION", default_value_t = OpacityConvention::Sampled)]
    pub opacity_convention: OpacityConvention,
}

/// How `--opacity` is read (see [`TransferArgs::opacity_convention`]).
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OpacityConvention {
    /// The opacity of a unit distance.
    #[default]
    Sampled,
    /// An attenuation coefficient per unit distance.
    Attenuation,
}

impl TransferArgs {
    /// The transfer function over the scalar range `range` of a mesh whose bounding-box
    /// diagonal is `diagonal`: the default one (`default_tf`) with whatever the options set in
    /// its place.
    pub fn apply(
        &self,
        default_tf: TransferFunction,
        range: [f64; 2],
        diagonal: f64,
    ) -> Result<TransferFunction, Error> {
        let mut tf = default_tf;
        if let Some(Points(points)) = &self.opacity {
            tf.opacity = points
                .iter()
                .map(|&(s, [a])| (s.resolve(range), a))
                .collect();
            in_order("--opacity", tf.opacity.iter().map(|p| p.0))?;
        }
        if let Some(Points(points)) = &self.color {
            tf.color = points.iter().map(|&(s, c)| (s.resolve(range), c)).collect();
            in_order("--color", tf.color.iter().map(|p| p.0))?;
        }
        if let Some(d) = self.unit_distance {
            let d = d.resolve([0.0, diagonal]);
            if !(d > 0.0 && d.is_finite()) {
                return Err(Error::Invalid(format!(
                    "--unit-distance must be positive and finite, not {}",
                    show(d)
                )));
            }
            tf.unit_distance = d;
        }
        if self.opacity_convention == OpacityConvention::Attenuation {
            // Resampled at as many scalars as vtkCylVolMapper's tables have, so that both read
            // a transfer function alike.
            tf = tf.attenuation_as_opacity(range[0], range[1], VTK_MAPPER_TABLE_ENTRIES);
        }
        Ok(tf)
    }
}

/// An error naming the first point of `option` whose resolved scalar is below the one before.
fn in_order(option: &str, scalars: impl Iterator<Item = f64>) -> Result<(), Error> {
    let mut last = f64::NEG_INFINITY;
    for (k, s) in scalars.enumerate() {
        if !s.is_finite() {
            return Err(Error::Invalid(format!(
                "{option}: point {} has a scalar that is not finite",
                k + 1
            )));
        }
        if s < last {
            return Err(Error::Invalid(format!(
                "{option}: point {} (scalar {}) is below the point before it ({}); \
                 points go in increasing scalar order",
                k + 1,
                show(s),
                show(last)
            )));
        }
        last = s;
    }
    Ok(())
}

fn parse_abscissa(s: &str) -> Result<Abscissa, String> {
    let s = s.trim();
    let (number, percent) = match s.strip_suffix('%') {
        Some(n) => (n, true),
        None => (s, false),
    };
    let v: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a scalar value or a percentage"))?;
    if !v.is_finite() {
        return Err(format!("scalar '{s}' is not finite"));
    }
    Ok(if percent {
        Abscissa::Percent(v)
    } else {
        Abscissa::Value(v)
    })
}

/// Parses `S:V:V…` points separated by commas, each with `N` values in [0, 1].
fn parse_points<const N: usize>(s: &str, what: &str) -> Result<Points<N>, String> {
    let points = s
        .split(',')
        .map(|point| {
            let fields: Vec<&str> = point.split(':').collect();
            if fields.len() != N + 1 {
                return Err(format!("'{point}' is not {what}"));
            }
            let abscissa = parse_abscissa(fields[0])?;
            let mut values = [0.0; N];
            for (v, f) in values.iter_mut().zip(&fields[1..]) {
                *v = f
                    .trim()
                    .parse()
                    .ok()
                    .filter(|v: &f64| (0.0..=1.0).contains(v))
                    .ok_or_else(|| format!("'{f}' in '{point}' is not a number in [0, 1]"))?;
            }
            Ok((abscissa, values))
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(Points(points))
}

fn parse_opacity(s: &str) -> Result<Points<1>, String> {
    parse_points(s, "S:A")
}

fn parse_color(s: &str) -> Result<Points<3>, String> {
    parse_points(s, "S:R:G:B")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn default_tf() -> TransferFunction {
        TransferFunction::default_for_range(10.0, 20.0, 0.3, 1.0)
    }

    #[test]
    fn percentages_resolve_over_the_range_and_values_stay() {
        let args = TransferArgs {
            opacity: Some(parse_opacity("0%:0,35%:0.1,17.5:0.5,100%:1").unwrap()),
            color: Some(parse_color("0%:0.1:0.2:0.9,100%:0.9:0.1:0.1").unwrap()),
            unit_distance: Some(Abscissa::Value(2.5)),
            opacity_convention: OpacityConvention::Sampled,
        };
        let tf = args.apply(default_tf(), [10.0, 20.0], 7.0).unwrap();
        assert_eq!(
            tf.opacity,
            vec![(10.0, 0.0), (13.5, 0.1), (17.5, 0.5), (20.0, 1.0)]
        );
        assert_eq!(
            tf.color,
            vec![(10.0, [0.1, 0.2, 0.9]), (20.0, [0.9, 0.1, 0.1])]
        );
        assert_eq!(tf.unit_distance, 2.5);
        let tenth = TransferArgs {
            unit_distance: Some(parse_abscissa("10%").unwrap()),
            ..TransferArgs::default()
        };
        let tf = tenth.apply(default_tf(), [10.0, 20.0], 7.0).unwrap();
        assert!((tf.unit_distance - 0.7).abs() < 1e-15);
        // Read as attenuation: resampled over the range as the VTK mapper's tables are.
        let attenuation = TransferArgs {
            opacity_convention: OpacityConvention::Attenuation,
            ..args
        };
        let tf = attenuation.apply(default_tf(), [10.0, 20.0], 7.0).unwrap();
        assert_eq!(tf.opacity.len(), VTK_MAPPER_TABLE_ENTRIES);
        assert_eq!(tf.opacity[0], (10.0, 0.0));
        assert_eq!(
            tf.opacity[VTK_MAPPER_TABLE_ENTRIES - 1],
            (20.0, -(-1.0f64).exp_m1())
        );
    }

    #[test]
    fn what_is_not_given_stays_the_default() {
        let args = TransferArgs {
            opacity: Some(parse_opacity("-5:0.2").unwrap()),
            ..TransferArgs::default()
        };
        let tf = args.apply(default_tf(), [10.0, 20.0], 7.0).unwrap();
        assert_eq!(tf.opacity, vec![(-5.0, 0.2)]);
        assert_eq!(tf.color, default_tf().color);
        assert_eq!(tf.unit_distance, default_tf().unit_distance);
        assert_eq!(
            TransferArgs::default()
                .apply(default_tf(), [10.0, 20.0], 7.0)
                .unwrap(),
            default_tf()
        );
    }

    #[test]
    fn malformed_points_are_refused_with_the_offending_text() {
        for (bad, says) in [
            ("0%:0,50%", "'50%' is not S:A"),
            ("0%:1.5", "'1.5' in '0%:1.5' is not a number in [0, 1]"),
            ("x:0.5", "'x' is not a scalar value or a percentage"),
            ("inf:0.5", "not finite"),
            ("0:0.1:0.2", "is not S:A"),
        ] {
            let err = parse_opacity(bad).unwrap_err();
            assert!(err.contains(says), "{bad}: {err}");
        }
        assert!(parse_color("0:0.1:0.2").unwrap_err().contains("S:R:G:B"));
        assert!(parse_color("0:0.1:0.2:-0.1").is_err());
    }

    #[test]
    fn points_out_of_order_and_bad_unit_distances_are_refused() {
        let args = TransferArgs {
            opacity: Some(parse_opacity("50%:0,12:1").unwrap()),
            ..TransferArgs::default()
        };
        let err = args.apply(default_tf(), [10.0, 20.0], 7.0).unwrap_err();
        assert!(err.to_string().contains("--opacity: point 2"), "{err}");
        for d in [
            Abscissa::Value(0.0),
            Abscissa::Value(-1.0),
            Abscissa::Percent(0.0),
            Abscissa::Percent(-5.0),
        ] {
            let args = TransferArgs {
                unit_distance: Some(d),
                ..TransferArgs::default()
            };
            assert!(
                args.apply(default_tf(), [10.0, 20.0], 7.0).is_err(),
                "{d:?}"
            );
        }
        assert!(parse_abscissa("nan").is_err() && parse_abscissa("1e400").is_err());
    }
}
