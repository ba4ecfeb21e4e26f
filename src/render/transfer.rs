//! The transfer function, as VTK's volume property holds it: a piecewise-linear RGB colour
//! function and a piecewise-linear scalar opacity function of the scalar, with the opacity
//! given per **unit distance** (VTK's `ScalarOpacityUnitDistance`), sampled into a table.
//!
//! # Table and lookup
//! [`TransferFunction::table`] samples both functions at `n` (default [`DEFAULT_TABLE_SIZE`])
//! evenly spaced scalars spanning `[lo, hi]` (entry `k` at `lo + k (hi − lo)/(n − 1)`). The
//! opacity stored is already corrected to the ray step:
//! `α_step = 1 − (1 − α)^(step / unit_distance)`, so that a homogeneous medium of opacity `α`
//! per unit distance gives the transmittance `(1 − α)^(L / unit)` = `exp(−σ L)` with
//! `σ = −ln(1 − α)/unit`, whatever the step. A lookup clamps the scalar to `[lo, hi]` and
//! interpolates linearly between the two entries around it. Functions are constant beyond
//! their first and last points (VTK's clamping).
//!
//! # Transparency queries
//! [`TransferTable::transparent_over`] says in O(1) whether every lookup of a scalar in
//! `[a, b]` gives zero opacity: it checks that the entries a lookup in that range can touch
//! (the one below `a` to the one above `b`) are all zero, with a prefix count of non-zero
//! entries. The fast path skips the samples of such cells, which changes nothing in the image.
//!
//! # Gradient opacity
//! [`GradientOpacity`] is `vtkVolumeProperty`'s gradient opacity: a piecewise-linear function
//! of the gradient magnitude `|∇s|` (scalar units per world unit) whose value multiplies the
//! scalar opacity **per unit distance**, before the correction to the step:
//! `α_step = 1 − (1 − α(s) · g(|∇s|))^(step / unit_distance)` (see
//! [`TransferTable::unit_opacity`] and [`TransferTable::step_opacity`]), so the image does not
//! depend on the step for a homogeneous medium. (VTK's GPU mapper multiplies the
//! step-corrected opacity instead; the two agree to first order in the step, and exactly where
//! `g` is 0 or 1.) It is held as a fixed table of [`GRADIENT_TABLE_SIZE`] entries so that
//! [`super::RenderOptions`] stays `Copy`.

use crate::error::show_number;
use crate::Error;

/// Table entries by default.
pub const DEFAULT_TABLE_SIZE: usize = 1024;

/// Entries of a [`GradientOpacity`] table.
pub const GRADIENT_TABLE_SIZE: usize = 128;

/// The gradient opacity function (see the module documentation): `g(|∇s|)` sampled at
/// [`GRADIENT_TABLE_SIZE`] evenly spaced magnitudes over the span of its points, linear
/// between entries, constant beyond the ends (VTK's clamping).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GradientOpacity {
    lo: f64,
    scale: f64,
    table: [f32; GRADIENT_TABLE_SIZE],
}

impl GradientOpacity {
    /// From `(gradient magnitude, opacity factor)` points in increasing magnitude order,
    /// factors in `[0, 1]` (a `vtkPiecewiseFunction`'s nodes). A jump (two points at one
    /// magnitude) becomes a ramp one table entry wide.
    ///
    /// ```
    /// use cylvol::render::GradientOpacity;
    /// let g = GradientOpacity::new(&[(0.0, 0.0), (2.0, 1.0)]).unwrap();
    /// assert_eq!(g.at(-1.0), 0.0);
    /// assert!((g.at(1.0) - 0.5).abs() < 1e-6);
    /// assert_eq!(g.at(5.0), 1.0);
    /// assert!(GradientOpacity::new(&[]).is_err());
    /// ```
    pub fn new(points: &[(f64, f64)]) -> Result<GradientOpacity, Error> {
        let bad = |m: &str| Err(Error::Invalid(format!("bad gradient opacity: {m}")));
        let (Some(first), Some(last)) = (points.first(), points.last()) else {
            return bad("needs at least one point");
        };
        if !points.iter().all(|p| p.0.is_finite()) || !points.windows(2).all(|w| w[0].0 <= w[1].0) {
            return bad("magnitudes must be finite and in increasing order");
        }
        if !points.iter().all(|p| (0.0..=1.0).contains(&p.1)) {
            return bad("opacity factors must lie in [0, 1]");
        }
        let pts: Vec<(f64, [f64; 1])> = points.iter().map(|&(x, a)| (x, [a])).collect();
        let (lo, hi) = (first.0, last.0);
        let n = GRADIENT_TABLE_SIZE;
        let mut table = [0f32; GRADIENT_TABLE_SIZE];
        for (k, e) in table.iter_mut().enumerate() {
            let x = lo + (hi - lo) * k as f64 / (n - 1) as f64;
            *e = piecewise(&pts, x)[0] as f32;
        }
        let scale = if hi > lo && ((n - 1) as f64 / (hi - lo)).is_finite() {
            (n - 1) as f64 / (hi - lo)
        } else {
            0.0
        };
        Ok(GradientOpacity { lo, scale, table })
    }

    /// The same factor `g` at every magnitude (in `[0, 1]`).
    pub fn constant(g: f64) -> Result<GradientOpacity, Error> {
        GradientOpacity::new(&[(0.0, g)])
    }

    /// The factor at gradient magnitude `m` (NaN counts as the lowest magnitude).
    #[inline]
    pub fn at(&self, m: f64) -> f64 {
        let x = ((m - self.lo) * self.scale)
            .max(0.0)
            .min((GRADIENT_TABLE_SIZE - 1) as f64);
        let i = (x as usize).min(GRADIENT_TABLE_SIZE - 2);
        let f = x - i as f64;
        let (a, b) = (self.table[i] as f64, self.table[i + 1] as f64);
        if a == b {
            a
        } else {
            a + (b - a) * f
        }
    }
}

/// The entries of vtkCylVolMapper's colour and opacity tables (its `kTableSize`): where
/// [`TransferFunction::attenuation_as_opacity`] resamples to read a function as the mapper does.
pub const VTK_MAPPER_TABLE_ENTRIES: usize = 1024;

/// A piecewise-linear colour and opacity transfer function.
#[derive(Clone, Debug, PartialEq)]
pub struct TransferFunction {
    /// `(scalar, [r, g, b])` points in increasing scalar order, components in `[0, 1]`.
    pub color: Vec<(f64, [f64; 3])>,
    /// `(scalar, opacity per unit distance)` points in increasing scalar order, in `[0, 1]`.
    pub opacity: Vec<(f64, f64)>,
    /// The distance over which `opacity` applies (VTK's `ScalarOpacityUnitDistance`, default 1).
    pub unit_distance: f64,
}

/// Evaluates a piecewise-linear function of sorted points, constant beyond its ends: between
/// the last point before `s` and the first at or past it (found by bisection, so that sampling
/// a table from VTK's 1,024-entry functions costs a few comparisons an entry). At a repeated
/// abscissa the function takes the value of the first point there from below and of the last
/// from above (a step); a NaN `s` gives the last point's value.
fn piecewise<const N: usize>(points: &[(f64, [f64; N])], s: f64) -> [f64; N] {
    let Some(first) = points.first() else {
        return [0.0; N];
    };
    if s <= first.0 {
        return first.1;
    }
    // The first point at or past `s`; `s > first.0`, so it is not the first point.
    let j = 1 + points[1..].partition_point(|p| p.0 < s);
    match (points.get(j - 1), points.get(j)) {
        (Some(&(s0, v0)), Some(&(s1, v1))) if !s.is_nan() => {
            let f = if s1 > s0 { (s - s0) / (s1 - s0) } else { 1.0 };
            let mut out = [0.0; N];
            for k in 0..N {
                out[k] = v0[k] + (v1[k] - v0[k]) * f;
            }
            out
        }
        _ => points[points.len() - 1].1,
    }
}

impl TransferFunction {
    /// A constant colour and opacity (per unit distance) at every scalar.
    pub fn constant(color: [f64; 3], opacity: f64, unit_distance: f64) -> TransferFunction {
        TransferFunction {
            color: vec![(0.0, color)],
            opacity: vec![(0.0, opacity)],
            unit_distance,
        }
    }

    /// The CLI's default over `[lo, hi]`: a cool-to-warm colour map (blue, white, red) and an
    /// opacity ramp that is zero over the lowest 25 % of the range and rises linearly to
    /// `max_opacity` per `unit_distance` at `hi`.
    pub fn default_for_range(
        lo: f64,
        hi: f64,
        max_opacity: f64,
        unit_distance: f64,
    ) -> TransferFunction {
        let at = |f: f64| lo + (hi - lo) * f;
        TransferFunction {
            color: vec![
                (at(0.0), [0.23, 0.30, 0.75]),
                (at(0.5), [0.87, 0.87, 0.87]),
                (at(1.0), [0.71, 0.02, 0.15]),
            ],
            opacity: vec![(at(0.0), 0.0), (at(0.25), 0.0), (at(1.0), max_opacity)],
            unit_distance,
        }
    }

    fn check(&self) -> Result<(), Error> {
        let bad = |m: &str| Err(Error::Invalid(format!("bad transfer function: {m}")));
        if !(self.unit_distance > 0.0 && self.unit_distance.is_finite()) {
            return bad("unit distance must be positive and finite");
        }
        if self.color.is_empty() || self.opacity.is_empty() {
            return bad("needs at least one colour and one opacity point");
        }
        let sorted_finite = |xs: &mut dyn Iterator<Item = f64>| {
            let v: Vec<f64> = xs.collect();
            v.iter().all(|x| x.is_finite()) && v.windows(2).all(|w| w[0] <= w[1])
        };
        if !sorted_finite(&mut self.color.iter().map(|p| p.0))
            || !sorted_finite(&mut self.opacity.iter().map(|p| p.0))
        {
            return bad("points must be finite and in increasing scalar order");
        }
        let in_unit = |x: f64| (0.0..=1.0).contains(&x);
        if !self.color.iter().all(|p| p.1.iter().all(|&c| in_unit(c)))
            || !self.opacity.iter().all(|p| in_unit(p.1))
        {
            return bad("colours and opacities must lie in [0, 1]");
        }
        Ok(())
    }

    /// This function with its opacity read as VTK's unstructured ray caster
    /// (`vtkUnstructuredGridVolumeRayCastMapper`) reads it: as an attenuation coefficient per
    /// unit distance `a`, of which a unit of distance lets `e^(−a)` through, rather than as
    /// the opacity of a unit of distance. The opacity is resampled at `entries` evenly spaced
    /// scalars over `[lo, hi]` (at least 2; [`VTK_MAPPER_TABLE_ENTRIES`] as the mapper does) and each
    /// sample `a` becomes `1 − e^(−a)`; the colour and unit distance are kept. A constant
    /// medium then lets `e^(−a L / unit)` through over a length `L`, Beer–Lambert's law. An
    /// empty opacity, or a reversed or non-finite range, is returned unchanged (and
    /// [`TransferFunction::table`] reports what is wrong with it).
    ///
    /// ```
    /// use cylvol::render::TransferFunction;
    /// let tf = TransferFunction::constant([1.0, 1.0, 1.0], 1.0, 1.0).attenuation_as_opacity(0.0, 1.0, 4);
    /// assert!((tf.opacity_at(0.5) - (1.0 - (-1.0f64).exp())).abs() < 1e-15);
    /// ```
    pub fn attenuation_as_opacity(&self, lo: f64, hi: f64, entries: usize) -> TransferFunction {
        if self.opacity.is_empty() || !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return self.clone();
        }
        let n = entries.max(2);
        let points = self.opacity_points();
        let opacity = (0..n)
            .map(|k| {
                let s = lo + (hi - lo) * k as f64 / (n - 1) as f64;
                let a = piecewise(&points, s)[0];
                (s, (-(-a).exp_m1()).clamp(0.0, 1.0))
            })
            .collect();
        TransferFunction {
            opacity,
            ..self.clone()
        }
    }

    /// The colour at scalar `s`.
    pub fn color_at(&self, s: f64) -> [f64; 3] {
        piecewise(&self.color, s)
    }

    /// The opacity per unit distance at scalar `s`.
    pub fn opacity_at(&self, s: f64) -> f64 {
        piecewise(&self.opacity_points(), s)[0]
    }

    /// The opacity points in the form [`piecewise`] takes (made once for many evaluations).
    fn opacity_points(&self) -> Vec<(f64, [f64; 1])> {
        self.opacity.iter().map(|&(x, a)| (x, [a])).collect()
    }

    /// Samples the function over `[lo, hi]` into `entries` entries, with opacities corrected
    /// to the ray step `step` (see the module documentation).
    ///
    /// ```
    /// use cylvol::render::TransferFunction;
    /// let tf = TransferFunction::constant([1.0, 0.5, 0.0], 0.5, 1.0);
    /// let t = tf.table(0.0, 1.0, 2.0, 16).unwrap();
    /// assert!((t.lookup(0.3)[3] - 0.75).abs() < 1e-15); // 1 − (1 − ½)²
    /// ```
    pub fn table(
        &self,
        lo: f64,
        hi: f64,
        step: f64,
        entries: usize,
    ) -> Result<TransferTable, Error> {
        self.check()?;
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(Error::Invalid(format!(
                "bad scalar range [{}, {}]",
                show_number(lo),
                show_number(hi)
            )));
        }
        if !(step > 0.0 && step.is_finite()) {
            return Err(Error::Invalid(format!("bad step {}", show_number(step))));
        }
        let n = entries.max(2);
        let exponent = step / self.unit_distance;
        let opacity = self.opacity_points();
        let mut rgba = Vec::with_capacity(n);
        let mut unit = Vec::with_capacity(n);
        let mut nonzero_prefix = Vec::with_capacity(n + 1);
        nonzero_prefix.push(0u32);
        for k in 0..n {
            let s = lo + (hi - lo) * k as f64 / (n - 1) as f64;
            let c = piecewise(&self.color, s);
            let a = piecewise(&opacity, s)[0];
            let a_step = if a >= 1.0 {
                1.0
            } else {
                1.0 - (1.0 - a).powf(exponent)
            };
            rgba.push([c[0], c[1], c[2], a_step]);
            unit.push(a);
            let last = nonzero_prefix[k];
            nonzero_prefix.push(last + u32::from(a_step > 0.0));
        }
        let scale = if hi > lo {
            (n - 1) as f64 / (hi - lo)
        } else {
            0.0
        };
        Ok(TransferTable {
            lo,
            scale,
            rgba,
            unit,
            exponent,
            nonzero_prefix,
        })
    }
}

/// The entries of a [`TransferTable`] (see [`TransferTable::entries`]).
pub(crate) struct TableEntries<'a> {
    /// The scalar of the first entry.
    pub(crate) lo: f64,
    /// The scalar between two entries (0 for a single value).
    pub(crate) width: f64,
    /// Per entry the colour (and the opacity of a step).
    pub(crate) rgba: &'a [[f64; 4]],
    /// Per entry the opacity per unit distance.
    pub(crate) unit: &'a [f64],
    /// The distance the opacities apply to.
    pub(crate) unit_distance: f64,
}

/// A transfer function sampled for one scalar range and one step.
#[derive(Clone, Debug, PartialEq)]
pub struct TransferTable {
    lo: f64,
    scale: f64,
    rgba: Vec<[f64; 4]>,
    /// The opacity per unit distance at each entry (uncorrected).
    unit: Vec<f64>,
    /// `step / unit_distance`.
    exponent: f64,
    nonzero_prefix: Vec<u32>,
}

impl TransferTable {
    /// Number of entries.
    pub fn len(&self) -> usize {
        self.rgba.len()
    }

    /// Whether the table is empty (never: it has at least two entries).
    pub fn is_empty(&self) -> bool {
        self.rgba.is_empty()
    }

    /// The fractional table position of scalar `s`, clamped to the table.
    #[inline]
    fn position(&self, s: f64) -> f64 {
        let x = (s - self.lo) * self.scale;
        // NaN goes to 0 through max.
        x.max(0.0).min((self.rgba.len() - 1) as f64)
    }

    /// `[r, g, b, α_step]` at scalar `s` (linear between entries).
    #[inline]
    pub fn lookup(&self, s: f64) -> [f64; 4] {
        let x = self.position(s);
        let i = (x as usize).min(self.rgba.len() - 2);
        let f = x - i as f64;
        let (a, b) = (self.rgba[i], self.rgba[i + 1]);
        [
            a[0] + (b[0] - a[0]) * f,
            a[1] + (b[1] - a[1]) * f,
            a[2] + (b[2] - a[2]) * f,
            a[3] + (b[3] - a[3]) * f,
        ]
    }

    /// The opacity per unit distance at scalar `s` (uncorrected; linear between entries).
    #[inline]
    pub fn unit_opacity(&self, s: f64) -> f64 {
        let x = self.position(s);
        let i = (x as usize).min(self.unit.len() - 2);
        let f = x - i as f64;
        let (a, b) = (self.unit[i], self.unit[i + 1]);
        a + (b - a) * f
    }

    /// An opacity per unit distance corrected to the step: `1 − (1 − α)^(step / unit)`.
    #[inline]
    pub fn step_opacity(&self, alpha_unit: f64) -> f64 {
        if alpha_unit >= 1.0 {
            1.0
        } else if alpha_unit > 0.0 {
            -(self.exponent * (-alpha_unit).ln_1p()).exp_m1()
        } else {
            0.0
        }
    }

    /// The entries as the error-bounded integration reads them: the scalar of the first entry,
    /// the scalar between two entries (0 for a single value), and per entry the colour and the
    /// opacity per unit distance, with the unit distance of a step of `step` (the step the
    /// table was made for).
    pub(crate) fn entries(&self, step: f64) -> TableEntries<'_> {
        TableEntries {
            lo: self.lo,
            width: if self.scale > 0.0 {
                1.0 / self.scale
            } else {
                0.0
            },
            rgba: &self.rgba,
            unit: &self.unit,
            unit_distance: step / self.exponent,
        }
    }

    /// Whether every lookup has zero opacity, whatever the scalar: nothing the table colours
    /// is ever seen.
    ///
    /// ```
    /// use cylvol::render::TransferFunction;
    /// let clear = TransferFunction::constant([1.0, 0.0, 0.0], 0.0, 1.0);
    /// assert!(clear.table(0.0, 1.0, 0.5, 64).unwrap().transparent_everywhere());
    /// let ramp = TransferFunction::default_for_range(0.0, 1.0, 0.3, 1.0);
    /// assert!(!ramp.table(0.0, 1.0, 0.5, 64).unwrap().transparent_everywhere());
    /// ```
    #[inline]
    pub fn transparent_everywhere(&self) -> bool {
        self.nonzero_prefix.last() == Some(&0)
    }

    /// Whether every lookup of a scalar in `[a, b]` has zero opacity.
    #[inline]
    pub fn transparent_over(&self, a: f64, b: f64) -> bool {
        let last = self.rgba.len() - 1;
        let i0 = (self.position(a) as usize).min(last);
        let i1 = ((self.position(b) as usize) + 1).min(last);
        self.nonzero_prefix[i1 + 1] == self.nonzero_prefix[i0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The first window `(s0, s1)` of sorted points with `s <= s1`, scanned in order: the
    /// definition [`piecewise`]'s bisection must agree with.
    fn piecewise_by_scan(points: &[(f64, [f64; 1])], s: f64) -> f64 {
        let first = points[0];
        if s <= first.0 {
            return first.1[0];
        }
        for w in points.windows(2) {
            let ((s0, v0), (s1, v1)) = (w[0], w[1]);
            if s <= s1 {
                let f = if s1 > s0 { (s - s0) / (s1 - s0) } else { 1.0 };
                return v0[0] + (v1[0] - v0[0]) * f;
            }
        }
        points[points.len() - 1].1[0]
    }

    proptest! {
        /// Bisection finds the scan's window: on random sorted points with repeated
        /// abscissae (steps), at the points themselves, between them and beyond both ends.
        #[test]
        fn piecewise_bisection_equals_the_scan(
            gaps in proptest::collection::vec((0u8..4, 0.0..1.0f64), 1..40),
            probes in proptest::collection::vec(-0.5..1.5f64, 1..20),
        ) {
            let mut x = 0.0;
            let points: Vec<(f64, [f64; 1])> = gaps
                .iter()
                .map(|&(gap, v)| {
                    x += f64::from(gap) * 0.125;
                    (x, [v])
                })
                .collect();
            let top = x.max(1.0);
            let at_points = points.iter().map(|p| p.0);
            for s in probes.iter().map(|&p| p * top).chain(at_points) {
                prop_assert_eq!(piecewise(&points, s)[0], piecewise_by_scan(&points, s), "s = {}", s);
            }
            prop_assert_eq!(piecewise(&points, f64::NAN)[0], piecewise_by_scan(&points, f64::NAN));
        }
    }

    #[test]
    fn interpolates_and_clamps() {
        let tf = TransferFunction::default_for_range(0.0, 4.0, 0.5, 1.0);
        let t = tf.table(0.0, 4.0, 1.0, 5).unwrap();
        assert_eq!(t.lookup(-3.0), t.lookup(0.0));
        assert_eq!(t.lookup(9.0)[3], 0.5);
        assert!((t.lookup(3.0)[3] - tf.opacity_at(3.0)).abs() < 1e-15);
        assert!((t.lookup(2.5)[0] - tf.color_at(2.5)[0]).abs() < 1e-15);
        assert!(t.transparent_over(0.0, 0.99));
        assert!(!t.transparent_over(0.0, 1.01));
        assert!(!t.transparent_over(3.0, 3.0));
        assert!(t.lookup(f64::NAN)[3] == 0.0);
    }

    #[test]
    fn unit_opacity_and_its_correction() {
        let tf = TransferFunction::default_for_range(0.0, 4.0, 0.5, 2.0);
        let t = tf.table(0.0, 4.0, 0.5, 64).unwrap();
        for s in [0.0, 1.5, 2.2, 3.9, 4.0] {
            assert!((t.unit_opacity(s) - tf.opacity_at(s)).abs() < 1e-12);
        }
        let entry = 4.0 * 50.0 / 63.0;
        assert!((t.step_opacity(t.unit_opacity(entry)) - t.lookup(entry)[3]).abs() < 1e-14);
        assert_eq!(t.step_opacity(0.0), 0.0);
        assert_eq!(t.step_opacity(1.0), 1.0);
    }

    #[test]
    fn gradient_opacity_table() {
        let g = GradientOpacity::new(&[(1.0, 0.0), (1.0, 1.0), (3.0, 0.5)]).unwrap();
        assert_eq!(g.at(0.0), 0.0);
        assert_eq!(g.at(f64::NAN), 0.0);
        assert_eq!(g.at(3.0), 0.5);
        assert!((g.at(2.0) - 0.75).abs() < 0.01);
        assert_eq!(GradientOpacity::constant(1.0).unwrap().at(7.0), 1.0);
        assert!(GradientOpacity::new(&[(1.0, 0.0), (0.0, 1.0)]).is_err());
        assert!(GradientOpacity::new(&[(0.0, 1.5)]).is_err());
        assert!(GradientOpacity::new(&[(f64::NAN, 1.0)]).is_err());
    }

    /// Read as attenuation, a constant medium follows Beer–Lambert: the step's opacity is
    /// `1 − e^(−a · step / unit)` whatever the step; a ramp is converted sample by sample and
    /// keeps its colour; what cannot be resampled is returned as it is.
    #[test]
    fn attenuation_read_as_opacity() {
        let (a, unit) = (2.5, 0.4);
        let tf = TransferFunction::constant([0.2, 0.4, 0.6], a, 1.0);
        // Out of the [0, 1] opacity range of `table`, but a valid attenuation coefficient.
        assert!(tf.table(0.0, 1.0, 0.1, 8).is_err());
        let tf = TransferFunction {
            unit_distance: unit,
            ..tf
        }
        .attenuation_as_opacity(0.0, 1.0, 16);
        for step in [0.01, 0.1, 0.4, 3.0] {
            let t = tf.table(0.0, 1.0, step, 8).unwrap();
            let expect = 1.0 - (-a * step / unit).exp();
            assert!((t.lookup(0.3)[3] - expect).abs() < 1e-14, "step {step}");
        }
        let ramp = TransferFunction::default_for_range(0.0, 4.0, 0.8, 1.0);
        let converted = ramp.attenuation_as_opacity(0.0, 4.0, 1024);
        assert_eq!(converted.opacity.len(), 1024);
        assert_eq!(converted.color, ramp.color);
        for (s, a) in &converted.opacity {
            assert!((a - (1.0 - (-ramp.opacity_at(*s)).exp())).abs() < 1e-15);
        }
        assert_eq!(ramp.attenuation_as_opacity(1.0, 0.0, 8), ramp);
        assert_eq!(ramp.attenuation_as_opacity(0.0, f64::NAN, 8), ramp);
    }

    #[test]
    fn opacity_correction_follows_the_step() {
        let tf = TransferFunction::constant([1.0; 3], 0.3, 2.0);
        let t = tf.table(0.0, 1.0, 0.5, 8).unwrap();
        let expect = 1.0 - 0.7f64.powf(0.25);
        assert!((t.lookup(0.5)[3] - expect).abs() < 1e-15);
        assert!(TransferFunction::constant([2.0; 3], 0.3, 1.0)
            .table(0.0, 1.0, 1.0, 8)
            .is_err());
    }
}
