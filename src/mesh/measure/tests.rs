//! Unit tests of the mesh measures: an octahedron's, exact scaling, broken meshes and the
//! edge statistics against their definition.

use super::*;
use crate::math::mesh::fixtures::octahedron;
use crate::run::cancel;

fn oct() -> (Vec<[f64; 3]>, Vec<[i64; 3]>) {
    let (v, f) = octahedron();
    (
        v.iter().map(|p| p.to_array()).collect(),
        f.iter().map(|t| t.map(|i| i as i64)).collect(),
    )
}

#[test]
fn octahedron_measures() {
    let (v, f) = oct();
    assert!((volume(&v, &f, &cancel::never).unwrap() - 4.0 / 3.0).abs() < 1e-15);
    let a = 8.0 * 3f64.sqrt() / 2.0;
    assert!((area(&v, &f, &cancel::never).unwrap() - a).abs() < 1e-14);
    let v32: Vec<[f32; 3]> = v.iter().map(|p| p.map(|x| x as f32)).collect();
    let f32i: Vec<[i32; 3]> = f.iter().map(|t| t.map(|i| i as i32)).collect();
    assert!((volume(&v32, &f32i, &cancel::never).unwrap() - 4.0 / 3.0).abs() < 1e-6);
    let e = edges(&f, 6, &cancel::never).unwrap();
    assert_eq!(e.edges, 12);
    assert!(e.watertight());
}

#[test]
fn measures_scale_exactly_with_the_mesh() {
    // scaling by 2^k scales the area by 4^k and the volume by 8^k bit for bit while the
    // results are representable; beyond, `inf` or 0 but never NaN
    let (v, f) = oct();
    let (a1, v1) = (
        area(&v, &f, &cancel::never).unwrap(),
        volume(&v, &f, &cancel::never).unwrap(),
    );
    for k in [-340i32, -300, -260, -150, -1, 0, 1, 100, 150, 250, 330] {
        let s = 2f64.powi(k);
        let w: Vec<[f64; 3]> = v.iter().map(|p| p.map(|x| x * s)).collect();
        let (a, vol) = (
            area(&w, &f, &cancel::never).unwrap(),
            volume(&w, &f, &cancel::never).unwrap(),
        );
        let want_a = a1 * s * s;
        let want_v = v1 * s * s * s;
        assert_eq!(
            a.to_bits(),
            want_a.to_bits(),
            "area at 2^{k}: {a} vs {want_a}"
        );
        assert_eq!(vol.to_bits(), want_v.to_bits(), "volume at 2^{k}");
    }
    // at 1e80 the plain sums overflowed to NaN; at 1e-80 they underflowed to 0
    for scale in [1e-120, 1e-80, 1e80, 1e102, 1e103] {
        let w: Vec<[f64; 3]> = v.iter().map(|p| p.map(|x| x * scale)).collect();
        let a = area(&w, &f, &cancel::never).unwrap();
        let vol = volume(&w, &f, &cancel::never).unwrap();
        assert!(
            (a / (a1 * scale * scale) - 1.0).abs() < 1e-15 || a.is_infinite(),
            "{a}"
        );
        assert!(vol.is_finite() || vol == f64::INFINITY, "{vol}");
        assert!(!a.is_nan() && !vol.is_nan());
    }
}

#[test]
fn broken_meshes() {
    let (_, f) = oct();
    // a hole: three boundary edges
    let e = edges(&f[1..], 6, &cancel::never).unwrap();
    assert_eq!((e.boundary, e.closed()), (3, false));
    // a flipped face: its three edges are traversed twice the same way
    let mut g = f.clone();
    g[0] = [g[0][0], g[0][2], g[0][1]];
    let e = edges(&g, 6, &cancel::never).unwrap();
    assert!(e.closed() && !e.winding_consistent() && e.inconsistent == 3);
    // a fin: a third face on an edge
    let mut g = f.clone();
    g.push([0, 2, 3]);
    let e = edges(&g, 6, &cancel::never).unwrap();
    assert_eq!((e.non_manifold, e.boundary), (2, 1)); // 0-2 and 3-0 thrice, 2-3 once
    assert!(!e.watertight());
    // degenerate and out-of-range faces
    let e = edges(&[[0i64, 0, 1]], 2, &cancel::never).unwrap();
    assert_eq!((e.degenerate, e.edges, e.boundary), (1, 1, 0));
    assert!(e.winding_consistent() && !e.closed());
    let err = edges(&[[0i64, 1, -1]], 3, &cancel::never).unwrap_err();
    assert_eq!(err.arg, "faces");
    assert!(err.msg.contains("face 0 refers to vertex -1"), "{err}");
    assert!(volume(&[[0.0; 3]; 3], &[[0i64, 1, 3]], &cancel::never).is_err());
    assert_eq!(
        edges::<i64>(&[], 0, &cancel::never).unwrap(),
        EdgeStats::default()
    );
}

/// The statistics by a map of the undirected edges (the definition, quadratic memory
/// aside).
fn brute(f: &[[i64; 3]]) -> EdgeStats {
    let mut map = std::collections::BTreeMap::<(i64, i64), (usize, usize)>::new();
    let mut st = EdgeStats::default();
    for t in f {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a == b {
                st.degenerate += 1;
                continue;
            }
            let e = map.entry((a.min(b), a.max(b))).or_default();
            e.0 += 1;
            e.1 += usize::from(a < b);
        }
    }
    for &(slots, forward) in map.values() {
        st.edges += 1;
        match slots {
            1 => st.boundary += 1,
            2 if forward != 1 => st.inconsistent += 1,
            2 => {}
            _ => st.non_manifold += 1,
        }
    }
    st
}

/// A closed torus grid of `r` rings of `s` vertices, wound consistently.
fn torus(r: i64, s: i64) -> Vec<[i64; 3]> {
    let id = |i: i64, j: i64| (i % r) * s + j % s;
    let mut f = Vec::new();
    for i in 0..r {
        for j in 0..s {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            f.push([a, b, c]);
            f.push([a, c, d]);
        }
    }
    f
}

#[test]
fn edges_match_the_definition() {
    // many parts of the vertices and many chunks of faces
    for (r, s) in [(3, 3), (50, 7), (700, 16), (1000, 40)] {
        let f = torus(r, s);
        let n = (r * s) as usize;
        let e = edges(&f, n, &cancel::never).unwrap();
        assert_eq!(e, brute(&f));
        assert!(e.watertight(), "{r} x {s}: {e:?}");
        assert_eq!(e.edges, 3 * n);
        let f32i: Vec<[i32; 3]> = f.iter().map(|t| t.map(|i| i as i32)).collect();
        assert_eq!(edges(&f32i, n, &cancel::never).unwrap(), e);
        // one flipped face far into the mesh, one removed, one duplicated
        let mut g = f.clone();
        let k = g.len() * 2 / 3;
        g[k] = [g[k][1], g[k][0], g[k][2]];
        let e = edges(&g, n, &cancel::never).unwrap();
        assert_eq!((e.inconsistent, e.closed()), (3, true));
        assert_eq!(e, brute(&g));
        g.remove(k / 2);
        g.push(g[k / 3]);
        assert_eq!(edges(&g, n, &cancel::never).unwrap(), brute(&g));
        // the vertices renumbered far apart: the slots are distributed by part first
        let far: Vec<[i64; 3]> = g.iter().map(|t| t.map(|i| (i * 7919) % n as i64)).collect();
        assert_eq!(edges(&far, n, &cancel::never).unwrap(), brute(&g));
    }
    // random faces (with repeats, degenerate corners, unused vertices)
    let mut x = 0x9e3779b97f4a7c15u64;
    let mut next = |m: u64| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x % m) as i64
    };
    for (n, faces) in [(4, 20), (30, 500), (5000, 30_000), (70_000, 60_000)] {
        let f: Vec<[i64; 3]> = (0..faces).map(|_| [next(n), next(n), next(n)]).collect();
        assert_eq!(
            edges(&f, n as usize, &cancel::never).unwrap(),
            brute(&f),
            "{n} vertices"
        );
    }
    // an index out of range in a late chunk is the one reported
    let mut f = torus(1000, 40);
    f[70_000][2] = 40_000;
    let err = edges(&f, 40_000, &cancel::never).unwrap_err();
    assert!(
        err.msg.contains("face 70000 refers to vertex 40000"),
        "{err}"
    );
}
