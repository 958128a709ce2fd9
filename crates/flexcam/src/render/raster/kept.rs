//! Per-object values a renderer keeps from frame to frame while what they depend on stays the
//! same: the common part of [`super::pole_clearance`] and [`super::kept_coordinates`].
//!
//! The values live with the renderer's other buffers, which go from renderer to renderer of
//! one prepared scene, whose objects do not change; the key (bits of what the values are
//! computed from) and each object's number of values are compared, so kept values are the
//! ones a new computation would give.

use crate::scene::{Mesh, Scene};

/// Per object of a scene, values computed for `key`.
#[derive(Debug)]
pub struct KeptPerObject<K, T> {
    key: Option<K>,
    values: Vec<Vec<T>>,
}

impl<K, T> Default for KeptPerObject<K, T> {
    fn default() -> Self {
        KeptPerObject {
            key: None,
            values: Vec::new(),
        }
    }
}

impl<K: PartialEq, T> KeptPerObject<K, T> {
    /// The values of `scene`'s objects: those kept where they were computed for an equal
    /// `key` and every object has `len(mesh)` of them, else computed again by `compute`
    /// (which fills an object's vector from its mesh) and kept with `key`.
    pub fn update(
        &mut self,
        key: K,
        scene: &Scene,
        len: impl Fn(&Mesh) -> usize,
        compute: impl Fn(&Mesh, &mut Vec<T>),
    ) -> &[Vec<T>] {
        let counts_match = self.values.len() == scene.objects.len()
            && self
                .values
                .iter()
                .zip(&scene.objects)
                .all(|(values, object)| values.len() == len(&object.mesh));
        if self.key.as_ref() != Some(&key) || !counts_match {
            self.key = Some(key);
            self.values.resize_with(scene.objects.len(), Vec::new);
            for (object, values) in scene.objects.iter().zip(self.values.iter_mut()) {
                compute(&object.mesh, values);
            }
        }
        &self.values
    }
}
