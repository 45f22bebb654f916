//! Four samples per operation: a tiny vector type for the loops of the fused path.
//!
//! `F4` holds one value of four consecutive samples; its operators act lane by lane with the
//! plain IEEE operations of `f64`, so a formula written once for [`Arith`] gives, lane for
//! lane, exactly the bits of the scalar formula. The compiler turns the lane loops into
//! vector instructions (two SSE2 operations per `F4` operation on baseline x86-64), and the
//! divisions and square roots of four samples overlap instead of waiting on each other.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// Lanes of [`F4`].
pub const L: usize = 4;

/// The arithmetic a formula shared by scalar and lane code needs.
pub trait Arith:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    fn splat(v: f64) -> Self;
}

impl Arith for f64 {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        v
    }
}

/// One `f64` of each of four samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct F4(pub [f64; L]);

impl F4 {
    /// `s[k .. k + 4]`.
    #[inline(always)]
    pub fn load(s: &[f64], k: usize) -> Self {
        let mut v = [0.0; L];
        v.copy_from_slice(&s[k..k + L]);
        F4(v)
    }

    /// Write into `s[k .. k + 4]`.
    #[inline(always)]
    pub fn store(self, s: &mut [f64], k: usize) {
        s[k..k + L].copy_from_slice(&self.0);
    }

    #[inline(always)]
    pub fn sqrt(self) -> Self {
        self.map(f64::sqrt)
    }

    // The lanes are spelled out (no loop over `l`): the compiler then sees four independent
    // operations and pairs them into vector instructions.
    #[inline(always)]
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        let a = self.0;
        F4([f(a[0]), f(a[1]), f(a[2]), f(a[3])])
    }

    #[inline(always)]
    fn zip(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let (a, b) = (self.0, o.0);
        F4([f(a[0], b[0]), f(a[1], b[1]), f(a[2], b[2]), f(a[3], b[3])])
    }

    /// Lanes where `f` holds, as a bit mask (lane `l` is bit `l`).
    #[inline(always)]
    pub fn mask(self, o: Self, f: impl Fn(f64, f64) -> bool) -> u32 {
        let (a, b) = (self.0, o.0);
        (f(a[0], b[0]) as u32)
            | (f(a[1], b[1]) as u32) << 1
            | (f(a[2], b[2]) as u32) << 2
            | (f(a[3], b[3]) as u32) << 3
    }
}

impl Arith for F4 {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        F4([v; L])
    }
}

macro_rules! lanewise {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for F4 {
            type Output = F4;
            #[inline(always)]
            fn $f(self, o: F4) -> F4 {
                self.zip(o, |a, b| a $op b)
            }
        }
    };
}
lanewise!(Add, add, +);
lanewise!(Sub, sub, -);
lanewise!(Mul, mul, *);
lanewise!(Div, div, /);

impl Neg for F4 {
    type Output = F4;
    #[inline(always)]
    fn neg(self) -> F4 {
        self.map(|a| -a)
    }
}

/// A 3-vector of four samples: `x`, `y`, `z` each an [`F4`].
#[derive(Debug, Clone, Copy)]
pub struct V4 {
    /// The `x` components of the four vectors.
    pub x: F4,
    /// The `y` components of the four vectors.
    pub y: F4,
    /// The `z` components of the four vectors.
    pub z: F4,
}

impl V4 {
    #[inline(always)]
    pub fn load(s: &[&[f64]; 3], k: usize) -> Self {
        V4 {
            x: F4::load(s[0], k),
            y: F4::load(s[1], k),
            z: F4::load(s[2], k),
        }
    }

    #[inline(always)]
    pub fn store(self, s: &mut [&mut [f64]; 3], k: usize) {
        self.x.store(s[0], k);
        self.y.store(s[1], k);
        self.z.store(s[2], k);
    }

    /// `(x·x + y·y) + z·z`, as `DVec3::dot`.
    #[inline(always)]
    pub fn dot(self, o: V4) -> F4 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// As `DVec3::cross`, term for term.
    #[inline(always)]
    pub fn cross(self, o: V4) -> V4 {
        V4 {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    #[inline(always)]
    pub fn scale(self, k: F4) -> V4 {
        V4 {
            x: k * self.x,
            y: k * self.y,
            z: k * self.z,
        }
    }

    /// Lanes whose three coordinates are finite, as a bit mask.
    #[inline(always)]
    pub fn finite_mask(self) -> u32 {
        let f = |a: F4| a.mask(a, |p, q| (p - q) == 0.0);
        f(self.x) & f(self.y) & f(self.z)
    }
}

impl Add for V4 {
    type Output = V4;
    #[inline(always)]
    fn add(self, o: V4) -> V4 {
        V4 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for V4 {
    type Output = V4;
    #[inline(always)]
    fn sub(self, o: V4) -> V4 {
        V4 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_are_the_scalar_operations() {
        let a = F4([1.5, -2.0, 1e-300, f64::INFINITY]);
        let b = F4([3.0, 0.1, 1e300, 2.0]);
        for (v, f) in [
            (a + b, (|p: f64, q: f64| p + q) as fn(f64, f64) -> f64),
            (a - b, |p, q| p - q),
            (a * b, |p, q| p * q),
            (a / b, |p, q| p / q),
        ] {
            for l in 0..L {
                assert_eq!(v.0[l].to_bits(), f(a.0[l], b.0[l]).to_bits());
            }
        }
        assert_eq!(a.mask(b, |p, q| p < q), 0b0111);
        let v = V4 { x: a, y: b, z: a };
        assert_eq!(v.finite_mask(), 0b0111);
    }
}
