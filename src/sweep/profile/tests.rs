//! Unit tests of the profile: its checks, exact orientation, the crossing sweep and the
//! triangulation of convex and non-convex profiles.

use super::fixtures::{Rng, comb, spiked_star, star_shaped};
use super::*;
use crate::math::predicates::{accurate_area2, accurate_cover2};

fn area_of(p: &[DVec2], tris: &[[usize; 3]]) -> f64 {
    0.5 * accurate_cover2(p, tris)
}

/// One edge 3e9 times longer than the others: the binning stays O(m) (it asked for
/// 8 GiB once, aborting the process).
#[test]
fn one_long_edge_bins_into_few_cells() {
    let t = 2.99865106e-10;
    let p = [
        DVec2::new(t, 0.0),
        DVec2::new(0.0, t),
        DVec2::new(-t, 0.0),
        DVec2::new(-1.0, -t),
    ];
    for closed in [false, true] {
        let mut cells = Cells::new(&p, closed);
        let edges = if closed { p.len() } else { p.len() - 1 };
        for e in 0..edges {
            cells.add_segment(p[e], p[(e + 1) % p.len()], e);
        }
        assert!(cells.items.len() <= 9 * 10 * edges, "{}", cells.items.len());
    }
    assert!(Profile::new(&p, false, &cancel::never).is_ok());
}

#[test]
fn triangulation_covers_non_convex_polygons() {
    // An L shape and a 5-pointed star, both orientations.
    let l = [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 3.), (0., 3.)];
    let star: Vec<(f64, f64)> = (0..10)
        .map(|k| {
            let r = if k % 2 == 0 { 1.0 } else { 0.4 };
            let a = std::f64::consts::PI * k as f64 / 5.0;
            (r * a.cos(), r * a.sin())
        })
        .collect();
    for poly in [l.to_vec(), star] {
        for rev in [false, true] {
            let mut p: Vec<DVec2> = poly.iter().map(|&(x, y)| DVec2::new(x, y)).collect();
            if rev {
                p.reverse();
            }
            let prof = Profile::new(&p, true, &cancel::never).unwrap();
            let tris = prof.triangulate(&cancel::never).unwrap();
            assert_eq!(tris.len(), p.len() - 2);
            // every triangle counter-clockwise, total = |area|
            for t in &tris {
                assert!(cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]) > 0.0);
            }
            assert!((area_of(&p, &tris) - prof.area.abs()).abs() < 1e-12);
        }
    }
}

/// A regular 1000-gon is convex (a fan); a gear of 400 teeth is not (monotone pieces);
/// both cover their area with counter-clockwise triangles, in either orientation.
#[test]
fn convex_and_many_vertex_profiles_are_covered() {
    let ngon: Vec<DVec2> = (0..1000)
        .map(|k| DVec2::from_angle(std::f64::consts::TAU * k as f64 / 1000.0))
        .collect();
    let gear: Vec<DVec2> = (0..1600)
        .map(|k| {
            let r = if (k / 2) % 2 == 0 { 1.0 } else { 0.9 };
            r * DVec2::from_angle(std::f64::consts::TAU * k as f64 / 1600.0)
        })
        .collect();
    for (poly, convex) in [(ngon, true), (gear, false)] {
        for rev in [false, true] {
            let mut p = poly.clone();
            if rev {
                p.reverse();
            }
            let prof = Profile::new(&p, true, &cancel::never).unwrap();
            assert_eq!(prof.convex, convex);
            let tris = prof.triangulate(&cancel::never).unwrap();
            assert_eq!(tris.len(), p.len() - 2);
            for t in &tris {
                assert!(cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]) > 0.0);
            }
            let a = area_of(&p, &tris);
            assert!((a - prof.area.abs()).abs() < 1e-12 * a);
        }
    }
    // a dent through the middle of the gear makes it self-intersecting
    let mut bad: Vec<DVec2> = (0..1600)
        .map(|k| DVec2::from_angle(std::f64::consts::TAU * k as f64 / 1600.0))
        .collect();
    bad[800] = DVec2::new(1.5, 0.0);
    assert!(Profile::new(&bad, true, &cancel::never).is_err());
}

#[test]
fn bad_profiles_are_refused() {
    let bowtie: Vec<DVec2> = [(0., 0.), (1., 1.), (1., 0.), (0., 1.)]
        .iter()
        .map(|&(x, y)| DVec2::new(x, y))
        .collect();
    assert!(Profile::new(&bowtie, true, &cancel::never).is_err());
    let line: Vec<DVec2> = [(0., 0.), (1., 1.), (2., 2.)]
        .iter()
        .map(|&(x, y)| DVec2::new(x, y))
        .collect();
    assert!(Profile::new(&line, true, &cancel::never).is_err());
    assert!(Profile::new(&line, false, &cancel::never).is_ok());
}

/// The definition: any two non-adjacent edges that meet, or adjacent ones that fold
/// back, by testing all pairs.
fn brute_crossing(p: &[DVec2], closed: bool) -> bool {
    let m = p.len();
    let edges = if closed { m } else { m - 1 };
    let fold = |a: usize| folds_back(p[a], p[(a + 1) % m], p[(a + 2) % m]);
    (0..edges).any(|a| (a + 1 < edges || closed) && fold(a))
        || (0..edges).any(|a| {
            (a + 2..edges).any(|b| {
                !(closed && a == 0 && b == m - 1)
                    && segments_meet(p[a], p[(a + 1) % m], p[b], p[(b + 1) % m])
            })
        })
}

#[test]
fn orientation_is_exact() {
    // nearly collinear points where the plain cross product rounds the wrong way or
    // to zero (Shewchuk's example: points near (0.5, 0.5) on y = x)
    let (a, b) = (DVec2::new(12.0, 12.0), DVec2::new(24.0, 24.0));
    let ulp = f64::EPSILON / 2.0;
    for i in 0..64 {
        for j in 0..64 {
            let c = DVec2::new(0.5 + i as f64 * ulp, 0.5 + j as f64 * ulp);
            // c lies left of a → b exactly when c.y > c.x
            let want = c.y.partial_cmp(&c.x).unwrap();
            assert_eq!(orient(a, b, c), want, "{c:?}");
        }
    }
}

/// The orientation of points with integer coordinates up to 2^52 (products beyond the
/// 53 bits of a double) against exact integer arithmetic: random points, points
/// repeated (products of zero) and nearly collinear triples.
#[test]
fn orientation_matches_integer_arithmetic() {
    let mut rng = Rng(0x5851f42d4c957f2d);
    let exact = |a: DVec2, b: DVec2, c: DVec2| {
        let i = |x: f64| x as i128;
        let d = (i(a.x) - i(c.x)) * (i(b.y) - i(c.y)) - (i(a.y) - i(c.y)) * (i(b.x) - i(c.x));
        d.cmp(&0)
    };
    for bits in [3u32, 20, 40, 52] {
        let big = 1u64 << bits;
        let pt = |rng: &mut Rng| {
            let s = |rng: &mut Rng| rng.below(big) as f64 - (big / 2) as f64;
            DVec2::new(s(rng), s(rng))
        };
        for _ in 0..20_000 {
            let (a, b) = (pt(&mut rng), pt(&mut rng));
            // c random, repeated, or on the line a b moved by a unit
            let c = match rng.below(3) {
                0 => pt(&mut rng),
                1 => [a, b][rng.below(2) as usize],
                _ => {
                    let t = rng.below(1 << 10) as f64;
                    let on = a + (b - a) * t;
                    (on + DVec2::new(rng.below(3) as f64 - 1.0, 0.0)).round()
                }
            };
            if [a, b, c]
                .iter()
                .any(|p| p.abs().max_element() >= 2f64.powi(61))
            {
                continue;
            }
            for (x, y, z) in [(a, b, c), (b, c, a), (c, a, b), (b, a, c)] {
                assert_eq!(orient(x, y, z), exact(x, y, z), "{x:?} {y:?} {z:?}");
            }
        }
    }
}

#[test]
fn sweep_finds_crossings_like_testing_all_pairs() {
    let mut rng = Rng(0x2545f4914f6cdd1d);
    // small polygons on a 5 × 5 grid: shared vertices, collinear and vertical edges,
    // touching at vertices, overlapping edges
    let mut found = [0usize; 2];
    for _ in 0..8_000 {
        let m = 3 + rng.below(8) as usize;
        let mut p: Vec<DVec2> = Vec::new();
        while p.len() < m {
            let q = DVec2::new(rng.below(5) as f64, rng.below(5) as f64);
            if p.last() != Some(&q) {
                p.push(q);
            }
        }
        for closed in [false, true] {
            if closed && p[0] == p[m - 1] {
                continue;
            }
            let want = brute_crossing(&p, closed);
            let got = sweep_crossing(&p, closed, &cancel::never).unwrap();
            assert_eq!(got.is_some(), want, "{p:?} closed {closed}");
            let grid = first_crossing(&p, closed).is_some();
            let fold = (0..m).any(|a| folds_back(p[a], p[(a + 1) % m], p[(a + 2) % m]));
            assert!(grid == want || fold, "{p:?}");
            if let Some((a, b)) = got {
                let e = |k: usize| (p[k], p[(k + 1) % m]);
                let ((w, x), (y, z)) = (e(a), e(b));
                assert!(a < b && segments_meet(w, x, y, z));
            }
            found[usize::from(want)] += 1;
        }
    }
    assert!(found[0] > 500 && found[1] > 500, "{found:?}");
    // star-shaped polygons are simple; one vertex moved across makes most cross
    for m in [3, 10, 100, 2000] {
        for _ in 0..20 {
            let mut p = star_shaped(&mut rng, m);
            let n = p.len();
            assert_eq!(sweep_crossing(&p, true, &cancel::never).unwrap(), None);
            assert_eq!(sweep_crossing(&p, false, &cancel::never).unwrap(), None);
            let k = rng.below(n as u64) as usize;
            p[k] = -1.5 * p[k];
            if n <= 100 {
                for closed in [false, true] {
                    assert_eq!(
                        sweep_crossing(&p, closed, &cancel::never)
                            .unwrap()
                            .is_some(),
                        brute_crossing(&p, closed)
                    );
                }
            } else {
                assert_eq!(
                    sweep_crossing(&p, true, &cancel::never).unwrap().is_some(),
                    first_crossing(&p, true).is_some()
                );
            }
        }
    }
}

/// Stars and combs of many packed spikes: simple, capped by `m − 2` counter-clockwise
/// triangles covering the area in either orientation, and one spike bent onto its
/// neighbour is found.
#[test]
fn packed_spikes_are_checked_in_m_log_m() {
    for mut p in [spiked_star(100_000, 0.2), comb(25_000)] {
        assert_eq!(sweep_crossing(&p, true, &cancel::never).unwrap(), None);
        for rev in [false, true] {
            let mut q = p.clone();
            if rev {
                q.reverse();
            }
            let prof = Profile::new(&q, true, &cancel::never).unwrap();
            let tris = prof.triangulate(&cancel::never).unwrap();
            assert_eq!(tris.len(), q.len() - 2);
            use std::cmp::Ordering::Greater;
            assert!(
                tris.iter()
                    .all(|t| orient(q[t[0]], q[t[1]], q[t[2]]) == Greater)
            );
            // the covered area against the polygon's, both to about the last bit
            let (a, want) = (area_of(&q, &tris), 0.5 * accurate_area2(&q).abs());
            assert!((a - want).abs() < 1e-12 * a, "{a} {want}");
        }
        let n = p.len();
        // two vertices of neighbouring spikes swapped: their edges cross
        let k = (n / 2) & !1;
        p.swap(k + 1, k + 5);
        assert!(sweep_crossing(&p, true, &cancel::never).unwrap().is_some());
    }
}
