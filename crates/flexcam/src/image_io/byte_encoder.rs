//! The 8-bit bytes of a colour channel, exactly [`encode_channel`]'s, without its `powf`
//! and `roundf` per channel: 2.8 million channels a 1280 x 720 frame, which cost the viewer
//! as much as a flat raster frame and a PNG of `flexcam render` 7 % of its time.
//!
//! [`encode_channel`] is non-decreasing in its input over every `f32`, so each byte value
//! `k` is taken by the inputs from a threshold on (the smallest `f32` giving `k` or more,
//! found by bisection over the bit patterns of `[0, 1]` with [`encode_channel`] itself).
//! A channel's byte is the number of thresholds at or below it, found from a table indexed
//! by the input's top bits (the byte of the bucket's first input) and a step over the
//! thresholds inside the bucket (at most one in practice). NaN gives 0, as it does there.
//! The test `bytes_are_encode_channels` compares the two on every input near a threshold
//! and a sweep of the rest; `every_input_in_the_unit_interval` (ignored: seconds) on all.

use std::sync::OnceLock;

use glam::Vec3;

use super::{encode_channel, ColorEncoding};

/// Bits dropped from an input's pattern to index [`ByteEncoder::base`].
const SHIFT: u32 = 15;
/// The bit pattern of 1.0, the largest input below the top byte's saturation.
const ONE: u32 = 0x3F80_0000;

/// [`encode_channel`] under one encoding, by thresholds (see the module documentation).
pub struct ByteEncoder {
    /// `thresholds[k]`: the smallest non-negative `f32` whose byte exceeds `k`.
    thresholds: [f32; 255],
    /// The byte of the smallest input of each bucket of `2^SHIFT` bit patterns in `[0, 1]`.
    base: Vec<u8>,
}

impl ByteEncoder {
    /// The encoder of `encoding`, built once per encoding.
    pub fn of(encoding: ColorEncoding) -> &'static ByteEncoder {
        static SRGB: OnceLock<ByteEncoder> = OnceLock::new();
        static LINEAR: OnceLock<ByteEncoder> = OnceLock::new();
        match encoding {
            ColorEncoding::Srgb => SRGB.get_or_init(|| ByteEncoder::new(encoding)),
            ColorEncoding::Linear => LINEAR.get_or_init(|| ByteEncoder::new(encoding)),
        }
    }

    fn new(encoding: ColorEncoding) -> ByteEncoder {
        let byte = |bits: u32| encode_channel(f32::from_bits(bits), encoding);
        let thresholds = std::array::from_fn(|k| {
            // The first bit pattern in [0, 1] whose byte exceeds k (1.0 gives 255).
            let (mut lo, mut hi) = (0u32, ONE);
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if usize::from(byte(mid)) > k {
                    hi = mid;
                } else {
                    lo = mid + 1;
                }
            }
            f32::from_bits(lo)
        });
        let base = (0..=ONE >> SHIFT).map(|b| byte(b << SHIFT)).collect();
        ByteEncoder { thresholds, base }
    }

    /// [`encode_channel`] of `c` under this encoder's encoding.
    #[inline]
    pub fn byte(&self, c: f32) -> u8 {
        if c.is_nan() || c <= 0.0 {
            // NaN, and zero and negative values (clamped to 0).
            return 0;
        }
        let Some(&base) = self.base.get((c.to_bits() >> SHIFT) as usize) else {
            return 255;
        };
        let mut k = base;
        while k < 255 && c >= self.thresholds[usize::from(k)] {
            k += 1;
        }
        k
    }
}

/// [`ByteEncoder::byte`] of the three channels of colours taken one after another, each
/// colour equal to the one before it (the background across a panorama's sky, pixel after
/// pixel) given the bytes found for that one instead of encoding it again: equal channels
/// encode alike (`0.0 == -0.0`, both 0; NaN equals nothing and is encoded each time).
pub struct RgbEncoder<'a> {
    encoder: &'a ByteEncoder,
    /// The last colour encoded (NaN before any) and its bytes.
    last: Vec3,
    bytes: [u8; 3],
}

impl<'a> RgbEncoder<'a> {
    /// Bytes by `encoder`, nothing encoded yet.
    pub fn new(encoder: &'a ByteEncoder) -> Self {
        RgbEncoder {
            encoder,
            last: Vec3::NAN,
            bytes: [0; 3],
        }
    }

    /// The bytes of `c`'s channels, each [`ByteEncoder::byte`]'s.
    #[inline]
    pub fn rgb(&mut self, c: Vec3) -> [u8; 3] {
        if c != self.last {
            let e = self.encoder;
            (self.last, self.bytes) = (c, [e.byte(c.x), e.byte(c.y), e.byte(c.z)]);
        }
        self.bytes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs of equal colours, signed zeros, NaN and colours differing in one channel by
    /// one ulp: each colour's bytes are its channels' own, whatever came before it.
    #[test]
    fn repeated_colours_keep_their_bytes() {
        let up = |v: f32| f32::from_bits(v.to_bits() + 1);
        let t = ByteEncoder::of(ColorEncoding::Srgb).thresholds[100];
        let colours = [
            Vec3::new(0.55, 0.7, 0.9),
            Vec3::new(0.55, 0.7, 0.9),
            Vec3::new(0.55, 0.7, up(0.9)),
            Vec3::new(0.0, -0.0, 0.0),
            Vec3::new(-0.0, 0.0, -0.0),
            Vec3::new(f32::NAN, 0.5, 0.5),
            Vec3::new(f32::NAN, 0.5, 0.5),
            Vec3::new(0.2, 0.5, 0.5),
            Vec3::new(f32::from_bits(t.to_bits() - 1), t, t),
            Vec3::new(t, t, t),
            Vec3::new(t, t, t),
            Vec3::new(2.0, f32::INFINITY, -1.0),
        ];
        for encoding in ENCODINGS {
            let encoder = ByteEncoder::of(encoding);
            let mut rgb = RgbEncoder::new(encoder);
            for c in colours {
                let own = [encoder.byte(c.x), encoder.byte(c.y), encoder.byte(c.z)];
                assert_eq!(rgb.rgb(c), own, "{c} {encoding:?}");
                assert_eq!(own, c.to_array().map(|v| encode_channel(v, encoding)));
            }
        }
    }

    const ENCODINGS: [ColorEncoding; 2] = [ColorEncoding::Srgb, ColorEncoding::Linear];

    fn check(encoder: &ByteEncoder, encoding: ColorEncoding, c: f32) {
        assert_eq!(
            encoder.byte(c),
            encode_channel(c, encoding),
            "{c} {encoding:?}"
        );
    }

    /// Every input within 2^14 patterns of each threshold, a sweep of every 97th pattern
    /// over all `f32`, and the special values.
    #[test]
    fn bytes_are_encode_channels() {
        for encoding in ENCODINGS {
            let encoder = ByteEncoder::of(encoding);
            for threshold in encoder.thresholds {
                let t = threshold.to_bits();
                for bits in t.saturating_sub(1 << 14)..=t.saturating_add(1 << 14) {
                    check(encoder, encoding, f32::from_bits(bits));
                }
            }
            for bits in (0..=u32::MAX).step_by(97) {
                check(encoder, encoding, f32::from_bits(bits));
            }
            for c in [
                0.0,
                -0.0,
                1.0,
                f32::MIN_POSITIVE,
                f32::from_bits(1),
                f32::from_bits(ONE - 1),
                f32::from_bits(ONE + 1),
                f32::MAX,
                f32::MIN,
                f32::INFINITY,
                f32::NEG_INFINITY,
                f32::NAN,
                -f32::NAN,
            ] {
                check(encoder, encoding, c);
            }
        }
    }

    /// Exhaustive over `[0, 1]` (about 10^9 inputs per encoding; 20 s in release):
    /// `cargo test --release -p flexcam --lib every_input -- --ignored`.
    #[test]
    #[ignore]
    fn every_input_in_the_unit_interval() {
        for encoding in ENCODINGS {
            let encoder = ByteEncoder::of(encoding);
            for bits in 0..=ONE {
                let c = f32::from_bits(bits);
                assert_eq!(encoder.byte(c), encode_channel(c, encoding), "{c}");
            }
        }
    }
}
