//! Fixed-length arrays read strictly: serde reads the first N elements of a TOML array into
//! `[T; N]` and the toml crate drops the rest unseen, so `position = [0, 2, 6, "x"]` would
//! read as `[0, 2, 6]`. Fields of the raw structs whose type holds a fixed-length array are
//! read through [`strict`] instead, which refuses an array of any other length at its span.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{self, Deserializer, IgnoredAny, SeqAccess, Visitor};
use serde::Deserialize;
use toml::Spanned;

/// A raw field type that [`strict`] can read: numbers, and fixed-length arrays, vectors,
/// options and spans of such types, nested to any depth.
pub trait Shape<'de>: Sized {
    /// Reads `Self`, refusing fixed-length arrays of the wrong length.
    fn read<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error>;
}

/// For `#[serde(deserialize_with = "strict")]` (with `default` on optional fields).
pub fn strict<'de, D: Deserializer<'de>, T: Shape<'de>>(deserializer: D) -> Result<T, D::Error> {
    T::read(deserializer)
}

/// Adapts a [`Shape`] to serde's `Deserialize`, for the containers that take one.
struct Strict<T>(T);

impl<'de, T: Shape<'de>> Deserialize<'de> for Strict<T> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        T::read(deserializer).map(Strict)
    }
}

macro_rules! plain_shapes {
    ($($t:ty),*) => {$(
        impl<'de> Shape<'de> for $t {
            fn read<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
                <$t>::deserialize(deserializer)
            }
        }
    )*};
}
plain_shapes!(f64, i64, u32);

impl<'de, T: Shape<'de>> Shape<'de> for Option<T> {
    fn read<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        Ok(Option::<Strict<T>>::deserialize(deserializer)?.map(|s| s.0))
    }
}

impl<'de, T: Shape<'de>> Shape<'de> for Vec<T> {
    fn read<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        Ok(Vec::<Strict<T>>::deserialize(deserializer)?
            .into_iter()
            .map(|s| s.0)
            .collect())
    }
}

impl<'de, T: Shape<'de>> Shape<'de> for Spanned<T> {
    fn read<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let spanned = Spanned::<Strict<T>>::deserialize(deserializer)?;
        let span = spanned.span();
        Ok(Spanned::new(span, spanned.into_inner().0))
    }
}

impl<'de, T: Shape<'de>, const N: usize> Shape<'de> for [T; N] {
    fn read<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_seq(ArrayVisitor(PhantomData))
    }
}

/// Reads exactly N elements, then counts any left over into the error.
struct ArrayVisitor<T, const N: usize>(PhantomData<T>);

impl<'de, T: Shape<'de>, const N: usize> Visitor<'de> for ArrayVisitor<T, N> {
    type Value = [T; N];

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "an array of length {N}")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[T; N], A::Error> {
        let mut elements = Vec::with_capacity(N);
        while elements.len() < N {
            match seq.next_element::<Strict<T>>()? {
                Some(Strict(x)) => elements.push(x),
                None => return Err(de::Error::invalid_length(elements.len(), &self)),
            }
        }
        let mut extra = 0;
        while seq.next_element::<IgnoredAny>()?.is_some() {
            extra += 1;
        }
        if extra > 0 {
            return Err(de::Error::invalid_length(N + extra, &self));
        }
        Ok(elements
            .try_into()
            .unwrap_or_else(|_| unreachable!("exactly N elements were read")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Deserialize)]
    struct Table {
        #[serde(default, deserialize_with = "strict")]
        v: Option<Spanned<[f64; 3]>>,
        #[serde(default, deserialize_with = "strict")]
        list: Option<Spanned<Vec<[u32; 3]>>>,
    }

    fn error(text: &str) -> String {
        toml::from_str::<Table>(text)
            .unwrap_err()
            .message()
            .to_string()
    }

    #[test]
    fn exact_lengths_read_as_arrays() {
        let t: Table = toml::from_str("v = [1, 2, 3.5]\nlist = [[0, 1, 2]]").unwrap();
        assert_eq!(*t.v.unwrap().get_ref(), [1.0, 2.0, 3.5]);
        assert_eq!(*t.list.unwrap().get_ref(), vec![[0, 1, 2]]);
        let t: Table = toml::from_str("").unwrap();
        assert!(t.v.is_none() && t.list.is_none());
    }

    #[test]
    fn extra_or_missing_elements_are_refused_at_the_array() {
        let text = "v = [0, 2, 6, \"x\"]";
        let e = toml::from_str::<Table>(text).unwrap_err();
        assert_eq!(e.span(), Some(4..18));
        assert_eq!(
            e.message(),
            "invalid length 4, expected an array of length 3"
        );
        assert!(error("v = [1, 2]").contains("invalid length 2"));
        assert!(error("list = [[0, 1, 2, 3]]").contains("invalid length 4"));
        assert!(error("v = [1, 2, \"x\"]").contains("invalid type"));
    }

    /// The class guard: every field of the raw scene-file structs whose type holds a
    /// fixed-length array (`[T; N]`, or `Vec3Value`) is read through [`strict`], so a new key
    /// cannot silently drop extra elements again.
    #[test]
    fn every_fixed_length_field_is_read_strictly() {
        for (file, text) in [
            ("raw.rs", include_str!("raw.rs")),
            ("displacement.rs", include_str!("displacement.rs")),
        ] {
            let lines: Vec<&str> = text.lines().collect();
            for (i, line) in lines.iter().enumerate().skip(1) {
                let Some((name, ty)) = line.trim().trim_start_matches("pub ").split_once(": ")
                else {
                    continue;
                };
                let is_field = name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
                let fixed = ty.contains("Vec3Value")
                    || ty
                        .split("; ")
                        .skip(1)
                        .any(|rest| rest.trim_start().starts_with(|c: char| c.is_ascii_digit()));
                if is_field && fixed && !ty.starts_with("type ") {
                    assert!(
                        lines[i - 1].contains("deserialize_with = \"strict\""),
                        "{file}:{}: `{}` holds a fixed-length array but is not read strictly",
                        i + 1,
                        line.trim()
                    );
                }
            }
        }
    }
}
