//! The reference ray caster: a BVH built once per scene, tiles rendered in parallel.
