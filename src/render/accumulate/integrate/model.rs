//! The scalar along a stretch of ray between what is known at its ends ([`Field`]), and the
//! light that stretch adds and lets through ([`Light::cross`]).
//!
//! At a sample the scalar and its slope along the ray (the trilinear interpolant's gradient
//! on the ray's direction) are known: a [`Knot`]. Between two knots of one run of samples the
//! scalar is the cubic matching both values and both slopes (Hermite); from one knot to a
//! boundary crossing or a cut it is the tangent at the knot, bent by a curvature where one is
//! known. The stretch is cut into pieces along which the scalar is taken linear, each
//! integrated through the transfer function exactly ([`Extinction::stretch`]); a piece's
//! colour is its emission-weighted mean, which leaves out the fall of the light within the
//! piece, so a piece is kept optically thin (at most [`PIECE_DEPTH`]).
//!
//! The same stretch integrated with the straight line between the knots' values instead
//! ([`Field::chord`]) differs from it by about the error of a field linear between samples:
//! [`Light::difference`] of the two is the error estimate the integration steers by. Where
//! the model strays little from that line ([`Field::deviation`]) against how steeply the
//! transfer function varies over the scalars it reaches, the line alone is integrated.

use super::table::Extinction;

/// The most optical depth a piece of a stretch is integrated over at once.
pub(crate) const PIECE_DEPTH: f64 = 0.5;

/// Pieces a stretch is cut into at most for its shape.
pub(crate) const MAX_SHAPE_PIECES: usize = 16;

/// Pieces a stretch is cut into at most (the light is negligible long before).
const MAX_PIECES: usize = 1024;

/// How a sample's light is changed where it lies: the colour `c` becomes `c·gain + specular`
/// (shading), the extinction is that of the opacity times `opacity` (gradient opacity).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Look {
    /// The shading's factor on the colour.
    pub(crate) gain: f64,
    /// The shading's specular term.
    pub(crate) specular: f64,
    /// The gradient opacity's factor.
    pub(crate) opacity: f64,
}

impl Look {
    /// No shading, no gradient opacity.
    pub(crate) const PLAIN: Look = Look {
        gain: 1.0,
        specular: 0.0,
        opacity: 1.0,
    };

    /// Part `f` of the way from `self` to `other`.
    #[inline]
    fn lerp(&self, other: &Look, f: f64) -> Look {
        Look {
            gain: self.gain + (other.gain - self.gain) * f,
            specular: self.specular + (other.specular - self.specular) * f,
            opacity: self.opacity + (other.opacity - self.opacity) * f,
        }
    }
}

/// What is known at a sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Knot {
    /// Where along the ray.
    pub(crate) t: f64,
    /// The scalar.
    pub(crate) s: f64,
    /// Its derivative along the ray.
    pub(crate) slope: f64,
    /// The shading and gradient opacity there.
    pub(crate) look: Look,
}

/// The scalar along a stretch (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Field {
    /// The cubic through two knots with their slopes.
    Cubic(Knot, Knot),
    /// The straight line between two knots' values.
    Chord(Knot, Knot),
    /// From one knot: `s + slope·x + curvature·x²/2` at `x = t − knot.t`.
    Tangent(Knot, f64),
}

impl Field {
    /// The straight line between the values at this field's knots (the tangent alone from
    /// one knot).
    pub(crate) fn chord(&self) -> Field {
        match *self {
            Field::Cubic(a, b) | Field::Chord(a, b) => Field::Chord(a, b),
            Field::Tangent(k, _) => Field::Tangent(k, 0.0),
        }
    }

    /// The most the scalar strays from the straight line between its values at the ends of
    /// `[t0, t1]` (bounded for the cubic by its slopes' differences from the chord's).
    pub(crate) fn deviation(&self, (t0, t1): (f64, f64)) -> f64 {
        match self {
            Field::Cubic(a, b) => {
                let h = b.t - a.t;
                if h.is_nan() || h <= 0.0 {
                    return 0.0;
                }
                let m = (b.s - a.s) / h;
                0.25 * h * (a.slope - m).abs().max((b.slope - m).abs())
            }
            Field::Chord(..) => 0.0,
            Field::Tangent(k, curvature) => {
                let x = (t0 - k.t).abs().max((t1 - k.t).abs());
                0.5 * curvature.abs() * x * x
            }
        }
    }

    /// The scalar at the ends of `[t0, t1]`.
    pub(crate) fn ends(&self, (t0, t1): (f64, f64)) -> (f64, f64) {
        (self.at(t0).0, self.at(t1).0)
    }

    /// The scalar and the look at `t`.
    #[inline]
    fn at(&self, t: f64) -> (f64, Look) {
        match self {
            Field::Cubic(a, b) => {
                let h = b.t - a.t;
                let x = if h > 0.0 { (t - a.t) / h } else { 0.0 };
                let (x2, x3) = (x * x, x * x * x);
                let h00 = 2.0 * x3 - 3.0 * x2 + 1.0;
                let h10 = x3 - 2.0 * x2 + x;
                let h01 = 1.0 - h00;
                let h11 = x3 - x2;
                let s = h00 * a.s + h10 * h * a.slope + h01 * b.s + h11 * h * b.slope;
                (s, a.look.lerp(&b.look, x))
            }
            Field::Chord(a, b) => {
                let h = b.t - a.t;
                let x = if h > 0.0 { (t - a.t) / h } else { 0.0 };
                (a.s + (b.s - a.s) * x, a.look.lerp(&b.look, x))
            }
            Field::Tangent(k, curvature) => {
                let x = t - k.t;
                (k.s + x * (k.slope + 0.5 * curvature * x), k.look)
            }
        }
    }
}

/// The light along a ray: what is let through from behind, and the premultiplied colour
/// gathered in front.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Light {
    /// The transmittance.
    pub(crate) transmittance: f64,
    /// The colour.
    pub(crate) color: [f64; 3],
}

/// A crossed stretch: the light after it, and where in it the light's opacity first reached
/// a given level (the middle of that piece).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Crossed {
    /// The light after the stretch.
    pub(crate) light: Light,
    /// Where the opacity first reached the level asked for, if it did in this stretch.
    pub(crate) reached: Option<f64>,
}

impl Light {
    /// Nothing gathered: all light let through.
    pub(crate) const CLEAR: Light = Light {
        transmittance: 1.0,
        color: [0.0; 3],
    };

    /// The light after crossing `[t0, t1]` with the scalar `field` cut into at least `shape`
    /// pieces, the light gathered down to `negligible` transmittance; `reached`: where the
    /// opacity `1 − T` first reaches `level`.
    pub(crate) fn cross(
        self,
        table: &Extinction,
        field: &Field,
        (t0, t1): (f64, f64),
        shape: usize,
        (level, negligible): (f64, f64),
    ) -> Crossed {
        let len = t1 - t0;
        let mut out = Crossed {
            light: self,
            reached: None,
        };
        if len.is_nan() || len <= 0.0 || self.transmittance <= negligible {
            return out;
        }
        // Pieces: the field's shape, and thin enough in optical depth (estimated from the
        // chord at the ends).
        let (s0, look0) = field.at(t0);
        let (s1, look1) = field.at(t1);
        let (p0, p1) = (table.point(s0), table.point(s1));
        let whole = table.between(&p0, &p1, len);
        let rough = whole.depth * look0.opacity.max(look1.opacity).max(1.0);
        let thin = (rough / PIECE_DEPTH).ceil();
        let n = shape
            .max(if thin.is_finite() {
                thin as usize
            } else {
                MAX_PIECES
            })
            .min(MAX_PIECES);
        if n == 1 && look0 == Look::PLAIN && look1 == Look::PLAIN {
            out.light = out.light.through(&whole, &Look::PLAIN);
            out.reached = reached_in(self.transmittance, &whole, (t0, t1), level);
            return out;
        }
        let piece = len / n as f64;
        let (mut t_a, mut p_a, mut look_a) = (t0, p0, look0);
        for k in 1..=n {
            let (t_b, p_b, look_b) = if k == n {
                (t1, p1, look1)
            } else {
                let t_b = t0 + piece * k as f64;
                let (s_b, look_b) = field.at(t_b);
                (t_b, table.point(s_b), look_b)
            };
            let look = look_a.lerp(&look_b, 0.5);
            let part = if look.opacity == 1.0 {
                table.between(&p_a, &p_b, t_b - t_a)
            } else {
                table.scaled_midpoint(0.5 * (p_a.s() + p_b.s()), t_b - t_a, look.opacity)
            };
            let before = out.light.transmittance;
            out.light = out.light.through(&part, &look);
            if out.reached.is_none() {
                out.reached = reached_in(before, &part, (t_a, t_b), level);
            }
            if out.light.transmittance <= negligible {
                break;
            }
            (t_a, p_a, look_a) = (t_b, p_b, look_b);
        }
        out
    }

    /// The light after one piece, its colour changed by `look`.
    #[inline]
    fn through(self, part: &super::table::Stretch, look: &Look) -> Light {
        let mut light = self;
        let depth = part.depth;
        if depth > 0.0 {
            // The piece's opacity over its depth weighs its emission-weighted colour.
            let through = (-depth).exp();
            let opacity_per_depth = if depth > 1e-6 {
                (1.0 - through) / depth
            } else {
                1.0 - 0.5 * depth
            };
            let w = light.transmittance * opacity_per_depth;
            for ch in 0..3 {
                let glow = look.gain * part.glow[ch] + look.specular * depth;
                light.color[ch] += w * glow;
            }
            light.transmittance *= through;
        }
        if let Some((_, c)) = part.opaque {
            for (gathered, c) in light.color.iter_mut().zip(c) {
                *gathered += light.transmittance * (look.gain * c + look.specular).clamp(0.0, 1.0);
            }
            light.transmittance = 0.0;
        }
        light
    }

    /// How far apart two lights are in their effect on the pixel: the largest difference of a
    /// colour channel, plus the difference of transmittance (which weighs all that lies
    /// behind, at most that much).
    pub(crate) fn difference(&self, other: &Light) -> f64 {
        let dc = (0..3)
            .map(|ch| (self.color[ch] - other.color[ch]).abs())
            .fold(0.0, f64::max);
        dc + (self.transmittance - other.transmittance).abs()
    }

    /// The pixel: premultiplied colour and opacity.
    pub(crate) fn rgba(&self) -> [f64; 4] {
        [
            self.color[0],
            self.color[1],
            self.color[2],
            1.0 - self.transmittance,
        ]
    }
}

/// Where along a piece `[t_a, t_b]` entered with transmittance `before` the opacity `1 − T`
/// reaches `level` (the optical depth taken uniform within it; an opaque part stops it
/// where it turns opaque), if it does.
fn reached_in(
    before: f64,
    part: &super::table::Stretch,
    (t_a, t_b): (f64, f64),
    level: f64,
) -> Option<f64> {
    let target = 1.0 - level;
    if before <= target {
        return Some(t_a);
    }
    let after = before * (-part.depth).exp();
    if after <= target && part.depth > 0.0 {
        let x = ((before / target).ln() / part.depth).clamp(0.0, 1.0);
        return Some(t_a + (t_b - t_a) * x);
    }
    part.opaque.map(|(f, _)| t_a + (t_b - t_a) * f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::transfer::TransferFunction;

    fn table() -> Extinction {
        let tf = TransferFunction {
            color: vec![(0.0, [1.0, 0.2, 0.0]), (1.0, [0.0, 0.4, 1.0])],
            opacity: vec![
                (0.0, 0.05),
                (0.45, 0.05),
                (0.5, 0.9),
                (0.55, 0.05),
                (1.0, 0.3),
            ],
            unit_distance: 0.2,
        };
        Extinction::new(&tf.table(0.0, 1.0, 0.01, 1024).unwrap(), 0.01)
    }

    /// The light through a stretch against a brute-force midpoint integration of the same
    /// scalar: a cubic through a narrow opaque band of the transfer function.
    #[test]
    fn crossing_a_cubic_matches_fine_sampling() {
        let e = table();
        let a = Knot {
            t: 0.0,
            s: 0.1,
            slope: 2.0,
            look: Look::PLAIN,
        };
        let b = Knot {
            t: 0.6,
            s: 0.9,
            slope: 0.3,
            look: Look::PLAIN,
        };
        let field = Field::Cubic(a, b);
        let cross = |pieces| {
            Light::CLEAR
                .cross(&e, &field, (0.0, 0.6), pieces, (2.0, 0.0))
                .light
        };
        let n = 400_000;
        let mut want = Light::CLEAR;
        for k in 0..n {
            let t = 0.6 * (k as f64 + 0.5) / n as f64;
            let (s, _) = field.at(t);
            let (sigma, c) = e.at(s);
            let alpha = -(-sigma * 0.6 / n as f64).exp_m1();
            for (gathered, c) in want.color.iter_mut().zip(c) {
                *gathered += want.transmittance * alpha * c;
            }
            want.transmittance *= 1.0 - alpha;
        }
        // Each piece takes the cubic as linear: the error falls with the square of the pieces.
        let errors = [8, 32, 128].map(|n| cross(n).difference(&want));
        assert!(errors[1] < errors[0] / 10.0, "{errors:?}");
        assert!(errors[2] < errors[1] / 10.0, "{errors:?}");
        assert!(errors[2] < 2e-5, "{errors:?}");
        let got = cross(128);
        // The chord differs from the cubic by much more than that: the error estimate sees it.
        let chord = Light::CLEAR
            .cross(&e, &field.chord(), (0.0, 0.6), 1, (2.0, 0.0))
            .light;
        assert!(chord.difference(&got) > 1e-3);
    }
}
