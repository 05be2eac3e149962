//! Training set built from BVH folders: features, joints, captions, splits, statistics.
