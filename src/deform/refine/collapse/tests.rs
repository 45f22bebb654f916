//! Unit tests of the edge collapse: a collapse keeps the mesh closed, wound and outward, the
//! link condition refuses non-manifold results, and a drag strip collapses keeping its volume.

use super::super::tests::{drag, sphere, watertight};
use super::super::{Refinement, deform, schedule};
use super::*;
use crate::math::mesh::signed_volume as volume;

/// The faces after collapsing half-edge `h` of `t` (no test), with `b` renamed `a`.
fn forced(t: &Topology, h: usize) -> Vec<[usize; 3]> {
    let (a, b) = t.ends(h);
    let (f, g) = (h / 3, t.twin[h] / 3);
    (0..t.faces.len())
        .filter(|&q| q != f && q != g)
        .map(|q| t.faces[q].map(|v| if v == b { a } else { v }))
        .collect()
}

/// A valid closed, consistently wound, edge-manifold mesh with no repeated face.
fn valid(faces: &[[usize; 3]], n: usize) -> bool {
    let mut keys: Vec<[usize; 3]> = faces
        .iter()
        .map(|f| {
            let mut k = *f;
            k.sort_unstable();
            k
        })
        .collect();
    keys.sort_unstable();
    keys.windows(2).all(|w| w[0] != w[1]) && watertight(faces, n)
}

#[test]
fn a_collapse_keeps_the_mesh_closed_wound_and_outward() {
    let (mut v, f) = sphere(2);
    let mut t = Topology::new(&f, v.len()).unwrap();
    // an edge between two vertices that are not the octahedron's (valence 6)
    let h = (0..3 * f.len())
        .find(|&h| t.ends(h).0 >= 6 && t.ends(h).1 >= 6)
        .unwrap();
    let (a, b) = t.ends(h);
    let (_, sb) = t
        .collapsible(h)
        .expect("the link condition holds on a sphere");
    let mut dead = vec![false; t.faces.len()];
    v[a] = (0.5 * (v[a] + v[b])).normalize();
    t.collapse(h, &sb, &mut dead);
    assert_eq!(dead.iter().filter(|&&d| d).count(), 2);
    t.compact(&dead).unwrap();
    assert_eq!(t.faces.len(), f.len() - 2);
    assert!(t.faces.iter().all(|q| !q.contains(&b)), "b is gone");
    assert!(valid(&t.faces, v.len()));
    // the compacted twins are the ones a fresh pairing finds, every face winds outwards
    let fresh = Topology::new(&t.faces, v.len()).unwrap();
    assert_eq!(fresh.twin, t.twin);
    for q in &t.faces {
        let n = (v[q[1]] - v[q[0]]).cross(v[q[2]] - v[q[0]]);
        assert!(n.dot(v[q[0]] + v[q[1]] + v[q[2]]) > 0.0, "{q:?}");
    }
}

#[test]
fn the_link_condition_refuses_the_collapses_that_leave_the_manifolds() {
    // a tetrahedron: every contraction leaves two faces on three vertices
    let (v, f) = (
        vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
    );
    let t = Topology::new(&f, v.len()).unwrap();
    for h in 0..12 {
        assert!(t.collapsible(h).is_none());
        assert!(!valid(&forced(&t, h), 4), "{h}");
    }
    // an 18-vertex sphere collapsed edge by edge while any edge passes: every collapse
    // allowed leaves a valid mesh; the edges whose ends have a third common neighbour are
    // refused, and their contraction would give an edge of more than two faces or a
    // repeated face
    let (v, f) = sphere(1);
    let n = v.len();
    let mut t = Topology::new(&f, n).unwrap();
    let (mut collapses, mut refused) = (0, 0);
    'collapse: loop {
        let neighbours = |x: usize| {
            let mut around: Vec<usize> = t
                .faces
                .iter()
                .filter(|q| q.contains(&x))
                .flatten()
                .copied()
                .filter(|&y| y != x)
                .collect();
            around.sort_unstable();
            around.dedup();
            around
        };
        for h in 0..3 * t.faces.len() {
            let (a, b) = t.ends(h);
            let common = neighbours(a)
                .iter()
                .filter(|y| neighbours(b).contains(y))
                .count();
            if common > 2 {
                refused += 1;
                assert!(t.collapsible(h).is_none(), "{h}");
                assert!(!valid(&forced(&t, h), n), "{h}");
            }
            if let Some((_, sb)) = t.collapsible(h) {
                assert!(valid(&forced(&t, h), n), "{h}");
                let mut dead = vec![false; t.faces.len()];
                t.collapse(h, &sb, &mut dead);
                t.compact(&dead).unwrap();
                assert!(valid(&t.faces, n));
                assert_eq!(Topology::new(&t.faces, n).unwrap().twin, t.twin);
                collapses += 1;
                continue 'collapse;
            }
        }
        break;
    }
    assert!(
        collapses > 5 && refused > 0,
        "{collapses} collapses, {refused} refused"
    );
}

#[test]
fn the_drag_strip_is_collapsed_keeping_the_volume() {
    // the drag of the torn-drag tests (a curl tool centred on a 4,098-vertex octahedral
    // sphere's surface, moved half a radius): collapses along the strip, each within
    // COLLAPSE_VOLUME × ℓ̄³ of the volume, leave a closed, consistently wound mesh with no
    // edge over the threshold, the slip vertices on the tool's surface and the volume
    // change of the refinement
    let (v, f) = sphere(5);
    let tool = drag(DVec3::new(0.0, 0.0, 0.9), 0.9, DVec3::new(0.5, 0.0, 0.0));
    let runs = schedule(&tool, 0.0, 1.0, 10).unwrap();
    let opts = Refinement {
        ratio: 1.5,
        max_vertices: 10 * v.len(),
        max_passes: 30,
    };
    let d = deform(&tool, &v, &f, &runs, Some(opts), true, &mut |_, _| true)
        .unwrap()
        .unwrap();
    assert!(valid(&d.faces, d.vertices.len()));
    assert_eq!((d.over_threshold, d.bounded), (0, false));
    assert!(d.collapses > 100, "{} collapses", d.collapses);
    assert_eq!(*d.step_vertices.last().unwrap(), d.vertices.len());
    let mean3 = (std::f64::consts::FRAC_PI_2 / 32.0).powi(3);
    assert!(
        d.collapse_volume.abs() <= (d.collapses + d.moves) as f64 * COLLAPSE_VOLUME * mean3,
        "{} collapses changed the volume by {:e}",
        d.collapses,
        d.collapse_volume
    );
    let change = volume(&d.vertices, &d.faces) / volume(&v, &f) - 1.0;
    assert!(change.abs() < 2.5e-4, "volume change {change}");
    // the rest mesh keeps its volume (two rest points the same, or flat rest faces)
    assert!((volume(&d.rest, &d.faces) / volume(&v, &f) - 1.0).abs() < 1e-13);
    // the input's vertices are kept, in order
    assert_eq!(&d.rest[..v.len()], &v[..]);
    // every used vertex is used; the strip vertices lie on the tool's surface
    let mut used = vec![false; d.vertices.len()];
    d.faces.iter().flatten().for_each(|&i| used[i] = true);
    assert!(used.iter().all(|&u| u));
    let c1 = DVec3::new(0.5, 0.0, 0.9);
    let on = d
        .vertices
        .iter()
        .filter(|x| ((**x - c1).length() - 0.9).abs() < 1e-12)
        .count();
    assert!(on >= d.slip_vertices, "{on} of {}", d.slip_vertices);
    // few slivers are left among the faces with a vertex on the surface
    let (mut band, mut slivers) = (0, 0);
    for q in &d.faces {
        if q.iter()
            .any(|&i| ((d.vertices[i] - c1).length() - 0.9).abs() < 1e-12)
        {
            band += 1;
            let [p, r, s] = q.map(|i| d.vertices[i]);
            slivers += usize::from(min_angle(p, r, s) < SLIVER);
        }
    }
    assert!(slivers * 20 < band, "{slivers} slivers of {band}");
}
