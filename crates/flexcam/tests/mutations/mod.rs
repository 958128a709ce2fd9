//! Spoiling a scene file in small ways, for the tests that check that bad input is refused
//! cleanly (`crates/flexcam/tests/scene_mutations.rs`, the library: never a panic;
//! `crates/flexcam-cli/tests/spoiled_scenes.rs`, the binary: one error line naming the file,
//! no output). Deterministic: a seed gives the same mutations, so a failure reproduces.

use std::path::{Path, PathBuf};

/// Replacement numbers: zero, negatives, non-finite, huge, subnormal, tiny and small ones.
const NUMBERS: [&str; 10] = [
    "0", "-1", "0.0", "-0.0", "nan", "inf", "-inf", "1e308", "1e-320", "2",
];

/// A small deterministic generator (xorshift64*), so failures reproduce.
pub struct Rng(pub u64);

impl Rng {
    pub fn below(&mut self, n: usize) -> usize {
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
pub fn mutate(text: &str, rng: &mut Rng) -> (String, String) {
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

/// The example scenes, `scenes/*.toml`, sorted.
pub fn example_scenes() -> Vec<PathBuf> {
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .unwrap_or_else(|e| panic!("{}: {e}", scenes_dir().display()))
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    scenes.sort();
    scenes
}

/// The repository's `scenes/` folder.
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}
