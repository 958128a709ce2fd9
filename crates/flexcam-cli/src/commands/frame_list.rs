//! `animate --frames LIST`: which frames of an animation a command renders, as render farms
//! write them (`3,5-10,20-40:5`): comma-separated items, each a frame number `N`, an
//! inclusive range `A-B`, or a range with a step `A-B:S` (A, A + S, ... up to B).

use flexcam::{Error, Result};

/// The frames of `list` in increasing order, each once, all below `frames` (the animation's
/// frame count). Errors name the item and the `--frames` argument: an empty item, a
/// non-number, a range running backwards, a zero step, a frame past the last.
pub fn parse(list: &str, frames: u32) -> Result<Vec<u32>> {
    let refuse = |item: &str, why: String| Error::new(format!("--frames {list}: {item:?} {why}"));
    let mut chosen = Vec::new();
    for item in list.split(',').map(str::trim) {
        let number = |text: &str| {
            text.trim().parse::<u32>().map_err(|_| {
                refuse(
                    item,
                    "is not a frame number, a range A-B or a range with a step A-B:S".into(),
                )
            })
        };
        let (range, step) = match item.split_once(':') {
            Some((range, step)) => (range, number(step)?),
            None => (item, 1),
        };
        let (first, last) = match range.split_once('-') {
            Some((a, b)) => (number(a)?, number(b)?),
            None if step == 1 && !item.contains(':') => (number(range)?, number(range)?),
            None => return Err(refuse(item, "has a step but no range A-B".into())),
        };
        if step == 0 {
            return Err(refuse(item, "has a zero step".into()));
        }
        if first > last {
            return Err(refuse(item, "runs backwards".into()));
        }
        if last >= frames {
            return Err(refuse(
                item,
                format!(
                    "is past the last frame, {} (frames count from 0)",
                    frames - 1
                ),
            ));
        }
        chosen.extend((first..=last).step_by(step as usize));
    }
    chosen.sort_unstable();
    chosen.dedup();
    Ok(chosen)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn items_ranges_and_steps_in_order_each_once() {
        assert_eq!(
            parse("3,5-10,20-40:5", 41).unwrap(),
            vec![3, 5, 6, 7, 8, 9, 10, 20, 25, 30, 35, 40]
        );
        assert_eq!(parse("4, 0-2, 1", 5).unwrap(), vec![0, 1, 2, 4]);
        assert_eq!(parse("0-9:4", 10).unwrap(), vec![0, 4, 8]);
        assert_eq!(parse("7-7", 8).unwrap(), vec![7]);
    }

    #[test]
    fn bad_items_are_named() {
        for (list, message) in [
            ("3,,4", "--frames 3,,4: \"\" is not a frame number"),
            ("x", "--frames x: \"x\" is not a frame number"),
            ("5-2", "--frames 5-2: \"5-2\" runs backwards"),
            ("0-4:0", "--frames 0-4:0: \"0-4:0\" has a zero step"),
            ("3:2", "--frames 3:2: \"3:2\" has a step but no range A-B"),
            (
                "1,9",
                "--frames 1,9: \"9\" is past the last frame, 8 (frames count from 0)",
            ),
            ("-1", "--frames -1: \"-1\" is not a frame number"),
        ] {
            let e = parse(list, 9).unwrap_err().to_string();
            assert!(e.starts_with(message), "{list}: {e}");
        }
    }
}
