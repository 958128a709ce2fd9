//! What the camera-triangle bench reads from a render: counters by name, and the agreement
//! of a reflector's pixels with the exact (ray-cast) reflection.
//!
//! With flat shading every reflected face and checker square has one exact colour, so the
//! colour of a reflector pixel names the surface the mirror shows there: the fraction of
//! reflector pixels away from colour edges whose colour is exactly the reference's is the
//! object-id agreement of the reflected content (the frame's own ids are the reflector's in
//! both renders). Degenerate cases: a reflector that covers no pixel (or none away from a
//! colour edge) gives agreement 1 over 0 pixels and a relative RGB error of 0.

use flexcam::render::{self, Counter, Frame};

/// The count `name` of `stats`, 0 when absent.
pub fn count(stats: &render::Stats, name: &str) -> u64 {
    match stats.get(name) {
        Some(Counter::Count(n)) => *n,
        _ => 0,
    }
}

/// The value `name` of `stats` (a count as a number), NaN when absent.
pub fn value(stats: &render::Stats, name: &str) -> f64 {
    match stats.get(name) {
        Some(Counter::Value(v)) => *v,
        Some(Counter::Count(n)) => *n as f64,
        None => f64::NAN,
    }
}

/// The fraction of the reference's pixels of object `id` whose colour (over the pixel's
/// 3 x 3 neighbourhood in the reference) is uniform that `frame` gives exactly, and their
/// number (1 over none); pixels marked in `excluded` (one flag per pixel) are not counted.
pub fn colour_agreement_inside(
    frame: &Frame,
    reference: &Frame,
    id: u32,
    excluded: Option<&[bool]>,
) -> (f64, u64) {
    let (w, h) = (reference.width as usize, reference.height as usize);
    let (mut pixels, mut same) = (0u64, 0u64);
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let k = y * w + x;
            if excluded.is_some_and(|e| e[k]) {
                continue;
            }
            let colour = reference.color[k];
            let uniform = (y - 1..=y + 1).all(|yy| {
                (x - 1..=x + 1).all(|xx| {
                    let n = yy * w + xx;
                    reference.ids[n] == id
                        && (reference.color[n] - colour).abs().max_element() < 1e-6
                })
            });
            if uniform {
                pixels += 1;
                same += u64::from((frame.color[k] - colour).abs().max_element() < 1e-6);
            }
        }
    }
    if pixels == 0 {
        return (1.0, 0);
    }
    (same as f64 / pixels as f64, pixels)
}

/// The relative RGB error (Vallance 2005: the mean absolute difference over the mean
/// reference value) of `frame` against `reference` over the pixels where the reference sees
/// object `id`; 0 where it sees none or both are black there.
pub fn relative_rgb_inside(frame: &Frame, reference: &Frame, id: u32) -> f64 {
    let (mut difference, mut total) = (0.0f64, 0.0f64);
    for (k, _) in reference.ids.iter().enumerate().filter(|(_, i)| **i == id) {
        difference += f64::from((frame.color[k] - reference.color[k]).abs().element_sum());
        total += f64::from(reference.color[k].abs().element_sum());
    }
    if difference == 0.0 {
        0.0
    } else {
        difference / total
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    /// A 4 x 4 reference: object 1 on the left three columns, red except one blue pixel at
    /// (1, 2); object 2 in the last column.
    fn reference() -> Frame {
        let (w, h) = (4usize, 4usize);
        let mut frame = Frame {
            width: w as u32,
            height: h as u32,
            color: vec![Vec3::new(1.0, 0.0, 0.0); w * h],
            depth: vec![1.0; w * h],
            ids: vec![1; w * h],
            surface: Vec::new(),
        };
        for y in 0..h {
            frame.ids[y * w + 3] = 2;
        }
        frame.color[2 * w + 1] = Vec3::new(0.0, 0.0, 1.0);
        frame
    }

    /// Only pixels whose whole 3 x 3 neighbourhood is the object in one colour count: with
    /// the blue pixel each interior pixel of object 1 touches it or object 2, so none does.
    #[test]
    fn agreement_counts_pixels_away_from_colour_edges() {
        let reference = reference();
        assert_eq!(
            colour_agreement_inside(&reference, &reference, 1, None),
            (1.0, 0)
        );
        // Without the blue pixel, (1, 1) and (1, 2) are inside; a wrong colour at (1, 1)
        // halves the agreement.
        let mut plain = reference.clone();
        plain.color[2 * 4 + 1] = Vec3::new(1.0, 0.0, 0.0);
        let mut frame = plain.clone();
        frame.color[4 + 1] = Vec3::ZERO;
        assert_eq!(colour_agreement_inside(&frame, &plain, 1, None), (0.5, 2));
        // Excluding the wrong pixel leaves the other one, in agreement.
        let mut excluded = vec![false; 16];
        excluded[4 + 1] = true;
        assert_eq!(
            colour_agreement_inside(&frame, &plain, 1, Some(&excluded)),
            (1.0, 1)
        );
    }

    /// The relative RGB error counts the object's pixels alone.
    #[test]
    fn relative_rgb_counts_the_object_alone() {
        let reference = reference();
        let mut frame = reference.clone();
        frame.color[3] = Vec3::ZERO; // object 2: not counted for object 1
        assert_eq!(relative_rgb_inside(&frame, &reference, 1), 0.0);
        frame.color[0] = Vec3::ZERO; // one of object 1's 12 pixels, each summing 1
        assert!((relative_rgb_inside(&frame, &reference, 1) - 1.0 / 12.0).abs() < 1e-12);
        assert_eq!(relative_rgb_inside(&frame, &reference, 7), 0.0);
    }
}
