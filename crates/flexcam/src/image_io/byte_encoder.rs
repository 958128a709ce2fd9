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

#[cfg(test)]
mod tests {
    use super::*;

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
