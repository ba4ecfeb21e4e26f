//! Fuzz target: the C ABI driven as a careless C caller would drive it — random points,
//! offsets, connectivity and type codes (mostly a jittered block of hexahedra, then mutated),
//! random scalar arrays, build parameters, cameras (look-at and matrices), transfer tables,
//! render parameters, tiny images and depth buffers, and out-of-range enum codes. Every call
//! must return a status, never a panic (CYLVOL_STATUS_PANIC) or a crash, and a successful
//! render must give finite premultiplied pixels in [0, 1]. Array lengths passed always match
//! the buffers (the ABI trusts them, as C must).
#![no_main]

use std::ffi::CStr;
use std::ptr::{null, null_mut};

use cylvol::ffi::*;
use libfuzzer_sys::arbitrary::{Result, Unstructured};

fn detail() -> String {
    unsafe { CStr::from_ptr(cylvol_last_error()) }
        .to_string_lossy()
        .into_owned()
}

fn not_panic(s: CylvolStatus) -> CylvolStatus {
    assert_ne!(s, CylvolStatus::Panic, "{}", detail());
    s
}

/// A float: usually in `[lo, hi]`, sometimes anything (NaN, ±∞, huge, tiny).
fn float(u: &mut Unstructured, lo: f64, hi: f64) -> Result<f64> {
    Ok(match u.int_in_range(0u8..=15)? {
        0 => f64::NAN,
        1 => f64::INFINITY,
        2 => -f64::INFINITY,
        3 => u.arbitrary::<f64>()?,
        4 => 0.0,
        _ => lo + (hi - lo) * (u.int_in_range(0u32..=1_000_000)? as f64 / 1e6),
    })
}

/// An enum code: usually valid (`0..n`), sometimes not.
fn code(u: &mut Unstructured, n: i32) -> Result<i32> {
    Ok(if u.ratio(1u8, 12)? {
        u.arbitrary()?
    } else {
        u.int_in_range(0..=n - 1)?
    })
}

/// Caller arrays: a jittered `nx × ny × nz` block of hexahedra, then mutations.
struct Arrays {
    points: Vec<f64>,
    offsets: Vec<i64>,
    conn: Vec<i64>,
    types: Vec<u8>,
}

fn arrays(u: &mut Unstructured) -> Result<Arrays> {
    let (nx, ny, nz) = (
        u.int_in_range(1usize..=3)?,
        u.int_in_range(1usize..=2)?,
        u.int_in_range(1usize..=2)?,
    );
    let id = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as i64;
    let mut points = Vec::new();
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let jitter = if u.ratio(1u8, 4)? { 0.3 } else { 0.0 };
                for c in [i, j, k] {
                    points.push(c as f64 + jitter * (float(u, -1.0, 1.0)?.clamp(-1.0, 1.0)));
                }
            }
        }
    }
    let mut a = Arrays {
        points,
        offsets: vec![0],
        conn: Vec::new(),
        types: Vec::new(),
    };
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let hex = [
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ];
                // Sometimes a wedge, pyramid or tetrahedron made of the hexahedron's corners.
                let (code, ids): (u8, Vec<i64>) = match u.int_in_range(0u8..=7)? {
                    0 => (13, vec![hex[0], hex[3], hex[1], hex[4], hex[7], hex[5]]),
                    1 => (14, vec![hex[0], hex[1], hex[2], hex[3], hex[4]]),
                    2 => (10, vec![hex[0], hex[1], hex[3], hex[4]]),
                    3 => (
                        11,
                        vec![
                            hex[0], hex[1], hex[3], hex[2], hex[4], hex[5], hex[7], hex[6],
                        ],
                    ),
                    _ => (12, hex.to_vec()),
                };
                a.conn.extend(ids);
                a.offsets.push(a.conn.len() as i64);
                a.types.push(code);
            }
        }
    }
    for _ in 0..u.int_in_range(0u8..=3)? {
        match u.int_in_range(0u8..=6)? {
            0 if !a.points.is_empty() => {
                let i = u.choose_index(a.points.len())?;
                a.points[i] = float(u, -2.0, 4.0)?;
            }
            1 if !a.conn.is_empty() => {
                let i = u.choose_index(a.conn.len())?;
                a.conn[i] = u.int_in_range(-3i64..=40)?;
            }
            2 if !a.offsets.is_empty() => {
                let i = u.choose_index(a.offsets.len())?;
                a.offsets[i] = u.int_in_range(-2i64..=80)?;
            }
            3 if !a.types.is_empty() => {
                let i = u.choose_index(a.types.len())?;
                a.types[i] = u.arbitrary()?;
            }
            4 => {
                a.conn.truncate(u.int_in_range(0..=a.conn.len())?);
            }
            5 => {
                // Drop the last cell (its offset and type together).
                if a.types.pop().is_some() {
                    a.offsets.pop();
                }
            }
            _ => {
                let n = u.int_in_range(0..=a.points.len() / 3)?;
                a.points.truncate(n * 3);
            }
        }
    }
    Ok(a)
}

/// Calls `cylvol_mesh_new` with the arrays in a random index and value type.
fn mesh_new(u: &mut Unstructured, a: &Arrays) -> Result<*mut CylvolMesh> {
    let value_type = code(u, 2)?;
    let index_type = code(u, 2)?;
    let p32: Vec<f32> = a.points.iter().map(|&v| v as f32).collect();
    let (o32, c32): (Vec<i32>, Vec<i32>) = (
        a.offsets.iter().map(|&v| v as i32).collect(),
        a.conn.iter().map(|&v| v as i32).collect(),
    );
    let points: *const std::ffi::c_void = if value_type == 0 {
        p32.as_ptr().cast()
    } else {
        a.points.as_ptr().cast()
    };
    let (offsets, conn): (*const std::ffi::c_void, *const std::ffi::c_void) = if index_type == 0 {
        (o32.as_ptr().cast(), c32.as_ptr().cast())
    } else {
        (a.offsets.as_ptr().cast(), a.conn.as_ptr().cast())
    };
    // n_cells + 1 offsets are read: never claim more cells than the offsets hold.
    let n_cells = a.types.len().min(a.offsets.len().saturating_sub(1));
    let points = if u.ratio(1u8, 30)? { null() } else { points };
    let mut out = null_mut();
    let s = unsafe {
        cylvol_mesh_new(
            points,
            ValueTypeCode(value_type),
            a.points.len() / 3,
            if a.offsets.is_empty() {
                null()
            } else {
                offsets
            },
            conn,
            IndexTypeCode(index_type),
            a.conn.len(),
            a.types.as_ptr(),
            n_cells,
            &mut out,
        )
    };
    not_panic(s);
    assert_eq!(s == CylvolStatus::Ok, !out.is_null());
    Ok(out)
}

/// Random scalars for a mesh or volume of `points` points and `cells` cells.
struct Scalars {
    association: i32,
    f64s: Vec<f64>,
    f32s: Vec<f32>,
    value_type: i32,
    tuples: usize,
    components: usize,
    component: i32,
}

fn scalars(u: &mut Unstructured, points: usize, cells: usize) -> Result<Scalars> {
    let association = code(u, 2)?;
    let right = if association == 1 { cells } else { points };
    let tuples = if u.ratio(1u8, 8)? {
        u.int_in_range(0..=right + 1)?
    } else {
        right
    };
    let components = u
        .int_in_range(0usize..=3)?
        .max(usize::from(!u.ratio(1u8, 10)?));
    let mut f64s = Vec::with_capacity(tuples * components);
    for _ in 0..tuples * components {
        f64s.push(if u.ratio(1u8, 50)? {
            float(u, -5.0, 5.0)?
        } else {
            u.int_in_range(-500i32..=500)? as f64 / 100.0
        });
    }
    let f32s = f64s.iter().map(|&v| v as f32).collect();
    Ok(Scalars {
        association,
        f64s,
        f32s,
        value_type: code(u, 2)?,
        tuples,
        components,
        component: u.int_in_range(-2i32..=3)?,
    })
}

impl Scalars {
    fn values(&self) -> *const std::ffi::c_void {
        if self.value_type == 0 {
            self.f32s.as_ptr().cast()
        } else {
            self.f64s.as_ptr().cast()
        }
    }
}

fn camera(u: &mut Unstructured) -> Result<CylvolCamera> {
    let mut c = CylvolCamera::default();
    c.mode = CameraModeCode(code(u, 2)?);
    if c.mode.0 == 1 {
        // A VTK-style view and projection, each entry sometimes replaced.
        let d = float(u, 3.0, 20.0)?;
        c.view = [
            1.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 1.0, -d, 0.0, 0.0, 0.0, 1.0,
        ];
        let (n, f) = (0.1, 50.0);
        c.projection = if u.arbitrary()? {
            [
                1.5,
                0.0,
                0.0,
                0.0,
                0.0,
                1.5,
                0.0,
                0.0,
                0.0,
                0.0,
                -(f + n) / (f - n),
                -2.0 * f * n / (f - n),
                0.0,
                0.0,
                -1.0,
                0.0,
            ]
        } else {
            let s = float(u, 0.5, 4.0)?;
            [
                1.0 / s,
                0.0,
                0.0,
                0.0,
                0.0,
                1.0 / s,
                0.0,
                0.0,
                0.0,
                0.0,
                -2.0 / (f - n),
                -(f + n) / (f - n),
                0.0,
                0.0,
                0.0,
                1.0,
            ]
        };
        for _ in 0..u.int_in_range(0u8..=2)? {
            let i = u.choose_index(16)?;
            if u.arbitrary()? {
                c.view[i] = float(u, -2.0, 2.0)?;
            } else {
                c.projection[i] = float(u, -2.0, 2.0)?;
            }
        }
    } else {
        for k in 0..3 {
            c.eye[k] = float(u, -8.0, 8.0)?;
            c.focal_point[k] = float(u, 0.0, 3.0)?;
            c.view_up[k] = float(u, -1.0, 1.0)?;
        }
        c.view_angle = float(u, 1.0, 179.0)?;
        c.parallel = u.int_in_range(0..=1)?;
        c.parallel_scale = float(u, 0.1, 5.0)?;
    }
    Ok(c)
}

fn table(u: &mut Unstructured, k: usize) -> Result<Vec<f32>> {
    let n = u
        .int_in_range(0usize..=5)?
        .max(usize::from(!u.ratio(1u8, 10)?) * 2);
    (0..n * k)
        .map(|_| {
            Ok(if u.ratio(1u8, 40)? {
                float(u, -1.0, 2.0)? as f32
            } else {
                u.int_in_range(0u32..=100)? as f32 / 100.0
            })
        })
        .collect()
}

fn render(u: &mut Unstructured, v: *mut CylvolVolume) -> Result<()> {
    let cam = camera(u)?;
    let rgb = table(u, 3)?;
    let opacity = table(u, 1)?;
    let gradient = if u.ratio(1u8, 4)? {
        Some(table(u, 1)?)
    } else {
        None
    };
    let transfer = CylvolTransfer {
        rgb: if rgb.is_empty() { null() } else { rgb.as_ptr() },
        n_color: rgb.len() / 3,
        opacity: if opacity.is_empty() {
            null()
        } else {
            opacity.as_ptr()
        },
        n_opacity: opacity.len(),
        range: [float(u, -6.0, 0.0)?, float(u, 0.0, 6.0)?],
        unit_distance: float(u, 0.05, 2.0)?,
        gradient_opacity: gradient.as_ref().map_or(null(), |g| g.as_ptr()),
        n_gradient_opacity: gradient.as_ref().map_or(0, |g| g.len()),
        gradient_range: [float(u, 0.0, 1.0)?, float(u, 1.0, 10.0)?],
    };
    let mut params = CylvolRenderParams::default();
    params.width = u.int_in_range(0u32..=6)?;
    params.height = u.int_in_range(0u32..=6)?;
    // Steps from the default to a few per cell; never so small that a render takes long.
    params.step = match u.int_in_range(0u8..=5)? {
        0 => f64::NAN,
        1 => -1.0,
        2 => 0.05 + u.int_in_range(0u32..=100)? as f64 / 50.0,
        3 => f64::MAX,
        _ => 0.0,
    };
    params.path = PathCode(code(u, 2)?);
    params.interpolation = InterpolationCode(code(u, 2)?);
    params.blend = BlendCode(code(u, 3)?);
    // Clipping planes: counts past the limit, equations any float (NaN, no normal) included.
    params.clip_plane_count = u.int_in_range(0u32..=7)?;
    for plane in params.clip_planes.iter_mut().take(params.clip_plane_count as usize) {
        for v in plane.iter_mut() {
            *v = float(u, -2.0, 2.0)?;
        }
    }
    // The march reach: refused values (NaN, negative), 0, a few cells, never.
    params.march_reach = match u.int_in_range(0u8..=4)? {
        0 => f64::NAN,
        1 => -1.0,
        2 => 0.0,
        3 => f64::INFINITY,
        _ => float(u, 0.0, 12.0)?,
    };
    params.shading = u.int_in_range(0..=1)?;
    params.specular_power = float(u, 0.0, 50.0)?;
    params.early_termination = float(u, 0.1, 1.5)?;
    params.rows_bottom_up = u.int_in_range(0..=1)?;
    let n = params.width as usize * params.height as usize;
    let depth_in: Option<Vec<f32>> = if u.ratio(1u8, 3)? {
        Some(
            (0..n)
                .map(|_| float(u, 0.0, 1.0).map(|x| x as f32))
                .collect::<Result<_>>()?,
        )
    } else {
        None
    };
    let mut depth_out = vec![0f32; n];
    let format = code(u, 2)?;
    let (mut bytes, mut floats) = (vec![0u8; n * 4], vec![0f32; n * 4]);
    let short = usize::from(u.ratio(1u8, 20)?);
    let (pixels, len): (*mut std::ffi::c_void, usize) = if format == 0 {
        (bytes.as_mut_ptr().cast(), bytes.len().saturating_sub(short))
    } else {
        (
            floats.as_mut_ptr().cast(),
            floats.len().saturating_sub(short),
        )
    };
    let s = not_panic(unsafe {
        cylvol_render(
            v,
            &cam,
            &transfer,
            &params,
            depth_in.as_ref().map_or(null(), |d| d.as_ptr()),
            if u.arbitrary()? {
                depth_out.as_mut_ptr()
            } else {
                null_mut()
            },
            PixelFormatCode(format),
            pixels,
            len,
        )
    });
    if s == CylvolStatus::Ok {
        if format == 1 {
            for p in floats.chunks(4) {
                assert!(
                    p.iter().all(|x| x.is_finite() && (0.0..=1.0).contains(x)),
                    "{p:?}"
                );
                assert!(
                    p[..3].iter().all(|&c| c <= p[3] + 1e-5),
                    "premultiplied {p:?}"
                );
            }
        }
        let mut stats = CylvolRenderStats::default();
        not_panic(unsafe { cylvol_volume_render_stats(v, &mut stats) });
        assert_eq!(stats.rays, n as u64);
    }
    Ok(())
}

fn run(u: &mut Unstructured) -> Result<()> {
    let a = arrays(u)?;
    let mesh = mesh_new(u, &a)?;
    if mesh.is_null() {
        return Ok(());
    }
    let (mut points, mut cells) = (0, 0);
    not_panic(unsafe { cylvol_mesh_counts(mesh, &mut points, &mut cells) });
    let mut range = [0.0; 2];
    let mut bounds = [0.0; 6];
    not_panic(unsafe { cylvol_mesh_bounds(mesh, bounds.as_mut_ptr()) });
    if u.arbitrary()? {
        let s = scalars(u, points, cells)?;
        not_panic(unsafe {
            cylvol_mesh_set_scalars(
                mesh,
                c"fuzz".as_ptr(),
                AssociationCode(s.association),
                s.values(),
                ValueTypeCode(s.value_type),
                s.tuples,
                s.components,
                s.component,
            )
        });
    }
    not_panic(unsafe { cylvol_mesh_scalar_range(mesh, range.as_mut_ptr()) });
    let params = CylvolBuildParams {
        structure: StructureCode(code(u, 5)?),
        axis_auto: u.int_in_range(0..=1)?,
        axis_origin: [float(u, -1.0, 1.0)?, float(u, -1.0, 1.0)?, 0.0],
        axis_direction: [float(u, -1.0, 1.0)?, 0.0, float(u, -1.0, 1.0)?],
        preset: u.int_in_range(-1..=5)?,
    };
    let mut volume = null_mut();
    let s = not_panic(unsafe { cylvol_volume_new(mesh, &params, &mut volume) });
    unsafe { cylvol_mesh_free(mesh) };
    if s != CylvolStatus::Ok {
        assert!(volume.is_null());
        return Ok(());
    }
    for _ in 0..u.int_in_range(1u8..=3)? {
        if u.ratio(1u8, 4)? {
            let s = scalars(u, points, cells)?;
            not_panic(unsafe {
                cylvol_volume_set_scalars(
                    volume,
                    null(),
                    AssociationCode(s.association),
                    s.values(),
                    ValueTypeCode(s.value_type),
                    s.tuples,
                    s.components,
                    s.component,
                )
            });
        }
        render(u, volume)?;
    }
    let mut stats = std::mem::MaybeUninit::<CylvolBuildStats>::uninit();
    not_panic(unsafe { cylvol_volume_build_stats(volume, stats.as_mut_ptr()) });
    unsafe { cylvol_volume_free(volume) };
    Ok(())
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = run(&mut Unstructured::new(data));
});
