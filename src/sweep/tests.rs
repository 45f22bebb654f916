//! Unit tests of the sweep: watertight meshes and their volumes, counts, seams, ribbons, and the
//! same bits from the AVX2, piecewise and per-edge paths.

use super::check::check_spine;
use super::faces::FacePattern;
use super::kernel::{Columns, RingScratch};
use super::rings::{Block, Rings};
use super::run::Shared;
use super::*;
use crate::run::cancel;
use std::collections::HashMap;
use std::f64::consts::{PI, TAU};
use std::sync::OnceLock;

/// A row-major frame with columns `r`, `s = t × r`, `t`.
fn frame(r: DVec3, t: DVec3) -> [f64; 9] {
    let s = t.cross(r);
    [r.x, s.x, t.x, r.y, s.y, t.y, r.z, s.z, t.z]
}

/// A straight spine along z, unevenly sampled from 0 to `length`.
fn straight(n: usize, length: f64) -> (Vec<DVec3>, Vec<[f64; 9]>) {
    let z = |i: usize| {
        let u = i as f64 / (n - 1) as f64;
        length * (u + 0.2 * u * (1.0 - u))
    };
    let x = (0..n).map(|i| DVec3::new(0.3, -0.2, z(i))).collect();
    (x, vec![frame(DVec3::X, DVec3::Z); n])
}

/// `n` samples of a circle of radius `radius` in the xy plane with its exact frames.
fn circle(n: usize, radius: f64) -> (Vec<DVec3>, Vec<[f64; 9]>) {
    (0..n)
        .map(|i| {
            let (s, c) = (TAU * i as f64 / n as f64).sin_cos();
            let r = DVec3::new(c, s, 0.0);
            (radius * r, frame(r, DVec3::new(-s, c, 0.0)))
        })
        .unzip()
}

/// A regular polygon and a five-pointed star, both centred on the origin.
fn polygon(m: usize) -> Vec<DVec2> {
    (0..m)
        .map(|j| DVec2::from_angle(TAU * j as f64 / m as f64))
        .collect()
}

fn star() -> Vec<DVec2> {
    (0..10)
        .map(|k| DVec2::from_angle(PI * k as f64 / 5.0) * if k % 2 == 0 { 1.0 } else { 0.4 })
        .collect()
}

fn options(closed: bool, caps: bool, split_seams: bool) -> Options<'static> {
    Options {
        closed,
        caps,
        miter_limit: 4.0,
        split_seams,
        join: crate::sweep::Join::Round,
        turns: 0.0,
        scale_name: "scale",
    }
}

fn sweep(
    x: &[DVec3],
    frames: &[[f64; 9]],
    scale: &[DVec2],
    profile: &Profile,
    opts: &Options,
) -> Mesh {
    let spine = Spine {
        points: x,
        frames,
        scale,
        twist: &[],
    };
    sweep_many(&spine, &[0, x.len()], profile, opts).expect("a valid sweep")
}

/// How often each directed edge occurs.
fn directed(faces: &[[i64; 3]]) -> HashMap<(i64, i64), usize> {
    let mut e = HashMap::new();
    for f in faces {
        for k in 0..3 {
            *e.entry((f[k], f[(k + 1) % 3])).or_default() += 1;
        }
    }
    e
}

/// Every undirected edge in exactly two faces, once in each direction: closed,
/// edge-manifold and consistently wound.
fn assert_watertight(faces: &[[i64; 3]]) {
    let e = directed(faces);
    for (&(a, b), &k) in &e {
        assert_eq!(k, 1, "edge {a}→{b} used {k} times");
        assert_eq!(e.get(&(b, a)), Some(&1), "edge {a}→{b} has no twin");
    }
}

/// Edges used once in one direction and never in the other.
fn boundary_edges(faces: &[[i64; 3]]) -> usize {
    let e = directed(faces);
    assert!(e.values().all(|&k| k == 1), "a directed edge used twice");
    e.keys().filter(|&&(a, b)| !e.contains_key(&(b, a))).count()
}

fn signed_volume(m: &Mesh) -> f64 {
    m.faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|i| m.vertices[i as usize]);
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

/// Every side face's winding agrees with the vertex normals (the side faces come first;
/// a cap's vertices carry the side's normals).
fn assert_faces_follow_normals(m: &Mesh, side: usize) {
    for (k, f) in m.faces[..side].iter().enumerate() {
        let [a, b, c] = f.map(|i| m.vertices[i as usize]);
        let nf = (b - a).cross(c - a);
        let nv: DVec3 = f.iter().map(|&i| m.normals[i as usize]).sum();
        assert!(nf.dot(nv) > 0.0, "face {k} is wound against its normals");
    }
}

/// The sizes `layout` reports, from the closed forms: `(rings + seam) × (m + seam)`
/// vertices, two triangles per quad and `m − 2` per cap.
fn expected_counts(rings: usize, m: usize, pclosed: bool, opts: &Options) -> (usize, usize) {
    let split = usize::from(opts.split_seams);
    let stored = rings + if opts.closed { split } else { 0 };
    let cols = m + if pclosed { split } else { 0 };
    let segments = if opts.closed { rings } else { rings - 1 };
    let edges = if pclosed { m } else { m - 1 };
    let caps = opts.caps && !opts.closed && pclosed;
    let faces = 2 * segments * edges + if caps { 2 * (m - 2) } else { 0 };
    (stored * cols, faces)
}

fn assert_counts(x: &[DVec3], frames: &[[f64; 9]], p: &Profile, opts: &Options, rings: usize) {
    let scale = vec![DVec2::ONE; x.len()];
    let spine = Spine {
        points: x,
        frames,
        scale: &scale,
        twist: &[],
    };
    let lay = layout(&spine, &[0, x.len()], p, opts, &cancel::never).expect("a valid sweep");
    let (v, f) = expected_counts(rings, p.len(), p.closed, opts);
    assert_eq!((lay.vertices, lay.faces), (v, f), "{opts:?}");
    let mesh = sweep(x, frames, &scale, p, opts);
    assert_eq!((mesh.vertices.len(), mesh.faces.len()), (v, f));
    assert_eq!((mesh.normals.len(), mesh.uv.len()), (v, v));
    let top = v as i64;
    assert!(mesh.faces.iter().flatten().all(|&i| (0..top).contains(&i)));
}

/// The faces of a float32 mesh are int32 up to 2³¹ − 1 vertices (its largest index,
/// 2³¹ − 2, is an `i32`) and int64 from 2³¹ vertices on (the largest counts included).
#[test]
fn faces_are_int32_below_two_to_the_31_vertices() {
    for v in [0usize, 1, 3, 1 << 20, 2_147_483_646, 2_147_483_647] {
        assert!(indices_fit_i32(v), "{v}");
        assert!(v == 0 || i32::try_from(v - 1).is_ok());
    }
    for v in [2_147_483_648usize, 2_147_483_649, 4_294_967_295, usize::MAX] {
        assert!(!indices_fit_i32(v), "{v}");
    }
    let lay = |vertices| Layout {
        sizes: Vec::new(),
        corners: Vec::new(),
        vertices,
        faces: 0,
    };
    assert!(lay(2_147_483_647).indices_fit_i32());
    assert!(!lay(2_147_483_648).indices_fit_i32());
}

/// A capped straight tube is a closed, consistently wound surface whose volume is that of
/// the prism (`area · length`) or, with a scale growing along it, of the frustums between
/// the rings; clockwise and counter-clockwise profiles both face outwards.
#[test]
fn capped_straight_tube_is_watertight_with_the_prism_volume() {
    let (x, frames) = straight(17, 3.0);
    let length = x[16].z - x[0].z;
    for pts in [polygon(7), star()] {
        for reverse in [false, true] {
            let mut pts = pts.clone();
            if reverse {
                pts.reverse();
            }
            let p = Profile::new(&pts, true, &cancel::never).expect("a simple polygon");
            let opts = options(false, true, false);
            let mesh = sweep(&x, &frames, &vec![DVec2::ONE; 17], &p, &opts);
            assert_watertight(&mesh.faces);
            let side = 2 * 16 * p.len();
            assert_faces_follow_normals(&mesh, side);
            // the caps face −t at the start and +t at the end
            for (k, f) in mesh.faces[side..].iter().enumerate() {
                let [a, b, c] = f.map(|i| mesh.vertices[i as usize]);
                let nz = (b - a).cross(c - a).z;
                assert!(
                    if k < p.len() - 2 { nz < 0.0 } else { nz > 0.0 },
                    "cap face {k}"
                );
            }
            let (want, got) = (p.area.abs() * length, signed_volume(&mesh));
            assert!((got - want).abs() < 1e-12 * want, "prism: {got} vs {want}");
            // side normals point away from the axis
            for (v, nv) in mesh.vertices.iter().zip(&mesh.normals) {
                let out = DVec3::new(v.x - 0.3, v.y + 0.2, 0.0);
                assert!(out.dot(*nv) > 0.0, "inward normal at {v}");
            }
            // a uniform scale from 1 to 2.5: frustums h/3 (A₁ + A₂ + √(A₁A₂))
            let sigma: Vec<f64> = (0..17).map(|i| 1.0 + 1.5 * (x[i].z / length)).collect();
            let scale: Vec<DVec2> = sigma.iter().map(|&s| DVec2::splat(s)).collect();
            let mesh = sweep(&x, &frames, &scale, &p, &opts);
            assert_watertight(&mesh.faces);
            let want: f64 = (0..16)
                .map(|i| {
                    let (a1, a2) = (
                        p.area.abs() * sigma[i].powi(2),
                        p.area.abs() * sigma[i + 1].powi(2),
                    );
                    (x[i + 1].z - x[i].z) / 3.0 * (a1 + a2 + (a1 * a2).sqrt())
                })
                .sum();
            let got = signed_volume(&mesh);
            assert!(
                (got - want).abs() < 1e-12 * want,
                "frustums: {got} vs {want}"
            );
        }
    }
}

/// A closed tube around a circle (a mitred polygonal torus) is watertight; each segment
/// is a prism on its chord cut by the bisector planes, so the volume is the profile's
/// area times the perimeter of the spine polygon (Pappus for the polygon).
#[test]
fn closed_tube_is_watertight_with_the_mitred_volume() {
    let (x, frames) = circle(24, 3.0);
    let perimeter: f64 = (0..24).map(|i| (x[(i + 1) % 24] - x[i]).length()).sum();
    for pts in [polygon(6), star()] {
        for reverse in [false, true] {
            let mut pts = pts.clone();
            if reverse {
                pts.reverse();
            }
            let p = Profile::new(&pts, true, &cancel::never).expect("a simple polygon");
            let opts = options(true, false, false);
            let mesh = sweep(&x, &frames, &vec![DVec2::splat(0.5); 24], &p, &opts);
            assert_watertight(&mesh.faces);
            assert_faces_follow_normals(&mesh, mesh.faces.len());
            assert!(mesh.folds.is_empty());
            let want = 0.25 * p.area.abs() * perimeter;
            let got = signed_volume(&mesh);
            assert!((got - want).abs() < 1e-12 * want, "torus: {got} vs {want}");
            // a repeated first point is dropped: the same mesh
            let (mut y, mut g) = (x.clone(), frames.clone());
            y.push(x[0]);
            g.push(frames[0]);
            let again = sweep(&y, &g, &vec![DVec2::splat(0.5); 25], &p, &opts);
            assert_eq!(again.faces, mesh.faces);
            assert_eq!(again.vertices, mesh.vertices);
        }
    }
}

/// Split seams duplicate the vertices on the texture seams: the mesh is then watertight
/// by position (vertices merged where they coincide bit for bit), not by index.
#[test]
fn split_seams_stay_watertight_by_position() {
    let (x, frames) = circle(12, 2.0);
    let p = Profile::new(&polygon(5), true, &cancel::never).expect("a pentagon");
    let scale = vec![DVec2::splat(0.4); 12];
    let mesh = sweep(&x, &frames, &scale, &p, &options(true, false, true));
    assert!(boundary_edges(&mesh.faces) > 0, "seams are open by index");
    let mut id: HashMap<[u64; 3], i64> = HashMap::new();
    let merged: Vec<i64> = mesh
        .vertices
        .iter()
        .map(|v| {
            let next = id.len() as i64;
            *id.entry(v.to_array().map(f64::to_bits)).or_insert(next)
        })
        .collect();
    assert_eq!(id.len(), 12 * 5, "one vertex per ring and profile vertex");
    let faces: Vec<[i64; 3]> = mesh
        .faces
        .iter()
        .map(|f| f.map(|i| merged[i as usize]))
        .collect();
    assert_watertight(&faces);
    let plain = sweep(&x, &frames, &scale, &p, &options(true, false, false));
    assert!((signed_volume(&mesh) - signed_volume(&plain)).abs() < 1e-12 * signed_volume(&plain));
    // the seam copies carry u = L (after the closing chord) and v = 1
    let cols = 6;
    for i in 0..=12 {
        assert_eq!(mesh.uv[i * cols + 5].y, 1.0);
    }
    let perimeter: f64 = (0..12).map(|i| (x[(i + 1) % 12] - x[i]).length()).sum();
    assert!((mesh.uv[12 * cols].x - perimeter).abs() < 1e-12);
}

/// An open profile sweeps a ribbon: its boundary is the rim of the `rings × m` grid
/// (two rails and two end rows; on a closed spine, the two rails only).
#[test]
fn open_ribbon_has_its_rim_as_boundary() {
    let p = Profile::new(
        &[
            DVec2::new(-1.0, 0.0),
            DVec2::new(0.0, 0.3),
            DVec2::new(1.0, 0.1),
            DVec2::new(2.0, 0.0),
        ],
        false,
        &cancel::never,
    )
    .expect("an open polyline");
    let (x, frames) = straight(9, 2.0);
    let mesh = sweep(
        &x,
        &frames,
        &[DVec2::ONE; 9],
        &p,
        &options(false, true, false),
    );
    assert_eq!(boundary_edges(&mesh.faces), 2 * 8 + 2 * 3);
    let (x, frames) = circle(10, 3.0);
    let mesh = sweep(
        &x,
        &frames,
        &[DVec2::ONE; 10],
        &p,
        &options(true, false, false),
    );
    assert_eq!(boundary_edges(&mesh.faces), 2 * 10);
    assert_faces_follow_normals(&mesh, mesh.faces.len());
}

/// `layout` sizes every kind of sweep by the closed forms, and the mesh fills it.
#[test]
fn vertex_and_face_counts_equal_the_layout() {
    let closed_p = Profile::new(&star(), true, &cancel::never).expect("a star");
    let open_p = Profile::new(&polygon(6)[..4], false, &cancel::never).expect("an open polyline");
    let (sx, sf) = straight(6, 1.0);
    let (cx, cf) = circle(8, 2.0);
    for p in [&closed_p, &open_p] {
        for caps in [false, true] {
            for split in [false, true] {
                assert_counts(&sx, &sf, p, &options(false, caps, split), 6);
                assert_counts(&cx, &cf, p, &options(true, caps, split), 8);
            }
        }
    }
}

/// The run-time choice of the AVX2 build of a block of rings changes no bit (on a
/// processor without AVX2 both calls run the same code): a helix with a growing scale
/// and a twist (mitres, tilted normals, twisted quads), a star with split seams.
#[test]
fn avx2_block_equals_baseline_block() {
    let n = 300;
    let (x, frames): (Vec<DVec3>, Vec<[f64; 9]>) = (0..n)
        .map(|i| {
            let u = 0.05 * i as f64;
            let t = DVec3::new(-u.sin(), u.cos(), 0.1).normalize();
            (
                DVec3::new(u.cos(), u.sin(), 0.1 * u),
                frame(DVec3::new(-u.cos(), -u.sin(), 0.0), t),
            )
        })
        .unzip();
    let scale: Vec<DVec2> = (0..n)
        .map(|i| DVec2::new(0.2 + 0.001 * i as f64, 0.3))
        .collect();
    let twist: Vec<f64> = (0..n).map(|i| 0.01 * i as f64).collect();
    let spine = Spine {
        points: &x,
        frames: &frames,
        scale: &scale,
        twist: &twist,
    };
    let p = Profile::new(&star(), true, &cancel::never).expect("a star");
    let opts = options(false, true, true);
    let lay = layout(&spine, &[0, n], &p, &opts, &cancel::never).expect("a sized sweep");
    let plan = check_spine(&spine, &opts, &p, true, None, &cancel::never)
        .expect("a valid sweep")
        .expect("not stopped");
    let plan = &plan;
    let column = OnceLock::from(Columns::of(&p, plan.cols));
    let rings = Rings {
        s: &spine,
        x: &x[..plan.rings],
        plan,
        p: &p,
        column: &column,
        closed: false,
        miter_limit: 4.0,
        sign: 1.0,
        rowbase: 0,
        seam: 0,
    };
    let pattern = FacePattern::of(plan.cols, p.len(), 1.0);
    type Out = (Vec<[u32; 3]>, Vec<[u32; 3]>, Vec<[u32; 2]>, Vec<[i32; 3]>);
    let run = |avx2: bool| -> (Out, (Vec<usize>, Option<usize>)) {
        let nv = lay.vertices;
        let (mut v, mut nn) = (vec![[0f32; 3]; nv], vec![[0f32; 3]; nv]);
        let mut u = vec![[0f32; 2]; nv];
        let mut f = vec![[0i32; 3]; 2 * plan.segments * p.len()];
        let b = Block {
            i0: 0,
            j: 0..plan.cols,
            bd: None,
            v: &mut v,
            n: Some(&mut nn),
            u: Some(&mut u),
            f: &mut f,
        };
        let ring = &mut RingScratch::new(plan.cols);
        let r = match avx2 {
            true => rings.block(
                b,
                &column.get().unwrap().view(0..plan.cols),
                &pattern,
                0,
                None,
                ring,
            ),
            false => rings.block_body(
                b,
                &column.get().unwrap().view(0..plan.cols),
                &pattern,
                0,
                None,
                ring,
            ),
        };
        let bits3 = |a: Vec<[f32; 3]>| a.iter().map(|t| t.map(f32::to_bits)).collect();
        let uv = u.iter().map(|t| t.map(f32::to_bits)).collect();
        ((bits3(v), bits3(nn), uv, f), r)
    };
    let (a, b) = (run(true), run(false));
    assert!(a.0.3.iter().flatten().any(|&i| i > 0), "faces written");
    assert!(a == b, "the AVX2 block differs from the baseline block");
}

/// Everything [`Rings::write`] gives for one spine, in `(grain, piece)` tasks: the bits
/// of the vertices, normals, uv and faces, the fold rows and the first vertex out of
/// range.
fn written(
    spine: &Spine,
    p: &Profile,
    opts: &Options,
    tasks: (usize, usize),
) -> (Vec<u64>, Vec<i64>, Vec<usize>, Option<usize>) {
    let plan = check_spine(spine, opts, p, true, None, &cancel::never)
        .expect("a valid sweep")
        .expect("not stopped");
    let sh = Shared::new(
        p,
        plan.cols,
        false,
        &options(false, false, false),
        &cancel::never,
    )
    .unwrap();
    let rings = Rings {
        s: spine,
        x: &spine.points[..plan.rings],
        plan: &plan,
        p,
        column: &sh.column,
        closed: opts.closed,
        miter_limit: opts.miter_limit,
        sign: sh.sign,
        rowbase: 7,
        seam: 0,
    };
    // the rings of the samples (the joins' extra rings are written after them)
    let nv = plan.stored_rings * plan.cols;
    let (mut v, mut n) = (vec![[0f64; 3]; nv], vec![[0f64; 3]; nv]);
    let mut u = vec![[0f64; 2]; nv];
    let mut f = vec![[0i64; 3]; 2 * plan.segments * sh.edges];
    let out = MeshMut {
        vertices: &mut v,
        faces: &mut f,
        normals: Some(&mut n),
        uv: Some(&mut u),
    };
    let ring = &mut RingScratch::new(0);
    let (folds, bad) = rings.write(out, &sh.pattern, 3, None, tasks, ring, &cancel::never);
    let bits: Vec<u64> = [v.as_flattened(), n.as_flattened(), u.as_flattened()]
        .concat()
        .iter()
        .map(|x| x.to_bits())
        .collect();
    (bits, f.concat(), folds, bad)
}

/// A ring written in pieces of its columns (each a parallel task) gives the bits of
/// the ring written whole: vertices, normals, uv, faces with the twisted segments' split,
/// folds and the first vertex out of range. A twisted helix with a star of split seams
/// (and the same star clockwise), and a tight closed loop of an open profile, which
/// folds over, with a scale so large at one sample that a ring's vertices overflow.
#[test]
fn rings_in_pieces_equal_whole_rings() {
    let n = 40;
    let (x, frames): (Vec<DVec3>, Vec<[f64; 9]>) = (0..n)
        .map(|i| {
            let u = 0.3 * i as f64;
            let t = DVec3::new(-u.sin(), u.cos(), 0.1).normalize();
            (
                DVec3::new(u.cos(), u.sin(), 0.1 * u),
                frame(DVec3::new(-u.cos(), -u.sin(), 0.0), t),
            )
        })
        .unzip();
    let scale: Vec<DVec2> = (0..n)
        .map(|i| DVec2::new(0.2 + 0.01 * i as f64, 0.3))
        .collect();
    let twist: Vec<f64> = (0..n).map(|i| 0.05 * i as f64).collect();
    let helix = Spine {
        points: &x,
        frames: &frames,
        scale: &scale,
        twist: &twist,
    };
    let mut cw = star();
    cw.reverse();
    let (cx, cf) = circle(9, 1.0);
    let ribbon: Vec<DVec2> = (0..13)
        .map(|j| DVec2::new(0.3 * j as f64 - 1.5, 0.1 * (j % 3) as f64))
        .collect();
    let mut scales = vec![DVec2::ONE; 9];
    scales[4] = DVec2::splat(1e308);
    let loop_ = Spine {
        points: &cx,
        frames: &cf,
        scale: &scales,
        twist: &[],
    };
    let cases = [
        (
            helix,
            Profile::new(&star(), true, &cancel::never),
            options(false, false, true),
        ),
        (
            helix,
            Profile::new(&cw, true, &cancel::never),
            options(false, false, false),
        ),
        (
            loop_,
            Profile::new(&ribbon, false, &cancel::never),
            options(true, false, true),
        ),
    ];
    for (k, (spine, p, opts)) in cases.into_iter().enumerate() {
        let p = p.expect("a valid profile");
        let cols = p.len() + usize::from(p.closed && opts.split_seams);
        let whole = written(&spine, &p, &opts, (3, cols));
        assert!(whole.1.iter().any(|&i| i > 0), "case {k}: faces written");
        if k == 2 {
            assert!(
                !whole.2.is_empty() && whole.3.is_some(),
                "folds and overflow"
            );
        }
        for piece in [1, 2, 3, cols - 1] {
            let pieces = written(&spine, &p, &opts, (3, piece));
            assert!(pieces == whole, "case {k}: pieces of {piece} differ");
        }
    }
}

/// The faces computed per edge (large profiles) are those of the tables (small ones):
/// both splits and windings, with and without a seam column, consecutive rings and the
/// last ring joined to the first, from every first edge.
#[test]
fn face_formula_equals_table() {
    for (cols, edges) in [(7, 7), (8, 7), (7, 6)] {
        for sign in [1.0, -1.0] {
            let table = FacePattern::of(cols, edges, sign);
            let formula = FacePattern {
                ac: Vec::new(),
                bd: Vec::new(),
                ..FacePattern::of(cols, edges, sign)
            };
            assert_eq!(table.ac.len(), 2 * edges);
            for bd in [false, true] {
                for (b0, b1) in [(30, 30 + cols), (30 + 5 * cols, 30)] {
                    for e0 in 0..edges {
                        let k = 2 * (edges - e0);
                        let (mut x, mut y) = (vec![[0i64; 3]; k], vec![[0i64; 3]; k]);
                        table.write(&mut x, bd, b0, b1, e0);
                        formula.write(&mut y, bd, b0, b1, e0);
                        assert_eq!(x, y, "{cols} {edges} {sign} {bd} {b0} {e0}");
                    }
                }
            }
        }
    }
}

/// Two straight legs meeting at `deg` degrees in the xy plane, `n` chords each of length
/// `1/n`, with the frames of a plane curve (`r` = z, `t` the chord bisector at the corner).
fn legs(deg: f64, n: usize) -> (Vec<DVec3>, Vec<[f64; 9]>) {
    let a = deg.to_radians();
    let d = DVec3::new(a.cos(), a.sin(), 0.0);
    let mut x: Vec<DVec3> = (0..=n)
        .map(|i| DVec3::new(i as f64 / n as f64 - 1.0, 0.0, 0.0))
        .collect();
    x.extend((1..=n).map(|i| d * (i as f64 / n as f64)));
    let frames = (0..x.len())
        .map(|i| {
            let t = match i.cmp(&n) {
                std::cmp::Ordering::Less => DVec3::X,
                std::cmp::Ordering::Equal => (DVec3::X + d).normalize(),
                std::cmp::Ordering::Greater => d,
            };
            frame(DVec3::Z, t)
        })
        .collect();
    (x, frames)
}

/// A sharp corner gets a join, a smooth sampling none: the corner's extra rings after the
/// spine's, a closed and consistently wound mesh whatever the join, faces left out where
/// the crease welds flatten them, and the round join's outer vertices on the sphere of the
/// profile's radius about the corner.
#[test]
fn corners_get_watertight_joins_and_smooth_spines_none() {
    let p = Profile::new(&polygon(16), true, &cancel::never).expect("a valid profile");
    let r = DVec2::splat(0.05);
    for (deg, n) in [(90.0, 20), (150.0, 2), (170.0, 200)] {
        let (x, frames) = legs(deg, n);
        for join in [Join::Round, Join::Bevel, Join::Miter] {
            let opts = Options {
                join,
                turns: 0.0,
                ..options(false, true, false)
            };
            let mut found = Vec::new();
            super::join::corners(&x, &[r], false, &p, &opts, |c| found.push(c));
            assert_eq!(found.len(), 1, "{deg}° {join:?}");
            assert_eq!(found[0].k, n);
            let m = sweep(&x, &frames, &[r], &p, &opts);
            assert_watertight(&m.faces);
            let rings = m.vertices.len() / 16;
            assert_eq!(rings, x.len() + found[0].extra);
            let plain = 2 * (rings - 1) * 16 + 2 * 14;
            // the rings of a round or bevelled join meet on the crease
            assert!(
                join == Join::Miter || m.faces.len() < plain,
                "{deg}° {join:?}: the crease flattens faces"
            );
            assert!(m.faces.len() <= plain);
            if join == Join::Round {
                let used: std::collections::HashSet<i64> =
                    m.faces.iter().flatten().copied().collect();
                for v in x.len() * 16..m.vertices.len() {
                    if used.contains(&(v as i64)) {
                        let d = (m.vertices[v] - x[n]).length();
                        assert!((d - 0.05).abs() < 1e-15, "{deg}°: {d}");
                    }
                }
            }
        }
    }
    // a dense helix: no corner, the plain sweep
    let (x, frames) = circle(200, 1.0);
    let opts = options(true, false, false);
    let mut found = 0;
    super::join::corners(&x, &[r], true, &p, &opts, |_| found += 1);
    assert_eq!(found, 0);
    let m = sweep(&x, &frames, &[r], &p, &opts);
    assert_eq!(m.vertices.len(), 200 * 16);
}
