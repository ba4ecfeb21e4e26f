//! Rendering into caller memory: the transfer function as tables, the render parameters, the
//! output formats, depth in and out in the camera's convention, rows top-down or bottom-up,
//! and the statistics of the last render.

use std::ffi::c_void;
use std::time::Instant;

use rayon::prelude::*;

use super::arrays::{self, product};
use super::camera::CylvolCamera;
use super::codes::{
    BlendCode, Code, CylvolBlend, CylvolInterpolation, CylvolPath, CylvolPixelFormat,
    InterpolationCode, PathCode, PixelFormatCode,
};
use super::status::{CylvolStatus, Failure};
use super::volume::{on_volume, CylvolVolume};
use crate::error::show_number;
use crate::render::{
    Blend, ClipPlanes, GradientOpacity, Image, Interpolation, RenderOptions, RenderPath,
    RenderStats, Renderer, Shading, TransferFunction, Volume, DEFAULT_TABLE_SIZE,
};

/// The transfer function: colour and opacity tables evenly spaced over a scalar range.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct CylvolTransfer {
    /// `n_color × 3` RGB values in `[0, 1]`, evenly spaced over `range` (clamped beyond).
    pub rgb: *const f32,
    /// Colour entries, ≥ 2.
    pub n_color: usize,
    /// `n_opacity` opacities in `[0, 1]` per `unit_distance`, evenly spaced over `range`.
    pub opacity: *const f32,
    /// Opacity entries, ≥ 2.
    pub n_opacity: usize,
    /// The scalar range the tables span, `range[0] ≤ range[1]`.
    pub range: [f64; 2],
    /// The distance the opacities apply to (VTK's `ScalarOpacityUnitDistance`), > 0.
    pub unit_distance: f64,
    /// NULL for none; else `n_gradient_opacity` factors in `[0, 1]`, evenly spaced over
    /// `gradient_range` of the gradient magnitude `|∇s|` (scalar units per world unit; clamped
    /// beyond), multiplying the opacity per unit distance (VTK's gradient opacity).
    pub gradient_opacity: *const f32,
    /// Gradient opacity entries, ≥ 2 when `gradient_opacity` is set.
    pub n_gradient_opacity: usize,
    /// The gradient-magnitude range the gradient opacity table spans.
    pub gradient_range: [f64; 2],
}

/// How to render.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylvolRenderParams {
    /// Image width in pixels, > 0.
    pub width: u32,
    /// Image height in pixels, > 0.
    pub height: u32,
    /// Sample spacing in world units; ≤ 0 means the volume's default step.
    pub step: f64,
    /// FAST or PAPER.
    pub path: PathCode,
    /// LINEAR (trilinear) or NEAREST (the value of the nearest corner).
    pub interpolation: InterpolationCode,
    /// Nonzero: shade with a headlight (gradients of the interpolated scalar).
    pub shading: i32,
    /// Ambient coefficient (default 0.1), ≥ 0.
    pub ambient: f64,
    /// Diffuse coefficient (default 0.7), ≥ 0.
    pub diffuse: f64,
    /// Specular coefficient (default 0.2), ≥ 0.
    pub specular: f64,
    /// Specular power (default 10), ≥ 0.
    pub specular_power: f64,
    /// Rays stop once their accumulated opacity reaches this (default 0.99), > 0.
    pub early_termination: f64,
    /// Nonzero: row 0 of the pixels and depths is the bottom row (VTK and OpenGL order).
    pub rows_bottom_up: i32,
    /// COMPOSITE (the default), MAXIMUM or MINIMUM (intensity projections). Added after the
    /// fields above: fill the struct with cylvol_render_params_default() first.
    pub blend: BlendCode,
    /// Clipping planes in use: the first `clip_plane_count` rows of `clip_planes`, 0 (the
    /// default) to CYLVOL_MAX_CLIP_PLANES. Added after the fields above.
    pub clip_plane_count: u32,
    /// Plane equations `{a, b, c, d}`: the volume is rendered only where
    /// `a x + b y + c z + d ≥ 0` for every plane in use (VTK's clipping planes, as
    /// `vtkAbstractMapper3D::GetClippingPlaneInDataCoords` gives them); each finite, with
    /// `(a, b, c)` not zero.
    pub clip_planes: [[f64; 4]; CYLVOL_MAX_CLIP_PLANES],
    /// The fast path's reach by marching, in cells (default 6, `INFINITY` always marches):
    /// a sample about more than this many cells ahead, times the cells a look-up through the
    /// volume's structure tests on average (about 1 on a BVH of well-shaped cells, 7–19 on a
    /// grid), where the ray provably stays in the mesh, is located through the structure
    /// instead (`CylvolRenderStats::far_locates`);
    /// the image is the same either way. ≥ 0, not NaN. Added after the fields above.
    pub march_reach: f64,
    /// The largest colour error allowed, in 1/255 of a pixel's premultiplied RGBA against the
    /// converged image (what the samples approach as they get denser); 0 (the default) for
    /// samples every `step`. Above 0, compositing places its samples along each ray where the
    /// field and the transfer function need them: each ray starts at `step`, and its steps
    /// adapt from 1/64 to 32 times it to hold the error; early termination stops a ray no
    /// earlier than its share of the error allows (`CylvolRenderStats::refined_samples`,
    /// `slopes` and `integrated_stretches` count its work). MAXIMUM and MINIMUM keep the fixed
    /// `step` and ignore it. Finite and ≥ 0. Added after the fields above.
    pub max_error: f64,
}

/// The most clipping planes a render takes (`CylvolRenderParams::clip_planes`).
pub const CYLVOL_MAX_CLIP_PLANES: usize = 6;
const _: () = assert!(CYLVOL_MAX_CLIP_PLANES == crate::render::MAX_CLIP_PLANES);

impl Default for CylvolRenderParams {
    /// 512 × 512, the default step, FAST, LINEAR, no shading (coefficients 0.1, 0.7, 0.2, 10),
    /// early termination at 0.99, rows top-down, compositing, no clipping plane, a march
    /// reach of 6 cells, the fixed step (no error bound).
    fn default() -> Self {
        let s = Shading::default();
        CylvolRenderParams {
            width: 512,
            height: 512,
            step: 0.0,
            path: CylvolPath::Fast.into(),
            interpolation: CylvolInterpolation::Linear.into(),
            shading: 0,
            ambient: s.ambient,
            diffuse: s.diffuse,
            specular: s.specular,
            specular_power: s.specular_power,
            early_termination: 0.99,
            rows_bottom_up: 0,
            blend: CylvolBlend::Composite.into(),
            clip_plane_count: 0,
            clip_planes: [[0.0; 4]; CYLVOL_MAX_CLIP_PLANES],
            march_reach: crate::render::DEFAULT_MARCH_REACH,
            max_error: 0.0,
        }
    }
}

/// The work of the last render of a volume: the counters of the Rust API's `RenderStats`,
/// field for field, with the wall time. Fields are only ever added at the end; compile against
/// the header of the library you link.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CylvolRenderStats {
    /// Wall time of the render call in seconds.
    pub seconds: f64,
    /// Rays cast (pixels).
    pub rays: u64,
    /// Sample positions taken along the rays.
    pub samples: u64,
    /// Samples found in a cell.
    pub samples_located: u64,
    /// Cells tested with the inverse trilinear map.
    pub hex_tests: u64,
    /// Internal nodes (grids: top-level cells) visited.
    pub internal_visits: u64,
    /// Leaf nodes (grids: second-level cells) visited.
    pub leaf_visits: u64,
    /// Gradients evaluated (shading only).
    pub gradient_evaluations: u64,
    /// Rays stopped by early termination.
    pub early_terminations: u64,
    /// Samples skipped because their cell is transparent (fast path).
    pub samples_skipped: u64,
    /// Of those, samples placed in their cell by its face planes alone, with no inverse map
    /// (fast path).
    pub plane_certified: u64,
    /// Samples found in the previous sample's cell (fast path).
    pub previous_cell_hits: u64,
    /// Samples found in a face neighbour of the previous sample's cell (fast path).
    pub neighbour_hits: u64,
    /// Cells stepped across by face planes, without an inverse map (fast path).
    pub walk_steps: u64,
    /// Samples passed over as empty space without point location (fast path).
    pub space_skips: u64,
    /// Samples located through the structure from scratch (fast path).
    pub structure_locates: u64,
    /// Samples with no previous cell found by a walk from the previous ray's first cell.
    pub entry_walk_hits: u64,
    /// Containment tests made to find where rays cross the mesh boundary (also counted in
    /// `hex_tests`).
    pub boundary_refinements: u64,
    /// Nodes of the boundary surface's BVH visited to skip the space outside the mesh (fast
    /// path).
    pub surface_visits: u64,
    /// Jumps over transparent space to the next cell that is not (fast path, every structure;
    /// the samples passed over are counted in `space_skips`).
    pub transparent_jumps: u64,
    /// Samples of an intensity projection passed over without interpolation, in cells whose
    /// scalar range cannot beat the ray's extreme so far (fast path).
    pub extreme_skips: u64,
    /// Jumps of an intensity projection over cells that cannot beat the ray's extreme to the
    /// next cell that may (fast path, BVH structures; the samples passed over are counted in
    /// `space_skips`).
    pub extreme_jumps: u64,
    /// Samples located through the structure rather than by marching to them: more than the
    /// march's reach ahead, the ray proved in the mesh up to them (fast path).
    pub far_locates: u64,
    /// Pieces of rays in the mesh too short to hold a sample (a grazing ray, a thin part),
    /// each sampled once at its middle (with the boundary surface, which the volume builds).
    pub chord_samples: u64,
    /// Stretches of rays outside the mesh between two samples in it (a thin blade crossed),
    /// left out of the samples' segments.
    pub gaps: u64,
    /// Samples an error-bounded render (`CylvolRenderParams::max_error` above 0) added between
    /// two others where the stretch between them was too long for the error allowed, or
    /// crossed an active cell; also counted in `samples` and `samples_located`. 0 at the
    /// fixed step.
    pub refined_samples: u64,
    /// Gradients of the scalar taken for its slope along the ray at the samples of an
    /// error-bounded render (shading and gradient opacity use the same gradient). 0 at the
    /// fixed step.
    pub slopes: u64,
    /// Stretches of rays an error-bounded render integrated through the transfer function,
    /// between two samples or from a sample to a crossing. 0 at the fixed step.
    pub integrated_stretches: u64,
}

impl From<(f64, RenderStats)> for CylvolRenderStats {
    fn from((seconds, s): (f64, RenderStats)) -> Self {
        CylvolRenderStats {
            seconds,
            rays: s.rays,
            samples: s.samples,
            samples_located: s.samples_located,
            hex_tests: s.hex_tests,
            internal_visits: s.internal_visits,
            leaf_visits: s.leaf_visits,
            gradient_evaluations: s.gradient_evaluations,
            early_terminations: s.early_terminations,
            samples_skipped: s.samples_skipped,
            plane_certified: s.plane_certified,
            previous_cell_hits: s.previous_cell_hits,
            neighbour_hits: s.neighbour_hits,
            walk_steps: s.walk_steps,
            space_skips: s.space_skips,
            structure_locates: s.structure_locates,
            entry_walk_hits: s.entry_walk_hits,
            boundary_refinements: s.boundary_refinements,
            surface_visits: s.surface_visits,
            transparent_jumps: s.transparent_jumps,
            extreme_skips: s.extreme_skips,
            extreme_jumps: s.extreme_jumps,
            far_locates: s.far_locates,
            chord_samples: s.chord_samples,
            gaps: s.gaps,
            refined_samples: s.refined_samples,
            slopes: s.slopes,
            integrated_stretches: s.integrated_stretches,
        }
    }
}

/// Reads `n` entries of `k` floats in `[0, 1]` at `ptr`.
unsafe fn table(ptr: *const f32, n: usize, k: usize, what: &str) -> Result<Vec<f64>, Failure> {
    if ptr.is_null() {
        return Err(Failure::null(what));
    }
    if n < 2 {
        return Err(Failure::invalid(format!(
            "{what} has {n} entries (at least 2)"
        )));
    }
    let len = product(n, k, what)?;
    // SAFETY: the caller vouches for the table's length.
    let values: Vec<f64> = unsafe { arrays::slice(ptr, len, what)? }
        .iter()
        .map(|&v| v as f64)
        .collect();
    match values.iter().position(|v| !(0.0..=1.0).contains(v)) {
        Some(i) => Err(Failure::invalid(format!(
            "{what}[{i}] = {} is not in [0, 1]",
            show_number(values[i])
        ))),
        None => Ok(values),
    }
}

fn range(r: [f64; 2], what: &str) -> Result<[f64; 2], Failure> {
    arrays::finite(&r, what)?;
    if r[0] > r[1] {
        return Err(Failure::invalid(format!(
            "{what} = [{}, {}] is reversed",
            show_number(r[0]),
            show_number(r[1])
        )));
    }
    Ok(r)
}

/// The transfer function of the tables, the table size that resolves them over the data range
/// `data`, and the gradient opacity if a table is given.
///
/// # Safety
/// The tables as the struct documents.
unsafe fn transfer_function(
    t: &CylvolTransfer,
    data: [f64; 2],
) -> Result<(TransferFunction, usize, Option<GradientOpacity>), Failure> {
    // SAFETY: the caller vouches for the tables.
    let rgb = unsafe { table(t.rgb, t.n_color, 3, "transfer->rgb")? };
    let opacity = unsafe { table(t.opacity, t.n_opacity, 1, "transfer->opacity")? };
    let [lo, hi] = range(t.range, "transfer->range")?;
    if !(t.unit_distance > 0.0 && t.unit_distance.is_finite()) {
        return Err(Failure::invalid(format!(
            "transfer->unit_distance = {} (must be positive and finite)",
            show_number(t.unit_distance)
        )));
    }
    let gradient = if t.gradient_opacity.is_null() {
        None
    } else {
        // SAFETY: as above.
        let g = unsafe {
            table(
                t.gradient_opacity,
                t.n_gradient_opacity,
                1,
                "transfer->gradient_opacity",
            )?
        };
        let [g0, g1] = range(t.gradient_range, "transfer->gradient_range")?;
        let n = g.len();
        let points: Vec<(f64, f64)> = g
            .iter()
            .enumerate()
            .map(|(k, &f)| (g0 + (g1 - g0) * k as f64 / (n - 1) as f64, f))
            .collect();
        Some(
            GradientOpacity::new(&points)
                .map_err(|e| Failure::invalid(format!("transfer->gradient_opacity: {e}")))?,
        )
    };
    let at = |k: usize, n: usize| lo + (hi - lo) * k as f64 / (n - 1) as f64;
    let tf = TransferFunction {
        color: rgb
            .chunks_exact(3)
            .enumerate()
            .map(|(k, c)| (at(k, t.n_color), [c[0], c[1], c[2]]))
            .collect(),
        opacity: opacity
            .iter()
            .enumerate()
            .map(|(k, &a)| (at(k, t.n_opacity), a))
            .collect(),
        unit_distance: t.unit_distance,
    };
    // Four table entries per table interval over the data range, within [1024, 65536].
    let entries = t.n_color.max(t.n_opacity) - 1;
    let span = data[1] - data[0];
    let size = if hi > lo && span > 0.0 {
        (4.0 * entries as f64 * span / (hi - lo)).ceil()
    } else {
        0.0
    };
    let size = (size.min(65536.0) as usize).max(DEFAULT_TABLE_SIZE);
    Ok((tf, size, gradient))
}

/// Checks the render parameters; returns the options (the step resolved against
/// `default_step`).
fn options(p: &CylvolRenderParams, default_step: f64) -> Result<RenderOptions, Failure> {
    if p.width == 0 || p.height == 0 {
        return Err(Failure::invalid(format!(
            "params: image size {}x{} (both must be > 0)",
            p.width, p.height
        )));
    }
    let path = match p.path.decode("params->path")? {
        CylvolPath::Fast => RenderPath::Fast,
        CylvolPath::Paper => RenderPath::Paper,
    };
    let interpolation = match p.interpolation.decode("params->interpolation")? {
        CylvolInterpolation::Linear => Interpolation::Linear,
        CylvolInterpolation::Nearest => Interpolation::Nearest,
    };
    let blend = match p.blend.decode("params->blend")? {
        CylvolBlend::Composite => Blend::Composite,
        CylvolBlend::Maximum => Blend::Maximum,
        CylvolBlend::Minimum => Blend::Minimum,
    };
    let step = match p.step {
        s if s.is_nan() || s.is_infinite() => {
            return Err(Failure::invalid(format!(
                "params->step = {} is not finite",
                show_number(s)
            )))
        }
        s if s <= 0.0 => default_step,
        s => s,
    };
    let shading = if p.shading != 0 {
        let k = [p.ambient, p.diffuse, p.specular, p.specular_power];
        if let Some(i) = k.iter().position(|v| !(*v >= 0.0 && v.is_finite())) {
            let name = ["ambient", "diffuse", "specular", "specular_power"][i];
            return Err(Failure::invalid(format!(
                "params->{name} = {} (must be finite and ≥ 0)",
                show_number(k[i])
            )));
        }
        Some(Shading {
            ambient: p.ambient,
            diffuse: p.diffuse,
            specular: p.specular,
            specular_power: p.specular_power,
        })
    } else {
        None
    };
    if !(p.early_termination > 0.0 && p.early_termination.is_finite()) {
        return Err(Failure::invalid(format!(
            "params->early_termination = {} (must be positive and finite)",
            show_number(p.early_termination)
        )));
    }
    let count = p.clip_plane_count as usize;
    if count > CYLVOL_MAX_CLIP_PLANES {
        return Err(Failure::invalid(format!(
            "params->clip_plane_count = {count} (at most {CYLVOL_MAX_CLIP_PLANES})"
        )));
    }
    let clip_planes = ClipPlanes::new(&p.clip_planes[..count])
        .map_err(|e| Failure::invalid(format!("params->clip_planes: {e}")))?;
    if p.march_reach.is_nan() || p.march_reach < 0.0 {
        return Err(Failure::invalid(format!(
            "params->march_reach = {} (a number of cells, ≥ 0; INFINITY always marches)",
            show_number(p.march_reach)
        )));
    }
    let max_error = max_error(p.max_error)?;
    let mut o = RenderOptions::new(p.width, p.height, step);
    o.max_error = max_error;
    o.clip_planes = clip_planes;
    o.path = path;
    o.shading = shading;
    o.early_termination = p.early_termination;
    o.interpolation = interpolation;
    o.blend = blend;
    o.march_reach = p.march_reach;
    Ok(o)
}

/// The error bound of `params->max_error`: `None` at 0 (the fixed step), the error above;
/// fails unless finite and ≥ 0.
fn max_error(e: f64) -> Result<Option<f64>, Failure> {
    if e == 0.0 {
        Ok(None)
    } else if e > 0.0 && e.is_finite() {
        Ok(Some(e))
    } else {
        Err(Failure::invalid(format!(
            "params->max_error = {} (must be a finite number of 1/255 of a pixel's RGBA, ≥ 0; \
             0 uses the fixed step)",
            show_number(e)
        )))
    }
}

/// The row of image row `j` in the caller's order.
fn caller_row(j: u32, height: u32, bottom_up: bool) -> usize {
    (if bottom_up { height - 1 - j } else { j }) as usize
}

/// Renders the volume into caller memory.
///
/// `pixels`: `width × height × 4` bytes (RGBA8) or floats (RGBA_F32), premultiplied alpha;
/// `pixels_len` counts elements (bytes or floats) and must equal `width × height × 4`.
/// `depth_in` / `depth_out`: NULL or `width × height` floats. With a LOOK_AT camera a depth
/// is the distance along the pixel's ray from the eye (from the eye's plane for a parallel
/// camera); with MATRICES it is the window depth in `[0, 1]` (the OpenGL z-buffer value,
/// 1 = far plane). Rays stop at `depth_in` (opaque geometry; window depth 1 stops none);
/// `depth_out` is where the accumulated opacity first reaches 0.5 (+∞, or 1 with MATRICES,
/// where it never does). `rows_bottom_up` orders the rows of all three.
///
/// Errors: NULL_POINTER (volume, camera, transfer, params, pixels, a table),
/// INVALID_ARGUMENT (a bad enum value, a zero image size, NaN or infinite camera, table,
/// range, step or depth values, a negative, NaN or infinite max_error, tables of fewer than 2 entries or values outside [0, 1], a
/// degenerate camera), LENGTH_MISMATCH
/// (`pixels_len`), NO_SCALARS (no scalars set).
///
/// # Safety
/// `volume` a live handle used by this thread only; the structs readable; the arrays of the
/// lengths stated, `pixels` and `depth_out` writable and not overlapping anything else.
#[no_mangle]
pub unsafe extern "C" fn cylvol_render(
    volume: *mut CylvolVolume,
    camera: *const CylvolCamera,
    transfer: *const CylvolTransfer,
    params: *const CylvolRenderParams,
    depth_in: *const f32,
    depth_out: *mut f32,
    format: PixelFormatCode,
    pixels: *mut c_void,
    pixels_len: usize,
) -> CylvolStatus {
    // SAFETY: the caller vouches for every pointer.
    unsafe {
        on_volume("cylvol_render", volume, |v| {
            let started = Instant::now();
            let camera = camera.as_ref().ok_or_else(|| Failure::null("camera"))?;
            let transfer = transfer.as_ref().ok_or_else(|| Failure::null("transfer"))?;
            let params = params.as_ref().ok_or_else(|| Failure::null("params"))?;
            let format = format.decode("format")?;
            let options = options(params, v.default_step)?;
            let (w, h) = (params.width, params.height);
            let n = product(w as usize, h as usize, "width × height")?;
            let expected = product(n, 4, "pixels")?;
            if pixels.is_null() {
                return Err(Failure::null("pixels"));
            }
            if pixels_len != expected {
                return Err(Failure::new(
                    CylvolStatus::LengthMismatch,
                    format!("pixels_len = {pixels_len}, expected {expected} for {w}x{h} RGBA"),
                ));
            }
            let earlier = v.derived.take();
            let mesh = v.mesh();
            let (field, lo, hi) = match &v.field {
                Some(field) => {
                    let [lo, hi] = field.range();
                    (field, lo, hi)
                }
                None => {
                    return Err(Failure::new(
                        CylvolStatus::NoScalars,
                        "the volume has no scalar array (cylvol_mesh_set_scalars before \
                         cylvol_volume_new, or cylvol_volume_set_scalars)",
                    ))
                }
            };
            let volume = Volume::with_field(mesh, &v.accel, field)?;
            // Over every copy drawn where a vector's component turns with the copies.
            let data = match &v.copies {
                Some(c) => c.scalar_range(&volume)?,
                None => [lo, hi],
            };
            let (tf, table_size, gradient) = transfer_function(transfer, data)?;
            let rays = camera.rays(w, h)?;
            let bottom_up = params.rows_bottom_up != 0;
            let depth = if depth_in.is_null() {
                None
            } else {
                let d = arrays::slice(depth_in, n, "depth_in")?;
                let mut t = vec![0f32; n];
                for j in 0..h {
                    let row = caller_row(j, h, bottom_up) * w as usize;
                    for i in 0..w {
                        let at = row + i as usize;
                        let z = d[at];
                        let bad = z.is_nan() || rays.window_depths() && !(0.0..=1.0).contains(&z);
                        if bad {
                            return Err(Failure::invalid(format!(
                                "depth_in[{at}] = {z} (must be {})",
                                if rays.window_depths() {
                                    "a window depth in [0, 1]"
                                } else {
                                    "a distance, not NaN"
                                }
                            )));
                        }
                        t[j as usize * w as usize + i as usize] = rays.distance(i, j, z) as f32;
                    }
                }
                Some(t)
            };
            let mut options = options;
            options.table_size = table_size;
            options.gradient_opacity = gradient;
            let mut renderer = Renderer::new(&volume, &tf, &options)?;
            if options.path == RenderPath::Fast {
                renderer = renderer.with_topology(&v.neighbours);
            }
            if let Some(c) = v.copies {
                renderer = renderer.with_copies(c)?;
            }
            // The last frame's transparent cells and visible nodes, where its table is this
            // one's (a mapper's next frame): same volume, since they are dropped with the
            // scalars.
            if let Some(derived) = earlier {
                renderer = renderer.with_derived(derived);
            }
            let (image, stats) = renderer.render_rays(rays.source(), depth.as_deref())?;
            let derived = renderer.into_derived();
            write_pixels(&image, format, pixels, bottom_up)?;
            if !depth_out.is_null() {
                let out = arrays::slice_mut(depth_out, n, "depth_out")?;
                for j in 0..h {
                    let row = caller_row(j, h, bottom_up) * w as usize;
                    for i in 0..w {
                        let t = image.depth[j as usize * w as usize + i as usize];
                        out[row + i as usize] = rays.depth(i, j, t);
                    }
                }
            }
            v.derived = derived;
            v.last_render = (started.elapsed().as_secs_f64(), stats);
            Ok(())
        })
    }
}

/// Copies the image into the caller's pixels (length checked by the caller), rows in parallel.
unsafe fn write_pixels(
    image: &Image,
    format: CylvolPixelFormat,
    pixels: *mut c_void,
    bottom_up: bool,
) -> Result<(), Failure> {
    let (w, h) = (image.width as usize, image.height);
    let n = w * h as usize * 4;
    // The image row that goes to the caller's row `r` (`caller_row` is its own inverse).
    let source = |r: usize| {
        let j = caller_row(r as u32, h, bottom_up);
        &image.rgba[j * w..(j + 1) * w]
    };
    match format {
        CylvolPixelFormat::RGBA8 => {
            // SAFETY: the caller checked the length.
            let out = unsafe { arrays::slice_mut(pixels as *mut u8, n, "pixels")? };
            out.par_chunks_mut(w * 4).enumerate().for_each(|(r, row)| {
                for (px, p) in row.chunks_exact_mut(4).zip(source(r)) {
                    for k in 0..4 {
                        px[k] = (p[k].clamp(0.0, 1.0) * 255.0).round() as u8;
                    }
                }
            });
        }
        CylvolPixelFormat::RGBA_F32 => {
            // SAFETY: as above.
            let out = unsafe { arrays::slice_mut(pixels as *mut f32, n, "pixels")? };
            out.par_chunks_mut(w * 4).enumerate().for_each(|(r, row)| {
                for (px, p) in row.chunks_exact_mut(4).zip(source(r)) {
                    px.copy_from_slice(p);
                }
            });
        }
    }
    Ok(())
}

/// Fills `params` with the defaults: 512 × 512, the default step, FAST, LINEAR, no shading
/// (coefficients 0.1, 0.7, 0.2, 10), early termination at 0.99, rows top-down, compositing,
/// no clipping plane, a march reach of 6 cells, the fixed step (`max_error` 0).
///
/// # Safety
/// `params` NULL (nothing happens) or valid for writing a `CylvolRenderParams`.
#[no_mangle]
pub unsafe extern "C" fn cylvol_render_params_default(params: *mut CylvolRenderParams) {
    let _ = super::status::guard("cylvol_render_params_default", || {
        // SAFETY: the caller vouches for the pointer.
        unsafe { arrays::write(params, CylvolRenderParams::default(), "params") }
    });
}

/// The work of the volume's last successful render (zeros before the first).
///
/// # Safety
/// `volume` a live handle; `stats` valid for writing.
#[no_mangle]
pub unsafe extern "C" fn cylvol_volume_render_stats(
    volume: *const CylvolVolume,
    stats: *mut CylvolRenderStats,
) -> CylvolStatus {
    super::status::status("cylvol_volume_render_stats", || {
        // SAFETY: the caller vouches for the pointers.
        let v = unsafe { arrays::handle(volume, "volume")? };
        unsafe { arrays::write(stats, CylvolRenderStats::from(v.last_render), "stats") }
    })
}
