//! Checks of individual values, each reporting the value's own position: every number must be
//! finite (TOML allows `nan` and `inf`) and within f32 range, since meshes are f32.

use glam::{DVec3, Vec3};
use toml::Spanned;

use super::source::Source;
use crate::error::Result;

impl Source<'_> {
    /// A finite number within f32 range.
    pub fn number(&self, value: &Spanned<f64>, key: &str) -> Result<f64> {
        self.finite(value.get_ref(), value, key)?;
        Ok(*value.get_ref())
    }

    /// A finite number greater than zero.
    pub fn positive(&self, value: &Spanned<f64>, key: &str) -> Result<f64> {
        let x = self.number(value, key)?;
        if x <= 0.0 {
            return Err(self.error(&value.span(), format!("`{key}` must be positive, not {x}")));
        }
        Ok(x)
    }

    /// A vector of finite numbers within f32 range.
    pub fn vector<const N: usize>(&self, value: &Spanned<[f64; N]>, key: &str) -> Result<[f64; N]> {
        self.all_finite(value.get_ref(), value, key)?;
        Ok(*value.get_ref())
    }

    /// A 3-vector, in f64 (projection parameters).
    pub fn dvec3(&self, value: &Spanned<[f64; 3]>, key: &str) -> Result<DVec3> {
        self.vector(value, key).map(DVec3::from_array)
    }

    /// A 3-vector, in f32 (scene geometry).
    pub fn vec3(&self, value: &Spanned<[f64; 3]>, key: &str) -> Result<Vec3> {
        self.dvec3(value, key).map(|v| v.as_vec3())
    }

    /// A linear RGB colour: finite, non-negative components (above 1 is allowed, for
    /// emitters and bright lights).
    pub fn color(&self, value: &Spanned<[f64; 3]>, key: &str) -> Result<Vec3> {
        let color = self.vec3(value, key)?;
        if color.min_element() < 0.0 {
            return Err(self.error(
                &value.span(),
                format!(
                    "`{key}` components must not be negative, got {:?}",
                    value.get_ref()
                ),
            ));
        }
        Ok(color)
    }

    /// Fails unless every number of `numbers` (the value of `key` at `at`) is finite and
    /// within f32 range.
    pub fn all_finite<T>(&self, numbers: &[f64], at: &Spanned<T>, key: &str) -> Result<()> {
        numbers.iter().try_for_each(|x| self.finite(x, at, key))
    }

    fn finite<T>(&self, x: &f64, at: &Spanned<T>, key: &str) -> Result<()> {
        if (*x as f32).is_finite() {
            Ok(())
        } else if x.is_finite() {
            Err(self.error(
                &at.span(),
                format!(
                    "`{key}` value {x:e} is out of range (beyond single precision, about 3.4e38)"
                ),
            ))
        } else {
            Err(self.error(
                &at.span(),
                format!("`{key}` must be a finite number, not {x}"),
            ))
        }
    }
}
