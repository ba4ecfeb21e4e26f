//! Property tests of the cell geometry: the inverse map on distorted, needle-thin, far-away and
//! collapsed cells; containment against a tetrahedral decomposition and on shared faces;
//! conservative cylindrical bounds; periodic θ intervals; crossings of a face by a segment;
//! clean failures.

use cylvol::geometry::containment::{
    certainly_inside, contains, locate_in_cell, param_inside, CONTAINMENT_TOLERANCE,
};
use cylvol::geometry::cylindrical::{
    cylindrical_bounds, normalize_angle, straddle_sectors, CylFrame, ThetaInterval,
};
use cylvol::geometry::inverse::{
    invert, InverseFailure, Inversion, PreparedCell, ACCEPT_TOLERANCE, LOCATE_STEP,
};
use cylvol::geometry::patch::segment_crossings;
use cylvol::geometry::trilinear::{corner_jacobian_determinants, jacobian, map, CORNER_PARAMETERS};
use cylvol::CellKind;
use glam::{DMat3, DQuat, DVec3};
use proptest::prelude::*;
use std::f64::consts::{PI, TAU};

fn unit_cube() -> [DVec3; 8] {
    CORNER_PARAMETERS.map(DVec3::from_array)
}

/// How to distort a unit cube into a test cell.
#[derive(Clone, Debug)]
struct Shape {
    perturb: [[f64; 3]; 8],
    twist: f64,
    scale: [f64; 3],
    shear: [f64; 3],
    rotation: [f64; 4],
    offset: DVec3,
}

fn shape(
    max_perturb: f64,
    max_twist: f64,
    max_aspect: f64,
    max_shear: f64,
) -> impl Strategy<Value = Shape> {
    (
        prop::array::uniform8(prop::array::uniform3(-max_perturb..=max_perturb)),
        -max_twist..=max_twist,
        prop::array::uniform3(0.0..=max_aspect.log10()),
        1e-3f64..=10.0,
        prop::array::uniform3(-max_shear..=max_shear),
        prop::array::uniform4(-1.0f64..1.0),
        prop_oneof![Just(0.0), Just(1e6)],
        prop::array::uniform3(-1.0f64..1.0),
    )
        .prop_map(
            |(perturb, twist, log_aspect, size, shear, rotation, dist, dir)| Shape {
                perturb,
                twist,
                scale: log_aspect.map(|a| size / 10f64.powf(a)),
                shear,
                rotation,
                offset: DVec3::from_array(dir).normalize_or(DVec3::X) * dist,
            },
        )
}

/// Apply a shape's global transform (twist about the cell's w axis, scale, shear, rotation,
/// offset) to points given in unit-cube coordinates.
fn place(s: &Shape, p: DVec3) -> DVec3 {
    let a = s.twist * p.z;
    let c = DVec3::new(0.5, 0.5, 0.0);
    let q = p - c;
    let q = DVec3::new(
        q.x * a.cos() - q.y * a.sin(),
        q.x * a.sin() + q.y * a.cos(),
        q.z,
    ) + c;
    let q = q * DVec3::from_array(s.scale);
    let m = DMat3::from_cols(
        DVec3::new(1.0, s.shear[0], s.shear[1]),
        DVec3::new(0.0, 1.0, s.shear[2]),
        DVec3::Z,
    );
    let quat = DQuat::from_array(s.rotation);
    let rot = if quat.length() > 1e-3 {
        quat.normalize()
    } else {
        DQuat::IDENTITY
    };
    rot * (m * q) + s.offset
}

fn hex(s: &Shape) -> [DVec3; 8] {
    let mut c = unit_cube();
    for (k, ck) in c.iter_mut().enumerate() {
        *ck = place(s, *ck + DVec3::from_array(s.perturb[k]));
    }
    c
}

fn size(c: &[DVec3; 8]) -> f64 {
    cylvol::geometry::cell_bounds(c).diagonal()
}

/// A valid cell: positive Jacobian at the corners and on a grid inside.
fn valid(c: &[DVec3; 8]) -> bool {
    let l = size(c);
    let tol = 1e-9 * l * l * l;
    corner_jacobian_determinants(c).iter().all(|&d| d > tol)
        && (0..27).all(|i| {
            let p = DVec3::new((i % 3) as f64, ((i / 3) % 3) as f64, (i / 9) as f64) * 0.5;
            jacobian(c, p).determinant() > tol
        })
}

/// An upper bound of ‖J⁻¹‖₂ (its Frobenius norm).
fn inv_norm(j: DMat3) -> f64 {
    let i = j.inverse();
    (i.x_axis.length_squared() + i.y_axis.length_squared() + i.z_axis.length_squared()).sqrt()
}

fn param() -> impl Strategy<Value = DVec3> {
    prop::array::uniform3(0.0f64..=1.0).prop_map(DVec3::from_array)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// forward ∘ inverse = identity on distorted hexahedra: perturbed corners, twists up to
    /// ±70°, skew, aspect up to 1:1000, 10⁶ from the origin.
    #[test]
    fn inverse_recovers_param(s in shape(0.2, 1.2, 1000.0, 0.8), p in param(), use_guess in any::<bool>()) {
        let c = hex(&s);
        prop_assume!(valid(&c));
        let target = map(&c, p);
        let guess = use_guess.then_some(DVec3::new(0.9, 0.1, 0.8));
        let inv = invert(&c, target, guess);
        let sol = inv.outcome.expect("converges");
        // The target itself is only representable to about an ulp of its magnitude; that error,
        // seen through J⁻¹, is the best any inverse can do. Away from the origin it can exceed
        // 1e-9 for a needle; near it the bound is 1e-9.
        let rep = 4.0 * f64::EPSILON * target.abs().max_element();
        let bound = 1e-9 + rep * inv_norm(jacobian(&c, p));
        prop_assert!((sol.param - p).abs().max_element() <= bound,
            "param {} vs {}, bound {bound:e}, stats {:?}", sol.param, p, inv.stats);
        prop_assert!(sol.residual <= ACCEPT_TOLERANCE * size(&c));
    }

    /// `PreparedCell::locate` (Newton stopped early where the containment is settled) decides
    /// containment exactly as `invert` does, on distorted, twisted, needle-thin and far cells and
    /// points inside, near and beyond the faces; its coordinates are within a few `LOCATE_STEP`
    /// of `invert`'s, and it never evaluates the map more often.
    #[test]
    fn locate_decides_as_invert_does(
        s in shape(0.2, 1.2, 1000.0, 0.8),
        q in prop::array::uniform3(-0.3f64..=1.3),
        guess in prop::option::of(param()),
    ) {
        let c = hex(&s);
        prop_assume!(valid(&c));
        let prepared = PreparedCell::new(&c).unwrap();
        let x = map(&c, DVec3::from_array(q));
        let (full, early) = (prepared.invert(x, guess), prepared.locate(x, guess));
        let inside = |i: &Inversion| i.param().is_some_and(param_inside);
        prop_assert_eq!(inside(&full), inside(&early), "{:?} vs {:?}", full, early);
        if let (Some(a), Some(b)) = (full.param(), early.param()) {
            let rep = 4.0 * f64::EPSILON * x.abs().max_element();
            let bound = 4.0 * LOCATE_STEP + rep * inv_norm(jacobian(&c, a));
            prop_assert!((a - b).abs().max_element() <= bound, "{a} vs {b}, bound {bound:e}");
        }
        prop_assert!(early.stats.map_evaluations <= full.stats.map_evaluations);
    }

    /// Collapsed cells (wedge, pyramid, tetrahedron): the parameter is not unique on the
    /// collapsed edges, so compare the physical point; the point must also count as contained.
    #[test]
    fn inverse_on_collapsed_cells(
        kind in prop_oneof![Just(CellKind::Wedge), Just(CellKind::Pyramid), Just(CellKind::Tetrahedron)],
        s in shape(0.15, 0.5, 10.0, 0.5),
        p in param(),
    ) {
        let reference: Vec<DVec3> = match kind {
            CellKind::Wedge => vec![
                DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.0, 0.0, 1.0), DVec3::new(1.0, 0.0, 1.0), DVec3::new(0.0, 1.0, 1.0),
            ],
            CellKind::Pyramid => vec![
                DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0), DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0), DVec3::new(0.5, 0.5, 1.0),
            ],
            _ => vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
        };
        let mut pts: Vec<DVec3> = reference
            .iter()
            .enumerate()
            .map(|(k, r)| place(&s, *r + DVec3::from_array(s.perturb[k])))
            .collect();
        let ids: Vec<u32> = (0..pts.len() as u32).collect();
        let slots = kind.collapse(&ids);
        let mut c = slots.map(|i| pts[i as usize]);
        if jacobian(&c, DVec3::splat(0.5)).determinant() < 0.0 {
            // Mirror to VTK's orientation.
            for q in pts.iter_mut() { *q = DVec3::new(-q.x, q.y, q.z); }
            c = slots.map(|i| pts[i as usize]);
        }
        let l = size(&c);
        prop_assume!(corner_jacobian_determinants(&c).iter().all(|&d| d >= -1e-12 * l * l * l));
        prop_assume!(jacobian(&c, DVec3::splat(0.5)).determinant() > 1e-3 * l * l * l);
        let target = map(&c, p);
        let sol = invert(&c, target, None).outcome.expect("converges");
        let rep = 4.0 * f64::EPSILON * target.abs().max_element();
        prop_assert!((map(&c, sol.param) - target).length() <= ACCEPT_TOLERANCE * l + rep);
        prop_assert!(locate_in_cell(&c, target, None).is_some(), "{kind:?} {p} -> {}", sol.param);
    }

    /// Containment agrees with the 24-tetrahedron decomposition (cell centre, face centres,
    /// edges) for every point farther than a margin from the decomposition's boundary. The
    /// margin is the largest distance between a face's bilinear patch and its 4 triangles:
    /// with `d = x₀ − x₁ + x₂ − x₃` the face's twist vector, the patch is `linear + d·uv` and
    /// its fan interpolant differs by `d · v(u − ½)`, at most `|d|/16` (0 for planar faces).
    #[test]
    fn containment_matches_tetrahedra(
        s in shape(0.1, 0.35, 3.0, 0.3),
        q in prop::array::uniform3(-0.3f64..=1.3),
    ) {
        let c = hex(&s);
        prop_assume!(valid(&c));
        let tets = TetCell::new(&c);
        prop_assume!(tets.all_positive());
        let x = map(&c, DVec3::from_array(q));
        let by_hex = contains(&c, x);
        let by_tet = tets.contains(x);
        if by_hex != by_tet {
            let d = tets.boundary_distance(x);
            let margin = tets.margin * (1.0 + 1e-9) + 4.0 * CONTAINMENT_TOLERANCE * size(&c)
                + 16.0 * f64::EPSILON * x.abs().max_element();
            prop_assert!(d <= margin, "hex {by_hex} tet {by_tet} at {q:?}: distance {d:e} > margin {margin:e}");
        }
        // And clearly inside / outside points are classified as expected.
        let inside = q.iter().all(|&t| (0.0..=1.0).contains(&t));
        if tets.boundary_distance(x) > tets.margin + 1e-9 * size(&c) {
            prop_assert_eq!(by_hex, inside);
        }
    }

    /// The face-plane certificate is never wrong: a point it certifies inside a distorted,
    /// twisted, needle-thin or far-away cell is inside by the inverse map too, and only points
    /// the inverse map puts at least `1e-9` inside are certified. On mildly distorted cells it
    /// certifies the parametric centre region, so it is not a stub that says no.
    #[test]
    fn plane_certificate_is_exact(
        s in shape(0.2, 0.8, 100.0, 0.5),
        q in prop::array::uniform3(-0.5f64..=1.5),
        mild in shape(0.05, 0.0, 3.0, 0.2),
        centre in prop::array::uniform3(0.4f64..=0.6),
    ) {
        let c = hex(&s);
        prop_assume!(valid(&c));
        let x = map(&c, DVec3::from_array(q));
        if certainly_inside(&c, x) {
            prop_assert!(contains(&c, x), "certified at {q:?} but not contained");
            let p = locate_in_cell(&c, x, None).expect("contained");
            prop_assert!(p.min_element() > 1e-9 && p.max_element() < 1.0 - 1e-9, "{p:?}");
        }
        let m = hex(&mild);
        prop_assume!(valid(&m));
        prop_assert!(certainly_inside(&m, map(&m, DVec3::from_array(centre))));
    }

    /// A point on the face two distorted neighbours share belongs to at least one of them.
    #[test]
    fn shared_face_has_no_cracks(
        s in shape(0.2, 0.8, 100.0, 0.5),
        extra in prop::array::uniform4(prop::array::uniform3(-0.2f64..=0.2)),
        st in prop::array::uniform2(prop_oneof![Just(0.0), Just(1.0), 0.0f64..=1.0]),
        nudge in prop_oneof![Just(0.0), -1e-13f64..1e-13],
    ) {
        let a = hex(&s);
        // Cell B continues A across its u = 1 face (corners 1, 2, 6, 5).
        let far = [0usize, 3, 7, 4].map(|k| CORNER_PARAMETERS[k]);
        let mut b = [DVec3::ZERO; 8];
        // B's u = 0 face is A's u = 1 face.
        b[0] = a[1]; b[3] = a[2]; b[7] = a[6]; b[4] = a[5];
        for (slot, (fp, e)) in [1usize, 2, 6, 5].iter().zip(far.iter().zip(extra.iter())) {
            let unit = DVec3::from_array(*fp) + DVec3::new(2.0, 0.0, 0.0) + DVec3::from_array(*e);
            b[*slot] = place(&s, unit);
        }
        prop_assume!(valid(&a) && valid(&b));
        // On the face's own edges a point may, once rounded to f64, fall just outside both
        // cells (into a third neighbour): that is no crack between A and B. Keep (s, t) away
        // from the edges by the parametric size of that rounding, which is nil near the origin
        // and grows with the distance from it (`4 ulp · ‖J⁻¹‖`).
        let x0 = map(&a, DVec3::new(1.0, st[0], st[1]));
        let delta = 8.0 * f64::EPSILON * x0.abs().max_element()
            * inv_norm(jacobian(&a, DVec3::new(1.0, st[0], st[1])))
                .max(inv_norm(jacobian(&b, DVec3::new(0.0, st[0], st[1]))));
        prop_assume!(delta < 0.1);
        let (s_, t_) = (st[0].clamp(delta, 1.0 - delta), st[1].clamp(delta, 1.0 - delta));
        let l = size(&a).max(size(&b));
        let normal = jacobian(&a, DVec3::new(1.0, s_, t_)).x_axis.normalize_or_zero();
        for x in [map(&a, DVec3::new(1.0, s_, t_)), map(&b, DVec3::new(0.0, s_, t_))] {
            let x = x + normal * (nudge * l);
            prop_assert!(contains(&a, x) || contains(&b, x), "crack at ({s_}, {t_}), nudge {nudge:e}: {:?} {:?}",
                invert(&a, x, None), invert(&b, x, None));
        }
    }

    /// Cylindrical bounds hold every point of the cell: cells far from the axis, near it,
    /// touching it (a corner on it) and straddling it, at every angle incl. across ±π and 0,
    /// about a tilted axis whose origin may be 10⁶ away.
    #[test]
    fn cylindrical_bounds_are_conservative(
        s in shape(0.2, 0.6, 20.0, 0.4),
        r_over_size in prop_oneof![Just(0.0), 0.0f64..=0.6, 0.6f64..=5.0, 5.0f64..=200.0],
        theta in prop_oneof![Just(PI), Just(0.0), Just(-PI + 1e-3), -PI..=PI],
        touch in any::<bool>(),
        axis_dir in prop::array::uniform3(-1.0f64..1.0),
        axis_far in any::<bool>(),
        k in 3usize..=12,
        params in prop::collection::vec(param(), 64),
    ) {
        let origin = if axis_far { DVec3::new(1e6, -2e6, 5e5) } else { DVec3::ZERO };
        let frame = CylFrame::new(origin, DVec3::from_array(axis_dir)).unwrap_or(CylFrame::new(origin, DVec3::Z).unwrap());
        let mut shp = s.clone();
        shp.offset = DVec3::ZERO;
        let local = hex(&shp);
        let centre = local.iter().copied().sum::<DVec3>() / 8.0;
        let l = size(&local);
        let at = frame.from_cylindrical(r_over_size * l, theta, 0.3 * l);
        let mut c = local.map(|p| p - centre + at);
        if touch {
            // Move corner 0 onto the axis.
            let (_, _, h) = frame.to_cylindrical(c[0]);
            c[0] = frame.origin + frame.axis * h;
        }
        let b = cylindrical_bounds(&c, &frame);
        let sectors = straddle_sectors(&c, &frame, k);
        let mut pts: Vec<DVec3> = params.iter().map(|p| map(&c, *p)).collect();
        pts.extend(c.iter().copied());
        // Points on the edges, where the closest approach to the axis may be.
        for e in 0..=20 {
            let t = e as f64 / 20.0;
            for (i, j) in [(0, 1), (1, 2), (2, 3), (3, 0), (0, 4), (1, 5), (2, 6), (3, 7)] {
                pts.push(c[i].lerp(c[j], t));
            }
        }
        for x in pts {
            let (r, th, h) = frame.to_cylindrical(x);
            prop_assert!(b.contains(r, th, h), "{:?} misses ({r}, {th}, {h})", b);
            prop_assert!(sectors.iter().any(|sb| sb.contains(r, th, h)), "sectors miss ({r}, {th}, {h})");
        }
        if b.straddles_axis {
            prop_assert!(b.theta.is_full() && b.r[0] == 0.0);
        } else {
            prop_assert!(b.theta.width() < PI);
        }
        // r_max is the largest corner radius (up to the padding), not more.
        let rmax = c.iter().map(|p| frame.to_cylindrical(*p).0).fold(0.0, f64::max);
        prop_assert!(b.r[1] >= rmax && b.r[1] <= rmax + 1e-9 * l + 1e-9);
    }

    /// θ intervals: a union holds both arcs, is the smallest such arc (never the complement:
    /// the part it leaves out is the largest uncovered run of the circle, found by sampling),
    /// and `ranges` describes exactly the arc.
    #[test]
    fn theta_interval_union(
        s1 in -PI..=PI, w1 in prop_oneof![0.0f64..TAU, Just(0.0)],
        s2 in prop_oneof![-PI..=PI, Just(PI), Just(0.0)], w2 in 0.0f64..TAU,
        probes in prop::collection::vec(-4.0f64..4.0, 32),
    ) {
        let a = ThetaInterval::new(s1, w1);
        let b = ThetaInterval::new(s2, w2);
        let u = a.union(&b);
        prop_assert!((u.width() - b.union(&a).width()).abs() < 1e-12);
        for &t in &probes {
            if a.contains(t) || b.contains(t) {
                prop_assert!(u.contains(t));
            }
            prop_assert_eq!(a.overlaps(&b), b.overlaps(&a));
            if !near_end(&u, t) {
                let n = normalize_angle(t);
                let in_ranges = u.ranges().any(|[lo, hi]| n >= lo && n <= hi);
                prop_assert_eq!(in_ranges, u.contains(t), "{:?} {}", u, t);
            }
        }
        // Longest uncovered run of a fine sampling of the circle.
        let n = 4096;
        let step = TAU / n as f64;
        let covered: Vec<bool> = (0..n)
            .map(|i| {
                let cell = ThetaInterval::new(-PI + step * i as f64, step);
                a.overlaps(&cell) || b.overlaps(&cell)
            })
            .collect();
        let mut longest = 0usize;
        if covered.iter().any(|&c| c) {
            let mut run = 0usize;
            for i in 0..2 * n {
                if covered[i % n] { run = 0 } else { run += 1; longest = longest.max(run.min(n)); }
            }
        }
        let left_out = TAU - u.width().min(TAU);
        prop_assert!(left_out + 2.0 * step >= longest as f64 * step,
            "union {:?} of {:?} and {:?} leaves out {left_out} < run {}", u, a, b, longest as f64 * step);
        // Nothing of either arc lies in the part left out.
        if !u.is_full() {
            for i in 0..64 {
                let t = u.end() + (TAU - u.width()) * (i as f64 + 0.5) / 64.0;
                prop_assert!(!a.contains(t) && !b.contains(t));
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    /// A line through two points of a twisted bilinear patch (not on one ruling) meets the
    /// patch's surface there only, so the count of crossings on a part of it is the number of
    /// those points in the patch (`[0, 1]²`) and in that part — at any scale, 10⁶ from the
    /// origin. The answer is never wrong, and is missing only for points near the edges.
    #[test]
    fn segment_crossings_count_the_points_in_the_patch(
        z in prop::array::uniform4(-1.0f64..1.0),
        xy in prop::array::uniform4(prop::array::uniform2(-0.2f64..0.2)),
        a in prop::array::uniform2(-0.5f64..1.5),
        b in prop::array::uniform2(-0.5f64..1.5),
        scale_exp in -3i32..=3,
        offset in prop::array::uniform3(-1e6f64..1e6),
        part in 0usize..4,
    ) {
        prop_assume!((z[0] - z[1] + z[2] - z[3]).abs() > 0.3);
        prop_assume!((a[0] - b[0]).abs() > 0.05 && (a[1] - b[1]).abs() > 0.05);
        let scale = 10f64.powi(scale_exp);
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let corners: [DVec3; 4] = std::array::from_fn(|i| {
            DVec3::new(square[i][0] + xy[i][0], square[i][1] + xy[i][1], z[i]) * scale
                + DVec3::from_array(offset)
        });
        let at = |[s, r]: [f64; 2]| {
            corners[0] * ((1.0 - s) * (1.0 - r))
                + corners[1] * (s * (1.0 - r))
                + corners[2] * (s * r)
                + corners[3] * ((1.0 - s) * r)
        };
        // The points at t = 1 and t = 2.
        let (x, y) = (at(a), at(b));
        let d = y - x;
        let o = x - d;
        let (t0, t1) = [(0.0, 3.0), (0.0, 1.5), (1.5, 3.0), (1.2, 1.8)][part];
        let in_patch = |p: [f64; 2]| p.iter().all(|v| (0.0..=1.0).contains(v));
        let expected = [(a, 1.0), (b, 2.0)]
            .iter()
            .filter(|(p, t)| in_patch(*p) && *t > t0 && *t < t1)
            .count() as u32;
        let crossings = segment_crossings(&corners, o, d, t0, t1, 0.0);
        // Each crossing is one of the two points, to the precision the points are given with
        // (their coordinates are rounded 10⁶ from the origin).
        let tol = 1e-8 + 1e4 * f64::EPSILON * DVec3::from_array(offset).length() / scale;
        for &t in crossings.iter().flat_map(|c| c.ts()) {
            prop_assert!((t - 1.0).abs() < tol || (t - 2.0).abs() < tol, "{} {}", t, tol);
        }
        let got = crossings.map(|c| c.count());
        let clear = |p: [f64; 2]| p.iter().all(|&v| v.abs() > 0.01 && (v - 1.0).abs() > 0.01);
        if clear(a) && clear(b) {
            prop_assert_eq!(got, Some(expected));
        } else {
            prop_assert!(got.is_none() || got == Some(expected), "{:?} vs {}", got, expected);
        }
    }
}

fn near_end(u: &ThetaInterval, t: f64) -> bool {
    let n = normalize_angle(t);
    [u.start(), u.end(), PI, -PI].iter().any(|&e| {
        let d = (n - e).rem_euclid(TAU);
        !(1e-9..=TAU - 1e-9).contains(&d)
    })
}

/// The 24-tetrahedron decomposition of a hexahedron: each face split into 4 triangles about its
/// centre, each triangle joined to the cell centre.
struct TetCell {
    tets: Vec<[DVec3; 4]>,
    tris: Vec<[DVec3; 3]>,
    margin: f64,
}

const FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];

impl TetCell {
    fn new(c: &[DVec3; 8]) -> Self {
        let centre = c.iter().copied().sum::<DVec3>() / 8.0;
        let mut tets = Vec::new();
        let mut tris = Vec::new();
        let mut margin: f64 = 0.0;
        for f in FACES {
            let q = f.map(|i| c[i]);
            let m = (q[0] + q[1] + q[2] + q[3]) / 4.0;
            margin = margin.max((q[0] - q[1] + q[2] - q[3]).length() / 16.0);
            for e in 0..4 {
                let (a, b) = (q[e], q[(e + 1) % 4]);
                // Faces listed with outward normals: (a, b, m) is outward, so (a, b, m, centre)
                // has negative orientation; store it positively.
                tets.push([b, a, m, centre]);
                tris.push([a, b, m]);
            }
        }
        TetCell { tets, tris, margin }
    }

    fn vol(t: &[DVec3; 4]) -> f64 {
        (t[1] - t[0]).cross(t[2] - t[0]).dot(t[3] - t[0])
    }

    fn all_positive(&self) -> bool {
        self.tets.iter().all(|t| Self::vol(t) > 0.0)
    }

    fn contains(&self, x: DVec3) -> bool {
        self.tets.iter().any(|t| {
            let v = Self::vol(t);
            let b = [
                Self::vol(&[x, t[1], t[2], t[3]]),
                Self::vol(&[t[0], x, t[2], t[3]]),
                Self::vol(&[t[0], t[1], x, t[3]]),
                Self::vol(&[t[0], t[1], t[2], x]),
            ];
            b.iter().all(|&bi| bi >= -1e-12 * v)
        })
    }

    fn boundary_distance(&self, x: DVec3) -> f64 {
        self.tris
            .iter()
            .map(|t| (closest_on_triangle(x, t[0], t[1], t[2]) - x).length())
            .fold(f64::INFINITY, f64::min)
    }
}

/// Closest point of triangle abc to p (by regions of the triangle's Voronoi diagram).
fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

#[test]
fn inverse_fails_cleanly_on_degenerate_and_nan_input() {
    // Flat: all corners in the plane z = 0.
    let flat = unit_cube().map(|p| DVec3::new(p.x, p.y, 0.0));
    let inv = invert(&flat, DVec3::new(0.5, 0.5, 0.0), None);
    assert_eq!(inv.outcome, Err(InverseFailure::Degenerate));
    assert_eq!(inv.stats.failures, 1);
    assert!(!contains(&flat, DVec3::new(0.5, 0.5, 0.0)));
    // A line and a point.
    let line = unit_cube().map(|p| DVec3::new(p.x, 0.0, 0.0));
    assert_eq!(
        invert(&line, DVec3::new(0.5, 0.0, 0.0), None).outcome,
        Err(InverseFailure::Degenerate)
    );
    let point = [DVec3::splat(3.0); 8];
    assert_eq!(
        invert(&point, DVec3::splat(3.0), None).outcome,
        Err(InverseFailure::Degenerate)
    );
    // NaN and infinity anywhere.
    let cube = unit_cube();
    assert_eq!(
        invert(&cube, DVec3::new(f64::NAN, 0.5, 0.5), None).outcome,
        Err(InverseFailure::NonFinite)
    );
    let mut bad = cube;
    bad[5].y = f64::INFINITY;
    assert_eq!(
        invert(&bad, DVec3::splat(0.5), None).outcome,
        Err(InverseFailure::NonFinite)
    );
    assert_eq!(
        invert(&cube, DVec3::splat(0.5), Some(DVec3::NAN)).outcome,
        Err(InverseFailure::NonFinite)
    );
    assert!(!contains(&bad, DVec3::splat(0.5)));
}

#[test]
fn inverse_far_outside_is_not_found_or_outside() {
    let mut c = unit_cube();
    c[6] += DVec3::new(0.4, -0.2, 0.3);
    for target in [
        DVec3::splat(100.0),
        DVec3::new(-40.0, 3.0, 0.5),
        DVec3::new(0.5, 0.5, 2.5),
    ] {
        match invert(&c, target, None).outcome {
            Ok(sol) => {
                assert!(sol.param.abs().max_element() > 1.0 + CONTAINMENT_TOLERANCE);
                assert!((map(&c, sol.param) - target).length() <= ACCEPT_TOLERANCE * size(&c));
            }
            Err(e) => assert_eq!(e, InverseFailure::NotFound),
        }
        assert!(!contains(&c, target));
    }
}

#[test]
fn inverse_on_a_strongly_twisted_cell() {
    // The top face turned by 150° about the cell's axis: the map folds outside the cell and
    // Newton from the centre is pulled around; every interior point must still be found.
    let twist = 150f64.to_radians();
    let c = unit_cube().map(|p| {
        let a = twist * p.z;
        let q = p - DVec3::new(0.5, 0.5, 0.0);
        DVec3::new(
            q.x * a.cos() - q.y * a.sin(),
            q.x * a.sin() + q.y * a.cos(),
            q.z,
        )
    });
    let mut fallbacks = 0;
    for i in 0..9 {
        for j in 0..9 {
            for k in 0..9 {
                let p = DVec3::new(i as f64, j as f64, k as f64) / 8.0;
                let target = map(&c, p);
                if jacobian(&c, p).determinant() <= 1e-6 {
                    continue; // the fold itself: not a valid cell point
                }
                let inv = invert(&c, target, Some(DVec3::new(0.0, 1.0, 0.0)));
                fallbacks += inv.stats.fallbacks;
                let q = inv.param().expect("found");
                assert!((map(&c, q) - target).length() < 1e-9, "{p} -> {q}");
            }
        }
    }
    eprintln!("twisted cell: {fallbacks} fallbacks");
}
