//! Image agreement between two renders of the same scene, projection and resolution: how the
//! fast renderers are held to the ray-cast reference, in tests and in `flexcam compare`.
//!
//! Four measures:
//! - **id agreement**: the fraction of pixels whose object id (0 = background) is the same in
//!   both frames; it counts silhouette and visibility errors.
//! - **depth error**: over the pixels where both frames hit the same object, the largest and
//!   the mean of `|d - d_ref| / d_ref`; it counts geometric error inside shapes.
//! - **relative RGB error** (the measure of Vallance 2005, ch. 8): the mean over pixels and channels
//!   of `|c - c_ref|`, divided by the mean over pixels and channels of `c_ref`.
//! - **interior id agreement** ([`interior_id_agreement`]): the id agreement over the pixels
//!   away from id edges (the reference's 3 x 3 neighbourhood holds one id). Which side of a
//!   silhouette an edge pixel's centre falls on is a sub-pixel matter on which two exact
//!   renderers may differ; inside shapes they must not.
//!
//! Degenerate cases: two empty frames agree perfectly (agreement 1, errors 0); a reference
//! that is black everywhere gives a relative RGB error of 0 when the test frame is black too
//! and infinity otherwise; a pixel where the reference depth is zero compares absolute depth.

use crate::error::{Error, Result};
use crate::render::Frame;

/// How closely a frame matches a reference frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Comparison {
    /// Pixels compared (width x height).
    pub pixels: u64,
    /// Fraction of pixels with the same object id, in [0, 1].
    pub id_agreement: f64,
    /// Pixels where both frames hit the same object (the depth measures' sample).
    pub depth_pixels: u64,
    /// Largest relative depth error over `depth_pixels` (0 when there are none).
    pub depth_max: f64,
    /// Mean relative depth error over `depth_pixels` (0 when there are none).
    pub depth_mean: f64,
    /// Mean absolute RGB difference over the mean reference RGB value.
    pub relative_rgb_error: f64,
}

/// Compares `frame` with `reference`. Fails when the sizes differ, and when either frame
/// lacks its depth or id buffer (rendered with fewer [`crate::render::Outputs`] than
/// `Outputs::ALL`): the measures need both.
///
/// ```
/// use flexcam::render::{self, compare, Method, PreparedScene, RenderOptions, Shading};
///
/// let scene = flexcam::scene::load("builtin:cube-floor")?;
/// let projection = scene.projection.build(64, 48)?;
/// let prepared = PreparedScene::new(&scene);
/// let frame = |method| {
///     let options = RenderOptions { method, shading: Shading::Flat, ..RenderOptions::default() };
///     render::render(&prepared, projection.as_ref(), &options).map(|r| r.frame)
/// };
/// let reference = frame(Method::Raycast)?;
/// let agreement = compare(&frame(Method::Raster)?, &reference)?;
/// assert_eq!(agreement.pixels, 64 * 48);
/// assert!(agreement.id_agreement > 0.99, "{agreement:?}");
/// // A frame agrees with itself exactly.
/// assert_eq!(compare(&reference, &reference)?.relative_rgb_error, 0.0);
/// # Ok::<(), flexcam::Error>(())
/// ```
pub fn compare(frame: &Frame, reference: &Frame) -> Result<Comparison> {
    if (frame.width, frame.height) != (reference.width, reference.height) {
        return Err(Error::new(format!(
            "cannot compare a {}x{} image with a {}x{} reference",
            frame.width, frame.height, reference.width, reference.height
        )));
    }
    let expected = frame.width as usize * frame.height as usize;
    for (which, f) in [("frame", frame), ("reference", reference)] {
        if [f.color.len(), f.depth.len(), f.ids.len()] != [expected; 3] {
            return Err(Error::new(format!(
                "cannot compare: the {which} lacks its depth or id buffer (render it with \
                 Outputs::ALL)"
            )));
        }
    }
    let pixels = frame.ids.len() as u64;
    let mut same_id = 0u64;
    let mut depth_pixels = 0u64;
    let (mut depth_max, mut depth_sum) = (0.0f64, 0.0f64);
    let (mut diff_sum, mut ref_sum) = (0.0f64, 0.0f64);
    for i in 0..frame.ids.len() {
        let id = frame.ids[i];
        if id == reference.ids[i] {
            same_id += 1;
            if id != 0 {
                let error = relative_depth_error(frame.depth[i], reference.depth[i]);
                depth_pixels += 1;
                depth_max = depth_max.max(error);
                depth_sum += error;
            }
        }
        let (c, r) = (frame.color[i], reference.color[i]);
        diff_sum += f64::from((c - r).abs().element_sum());
        ref_sum += f64::from(r.abs().element_sum());
    }
    let relative_rgb_error = if diff_sum == 0.0 {
        0.0
    } else if ref_sum == 0.0 {
        f64::INFINITY
    } else {
        diff_sum / ref_sum
    };
    Ok(Comparison {
        pixels,
        id_agreement: if pixels == 0 {
            1.0
        } else {
            same_id as f64 / pixels as f64
        },
        depth_pixels,
        depth_max,
        depth_mean: if depth_pixels == 0 {
            0.0
        } else {
            depth_sum / depth_pixels as f64
        },
        relative_rgb_error,
    })
}

/// The fraction of the pixels away from id edges whose ids agree, and how many such pixels
/// there are: a pixel counts when the `reference` ids over its 3 x 3 neighbourhood are all
/// the same (so the image's border rows and columns never count). `ids` and `reference` are
/// row-major `width` x `height` id images: a [`Frame`]'s `ids`, or the 16-bit ids of an
/// `--ids` PNG.
///
/// Degenerate cases: an image narrower or lower than 3 pixels, or one with an id edge
/// through every neighbourhood, has no interior pixel: agreement 1 over 0 pixels (the caller
/// decides whether 0 pixels is a failure). Fails when either buffer is not `width x height`.
///
/// ```
/// use flexcam::render::interior_id_agreement;
///
/// // 4 x 3: of the middle row's inner pixels only x = 1 is interior (x = 2 touches id 2);
/// // the frame differs only in column x = 3, at the edge, which does not count.
/// let reference = [1u32, 1, 1, 2, 1, 1, 1, 2, 1, 1, 1, 2];
/// let frame = [1u32, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 2];
/// assert_eq!(interior_id_agreement(4, 3, &frame, &reference)?, (1.0, 1));
/// # Ok::<(), flexcam::Error>(())
/// ```
pub fn interior_id_agreement<T: Copy + PartialEq>(
    width: u32,
    height: u32,
    ids: &[T],
    reference: &[T],
) -> Result<(f64, u64)> {
    let (w, h) = (width as usize, height as usize);
    let expected = w.checked_mul(h);
    if [ids.len(), reference.len()].map(Some) != [expected; 2] {
        return Err(Error::new(format!(
            "cannot compare ids: {} and {} ids for a {width}x{height} image",
            ids.len(),
            reference.len()
        )));
    }
    let (mut interior, mut same) = (0u64, 0u64);
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let id = reference[y * w + x];
            let uniform =
                (y - 1..=y + 1).all(|v| (x - 1..=x + 1).all(|u| reference[v * w + u] == id));
            if uniform {
                interior += 1;
                same += u64::from(ids[y * w + x] == id);
            }
        }
    }
    let agreement = if interior == 0 {
        1.0
    } else {
        same as f64 / interior as f64
    };
    Ok((agreement, interior))
}

/// `|d - d_ref| / d_ref`, absolute where the reference depth is zero; infinite where exactly
/// one of the two is infinite.
fn relative_depth_error(depth: f32, reference: f32) -> f64 {
    let (d, r) = (f64::from(depth), f64::from(reference));
    if d == r {
        return 0.0;
    }
    let error = (d - r).abs();
    if r == 0.0 {
        error
    } else {
        error / r.abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn frame(ids: &[u32], depth: &[f32], color: &[f32]) -> Frame {
        Frame {
            width: ids.len() as u32,
            height: 1,
            color: color.iter().map(|&c| Vec3::splat(c)).collect(),
            depth: depth.to_vec(),
            ids: ids.to_vec(),
            surface: Vec::new(),
        }
    }

    #[test]
    fn identical_frames_agree_exactly() {
        let f = frame(&[0, 1, 2], &[f32::INFINITY, 2.0, 3.0], &[0.0, 0.5, 1.0]);
        let c = compare(&f, &f).unwrap();
        assert_eq!(c.pixels, 3);
        assert_eq!(c.id_agreement, 1.0);
        assert_eq!(c.depth_pixels, 2);
        assert_eq!(
            (c.depth_max, c.depth_mean, c.relative_rgb_error),
            (0.0, 0.0, 0.0)
        );
    }

    #[test]
    fn measures_follow_their_definitions() {
        let reference = frame(
            &[1, 1, 2, 0],
            &[2.0, 4.0, 1.0, f32::INFINITY],
            &[1.0, 1.0, 1.0, 1.0],
        );
        let test = frame(
            &[1, 1, 3, 0],
            &[2.2, 4.0, 1.0, f32::INFINITY],
            &[1.0, 0.5, 0.0, 1.0],
        );
        let c = compare(&test, &reference).unwrap();
        assert_eq!(c.id_agreement, 0.75);
        // Pixel 2 has different ids: excluded from depth; pixel 3 is background.
        assert_eq!(c.depth_pixels, 2);
        assert!((c.depth_max - 0.1).abs() < 1e-6);
        assert!((c.depth_mean - 0.05).abs() < 1e-6);
        // |diff| per channel summed: 0 + 1.5 + 3 + 0 over 12 reference units.
        assert!((c.relative_rgb_error - 4.5 / 12.0).abs() < 1e-12);
    }

    /// Only pixels whose reference neighbourhood holds one id count; the border never does.
    #[test]
    fn interior_agreement_counts_pixels_away_from_id_edges() {
        // 5 x 4, id 1 left of x = 3, id 2 from x = 3: interior pixels are (1, 1), (1, 2)
        // (id 1) and none of id 2 (its column 3 touches id 1, column 4 is the border).
        let reference: Vec<u32> = (0..20).map(|i| if i % 5 < 3 { 1 } else { 2 }).collect();
        assert_eq!(
            interior_id_agreement(5, 4, &reference, &reference).unwrap(),
            (1.0, 2)
        );
        let mut frame = reference.clone();
        frame[6] = 7; // (1, 1): interior, now wrong
        frame[8] = 7; // (3, 1): at the edge, ignored
        frame[0] = 7; // the border, ignored
        assert_eq!(
            interior_id_agreement(5, 4, &frame, &reference).unwrap(),
            (0.5, 2)
        );
        // 16-bit ids (an --ids PNG) work alike.
        let small: Vec<u16> = reference.iter().map(|&i| i as u16).collect();
        assert_eq!(
            interior_id_agreement(5, 4, &small, &small).unwrap(),
            (1.0, 2)
        );
    }

    /// Too small an image has no interior: agreement 1 over 0 pixels; wrong lengths fail.
    #[test]
    fn interior_agreement_degenerate_cases() {
        for (w, h) in [(0, 0), (2, 5), (5, 2)] {
            let ids = vec![1u32; w * h];
            assert_eq!(
                interior_id_agreement(w as u32, h as u32, &ids, &ids).unwrap(),
                (1.0, 0)
            );
        }
        let e = interior_id_agreement(3, 3, &[0u32; 9], &[0u32; 8]).unwrap_err();
        assert!(e.to_string().contains("9 and 8 ids for a 3x3"), "{e}");
        assert!(interior_id_agreement(u32::MAX, u32::MAX, &[0u8], &[0u8]).is_err());
    }

    #[test]
    fn degenerate_frames() {
        let empty = frame(&[], &[], &[]);
        let c = compare(&empty, &empty).unwrap();
        assert_eq!((c.id_agreement, c.relative_rgb_error), (1.0, 0.0));
        let black = frame(&[0], &[f32::INFINITY], &[0.0]);
        let grey = frame(&[0], &[f32::INFINITY], &[0.5]);
        assert_eq!(compare(&black, &black).unwrap().relative_rgb_error, 0.0);
        assert_eq!(
            compare(&grey, &black).unwrap().relative_rgb_error,
            f64::INFINITY
        );
        let zero_ref = frame(&[1], &[0.0], &[0.0]);
        let near = frame(&[1], &[0.25], &[0.0]);
        assert_eq!(compare(&near, &zero_ref).unwrap().depth_max, 0.25);
        let wide = frame(&[0, 0], &[1.0, 1.0], &[0.0, 0.0]);
        let e = compare(&wide, &black).unwrap_err();
        assert!(e.to_string().contains("2x1 image with a 1x1"), "{e}");
        let colour_only = Frame {
            ids: Vec::new(),
            ..grey.clone()
        };
        for (f, r, which) in [
            (&colour_only, &grey, "frame"),
            (&grey, &colour_only, "reference"),
        ] {
            let e = compare(f, r).unwrap_err().to_string();
            assert!(e.contains(&format!("the {which} lacks")), "{e}");
        }
    }
}
