//! Bad input never panics: every example scene in `scenes/`, spoiled in many small ways (a
//! number replaced by an extreme or meaningless one, a string emptied, an array emptied or
//! shortened, a line deleted, the text cut short), is loaded, its projection built and, where
//! that succeeds, rendered at 8 x 6 by every method that renders it. Each step may refuse
//! the input with an error (that is what it should do); none may panic. The mutations are
//! drawn from a fixed seed, so a failure names a mutation that reproduces.
//!
//! What this does not check: that the error is one line naming the file (the CLI tests do
//! that for the cases they list), and workloads that are merely large: the replacement
//! numbers are small (at most 2) or huge or non-finite, which the loader's limits (with
//! their own tests) refuse for sizes such as `tessellation`, so no mutation asks for a long
//! render.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use flexcam::render::{composite, Method, RenderOptions, Shading};
use flexcam::scene::file;

/// Mutations per example scene.
const MUTATIONS: usize = 24;

/// Replacement numbers: zero, negatives, non-finite, huge, subnormal, tiny and small ones.
const NUMBERS: [&str; 10] = [
    "0", "-1", "0.0", "-0.0", "nan", "inf", "-inf", "1e308", "1e-320", "2",
];

/// A small deterministic generator (xorshift64*), so failures reproduce.
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 33) as usize % n.max(1)
    }
}

/// Byte ranges of the number literals of `text` outside strings and comments.
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let (mut spans, mut i, mut in_string) = (Vec::new(), 0, false);
    while i < bytes.len() {
        let c = bytes[i];
        if in_string {
            in_string = c != b'"';
            i += 1;
        } else if c == b'"' {
            in_string = true;
            i += 1;
        } else if c == b'#' {
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
        } else if c.is_ascii_digit()
            || (c == b'-' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            let start = i;
            i += 1;
            while i < bytes.len()
                && (bytes[i].is_ascii_alphanumeric() || b".+-_".contains(&bytes[i]))
            {
                i += 1;
            }
            spans.push((start, i));
        } else {
            i += 1;
        }
    }
    spans
}

/// Byte ranges of the string literals of `text` (quotes included) outside comments.
fn string_spans(text: &str) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    for (line_start, line) in line_starts(text) {
        let code = line.split('#').next().unwrap_or("");
        let quotes: Vec<usize> = code.match_indices('"').map(|(i, _)| i).collect();
        for pair in quotes.chunks_exact(2) {
            spans.push((line_start + pair[0], line_start + pair[1] + 1));
        }
    }
    spans
}

/// Byte ranges of the innermost `[...]` arrays of `text` on one line.
fn array_spans(text: &str) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    for (line_start, line) in line_starts(text) {
        let code = line.split('#').next().unwrap_or("");
        let mut open = None;
        for (i, c) in code.char_indices() {
            match c {
                '[' => open = Some(i),
                ']' => {
                    if let Some(o) = open.take() {
                        // Skip table headers such as [image] and [[object]].
                        if code[..o].contains('=') || code[..o].trim_end().ends_with(',') {
                            spans.push((line_start + o, line_start + i + 1));
                        }
                    }
                }
                _ => {}
            }
        }
    }
    spans
}

fn line_starts(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.split_inclusive('\n').scan(0, |at, line| {
        let start = *at;
        *at += line.len();
        Some((start, line))
    })
}

/// One mutation of `text`: what was done (for the failure message) and the new text.
fn mutate(text: &str, rng: &mut Rng) -> (String, String) {
    let replace = |(a, b): (usize, usize), with: &str| {
        (
            format!("{:?} at byte {a} -> {with:?}", &text[a..b]),
            format!("{}{with}{}", &text[..a], &text[b..]),
        )
    };
    match rng.below(6) {
        0..=2 => {
            let spans = number_spans(text);
            if let Some(&span) = spans.get(rng.below(spans.len())) {
                return replace(span, NUMBERS[rng.below(NUMBERS.len())]);
            }
        }
        3 => {
            let spans = string_spans(text);
            if let Some(&span) = spans.get(rng.below(spans.len())) {
                return replace(span, ["\"\"", "\"zzz\""][rng.below(2)]);
            }
        }
        4 => {
            let spans = array_spans(text);
            if let Some(&span) = spans.get(rng.below(spans.len())) {
                return replace(span, ["[]", "[1]", "[0, 0]"][rng.below(3)]);
            }
        }
        _ => {}
    }
    let lines: Vec<(usize, &str)> = line_starts(text).collect();
    if rng.below(2) == 0 && !lines.is_empty() {
        let (start, line) = lines[rng.below(lines.len())];
        return replace((start, start + line.len()), "");
    }
    let mut cut = rng.below(text.len());
    while !text.is_char_boundary(cut) {
        cut -= 1;
    }
    (format!("cut at byte {cut}"), text[..cut].to_string())
}

/// Loads, builds and renders `text` as if it were the file `path`; errors are fine.
/// Returns whether it got as far as rendering.
fn exercise(text: &str, path: &Path) -> bool {
    let Ok((scene, _animation)) = file::parse_animated(text, path) else {
        return false;
    };
    let Ok(projection) = scene.projection.build(8, 6) else {
        return false;
    };
    let options = RenderOptions {
        shading: Shading::Flat,
        ..RenderOptions::default()
    };
    let mut methods = vec![Method::Raycast];
    if projection.has_inverse() {
        methods.push(Method::Raster);
    }
    if projection.as_trilinear().is_some() {
        methods.push(Method::Trilinear);
    }
    for method in methods {
        let _ = composite::render_with_method(&scene, projection.as_ref(), &options, method);
    }
    true
}

fn example_scenes() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    scenes.sort();
    scenes
}

#[test]
fn spoiled_example_scenes_are_refused_or_rendered_never_a_panic() {
    let scenes = example_scenes();
    assert!(scenes.len() >= 20, "found only {} scenes", scenes.len());
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut panics, mut rendered) = (Vec::new(), 0);
    for path in &scenes {
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{e}"));
        for _ in 0..MUTATIONS {
            let (what, spoiled) = mutate(&text, &mut rng);
            match catch_unwind(AssertUnwindSafe(|| exercise(&spoiled, path))) {
                Ok(reached_render) => rendered += usize::from(reached_render),
                Err(_) => panics.push(format!("{}: {what}", path.display())),
            }
        }
    }
    assert!(
        panics.is_empty(),
        "{} panics:\n{}",
        panics.len(),
        panics.join("\n")
    );
    // Most mutations keep a loadable scene (a changed colour or position): if few reach the
    // renderers, the mutations (or the paths the scenes resolve models against) are broken
    // and the test checks nothing past the parser.
    let total = scenes.len() * MUTATIONS;
    assert!(
        4 * rendered >= total,
        "only {rendered} of {total} mutations were rendered"
    );
    eprintln!("{rendered} of {total} spoiled scenes loaded and rendered, the rest refused");
}
