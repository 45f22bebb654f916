//! Property tests (proptest) of the mitre stretch: the stretched ring is the cut of both
//! adjacent straight prisms.

use super::rings::mitre;
use super::*;
use proptest::prelude::*;

fn unit() -> impl Strategy<Value = DVec3> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
        .prop_map(|(x, y, z)| DVec3::new(x, y, z))
        .prop_filter("not tiny", |v| v.length() > 1e-2)
        .prop_map(|v| v.normalize())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    /// At a corner between the unit chords `din`, `dout` (turn φ < 160°) with the
    /// bisector tangent, a profile point `p ⊥ t` stretched by the mitre lies at the
    /// distance |p| from both chord lines (the two prisms of radius |p| meet in the
    /// bisector plane), and the factor is `1/cos(φ/2)`, capped by the limit.
    #[test]
    fn mitre_ring_is_the_cut_of_both_prisms(
        din in unit(), dout in unit(), p in unit(), len in 1e-3..1e3f64,
        limit in 1.0..20.0f64,
    ) {
        prop_assume!(din.dot(dout) > (160f64.to_radians()).cos());
        let t = (din + dout).normalize();
        let p = len * (p - p.dot(t) * t);
        prop_assume!(p.length() > 1e-6 * len);
        let (f, k) = mitre(din, dout, t, 1e9);
        let q = p + f * p.dot(k) * k;
        let dist = |d: DVec3| (q - q.dot(d) * d).length();
        let r = p.length();
        prop_assert!((dist(din) - r).abs() < 1e-12 * r, "{} {}", dist(din), r);
        prop_assert!((dist(dout) - r).abs() < 1e-12 * r, "{} {}", dist(dout), r);
        let half = 0.5 * din.angle_between(dout);
        let (fl, _) = mitre(din, dout, t, limit);
        if f > 0.0 {
            prop_assert!(((1.0 + f) * half.cos() - 1.0).abs() < 1e-12);
        }
        prop_assert!(1.0 + fl <= limit + 1e-15);
        prop_assert!((1.0 + fl - (1.0 + f).min(limit)).abs() < 1e-15);
    }
}
