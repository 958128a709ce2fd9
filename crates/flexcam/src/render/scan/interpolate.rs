//! The values interpolated across a shape: a depth and `N` attributes (for trilinear
//! rasterisation the depth is `t` and the attributes are the scene barycentrics).

/// Depth and attributes at one point of a shape, interpolated together.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Varying<const N: usize> {
    /// Depth for the z-test: smaller is nearer.
    pub depth: f64,
    /// Caller-defined attributes, interpolated linearly like the depth.
    pub attributes: [f64; N],
}

impl<const N: usize> Varying<N> {
    /// `self + s (other - self)`: exactly `self` at `s = 0`. Written as an offset from `self`
    /// so that, for `s` in `[0, 1]` and components bounded by [`crate::render::scan::LIMIT`],
    /// the result is finite and lies between the two values.
    pub fn lerp(&self, other: &Self, s: f64) -> Self {
        Varying {
            depth: mix(self.depth, other.depth, s),
            attributes: std::array::from_fn(|i| mix(self.attributes[i], other.attributes[i], s)),
        }
    }
}

/// `a + s (b - a)`.
fn mix(a: f64, b: f64, s: f64) -> f64 {
    a + s * (b - a)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raster_lerp_endpoints_and_midpoint() {
        let a = Varying {
            depth: 1.0,
            attributes: [0.0, 2.0],
        };
        let b = Varying {
            depth: 3.0,
            attributes: [1.0, -2.0],
        };
        assert_eq!(a.lerp(&b, 0.0), a);
        assert_eq!(a.lerp(&b, 1.0), b);
        let m = a.lerp(&b, 0.5);
        assert_eq!(m.depth, 2.0);
        assert_eq!(m.attributes, [0.5, 0.0]);
    }
}
