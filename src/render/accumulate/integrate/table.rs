//! The transfer function as the error-bounded integration reads it ([`Extinction`]): per entry
//! of the transfer table, the extinction coefficient `σ = −ln(1 − α)/unit` (α the opacity per
//! unit distance) and the colour `c`, linear in the scalar between entries — the medium the
//! table's samples converge to as the step shrinks — with their integrals over the scalar,
//! `∫σ ds` and `∫cσ ds`, summed entry by entry.
//!
//! Along a stretch of ray of length `L` over which the scalar goes linearly from `s₀` to `s₁`,
//! the optical depth is then exact whatever the transfer function does in between,
//! `τ = L · (∫σ ds)/(s₁ − s₀)`, and so is the emission density integrated over it,
//! `∫cσ dt = L · (∫cσ ds)/(s₁ − s₀)` ([`Extinction::stretch`]): a thin opaque band of the
//! transfer function crossed between two samples is seen whole.
//!
//! An entry of opacity 1 (or more) per unit distance is opaque: the table's step opacity is
//! 1 there at every step, and between it and its neighbours the samples' opacity grows to 1
//! as the step shrinks. A stretch whose scalar reaches such a part of the table stops the ray
//! where it first does ([`Stretch::opaque`]).

use crate::render::transfer::TransferTable;

/// Extinction and emission per scalar, with their integrals (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Extinction {
    lo: f64,
    /// The scalar between two entries (0: every scalar reads the first entry).
    width: f64,
    /// `1 / width` (0 for a single value).
    inv_width: f64,
    /// Per entry: `σ` (0 where opaque), the opacity per unit distance and the colour.
    sigma: Vec<f64>,
    unit: Vec<f64>,
    color: Vec<[f64; 3]>,
    /// `∫σ ds` and `∫cσ ds` from the first entry to each entry (opaque entries count 0).
    depth: Vec<f64>,
    glow: Vec<[f64; 3]>,
    /// The opaque entries before each entry (a prefix count), and whether there is one.
    opaque_before: Vec<u32>,
    any_opaque: bool,
    /// The distance the opacities apply to.
    unit_distance: f64,
    /// The variation of `σ` plus the largest of `cσ`'s channels over the intervals before
    /// each entry (a prefix sum).
    variation_before: Vec<f64>,
    /// Per level `l`, per interval `i`: the steepest slope of `σ` or a channel of `cσ` over
    /// the intervals `i .. i + 2^l` (a sparse table).
    steepest_by_level: Vec<Vec<f64>>,
}

/// A scalar with the integrals up to it: the entry below it and the part past that entry,
/// made once for the two stretches it ends and starts ([`Extinction::point`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Point {
    s: f64,
    entry: usize,
    depth: f64,
    glow: [f64; 3],
}

/// What a stretch of ray does to the light crossing it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Stretch {
    /// Its optical depth `∫σ dt` (up to where it turns opaque).
    pub(crate) depth: f64,
    /// Its emission `∫cσ dt` (up to where it turns opaque).
    pub(crate) glow: [f64; 3],
    /// Where it turns opaque, as a fraction of its length, and the colour there.
    pub(crate) opaque: Option<(f64, [f64; 3])>,
}

impl Point {
    /// The scalar.
    #[inline]
    pub(crate) fn s(&self) -> f64 {
        self.s
    }
}

impl Extinction {
    /// The table's entries read as extinction (`step`: the step the table was made for).
    pub(crate) fn new(table: &TransferTable, step: f64) -> Extinction {
        let e = table.entries(step);
        let n = e.rgba.len();
        let mut sigma = Vec::with_capacity(n);
        let mut color = Vec::with_capacity(n);
        let mut opaque_before = Vec::with_capacity(n + 1);
        opaque_before.push(0u32);
        for k in 0..n {
            let a = e.unit[k];
            let opaque = a >= 1.0 || a.is_nan();
            let s = if opaque || a <= 0.0 {
                0.0
            } else {
                -(-a).ln_1p() / e.unit_distance
            };
            sigma.push(s);
            let c = e.rgba[k];
            color.push([c[0], c[1], c[2]]);
            opaque_before.push(opaque_before[k] + u32::from(opaque));
        }
        let mut variation_before = Vec::with_capacity(n);
        variation_before.push(0.0);
        for k in 1..n {
            let glow = |j: usize| color[j].map(|c| c * sigma[j]);
            let (g0, g1) = (glow(k - 1), glow(k));
            let dg = (0..3).map(|ch| (g1[ch] - g0[ch]).abs()).fold(0.0, f64::max);
            variation_before.push(variation_before[k - 1] + (sigma[k] - sigma[k - 1]).abs() + dg);
        }
        let steepest_by_level = steepest_table(&sigma, &color, e.width);
        let mut depth = Vec::with_capacity(n);
        let mut glow = Vec::with_capacity(n);
        depth.push(0.0);
        glow.push([0.0; 3]);
        for k in 1..n {
            let (d, g) = interval_integrals(
                e.width,
                (sigma[k - 1], sigma[k]),
                (color[k - 1], color[k]),
                1.0,
            );
            depth.push(depth[k - 1] + d);
            let before = glow[k - 1];
            glow.push([before[0] + g[0], before[1] + g[1], before[2] + g[2]]);
        }
        Extinction {
            lo: e.lo,
            width: e.width,
            inv_width: if e.width > 0.0 { 1.0 / e.width } else { 0.0 },
            sigma,
            unit: e.unit.to_vec(),
            color,
            depth,
            glow,
            any_opaque: opaque_before[n] > 0,
            opaque_before,
            unit_distance: e.unit_distance,
            variation_before,
            steepest_by_level,
        }
    }

    /// The number of entries.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.sigma.len()
    }

    /// The variation of the extinction plus that of the emission density over the entries a
    /// scalar in `[lo, hi]` reads (the intervals it touches, whole); infinite where one of
    /// them is opaque.
    pub(crate) fn variation(&self, lo: f64, hi: f64) -> f64 {
        let (i0, _) = self.position(lo);
        let (i1, f1) = self.position(hi);
        let end = (i1 + usize::from(f1 > 0.0 || i1 == i0)).min(self.sigma.len() - 1);
        if self.opaque_before[end + 1] > self.opaque_before[i0] {
            return f64::INFINITY;
        }
        self.variation_before[end] - self.variation_before[i0]
    }

    /// The entry below `s` and the fraction of the way to the next one (clamped to the table;
    /// NaN reads the first entry).
    #[inline]
    fn position(&self, s: f64) -> (usize, f64) {
        let last = self.sigma.len() - 1;
        let x = ((s - self.lo) * self.inv_width).max(0.0).min(last as f64);
        let i = (x as usize).min(last.saturating_sub(1));
        (i, x - i as f64)
    }

    /// `σ` and the colour at `s` (linear between entries).
    #[inline]
    pub(crate) fn at(&self, s: f64) -> (f64, [f64; 3]) {
        let (i, f) = self.position(s);
        if i + 1 >= self.sigma.len() {
            return (self.sigma[i], self.color[i]);
        }
        let (c0, c1) = (self.color[i], self.color[i + 1]);
        (
            self.sigma[i] + (self.sigma[i + 1] - self.sigma[i]) * f,
            [
                c0[0] + (c1[0] - c0[0]) * f,
                c0[1] + (c1[1] - c0[1]) * f,
                c0[2] + (c1[2] - c0[2]) * f,
            ],
        )
    }

    /// A stretch of length `len` at the scalar `s`, its opacity per unit distance scaled by
    /// `factor` before it is read as extinction (gradient opacity, which multiplies the opacity
    /// as the fixed-step table does): the midpoint rule.
    pub(crate) fn scaled_midpoint(&self, s: f64, len: f64, factor: f64) -> Stretch {
        let (i, f) = self.position(s);
        let j = (i + 1).min(self.unit.len() - 1);
        let a = (self.unit[i] + (self.unit[j] - self.unit[i]) * f) * factor;
        let c = self.at(s).1;
        if a >= 1.0 {
            return Stretch {
                depth: 0.0,
                glow: [0.0; 3],
                opaque: Some((0.0, c)),
            };
        }
        let d = if a > 0.0 {
            -(-a).ln_1p() / self.unit_distance * len
        } else {
            0.0
        };
        Stretch {
            depth: d,
            glow: [c[0] * d, c[1] * d, c[2] * d],
            opaque: None,
        }
    }

    /// `∫σ ds` and `∫cσ ds` from the first entry to `s` within the table; beyond its ends the
    /// functions are constant (the table's clamping).
    #[inline]
    pub(crate) fn point(&self, s: f64) -> Point {
        let n = self.sigma.len();
        let x = (s - self.lo) * self.inv_width;
        let last = (n - 1) as f64;
        // Beyond the ends: the part past the end entry at that entry's (constant) values.
        let (entry, f, beyond) = if x.is_nan() || x <= 0.0 || n < 2 {
            (0, 0.0, if x < 0.0 { x } else { 0.0 })
        } else if x >= last {
            (n - 1, 0.0, x - last)
        } else {
            let i = (x as usize).min(n - 2);
            (i, x - i as f64, 0.0)
        };
        let mut depth = 0.0;
        let mut glow = [0.0; 3];
        if f > 0.0 {
            let (d, g) = interval_integrals(
                self.width,
                (self.sigma[entry], self.sigma[entry + 1]),
                (self.color[entry], self.color[entry + 1]),
                f,
            );
            depth += d;
            glow = g;
        }
        if beyond != 0.0 {
            let d = self.sigma[entry] * beyond * self.width;
            let c = self.color[entry];
            depth += d;
            glow = [glow[0] + c[0] * d, glow[1] + c[1] * d, glow[2] + c[2] * d];
        }
        Point {
            s,
            entry,
            depth,
            glow,
        }
    }

    /// The optical depth and emission of a stretch of length `len` along which the scalar
    /// goes linearly from `s0` to `s1` (see the module documentation).
    #[cfg(test)]
    pub(crate) fn stretch(&self, s0: f64, s1: f64, len: f64) -> Stretch {
        self.between(&self.point(s0), &self.point(s1), len)
    }

    /// [`Extinction::stretch`] between two points made by [`Extinction::point`].
    #[inline]
    pub(crate) fn between(&self, a: &Point, b: &Point, len: f64) -> Stretch {
        if self.any_opaque {
            if let Some(f) = self.first_opaque(a.s, b.s) {
                let s = a.s + (b.s - a.s) * f;
                let mut before = self.linear(a, &self.point(s), len * f);
                before.opaque = Some((f, self.at(s).1));
                return before;
            }
        }
        self.linear(a, b, len)
    }

    /// [`Extinction::between`] where no part of it is opaque.
    #[inline]
    fn linear(&self, a: &Point, b: &Point, len: f64) -> Stretch {
        let ds = b.s - a.s;
        // Within a millionth of an entry the integrand is its value at the middle.
        let entries = ds.abs() * self.inv_width;
        if entries.is_nan() || entries <= 1e-6 {
            let (sigma, c) = self.at(0.5 * (a.s + b.s));
            let d = sigma * len;
            return Stretch {
                depth: d,
                glow: [c[0] * d, c[1] * d, c[2] * d],
                opaque: None,
            };
        }
        // The entries' sums cancel exactly where both ends lie in one interval.
        let per = len / ds;
        let (ga, gb) = (&self.glow[a.entry], &self.glow[b.entry]);
        let depth = ((self.depth[b.entry] - self.depth[a.entry]) + (b.depth - a.depth)) * per;
        let mut glow = [0.0; 3];
        for ch in 0..3 {
            glow[ch] = (((gb[ch] - ga[ch]) + (b.glow[ch] - a.glow[ch])) * per).max(0.0);
        }
        Stretch {
            depth: depth.max(0.0),
            glow,
            opaque: None,
        }
    }

    /// The steepest rate at which the extinction or a channel of the emission density
    /// changes with the scalar over the entries a scalar in `[lo, hi]` reads (per unit
    /// scalar; infinite where one of them is opaque).
    #[inline]
    pub(crate) fn steepest(&self, lo: f64, hi: f64) -> f64 {
        let (i0, _) = self.position(lo);
        let (i1, _) = self.position(hi);
        let i1 = i1.max(i0);
        // The intervals read the entries `i0 ..= i1 + 1`.
        let end = (i1 + 2).min(self.sigma.len());
        if self.opaque_before[end] > self.opaque_before[i0] {
            return f64::INFINITY;
        }
        // The larger of two overlapping spans of a power of two intervals.
        let n = i1 - i0 + 1;
        let level = (usize::BITS - 1 - n.leading_zeros()) as usize;
        let row = &self.steepest_by_level[level];
        row[i0].max(row[i1 + 1 - (1 << level)])
    }

    /// Where along a stretch from `s0` to `s1` the scalar first reaches an opaque part of the
    /// table (an opaque entry, or the interval on either side of one), as a fraction of the
    /// stretch; `None` where it does not.
    fn first_opaque(&self, s0: f64, s1: f64) -> Option<f64> {
        let (lo, hi) = (s0.min(s1), s0.max(s1));
        let (i0, _) = self.position(lo);
        let (i1, f1) = self.position(hi);
        let last = self.sigma.len() - 1;
        let end = (i1 + usize::from(f1 > 0.0)).min(last);
        if self.opaque_before[end + 1] == self.opaque_before[i0] {
            return None;
        }
        // Scan the entries' intervals in the stretch's direction for the first opaque point.
        let opaque = |k: usize| self.opaque_before[k + 1] > self.opaque_before[k];
        let scalar = |k: usize| self.lo + k as f64 * self.width;
        let reach = |s: f64| {
            if s1 == s0 {
                0.0
            } else {
                ((s - s0) / (s1 - s0)).clamp(0.0, 1.0)
            }
        };
        if s1 >= s0 {
            for k in i0..=end {
                if opaque(k) {
                    // Open on the side of the entry below: opaque right past it.
                    let from = if k > 0 { scalar(k - 1) } else { scalar(k) };
                    return Some(reach(from.max(s0)));
                }
            }
        } else {
            for k in (i0..=end).rev() {
                if opaque(k) {
                    let from = if k < last { scalar(k + 1) } else { scalar(k) };
                    return Some(reach(from.min(s0)));
                }
            }
        }
        None
    }
}

/// The sparse table of [`Extinction::steepest`]: level 0 holds each interval's slope (the
/// last entry's, none: 0), level `l` the larger of two halves of level `l − 1`.
fn steepest_table(sigma: &[f64], color: &[[f64; 3]], width: f64) -> Vec<Vec<f64>> {
    let n = sigma.len();
    let inv = if width > 0.0 { 1.0 / width } else { 0.0 };
    let slope = |k: usize| {
        if k + 1 >= n {
            return 0.0;
        }
        let glow_slope = color[k + 1]
            .iter()
            .zip(&color[k])
            .map(|(c1, c0)| (c1 * sigma[k + 1] - c0 * sigma[k]).abs())
            .fold(0.0, f64::max);
        (sigma[k + 1] - sigma[k]).abs().max(glow_slope) * inv
    };
    let mut levels = vec![(0..n).map(slope).collect::<Vec<f64>>()];
    let mut span = 1;
    while 2 * span <= n {
        let below = &levels[levels.len() - 1];
        let row = (0..n)
            .map(|i| below[i].max(below[(i + span).min(n - 1)]))
            .collect();
        levels.push(row);
        span *= 2;
    }
    levels
}

/// `∫σ ds` and `∫cσ ds` over the first `f` of an interval of width `w` from entry values
/// `(σ₀, σ₁)` and `(c₀, c₁)`, both linear in the scalar.
#[inline]
fn interval_integrals(
    w: f64,
    (s0, s1): (f64, f64),
    (c0, c1): ([f64; 3], [f64; 3]),
    f: f64,
) -> (f64, [f64; 3]) {
    let ds = s1 - s0;
    let (f2, f3) = (f * f * 0.5, f * f * f / 3.0);
    let depth = w * (s0 * f + ds * f2);
    let glow = [0, 1, 2].map(|ch| {
        let dc = c1[ch] - c0[ch];
        w * (c0[ch] * s0 * f + (c0[ch] * ds + dc * s0) * f2 + dc * ds * f3)
    });
    (depth, glow)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::transfer::TransferFunction;

    fn ramp() -> (TransferFunction, Extinction) {
        let tf = TransferFunction {
            color: vec![(0.0, [1.0, 0.0, 0.0]), (1.0, [0.0, 0.0, 1.0])],
            opacity: vec![(0.0, 0.0), (0.5, 0.6), (1.0, 0.2)],
            unit_distance: 0.5,
        };
        let table = tf.table(0.0, 1.0, 0.1, 64).unwrap();
        let e = Extinction::new(&table, 0.1);
        (tf, e)
    }

    /// The stretch's integrals against many midpoint samples of the same linear scalar.
    #[test]
    fn stretches_are_exact_for_a_linear_scalar() {
        let (_, e) = ramp();
        assert_eq!(e.len(), 64);
        for (s0, s1, len) in [
            (0.1, 0.9, 2.0),
            (0.9, 0.05, 0.3),
            (0.3, 0.3, 1.0),
            (-0.5, 0.4, 1.0),
        ] {
            let got = e.stretch(s0, s1, len);
            let n = 200_000;
            let (mut depth, mut glow) = (0.0, [0.0; 3]);
            for k in 0..n {
                let x = (k as f64 + 0.5) / n as f64;
                let (sigma, c) = e.at(s0 + (s1 - s0) * x);
                let d = sigma * len / n as f64;
                depth += d;
                for ch in 0..3 {
                    glow[ch] += c[ch] * d;
                }
            }
            assert!(
                (got.depth - depth).abs() < 1e-8 * (1.0 + depth),
                "{s0} {s1}: {got:?} {depth}"
            );
            for (got, want) in got.glow.iter().zip(glow) {
                assert!((got - want).abs() < 1e-8 * (1.0 + want));
            }
            assert_eq!(got.opaque, None);
        }
    }

    /// σ is the opacity per unit distance read as extinction: a unit distance of a constant
    /// medium lets `1 − α` through.
    #[test]
    fn extinction_of_the_opacity() {
        let (tf, e) = ramp();
        // At an entry's scalar (between entries σ is linear, the opacity is not).
        let s = 32.0 / 63.0;
        let (sigma, _) = e.at(s);
        let alpha = tf.opacity_at(s);
        assert!(((-sigma * tf.unit_distance).exp() - (1.0 - alpha)).abs() < 1e-12);
    }

    /// An opaque band stops a stretch where the scalar first reaches it, from either side.
    #[test]
    fn opaque_parts_stop_a_stretch() {
        let tf = TransferFunction {
            color: vec![(0.0, [0.0, 1.0, 0.0])],
            opacity: vec![(0.0, 0.0), (0.5, 1.0), (1.0, 0.0)],
            unit_distance: 1.0,
        };
        let table = tf.table(0.0, 1.0, 0.1, 11).unwrap();
        let e = Extinction::new(&table, 0.1);
        let up = e.stretch(0.0, 1.0, 1.0);
        let (f, c) = up.opaque.expect("opaque");
        assert!((f - 0.4).abs() < 1e-12);
        assert_eq!(c, [0.0, 1.0, 0.0]);
        let down = e.stretch(1.0, 0.0, 1.0);
        assert!((down.opaque.unwrap().0 - 0.4).abs() < 1e-12);
        assert_eq!(e.stretch(0.0, 0.35, 1.0).opaque, None);
    }
}
