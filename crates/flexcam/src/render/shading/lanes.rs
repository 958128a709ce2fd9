//! Four lanes of f64 arithmetic, for shading the pixels of a 2x2 quad together: every
//! operation is the scalar one lane by lane (the same IEEE operation on the same operands,
//! so the same bits as glam's `DVec3` arithmetic that the one-hit shading uses), written
//! over fixed arrays so that the compiler issues it two lanes to an instruction
//! (`sqrtpd`, `divpd`, ...) instead of one.

use std::ops::{Add, Mul, Neg, Sub};

use glam::DVec3;

/// Four f64 values, one a lane.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct F64x4(pub [f64; 4]);

impl F64x4 {
    pub fn splat(v: f64) -> F64x4 {
        F64x4([v; 4])
    }

    /// `f` of each lane.
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> F64x4 {
        let a = self.0;
        F64x4([f(a[0]), f(a[1]), f(a[2]), f(a[3])])
    }

    /// `f` of each lane of `self` and `other`.
    #[inline(always)]
    fn zip(self, other: F64x4, f: impl Fn(f64, f64) -> f64) -> F64x4 {
        let (a, b) = (self.0, other.0);
        F64x4([f(a[0], b[0]), f(a[1], b[1]), f(a[2], b[2]), f(a[3], b[3])])
    }

    #[inline]
    pub fn sqrt(self) -> F64x4 {
        self.map(f64::sqrt)
    }

    /// `1 / x` of each lane (`f64::recip`).
    #[inline]
    pub fn recip(self) -> F64x4 {
        self.map(f64::recip)
    }

    /// `f64::max` of each lane (a NaN lane gives the other operand).
    #[inline]
    pub fn max(self, other: F64x4) -> F64x4 {
        self.zip(other, f64::max)
    }
}

impl Add for F64x4 {
    type Output = F64x4;
    #[inline]
    fn add(self, o: F64x4) -> F64x4 {
        self.zip(o, |a, b| a + b)
    }
}

impl Sub for F64x4 {
    type Output = F64x4;
    #[inline]
    fn sub(self, o: F64x4) -> F64x4 {
        self.zip(o, |a, b| a - b)
    }
}

impl Mul for F64x4 {
    type Output = F64x4;
    #[inline]
    fn mul(self, o: F64x4) -> F64x4 {
        self.zip(o, |a, b| a * b)
    }
}

/// Four 3-vectors, one a lane, stored by coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DVec3x4 {
    pub x: F64x4,
    pub y: F64x4,
    pub z: F64x4,
}

impl DVec3x4 {
    pub fn splat(v: DVec3) -> DVec3x4 {
        DVec3x4 {
            x: F64x4::splat(v.x),
            y: F64x4::splat(v.y),
            z: F64x4::splat(v.z),
        }
    }

    /// The vector of lane `lane` (0 to 3).
    #[inline]
    pub fn lane(&self, lane: usize) -> DVec3 {
        DVec3::new(self.x.0[lane], self.y.0[lane], self.z.0[lane])
    }

    /// Sets lane `lane` (0 to 3) to `v`.
    #[inline]
    pub fn set(&mut self, lane: usize, v: DVec3) {
        (self.x.0[lane], self.y.0[lane], self.z.0[lane]) = (v.x, v.y, v.z);
    }

    /// `DVec3::dot` of each lane: `(x x') + (y y') + (z z')`.
    #[inline]
    pub fn dot(self, o: DVec3x4) -> F64x4 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Each lane's vector times that lane of `s` (`DVec3 * f64`).
    #[inline]
    pub fn scale(self, s: F64x4) -> DVec3x4 {
        DVec3x4 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// `DVec3::normalize` of each lane: the vector times `1 / sqrt(dot(v, v))` (a zero or
    /// non-finite lane gives NaN or zero coordinates, as the scalar one does).
    #[inline]
    pub fn normalize(self) -> DVec3x4 {
        self.scale(self.dot(self).sqrt().recip())
    }

    /// `DVec3::normalize_or_zero` of each lane: zero where `1 / |v|` is not finite and
    /// positive (a zero, infinite or NaN vector).
    #[inline]
    pub fn normalize_or_zero(self) -> DVec3x4 {
        let rcp = self.dot(self).sqrt().recip();
        let keep = rcp.map(|r| if r.is_finite() && r > 0.0 { r } else { 0.0 });
        let scaled = self.scale(keep);
        // A kept lane is `v * rcp`; the others zero (not `v * 0`, which keeps the sign of
        // negative coordinates and is NaN for infinite ones).
        let zero_where_dropped = |c: F64x4| c.zip(keep, |c, k| if k == 0.0 { 0.0 } else { c });
        DVec3x4 {
            x: zero_where_dropped(scaled.x),
            y: zero_where_dropped(scaled.y),
            z: zero_where_dropped(scaled.z),
        }
    }
}

impl Add for DVec3x4 {
    type Output = DVec3x4;
    #[inline]
    fn add(self, o: DVec3x4) -> DVec3x4 {
        DVec3x4 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for DVec3x4 {
    type Output = DVec3x4;
    #[inline]
    fn sub(self, o: DVec3x4) -> DVec3x4 {
        DVec3x4 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl Neg for DVec3x4 {
    type Output = DVec3x4;
    #[inline]
    fn neg(self) -> DVec3x4 {
        let minus = |c: F64x4| c.map(|v| -v);
        DVec3x4 {
            x: minus(self.x),
            y: minus(self.y),
            z: minus(self.z),
        }
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    /// Coordinates of every kind: ordinary, tiny and huge, zero of both signs, subnormal,
    /// infinite and NaN.
    fn coordinate() -> impl Strategy<Value = f64> {
        prop_oneof![
            6 => -1e3f64..1e3,
            1 => -1e-160f64..1e-160,
            1 => -1e160f64..1e160,
            1 => prop::sample::select(vec![
                0.0,
                -0.0,
                f64::MIN_POSITIVE / 4.0,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NAN,
            ]),
        ]
    }

    fn vector() -> impl Strategy<Value = DVec3> {
        (coordinate(), coordinate(), coordinate()).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    fn lanes(v: [DVec3; 4]) -> DVec3x4 {
        let mut out = DVec3x4::default();
        for (lane, v) in v.into_iter().enumerate() {
            out.set(lane, v);
        }
        out
    }

    /// Bit for bit (NaN payloads aside: any NaN equals any NaN).
    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    fn same3(a: DVec3, b: DVec3) -> bool {
        same(a.x, b.x) && same(a.y, b.y) && same(a.z, b.z)
    }

    proptest! {
        /// Each lane of every operation is glam's scalar result, bit for bit, on finite,
        /// zero, subnormal, huge, infinite and NaN coordinates.
        #[test]
        fn each_lane_is_the_scalar_operation(
            a in prop::array::uniform4(vector()),
            b in prop::array::uniform4(vector()),
            s in prop::array::uniform4(coordinate()),
        ) {
            let (la, lb, ls) = (lanes(a), lanes(b), F64x4(s));
            for k in 0..4 {
                prop_assert!(same3(la.lane(k), a[k]));
                prop_assert!(same((la.dot(lb)).0[k], a[k].dot(b[k])));
                prop_assert!(same3((la + lb).lane(k), a[k] + b[k]));
                prop_assert!(same3((la - lb).lane(k), a[k] - b[k]));
                prop_assert!(same3((-la).lane(k), -a[k]));
                prop_assert!(same3(la.scale(ls).lane(k), a[k] * s[k]));
                prop_assert!(same3(la.normalize().lane(k), a[k].normalize()));
                prop_assert!(same3(la.normalize_or_zero().lane(k), a[k].normalize_or_zero()));
                prop_assert!(same(ls.sqrt().0[k], s[k].sqrt()));
                prop_assert!(same(ls.recip().0[k], s[k].recip()));
                prop_assert!(same(ls.max(F64x4::splat(0.0)).0[k], s[k].max(0.0)));
                prop_assert!(same3(DVec3x4::splat(a[k]).lane(3 - k), a[k]));
            }
        }
    }

    /// Degenerate lanes of `normalize_or_zero`: a zero vector (either sign), an infinite and
    /// a NaN one give zero, as glam's does, next to an ordinary lane.
    #[test]
    fn normalize_or_zero_drops_degenerate_lanes() {
        let v = [
            DVec3::new(3.0, -4.0, 0.0),
            DVec3::new(-0.0, 0.0, -0.0),
            DVec3::new(f64::INFINITY, -1.0, 2.0),
            DVec3::new(f64::NAN, 1.0, 1.0),
        ];
        let n = lanes(v).normalize_or_zero();
        assert_eq!(n.lane(0), v[0].normalize());
        for (k, v) in v.iter().enumerate().skip(1) {
            assert_eq!(v.normalize_or_zero(), DVec3::ZERO);
            assert_eq!(n.lane(k).to_array().map(f64::to_bits), [0; 3], "lane {k}");
        }
    }
}
