//! The nearest valid key for a misspelt one: serde's "unknown field `fvo`, expected one of
//! `type`, `position`, ... (57 names)" becomes "unknown key `fvo`; did you mean `fov`?".

/// `message` with serde's list of expected fields replaced by the nearest of them, or
/// `None` when it is not serde's unknown-field message.
pub(super) fn unknown_key(message: &str) -> Option<String> {
    let rest = message.strip_prefix("unknown field `")?;
    let (key, rest) = rest.split_once('`')?;
    let expected: Vec<&str> = rest.split('`').skip(1).step_by(2).collect();
    Some(match nearest(key, &expected) {
        Some(best) => format!("unknown key `{key}`; did you mean `{best}`?"),
        None => format!("unknown key `{key}`: this table takes no keys"),
    })
}

/// The candidate nearest `word` by edit distance (the first of equals), `None` when there
/// are no candidates.
fn nearest<'a>(word: &str, candidates: &[&'a str]) -> Option<&'a str> {
    candidates
        .iter()
        .min_by_key(|c| edit_distance(word, c))
        .copied()
}

/// The Levenshtein distance between `a` and `b`: the fewest single-character insertions,
/// deletions and substitutions that turn one into the other.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let substitute = diagonal + usize::from(ca != cb);
            diagonal = row[j + 1];
            row[j + 1] = substitute.min(row[j] + 1).min(diagonal + 1);
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distances() {
        assert_eq!(edit_distance("fvo", "fov"), 2);
        assert_eq!(edit_distance("widht", "width"), 2);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("same", "same"), 0);
    }

    #[test]
    fn serde_lists_become_the_nearest_key() {
        assert_eq!(
            unknown_key(
                "unknown field `lookat`, expected one of `type`, `position`, `look_at`, `up`"
            )
            .as_deref(),
            Some("unknown key `lookat`; did you mean `look_at`?")
        );
        assert_eq!(
            unknown_key("unknown field `colour`, expected `color`").as_deref(),
            Some("unknown key `colour`; did you mean `color`?")
        );
        assert_eq!(
            unknown_key("unknown field `x`, there are no fields").as_deref(),
            Some("unknown key `x`: this table takes no keys")
        );
        assert_eq!(unknown_key("invalid type: string"), None);
    }
}
