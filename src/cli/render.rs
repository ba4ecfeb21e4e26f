//! `cylvol render INPUT -o OUT.png [--structure …] [--size WxH] [--step S] [--scalar NAME]
//! [--view AZIMUTH,ELEVATION,ZOOM] [--path paper|fast] [--shade] [--interpolation linear|nearest]
//! [--gradient-opacity M:G,M:G,...] [--opacity S:A,...] [--color S:R:G:B,...]
//! [--unit-distance D] [--blend composite|max|min] [--camera POSITION:FOCAL:UP]
//! [--view-angle DEG] [--parallel [--parallel-scale S]] [--clip-plane X,Y,Z:NX,NY,NZ]...
//! [--depth OUT.vti [--depth-opacity A]] [--depth-in IN.vti]`:
//! renders one image (and its depth image with `--depth`; rays stopped by opaque geometry's
//! depth image with `--depth-in`) and reports the time and the work counters on standard error
//! (as JSON on standard output with `--json`).
//!
//! Defaults: `--structure auto` (the cylindrical BVH when the detected axis is clear, else the
//! Cartesian BVH), `--size 512x512`, `--step` half the mean cell size
//! ([`cylvol::render::default_step`]), `--view 0,0,1` (VTK's reset camera: looking down `−z`
//! at the bounds' centre), `--path fast`, no shading, compositing (`--blend max` and `min`
//! are maximum- and minimum-intensity projections, [`cylvol::render::Blend`]). The transfer function is
//! [`cylvol::render::TransferFunction::default_for_range`] over the scalar range with a
//! maximum opacity of 0.3 per hundredth of the mesh's diagonal, or what `--opacity`, `--color`
//! and `--unit-distance` set ([`super::transfer`]); the background is black. The camera
//! options are [`super::camera`]'s.

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;
use serde_json::json;

use super::camera::CameraArgs;
use super::number::show;
use super::periodic::{self, PeriodicArgs};
use super::scene::StructureChoice;
use super::transfer::TransferArgs;
use super::{log, output, scene, InputArgs};
use cylvol::accel::AccelParams;
use cylvol::io::vti;
use cylvol::render::{
    Blend, ClipPlanes, GradientOpacity, Interpolation, RenderOptions, RenderPath, Renderer,
    Shading, Volume,
};
use cylvol::Error;

/// Arguments of `cylvol render`.
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    input: InputArgs,
    /// The PNG file to write.
    #[arg(short = 'o', long = "output", value_name = "OUT.png")]
    output: PathBuf,
    /// cart-grid, cyl-grid, cart-bvh, cyl-bvh or auto.
    #[arg(long, default_value = "auto")]
    structure: StructureChoice,
    /// Image size WxH.
    #[arg(long, default_value = "512x512", value_parser = parse_size, allow_hyphen_values = true)]
    size: (u32, u32),
    /// Sample spacing in world units (default: half the mean cell size). Given alone, every
    /// ray is sampled at this fixed step; with --max-error, it is the step rays start with.
    #[arg(long, value_parser = super::number::parse_step, allow_hyphen_values = true)]
    step: Option<f64>,
    /// The largest colour error allowed, in 1/255 of a pixel's premultiplied RGBA against the
    /// converged image (e.g. 2; default: none, every ray sampled at the fixed step): the samples are placed along each
    /// ray where the field and the transfer function need them.
    #[arg(long, value_name = "E", value_parser = scene::parse_max_error, allow_hyphen_values = true)]
    max_error: Option<f64>,
    #[command(flatten)]
    camera: CameraArgs,
    /// paper (locate every sample through the structure) or fast.
    #[arg(long, default_value = "fast")]
    path: RenderPath,
    /// Shade with a headlight (gradients from the trilinear interpolant).
    #[arg(long)]
    shade: bool,
    /// Every sample stands for a whole step, even where the ray crosses the mesh boundary
    /// (faster, first order in the step); by default boundary samples are cut at the crossing.
    #[arg(long)]
    whole_steps: bool,
    /// linear (trilinear) or nearest (the value of the nearest cell corner).
    #[arg(long, default_value = "linear")]
    interpolation: Interpolation,
    /// Gradient opacity as `vtkVolumeProperty` holds it: `M:G` points of a piecewise-linear
    /// factor G in [0, 1] of the gradient magnitude M, in increasing M, e.g. `0:0,0.5:1`.
    #[arg(long, value_name = "M:G,M:G,...", value_parser = parse_gradient_opacity, allow_hyphen_values = true)]
    gradient_opacity: Option<Box<GradientOpacity>>,
    /// composite (front-to-back compositing), max or min (maximum- or minimum-intensity
    /// projection: the extreme scalar's colour and opacity; no shading).
    #[arg(long, default_value = "composite")]
    blend: Blend,
    #[command(flatten)]
    transfer: TransferArgs,
    #[command(flatten)]
    periodic: PeriodicArgs,
    /// Also write the depth image as VTK image data (`.vti`, a `depth` point array over a
    /// WxH image, rows bottom to top): per pixel, the distance from the camera (from its plane
    /// with `--parallel`) of the sample at which the accumulated opacity reaches
    /// `--depth-opacity`, NaN where it never does.
    #[arg(long, value_name = "OUT.vti")]
    depth: Option<PathBuf>,
    /// The accumulated opacity, in (0, 1], at which a pixel's depth is taken [default: 0.5].
    #[arg(long, value_name = "A", value_parser = parse_depth_opacity, requires = "depth", allow_hyphen_values = true)]
    depth_opacity: Option<f64>,
    /// Opaque geometry's depth image, where rays stop: VTK image data (`.vti`) of WxH points,
    /// rows bottom to top, its active (or only) point array per pixel the distance along the
    /// pixel's ray from the camera (from its plane with `--parallel`), as `--depth` writes
    /// it; NaN or infinity where nothing stops the ray.
    #[arg(long, value_name = "IN.vti")]
    depth_in: Option<PathBuf>,
    /// A clipping plane, as VTK's mappers take one: a point on it and its normal, in world
    /// units; only the side the normal points to is rendered, and the volume ends on the plane.
    /// Up to 6 (repeat the option).
    #[arg(long = "clip-plane", value_name = "X,Y,Z:NX,NY,NZ", value_parser = parse_clip_plane, allow_hyphen_values = true)]
    clip_planes: Vec<[f64; 4]>,
    /// The fast path marches from cell to cell up to about this many cells ahead, times the
    /// cells a look-up through the structure tests on average (`cylvol stats`, `hex/lk`); a
    /// sample further ahead, where the ray provably stays in the mesh, is located through the
    /// structure (`stats.far_locates`); `inf` always marches. The image is the same either way.
    #[arg(long, value_name = "CELLS", default_value_t = cylvol::render::DEFAULT_MARCH_REACH, value_parser = parse_march_reach, allow_hyphen_values = true)]
    march_reach: f64,
    /// Print the figures as JSON on standard output.
    #[arg(long)]
    json: bool,
}

/// Parses `--march-reach CELLS`: a number of cells, 0 or more, or `inf`.
fn parse_march_reach(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(r) if r >= 0.0 => Ok(r),
        _ => Err(format!(
            "march reach '{s}' is not a number of cells, 0 or more (inf to always march)"
        )),
    }
}

/// Parses `--clip-plane X,Y,Z:NX,NY,NZ` into the plane's equation (see [`ClipPlanes`]).
fn parse_clip_plane(s: &str) -> Result<[f64; 4], String> {
    let [point, normal] = super::camera::parse_vectors(s)
        .ok_or_else(|| format!("clip plane '{s}' is not POINT:NORMAL, each X,Y,Z"))?;
    if normal == DVec3::ZERO {
        return Err(format!("clip plane '{s}' has a zero normal"));
    }
    let equation = ClipPlanes::equation(point, normal);
    if !equation[3].is_finite() {
        return Err(format!(
            "clip plane '{s}': its point and normal are too large for the plane's equation \
             (their dot product overflows)"
        ));
    }
    Ok(equation)
}

fn parse_depth_opacity(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(a) if a > 0.0 && a <= 1.0 => Ok(a),
        _ => Err(format!("depth opacity '{s}' must be a number in (0, 1]")),
    }
}

fn parse_gradient_opacity(s: &str) -> Result<Box<GradientOpacity>, String> {
    let points = s
        .split(',')
        .map(|pair| {
            let (m, g) = pair
                .split_once(':')
                .ok_or_else(|| format!("'{pair}' is not M:G"))?;
            let m: f64 = m
                .trim()
                .parse()
                .map_err(|_| format!("bad magnitude in '{pair}'"))?;
            let g: f64 = g
                .trim()
                .parse()
                .map_err(|_| format!("bad factor in '{pair}'"))?;
            Ok((m, g))
        })
        .collect::<Result<Vec<_>, String>>()?;
    GradientOpacity::new(&points)
        .map(Box::new)
        .map_err(|e| e.to_string())
}

/// Parses `--size WxH`, each side a whole number of pixels from 1 to 16384.
fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("size '{s}' must be WxH, each a whole number of pixels from 1 to 16384");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let side = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|n| (1..=16384).contains(n))
            .ok_or_else(bad)
    };
    Ok((side(w)?, side(h)?))
}

/// What `--shade` and `--gradient-opacity` cannot do in this render, said before it: with
/// `--blend max` or `min` neither is applied (a projection takes the extreme scalar's colour
/// and opacity); a cell scalar is constant in each cell, so the renderer has no gradient for
/// it: shading lights every sample alike, as if it faced the light, and gradient opacity
/// gives every sample the factor of a zero gradient.
fn ignored_effects(
    mesh: &cylvol::Mesh,
    shade: bool,
    gradient_opacity: Option<&GradientOpacity>,
    blend: Blend,
) -> Vec<String> {
    let mut warnings = Vec::new();
    let options = match (shade, gradient_opacity.is_some()) {
        (true, true) => "--shade and --gradient-opacity",
        (true, false) => "--shade",
        (false, true) => "--gradient-opacity",
        (false, false) => return warnings,
    };
    if blend != Blend::Composite {
        let verb = if shade && gradient_opacity.is_some() {
            "are"
        } else {
            "is"
        };
        warnings.push(format!(
            "--blend {} takes the extreme scalar's colour and opacity as they are: {options} \
             {verb} ignored",
            blend.name()
        ));
        return warnings;
    }
    let Some(active) = mesh.active_scalar() else {
        return warnings;
    };
    if active.association != cylvol::Association::Cell {
        return warnings;
    }
    let scalar = active.selector(mesh.point_data(), mesh.cell_data());
    let why = format!(
        "the scalar {scalar} is a cell array, constant in each cell, so it has no gradient"
    );
    if shade {
        warnings.push(format!(
            "--shade: {why}: every sample is lit alike, as if it faced the light, and no \
             shape shows; shade a point array (--scalar)"
        ));
    }
    if let Some(g) = gradient_opacity {
        let factor = g.at(0.0);
        let effect = if factor == 0.0 {
            ", so nothing is visible".to_string()
        } else if factor == 1.0 {
            ", so it changes nothing".to_string()
        } else {
            format!(": every opacity is scaled by {}", show(factor))
        };
        warnings.push(format!(
            "--gradient-opacity: {why}: every sample takes the factor of a zero gradient, \
             {}{effect}; use a point array (--scalar)",
            show(factor)
        ));
    }
    warnings
}

/// `--depth-in`'s image, rows top to bottom, checked to be `width × height`.
fn depth_image(path: &Path, width: u32, height: u32) -> Result<Vec<f32>, Error> {
    let image = vti::read_point_scalars_file(path)
        .map_err(|e| Error::Invalid(format!("--depth-in: {e}")))?;
    if (image.width, image.height) != (width, height) {
        return Err(Error::Invalid(format!(
            "--depth-in {}: a {}x{} image, but the render is {width}x{height} (--size)",
            path.display(),
            image.width,
            image.height
        )));
    }
    Ok(image.top_down_f32())
}

pub fn run(args: &RenderArgs) -> Result<(), Error> {
    // Checked before any work (clap has checked each plane; this, their number).
    output::check("-o", &args.output, "a PNG image", &["png"])?;
    if let Some(depth) = &args.depth {
        output::check("--depth", depth, "VTK image data", &["vti"])?;
    }
    args.camera.check()?;
    let clip_planes = ClipPlanes::new(&args.clip_planes)
        .map_err(|e| Error::Invalid(format!("--clip-plane: {e}")))?;
    let (width, height) = args.size;
    let depth_in = args
        .depth_in
        .as_deref()
        .map(|path| depth_image(path, width, height))
        .transpose()?;
    let mesh = scene::renderable(args.input.load()?)?;
    let (axis, _) = args.input.axis(&mesh);
    let copies = args.periodic.copies(&mesh, &axis)?;
    let kind = scene::structure(args.structure, &mesh, &axis);
    let (path, interpolation, blend) = (args.path, args.interpolation, args.blend);
    for warning in ignored_effects(&mesh, args.shade, args.gradient_opacity.as_deref(), blend) {
        log(format_args!("warning: {warning}"));
    }
    let accel = super::build_logged(&mesh, kind, &axis, &AccelParams::default())?;
    let volume = Volume::new(&mesh, &accel)?;
    let (step, max_error) = scene::sampling(&mesh, args.step, args.max_error)?;
    // The scene: the mesh, or the wheel its copies make (where a vector's component turns
    // with the copies, over its range in every copy drawn).
    let drawn_range = match &copies {
        Some(c) => c.scalar_range(&volume)?,
        None => volume.scalar_range(),
    };
    if let Some(warning) = scene::constant_field_warning(&mesh, drawn_range) {
        log(format_args!("warning: {warning}"));
    }
    let range = scene::transfer_range(drawn_range);
    let bounds = copies.as_ref().map_or(mesh.bounds(), |c| c.bounds());
    let diagonal = scene::diagonal_of(bounds);
    let transfer = args
        .transfer
        .apply(scene::transfer_over(diagonal, range), range, diagonal)?;
    let mut options = RenderOptions::new(width, height, step);
    options.path = path;
    options.shading = args.shade.then(Shading::default);
    options.boundary_segments = !args.whole_steps;
    options.interpolation = interpolation;
    options.gradient_opacity = args.gradient_opacity.as_deref().copied();
    options.blend = blend;
    options.clip_planes = clip_planes;
    options.march_reach = args.march_reach;
    options.max_error = max_error;
    if let Some(a) = args.depth_opacity {
        options.depth_opacity = a;
    }
    // The fast path walks from a sample's cell to its face neighbours (across duplicated
    // seams too); the paper path locates every sample from scratch and needs none.
    let neighbours = (path == RenderPath::Fast).then(|| {
        periodic::wheel_topology(scene::neighbours(&mesh, &accel), &mesh, copies.as_ref())
    });
    let mut renderer = Renderer::new(&volume, &transfer, &options)?;
    if renderer.table().transparent_everywhere() {
        let [lo, hi] = drawn_range.map(show);
        log(format_args!(
            "warning: the transfer function's opacity is zero at every value of the scalar \
             (over [{lo}, {hi}]): the image is empty; give --opacity a non-zero opacity there"
        ));
    }
    if let Some(n) = &neighbours {
        renderer = renderer.with_topology(n);
    }
    if let Some(c) = copies {
        renderer = renderer.with_copies(c)?;
    }
    let camera = args.camera.camera_for(bounds, width, height)?;
    let started = Instant::now();
    let (image, stats) = renderer.render(&camera, depth_in.as_deref())?;
    let frame_s = started.elapsed().as_secs_f64();
    output::write_replacing(&args.output, |path| image.write_png(path, Some([0.0; 3])))?;
    if let Some(depth) = &args.depth {
        output::write_replacing(depth, |path| image.write_depth_vti(path))?;
        log(format_args!("wrote the depth image {}", depth.display()));
    }
    log(format_args!(
        "rendered {width}x{height} with {kind} ({}, step {step:.4e}) in {frame_s:.3} s: {} samples ({} skipped), {} hexahedra tested, {} internal / {} leaf visits, {} gradients; wrote {}",
        path.name(),
        stats.samples,
        stats.samples_skipped,
        stats.hex_tests,
        stats.internal_visits,
        stats.leaf_visits,
        stats.gradient_evaluations,
        args.output.display()
    ));
    if args.json {
        let report = json!({
            "dataset": cylvol::input::Input::parse(&args.input.input)?.label(),
            "cells": mesh.cell_count(),
            "structure": kind.name(),
            "path": path.name(),
            "blend": blend.name(),
            "clip_planes": options.clip_planes.equations(),
            "depth_in": args.depth_in.as_ref().map(|p| p.display().to_string()),
            "width": width,
            "height": height,
            "step": step,
            "max_error": options.error_bounded().then_some(max_error).flatten(),
            "periodic": periodic::json(copies.as_ref()),
            "frame_s": frame_s,
            "stats": stats,
        });
        outln!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| Error::Invalid(e.to_string()))?
        );
    }
    Ok(())
}
