//! Shading with a headlight, as `vtkVolumeProperty` defines its coefficients: ambient
//! (default 0.1), diffuse (0.7), specular (0.2) and specular power (10).
//!
//! The normal is the scalar's gradient (`cylvol::geometry::trilinear::physical_gradient`,
//! the exact derivative of the trilinear interpolant, normalised). The light is a white
//! headlight at the camera: the light and view directions are both the reverse of the ray
//! direction, so the half vector is the light direction. Lighting is two-sided (VTK's default),
//! so `|n · l|` is used. The shaded colour is `c (k_a + k_d |n·l|) + k_s |n·l|^p`, each channel
//! clamped to `[0, 1]`. Where the gradient is zero or undefined (a constant region, a collapsed
//! edge of a wedge), the sample is lit as if it faced the light without highlight:
//! `c (k_a + k_d)`, so flat regions are not darkened.
//!
//! This module is only reached when shading is on: with it off (and no gradient opacity, see
//! [`super::GradientOpacity`]) no gradient is evaluated.

use glam::DVec3;

/// Lighting coefficients (those of `vtkVolumeProperty`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shading {
    /// Ambient coefficient.
    pub ambient: f64,
    /// Diffuse coefficient.
    pub diffuse: f64,
    /// Specular coefficient.
    pub specular: f64,
    /// Specular power.
    pub specular_power: f64,
}

impl Default for Shading {
    fn default() -> Self {
        Shading {
            ambient: 0.1,
            diffuse: 0.7,
            specular: 0.2,
            specular_power: 10.0,
        }
    }
}

impl Shading {
    /// The shaded colour of `color` with the scalar gradient `gradient` (if defined) seen
    /// along the unit ray direction `dir`.
    ///
    /// ```
    /// use cylvol::render::Shading;
    /// use glam::DVec3;
    /// let s = Shading::default();
    /// let c = s.shade([1.0, 0.5, 0.0], Some(DVec3::Z), -DVec3::Z);
    /// assert!((c[1] - (0.5 * 0.8 + 0.2)).abs() < 1e-12);
    /// ```
    #[inline]
    pub fn shade(&self, color: [f64; 3], gradient: Option<DVec3>, dir: DVec3) -> [f64; 3] {
        let (k, s) = self.terms(gradient, dir);
        color.map(|c| (c * k + s).clamp(0.0, 1.0))
    }

    /// The factor on the colour and the specular term that [`Shading::shade`] applies at a
    /// sample of gradient `gradient` seen along `dir`: the shaded colour is
    /// `(c · factor + specular)` clamped to `[0, 1]`.
    pub(crate) fn terms(&self, gradient: Option<DVec3>, dir: DVec3) -> (f64, f64) {
        let n = gradient
            .map(|g| g.normalize_or_zero())
            .unwrap_or(DVec3::ZERO);
        let (diffuse, specular) = if n == DVec3::ZERO || !n.is_finite() {
            (1.0, 0.0)
        } else {
            let d = n.dot(dir).abs().min(1.0);
            (d, d.powf(self.specular_power))
        };
        (
            self.ambient + self.diffuse * diffuse,
            self.specular * specular,
        )
    }
}
