//! Marks drawn into a frame's linear colours: lines, rings, squares and entry numbers, for
//! the overlay of `flexcam fit --overlay`. Everything is clipped to the frame; positions
//! are continuous pixel positions (x right, y down, a pixel's centre at +0.5).

use flexcam::render::Frame;
use glam::{DVec2, Vec3};

/// The colour under the shadow of labels and rings, so that they read on any picture.
pub const SHADOW: Vec3 = Vec3::new(0.0, 0.0, 0.0);

/// Sets pixel (x, y) to `color` where it lies in the frame.
fn set(frame: &mut Frame, x: i64, y: i64, color: Vec3) {
    let inside =
        (0..i64::from(frame.width)).contains(&x) && (0..i64::from(frame.height)).contains(&y);
    if inside {
        // In range of the frame's u32 sides: the casts are exact.
        frame.color[y as usize * frame.width as usize + x as usize] = color;
    }
}

/// The pixel holding continuous position `p`.
fn pixel_of(p: DVec2) -> (i64, i64) {
    // Positions are clamped far outside any frame before the cast.
    let bound = |c: f64| c.floor().clamp(-1e9, 1e9) as i64;
    (bound(p.x), bound(p.y))
}

/// A line from `a` to `b`, one pixel wide.
pub fn line(frame: &mut Frame, a: DVec2, b: DVec2, color: Vec3) {
    // Two samples a pixel along the longer axis, at most one per pixel of a large frame.
    let steps = ((b - a).abs().max_element() * 2.0).ceil().clamp(1.0, 1e5) as usize;
    for k in 0..=steps {
        let (x, y) = pixel_of(a.lerp(b, k as f64 / steps as f64));
        set(frame, x, y, color);
    }
}

/// A ring of radius `radius` pixels around `centre`, one pixel wide, inside a black one.
pub fn ring(frame: &mut Frame, centre: DVec2, radius: f64, color: Vec3) {
    let (cx, cy) = pixel_of(centre);
    let reach = radius.ceil() as i64 + 2;
    for y in cy - reach..=cy + reach {
        for x in cx - reach..=cx + reach {
            let d = (DVec2::new(x as f64 + 0.5, y as f64 + 0.5) - centre).length();
            if (d - radius).abs() < 0.6 {
                set(frame, x, y, color);
            } else if (d - radius + 1.0).abs() < 0.5 {
                set(frame, x, y, SHADOW);
            }
        }
    }
}

/// A filled square of side 2 `half` + 1 pixels centred on the pixel of `centre`.
pub fn square(frame: &mut Frame, centre: DVec2, half: i64, color: Vec3) {
    let (cx, cy) = pixel_of(centre);
    for y in cy - half..=cy + half {
        for x in cx - half..=cx + half {
            set(frame, x, y, color);
        }
    }
}

/// A cross (two diagonals) of half-size `half` pixels at `centre`.
pub fn cross(frame: &mut Frame, centre: DVec2, half: f64, color: Vec3) {
    let (d1, d2) = (DVec2::new(half, half), DVec2::new(half, -half));
    line(frame, centre - d1, centre + d1, color);
    line(frame, centre - d2, centre + d2, color);
}

/// The digits 0 to 9, 3 x 5 pixels each, rows top first, 3 bits a row (left bit first).
const DIGITS: [[u8; 5]; 10] = [
    [7, 5, 5, 5, 7],
    [2, 6, 2, 2, 7],
    [7, 1, 7, 4, 7],
    [7, 1, 7, 1, 7],
    [5, 5, 7, 1, 1],
    [7, 4, 7, 1, 7],
    [7, 4, 7, 5, 7],
    [7, 1, 1, 1, 1],
    [7, 5, 7, 5, 7],
    [7, 5, 7, 1, 7],
];

/// The decimal `number` in 3 x 5 digits with a black shadow one pixel down and right,
/// its top-left corner at pixel `at`.
pub fn number(frame: &mut Frame, at: DVec2, number: usize, color: Vec3) {
    let (x0, y0) = pixel_of(at);
    let text = number.to_string();
    for (offset, shade) in [(1, SHADOW), (0, color)] {
        for (k, digit) in text.bytes().enumerate() {
            let rows = DIGITS[usize::from(digit - b'0')];
            for (row, bits) in rows.iter().enumerate() {
                for column in 0..3 {
                    if bits & (4 >> column) != 0 {
                        let x = x0 + 4 * k as i64 + column + offset;
                        set(frame, x, y0 + row as i64 + offset, shade);
                    }
                }
            }
        }
    }
}
