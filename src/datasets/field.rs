//! Small smooth functions the datasets' `pressure` and `velocity` fields are made of: blade
//! wakes, blade loading, Gaussian bumps and the conversion of cylindrical vector components.

use std::f64::consts::{PI, TAU};

use glam::DVec3;

/// A periodic wake profile in the passage phase `phase` (in pitches): 1 on the blade line
/// (`phase` = 0 ≡ 1), falling smoothly to `exp(-2·sharpness)` mid-passage.
pub(crate) fn wake(phase: f64, sharpness: f64) -> f64 {
    (sharpness * ((TAU * phase).cos() - 1.0)).exp()
}

/// Blade loading along the chord: `sin²(π·chord)` inside the bladed zone, 0 outside; it
/// vanishes (with zero slope) at the leading and trailing edges, where the two sides of a
/// blade meet, so the pressure jump across a blade closes there.
pub(crate) fn loading(chord: Option<f64>) -> f64 {
    chord.map_or(0.0, |c| (PI * c).sin().powi(2))
}

/// `exp(−((x − centre)/width)²)`.
pub(crate) fn gaussian(x: f64, centre: f64, width: f64) -> f64 {
    let t = (x - centre) / width;
    (-t * t).exp()
}

/// The Cartesian vector with radial, tangential and axial components `[v_r, v_θ, v_z]` at
/// azimuth `theta` (about the z axis).
pub(crate) fn cylindrical_vector(theta: f64, [vr, vt, vz]: [f64; 3]) -> DVec3 {
    let (s, c) = theta.sin_cos();
    DVec3::new(vr * c - vt * s, vr * s + vt * c, vz)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wake_is_periodic_and_peaks_on_the_blade() {
        assert!((wake(0.0, 5.0) - 1.0).abs() < 1e-15);
        assert!((wake(1.0, 5.0) - 1.0).abs() < 1e-12);
        assert!((wake(0.1, 5.0) - wake(1.1, 5.0)).abs() < 1e-12);
        assert!(wake(0.5, 5.0) < 1e-4);
    }

    #[test]
    fn loading_closes_at_the_edges() {
        assert_eq!(loading(None), 0.0);
        assert!(loading(Some(0.0)).abs() < 1e-30);
        assert!(loading(Some(1.0)).abs() < 1e-30);
        assert!((loading(Some(0.5)) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn cylindrical_vector_rotates_components() {
        let v = cylindrical_vector(PI / 2.0, [1.0, 2.0, 3.0]);
        assert!((v - DVec3::new(-2.0, 1.0, 3.0)).length() < 1e-12);
        assert!((gaussian(1.0, 1.0, 0.3) - 1.0).abs() < 1e-15);
    }
}
