//! Motion file formats: BVH import/export, `.npy` joint arrays, `.json`.

pub mod bvh_export;
