//! Motion file formats: BVH import, `.npy` joint arrays, `.json`.

pub mod bvh;
