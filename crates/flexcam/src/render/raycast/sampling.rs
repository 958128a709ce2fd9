//! Where in a pixel the samples go: a deterministic low-discrepancy pattern, the same for
//! every pixel, so images do not depend on thread scheduling.

use glam::DVec2;

/// Sample offsets within a pixel (in `[0,1)^2`) and which of them is nearest the centre.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SamplePattern {
    pub offsets: Vec<DVec2>,
    /// Index of the sample nearest the pixel centre (the lowest index on ties): the one whose
    /// depth and object id the pixel reports.
    pub centre: usize,
}

impl SamplePattern {
    /// `spp` samples (at least one): the Hammersley set `((i + 1/2)/n, radical_inverse(i))`,
    /// shifted by half a cell in y, so that one sample lies exactly at the pixel centre
    /// `(0.5, 0.5)` and each row and column of an `n x n` grid holds one sample.
    pub fn new(spp: u32) -> SamplePattern {
        let n = spp.max(1);
        let offsets: Vec<DVec2> = (0..n)
            .map(|i| {
                let y = radical_inverse(i) + 0.5 / n as f64;
                DVec2::new((i as f64 + 0.5) / n as f64, y - y.floor())
            })
            .collect();
        let centre = (0..offsets.len())
            .min_by(|&a, &b| {
                let da = offsets[a].distance_squared(DVec2::splat(0.5));
                let db = offsets[b].distance_squared(DVec2::splat(0.5));
                da.total_cmp(&db)
            })
            .unwrap_or(0);
        SamplePattern { offsets, centre }
    }
}

/// The van der Corput radical inverse in base 2: the bits of `i` mirrored after the point.
fn radical_inverse(i: u32) -> f64 {
    i.reverse_bits() as f64 / (1u64 << 32) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sample_is_the_pixel_centre() {
        let p = SamplePattern::new(1);
        assert_eq!(p.offsets, vec![DVec2::splat(0.5)]);
        assert_eq!(p.centre, 0);
        assert_eq!(SamplePattern::new(0), p);
    }

    #[test]
    fn samples_are_stratified_in_both_axes() {
        for n in [2u32, 4, 8, 16] {
            let p = SamplePattern::new(n);
            let mut xs: Vec<usize> = p
                .offsets
                .iter()
                .map(|o| (o.x * n as f64) as usize)
                .collect();
            let mut ys: Vec<usize> = p
                .offsets
                .iter()
                .map(|o| (o.y * n as f64) as usize)
                .collect();
            xs.sort();
            ys.sort();
            let all: Vec<usize> = (0..n as usize).collect();
            assert_eq!(xs, all);
            assert_eq!(ys, all);
            let c = p.offsets[p.centre];
            assert!(p
                .offsets
                .iter()
                .all(|o| o.distance(DVec2::splat(0.5)) >= c.distance(DVec2::splat(0.5))));
        }
    }
}
